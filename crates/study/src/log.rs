//! The trial log: one CSV row per answered trial, written and synced to disk as the answer
//! comes, so that an interrupted session (Ctrl-C, a crash, a power cut) keeps every answer
//! given. Unlike the renderer's files it is appended to, not written all or nothing.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::StudyError;

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
}

/// What a resumed log must agree on with the session about each row.
#[derive(Debug, Clone, PartialEq)]
pub struct Expected {
    /// The participant.
    pub participant: String,
    /// The design's name.
    pub design: &'static str,
    /// The order's seed.
    pub seed: u64,
    /// Each planned trial's first and second stimulus names and parameters.
    pub trials: Vec<[String; 4]>,
}

/// An open trial log, appended to row by row.
#[derive(Debug)]
pub struct TrialLog {
    path: PathBuf,
    file: File,
}

impl TrialLog {
    /// A new log at `path` with its header; an existing file is refused (it may hold a session).
    pub fn create(path: &Path) -> Result<Self, StudyError> {
        let io = |source| StudyError::Io {
            path: path.to_owned(),
            source,
        };
        let file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(path)
            .map_err(|source| {
                if source.kind() == std::io::ErrorKind::AlreadyExists {
                    StudyError::LogExists(path.to_owned())
                } else {
                    io(source)
                }
            })?;
        let mut writer = csv::Writer::from_writer(Vec::new());
        writer
            .write_record(header())
            .map_err(|error| io(error.into()))?;
        let mut log = Self {
            path: path.to_owned(),
            file,
        };
        log.write(&writer.into_inner().expect("a Vec never fails"))?;
        Ok(log)
    }

    /// The log at `path` reopened to continue a session: every row is checked against
    /// `expected` (same participant, design, seed, and each trial's stimuli in the planned
    /// order), and a last row torn by a crash mid-write is dropped. Returns the log and how
    /// many trials it holds.
    pub fn resume(path: &Path, expected: &Expected) -> Result<(Self, usize), StudyError> {
        let io = |source| StudyError::Io {
            path: path.to_owned(),
            source,
        };
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .open(path)
            .map_err(|source| {
                if source.kind() == std::io::ErrorKind::NotFound {
                    StudyError::NothingToResume(path.to_owned())
                } else {
                    io(source)
                }
            })?;
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes).map_err(io)?;
        // Rows end in a line break: anything after the last one was cut off mid-write.
        let whole = bytes
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |at| at + 1);
        if whole < bytes.len() {
            eprintln!(
                "note: {}: its last line was cut off mid-write and is dropped",
                path.display()
            );
            file.set_len(whole as u64).map_err(io)?;
        }
        let bad = |line: u64, message: String| StudyError::Log {
            path: path.to_owned(),
            line,
            message,
        };
        let mut reader = csv::Reader::from_reader(&bytes[..whole]);
        let found: Vec<String> = reader
            .headers()
            .map_err(|error| bad(1, error.to_string()))?
            .iter()
            .map(str::to_owned)
            .collect();
        if found != header() {
            return Err(bad(
                1,
                format!("its columns are not a trial log's ({})", header().join(",")),
            ));
        }
        let mut done = 0;
        for record in reader.deserialize::<LogRow>() {
            let row = record.map_err(|error| {
                let line = error.position().map_or(0, |position| position.line());
                bad(line, error.to_string())
            })?;
            let line = 2 + done as u64;
            let other = |what: String| {
                bad(
                    line,
                    format!(
                        "{what}: the log is from another spec or participant; name another log"
                    ),
                )
            };
            if row.participant != expected.participant {
                return Err(other(format!("participant `{}`", row.participant)));
            }
            if row.design != expected.design || row.seed != expected.seed {
                return Err(other(format!(
                    "design `{}`, seed {} (this session: `{}`, seed {})",
                    row.design, row.seed, expected.design, expected.seed
                )));
            }
            let planned = expected
                .trials
                .get(done)
                .ok_or_else(|| other(format!("trial {}, past the session's last", row.trial)))?;
            let logged = [
                row.first.clone(),
                row.second.clone(),
                row.first_params.clone(),
                row.second_params.clone(),
            ];
            if row.trial != done + 1 || &logged != planned {
                return Err(other(format!(
                    "trial {} is `{}` then `{}`; this spec plans trial {} as `{}` then `{}`",
                    row.trial,
                    row.first,
                    row.second,
                    done + 1,
                    planned[0],
                    planned[1]
                )));
            }
            done += 1;
        }
        file.seek(SeekFrom::End(0)).map_err(io)?;
        Ok((
            Self {
                path: path.to_owned(),
                file,
            },
            done,
        ))
    }

    /// Appends `row` and syncs it to disk before returning.
    pub fn append(&mut self, row: &LogRow) -> Result<(), StudyError> {
        let mut writer = csv::WriterBuilder::new()
            .has_headers(false)
            .from_writer(Vec::new());
        writer.serialize(row).map_err(|error| StudyError::Io {
            path: self.path.clone(),
            source: error.into(),
        })?;
        self.write(&writer.into_inner().expect("a Vec never fails"))
    }

    /// One write of a whole row, then to disk.
    fn write(&mut self, bytes: &[u8]) -> Result<(), StudyError> {
        self.file
            .write_all(bytes)
            .and_then(|()| self.file.sync_data())
            .map_err(|source| StudyError::Io {
                path: self.path.clone(),
                source,
            })
    }
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
