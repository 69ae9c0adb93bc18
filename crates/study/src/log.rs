//! The trial log: one CSV row per answered trial, written and synced to disk as the answer
//! comes, so that an interrupted session (Ctrl-C, a crash, a power cut) keeps every answer
//! given. Unlike the renderer's files it is appended to, not written all or nothing; so it is
//! protected otherwise: opened for appending only (`O_APPEND`), a regular file only, locked for
//! its session (an advisory lock: a second session on it is refused at once), read and checked
//! whole before a resumed session writes anything, and never shortened. Text cells that a
//! spreadsheet would read as a formula are written as text.

use std::fs::{File, TryLockError};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::session::{Place, StudySession};
use super::StudyError;
use sake_glug_io::append::open_to_append;
use sake_glug_io::text::{csv_cell, cut_quotes, from_csv_cell, quoted};
use sake_glug_io::InputKind;

/// One answered trial. The struct's fields are the log's columns, in order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LogRow {
    /// The participant's ID.
    pub participant: String,
    /// The trial's number in the session, from 1.
    pub trial: usize,
    /// `paired` or `constant`.
    pub design: String,
    /// The stimulus played first.
    pub first: String,
    /// The stimulus played second.
    pub second: String,
    /// The name of the stimulus chosen.
    pub answer: String,
    /// The key answered: 1 (the first) or 2 (the second).
    pub pressed: u8,
    /// Seconds from the end of the second stimulus to the answer.
    pub rt_s: f64,
    /// The seed of the participant's trial order.
    pub seed: u64,
    /// Constant design: the comparison's level (empty for paired).
    pub level: Option<f64>,
    /// Constant design: 1 if the comparison was chosen, else 0 (empty for paired).
    pub chose_comparison: Option<u8>,
    /// The equalisation gain applied to the first stimulus (dB).
    pub first_gain_db: f64,
    /// The equalisation gain applied to the second stimulus (dB).
    pub second_gain_db: f64,
    /// The audio interface's frame (JACK frame time) at which the first stimulus started;
    /// empty in a dry run.
    pub first_onset_frame: Option<u64>,
    /// The frame at which the second stimulus started.
    pub second_onset_frame: Option<u64>,
    /// The first stimulus as the spec defines it (inline TOML).
    pub first_params: String,
    /// The second stimulus as the spec defines it.
    pub second_params: String,
    /// 1 for a practice trial (not data: the analyses leave it out), 0 for the study's.
    pub practice: u8,
    /// 2AFC: 1 if the target was chosen, else 0 (empty for the other designs).
    pub correct: Option<u8>,
}

impl LogRow {
    /// The row as written: every text cell that a spreadsheet would read as a formula marked
    /// as text ([`csv_cell`]).
    fn written(&self) -> Self {
        let cell = |text: &str| csv_cell(text).into_owned();
        Self {
            participant: cell(&self.participant),
            design: cell(&self.design),
            first: cell(&self.first),
            second: cell(&self.second),
            answer: cell(&self.answer),
            first_params: cell(&self.first_params),
            second_params: cell(&self.second_params),
            ..self.clone()
        }
    }

    /// The row as it was before [`LogRow::written`]: the text marks taken off.
    fn read_back(self) -> Self {
        let text = |cell: String| from_csv_cell(&cell).to_owned();
        Self {
            participant: text(self.participant),
            design: text(self.design),
            first: text(self.first),
            second: text(self.second),
            answer: text(self.answer),
            first_params: text(self.first_params),
            second_params: text(self.second_params),
            ..self
        }
    }
}

/// An open trial log, appended to row by row, and locked while it is open: one session at a time.
#[derive(Debug)]
pub struct TrialLog {
    path: PathBuf,
    file: File,
}

impl TrialLog {
    /// Refuses at once, before anything is rendered, a log that cannot serve: for a new session
    /// (`resume` false) an existing path, for `--resume` a missing one, and any path that is not
    /// a regular file (a FIFO, a device, a folder). [`TrialLog::create`] and
    /// [`TrialLog::resume`] check the file they open again.
    pub fn check_path(path: &Path, resume: bool) -> Result<(), StudyError> {
        match std::fs::metadata(path) {
            Ok(metadata) if !metadata.is_file() => Err(StudyError::Io {
                path: path.to_owned(),
                source: std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    "it is not a regular file, so it cannot be a trial log",
                ),
            }),
            Ok(_) if !resume => Err(StudyError::LogExists(path.to_owned())),
            Err(error) if resume && error.kind() == std::io::ErrorKind::NotFound => {
                Err(StudyError::NothingToResume(path.to_owned()))
            }
            _ => Ok(()),
        }
    }

    /// A new log at `path`, locked, with its header; an existing file is refused (it may hold a
    /// session).
    pub fn create(path: &Path) -> Result<Self, StudyError> {
        let file = open_to_append(path, true).map_err(|source| {
            if source.kind() == std::io::ErrorKind::AlreadyExists {
                StudyError::LogExists(path.to_owned())
            } else {
                StudyError::Io {
                    path: path.to_owned(),
                    source,
                }
            }
        })?;
        let mut log = Self::locked(path, file)?;
        let mut writer = csv::Writer::from_writer(Vec::new());
        writer
            .write_record(header())
            .map_err(|error| log.io(error.into()))?;
        log.write(&writer.into_inner().expect("a Vec never fails"))?;
        Ok(log)
    }

    /// The log at `path` reopened to continue `session`, locked, and read whole before anything
    /// is written to it: every row must be the session's (same participant, design, seed, each
    /// trial's stimuli in the planned order, an answer that is one of them, and for the constant
    /// design its level and whether the comparison was chosen), and the file must end with a
    /// whole row. A log that fails is refused as it is: nothing is cut or written. Returns the
    /// log and how many trials it holds.
    pub fn resume(path: &Path, session: &StudySession) -> Result<(Self, usize), StudyError> {
        let file = open_to_append(path, false).map_err(|source| {
            if source.kind() == std::io::ErrorKind::NotFound {
                StudyError::NothingToResume(path.to_owned())
            } else {
                StudyError::Io {
                    path: path.to_owned(),
                    source,
                }
            }
        })?;
        let mut log = Self::locked(path, file)?;
        let limit = InputKind::STUDY_LOG.max_bytes;
        let mut bytes = Vec::new();
        (&mut log.file)
            .take(limit + 1)
            .read_to_end(&mut bytes)
            .map_err(|source| log.io(source))?;
        let bad = |line: u64, message: String| StudyError::Log {
            path: path.to_owned(),
            line,
            message,
        };
        if bytes.len() as u64 > limit {
            return Err(bad(
                1,
                format!("it holds more than a trial log may ({} MiB)", limit >> 20),
            ));
        }
        // Rows end in a line break: whatever follows the last one is checked last, so that a
        // log of another session says so first.
        let whole = bytes
            .iter()
            .rposition(|&byte| byte == b'\n')
            .map_or(bytes.len(), |at| at + 1);
        let mut reader = csv::Reader::from_reader(&bytes[..whole]);
        let found: Vec<String> = reader
            .headers()
            .map_err(|error| bad(1, cut_quotes(&error.to_string())))?
            .iter()
            .map(str::to_owned)
            .collect();
        if found != header() {
            return Err(bad(
                1,
                format!("its columns are not a trial log's ({})", header().join(",")),
            ));
        }
        let places = session.places();
        let mut done = 0;
        for record in reader.deserialize::<LogRow>() {
            let row = record
                .map_err(|error| {
                    let line = error.position().map_or(0, |position| position.line());
                    bad(line, cut_quotes(&error.to_string()))
                })?
                .read_back();
            let line = 2 + done as u64;
            check_row(&row, done, &places, session).map_err(|what| {
                bad(
                    line,
                    format!(
                        "{what}: the log is from another spec or participant; name another log"
                    ),
                )
            })?;
            done += 1;
        }
        if bytes.last().is_some_and(|&last| last != b'\n') {
            let line = 1 + bytes.iter().filter(|&&byte| byte == b'\n').count() as u64;
            return Err(bad(
                line,
                "the last line ends without a line break: a row cut short (by a crash while \
                 it was written) or not a trial log's; nothing was changed. If that line is a \
                 torn trial, delete it (the trial is then asked again) and resume"
                    .into(),
            ));
        }
        Ok((log, done))
    }

    /// `file` locked for this session: refused at once if another session holds it. The lock is
    /// std's `File::try_lock` (an exclusive `flock` on Unix, `LockFileEx` on Windows, released
    /// when the file is closed, a crash included), stable since Rust 1.89, the workspace's
    /// minimum: no crate (fs2, fs4) or unsafe `libc::flock` needed. It is advisory: it keeps out
    /// another session, not an editor.
    fn locked(path: &Path, file: File) -> Result<Self, StudyError> {
        match file.try_lock() {
            Ok(()) => Ok(Self {
                path: path.to_owned(),
                file,
            }),
            Err(TryLockError::WouldBlock) => Err(StudyError::LogInUse(path.to_owned())),
            Err(TryLockError::Error(source)) => Err(StudyError::Io {
                path: path.to_owned(),
                source,
            }),
        }
    }

    /// Appends `row` and syncs it to disk before returning.
    pub fn append(&mut self, row: &LogRow) -> Result<(), StudyError> {
        let mut writer = csv::WriterBuilder::new()
            .has_headers(false)
            .from_writer(Vec::new());
        writer
            .serialize(row.written())
            .map_err(|error| self.io(error.into()))?;
        self.write(&writer.into_inner().expect("a Vec never fails"))
    }

    /// One write of a whole row at the end of the file, then to disk.
    fn write(&mut self, bytes: &[u8]) -> Result<(), StudyError> {
        self.file
            .write_all(bytes)
            .and_then(|()| self.file.sync_data())
            .map_err(|source| self.io(source))
    }

    fn io(&self, source: std::io::Error) -> StudyError {
        StudyError::Io {
            path: self.path.clone(),
            source,
        }
    }
}

/// Whether `row` is what `session` plans at its place `index` (0-based, of `places`), with one
/// of its two answers; else what differs, for the message.
fn check_row(
    row: &LogRow,
    index: usize,
    places: &[Place],
    session: &StudySession,
) -> Result<(), String> {
    let shown = |text: &str| format!("`{}`", quoted(text));
    if row.participant != session.participant {
        return Err(format!("participant {}", shown(&row.participant)));
    }
    let design = session.spec.design.name();
    if row.design != design || row.seed != session.seed {
        return Err(format!(
            "design {}, seed {} (this session: `{design}`, seed {})",
            shown(&row.design),
            row.seed,
            session.seed
        ));
    }
    let Some(&place) = places.get(index) else {
        return Err(format!("trial {}, past the session's last", row.trial));
    };
    if row.practice != u8::from(place.practice) {
        return Err(format!(
            "row {}: practice {}, where this session plans {}",
            index + 1,
            row.practice,
            if place.practice {
                "a practice trial (1)"
            } else {
                "a trial of the study (0)"
            }
        ));
    }
    let pressed = match row.pressed {
        1 | 2 => row.pressed,
        other => {
            return Err(format!(
                "trial {}: key {other} pressed, not 1 or 2",
                row.trial
            ))
        }
    };
    let planned = session.planned_row(place, pressed);
    let same_trial = row.trial == planned.trial
        && row.first == planned.first
        && row.second == planned.second
        && row.first_params == planned.first_params
        && row.second_params == planned.second_params;
    if !same_trial {
        return Err(format!(
            "trial {} is {} then {}; this spec plans trial {} as {} then {}",
            row.trial,
            shown(&row.first),
            shown(&row.second),
            planned.trial,
            shown(&planned.first),
            shown(&planned.second)
        ));
    }
    // Compared as written: a level is the spec's number, read back exactly.
    let same_answer = row.answer == planned.answer
        && row.level == planned.level
        && row.chose_comparison == planned.chose_comparison
        && row.correct == planned.correct;
    if !same_answer {
        return Err(format!(
            "trial {}: answer {}, key {pressed}, level {:?}, chose_comparison {:?}, correct \
             {:?}; key {pressed} of this trial chooses {} (level {:?}, chose_comparison {:?}, \
             correct {:?})",
            row.trial,
            shown(&row.answer),
            row.level,
            row.chose_comparison,
            row.correct,
            shown(&planned.answer),
            planned.level,
            planned.chose_comparison,
            planned.correct
        ));
    }
    if !(row.rt_s.is_finite() && row.rt_s >= 0.0) {
        return Err(format!(
            "trial {}: response time {} s is not a time",
            row.trial, row.rt_s
        ));
    }
    Ok(())
}

/// The log's columns: [`LogRow`]'s fields, in order.
pub fn header() -> Vec<String> {
    let mut writer = csv::Writer::from_writer(Vec::new());
    writer
        .serialize(LogRow {
            participant: String::new(),
            trial: 0,
            design: String::new(),
            first: String::new(),
            second: String::new(),
            answer: String::new(),
            pressed: 0,
            rt_s: 0.0,
            seed: 0,
            level: None,
            chose_comparison: None,
            first_gain_db: 0.0,
            second_gain_db: 0.0,
            first_onset_frame: None,
            second_onset_frame: None,
            first_params: String::new(),
            second_params: String::new(),
            practice: 0,
            correct: None,
        })
        .expect("a Vec never fails");
    let bytes = writer.into_inner().expect("a Vec never fails");
    let mut reader = csv::Reader::from_reader(&bytes[..]);
    reader
        .headers()
        .expect("just written")
        .iter()
        .map(str::to_owned)
        .collect()
}
