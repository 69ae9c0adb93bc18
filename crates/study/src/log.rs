//! The trial log: one CSV row per answered trial, written and synced to disk as the answer
//! comes, so that an interrupted session (Ctrl-C, a crash, a power cut) keeps every answer
//! given. Unlike the renderer's files it is appended to, not written all or nothing; so it is
//! protected otherwise: opened for appending only (`O_APPEND`), a regular file only, locked for
//! its session (an advisory lock: a second session on it is refused at once), read and checked
//! whole before a resumed session writes anything, and never shortened. Text cells that a
//! spreadsheet would read as a formula are written as text.
//!
//! A log an earlier runner wrote lacks the columns added since (`practice`, `correct`, the
//! third stimulus's, `dry_run`): it is resumed in its own columns when the session would leave every
//! missing one blank, else refused, naming them. This module knows rows and files; whether a
//! row is the session's is the session's to say ([`TrialLog::resume`] takes its check).

use std::fs::{File, TryLockError};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::StudyError;
use sake_glug_io::append::open_to_append;
use sake_glug_io::text::{csv_cell, cut_quotes, from_csv_cell};
use sake_glug_io::InputKind;

/// One answered trial. The struct's fields are the log's columns, in order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LogRow {
    /// The participant's ID.
    pub participant: String,
    /// The trial's number in the session, from 1.
    pub trial: usize,
    /// The design's name: `paired`, `constant`, `2afc`, `triangle` or `abx`.
    pub design: String,
    /// The stimulus played first.
    pub first: String,
    /// The stimulus played second.
    pub second: String,
    /// The name of the stimulus chosen.
    pub answer: String,
    /// The key answered: 1 (the first), 2 (the second) or, in the triangle, 3 (the third).
    pub pressed: u8,
    /// Seconds from the end of the trial's last stimulus to the answer.
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
    /// 1 for a practice trial (not data: the analyses leave it out), 0 for the study's. A log
    /// written before the column has none: its rows are the study's.
    #[serde(default)]
    pub practice: u8,
    /// The discrimination designs: 1 if the answer was right (2AFC: the target chosen;
    /// triangle: the odd one; ABX: the one X is), else 0; empty for the other designs.
    pub correct: Option<u8>,
    /// The stimulus played third (triangle, ABX's X); empty in the two-interval designs.
    pub third: Option<String>,
    /// The equalisation gain applied to the third stimulus (dB).
    pub third_gain_db: Option<f64>,
    /// The frame at which the third stimulus started; empty in a dry run.
    pub third_onset_frame: Option<u64>,
    /// The third stimulus as the spec defines it.
    pub third_params: Option<String>,
    /// 1 for a trial of a dry run (nothing was played: its answer is no data, and the analyses
    /// refuse it unless asked to read dry runs), 0 for a trial played. A log written before the
    /// column has none: its trials were played, or its dry run was not marked.
    #[serde(default)]
    pub dry_run: u8,
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
            third: self.third.as_deref().map(cell),
            third_params: self.third_params.as_deref().map(cell),
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
            third: self.third.map(text),
            third_params: self.third_params.map(text),
            ..self
        }
    }
}

/// An open trial log, appended to row by row, and locked while it is open: one session at a time.
#[derive(Debug)]
pub struct TrialLog {
    path: PathBuf,
    file: File,
    /// The file's columns, as indices into [`header`]: all of them in a log this runner began,
    /// fewer in one an earlier runner began.
    columns: Vec<usize>,
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

    /// The log at `path` reopened to continue a session, locked, and read whole before anything
    /// is written to it: `check` must accept every row (given its index from 0; its message says
    /// what differs), and the file must end with a whole row. A log whose columns are an
    /// earlier runner's (some of [`header`]'s missing) is continued in its own columns if every
    /// row of `planned` (the rows the session may still write) leaves the missing ones blank.
    /// A log that fails is refused as it is: nothing is cut or written. Returns the log and how
    /// many trials it holds.
    pub fn resume(
        path: &Path,
        planned: &[LogRow],
        mut check: impl FnMut(usize, &LogRow) -> Result<(), String>,
    ) -> Result<(Self, usize), StudyError> {
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
        log.columns = columns_of(&found, planned).map_err(|message| bad(1, message))?;
        let mut done = 0;
        for record in reader.deserialize::<LogRow>() {
            let row = record
                .map_err(|error| {
                    let line = error.position().map_or(0, |position| position.line());
                    bad(line, cut_quotes(&error.to_string()))
                })?
                .read_back();
            let line = 2 + done as u64;
            check(done, &row).map_err(|what| {
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
                columns: (0..header().len()).collect(),
            }),
            Err(TryLockError::WouldBlock) => Err(StudyError::LogInUse(path.to_owned())),
            Err(TryLockError::Error(source)) => Err(StudyError::Io {
                path: path.to_owned(),
                source,
            }),
        }
    }

    /// Appends `row` (in the file's columns) and syncs it to disk before returning.
    pub fn append(&mut self, row: &LogRow) -> Result<(), StudyError> {
        let cells = cells(&row.written());
        let mut writer = csv::WriterBuilder::new()
            .has_headers(false)
            .from_writer(Vec::new());
        writer
            .write_record(self.columns.iter().map(|&column| &cells[column]))
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

/// The cells of `row` in [`header`]'s order, as written.
fn cells(row: &LogRow) -> Vec<String> {
    let mut writer = csv::WriterBuilder::new()
        .has_headers(false)
        .from_writer(Vec::new());
    writer.serialize(row).expect("a Vec never fails");
    let bytes = writer.into_inner().expect("a Vec never fails");
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .from_reader(&bytes[..]);
    let record = reader
        .records()
        .next()
        .expect("one row written")
        .expect("read as written");
    record.iter().map(str::to_owned).collect()
}

/// What a column holds in a row that leaves it blank: nothing, or for `practice` and `dry_run`
/// 0 (a log written before those columns holds the study's trials, played).
fn blank(column: &str) -> &'static str {
    if ["practice", "dry_run"].contains(&column) {
        "0"
    } else {
        ""
    }
}

/// The columns of a log whose header is `found`, as indices into [`header`]; refused, with the
/// reason, when a column is not a trial log's or is given twice, or when one is missing that a
/// row of `planned` fills.
fn columns_of(found: &[String], planned: &[LogRow]) -> Result<Vec<usize>, String> {
    let all = header();
    let not_a_log = || format!("its columns are not a trial log's ({})", all.join(","));
    let mut columns = Vec::with_capacity(found.len());
    for name in found {
        let index = all
            .iter()
            .position(|column| column == name)
            .ok_or_else(not_a_log)?;
        if columns.contains(&index) {
            return Err(not_a_log());
        }
        columns.push(index);
    }
    // An earlier runner's log: it lacks the columns added since, and keeps its own.
    let missing: Vec<usize> = (0..all.len())
        .filter(|index| !columns.contains(index))
        .collect();
    if missing.is_empty() {
        return Ok(columns);
    }
    if !missing
        .iter()
        .any(|&index| ["participant", "trial", "design"].contains(&all[index].as_str()))
    {
        let planned_cells: Vec<Vec<String>> = planned.iter().map(cells).collect();
        let filled: Vec<String> = missing
            .iter()
            .filter(|&&index| {
                planned_cells
                    .iter()
                    .any(|cells| cells[index] != blank(&all[index]))
            })
            .map(|&index| format!("`{}`", all[index]))
            .collect();
        if filled.is_empty() {
            return Ok(columns);
        }
        return Err(format!(
            "an earlier runner's log: it has no column {}, which this session fills (the \
             spec's practice trials, whether each answer was right, a third stimulus, a dry run's \
             mark); finish \
             it with the version that began it, or start a new log (`analyze` reads this one as \
             it is)",
            filled.join(", ")
        ));
    }
    Err(not_a_log())
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
            third: None,
            third_gain_db: None,
            third_onset_frame: None,
            third_params: None,
            dry_run: 0,
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
