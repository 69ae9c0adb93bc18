//! Study logs as the analyses read them: CSV with a header, of which only the columns an
//! analysis names are read (a log holds many more: the runner logs every stimulus parameter).
//! A cell the runner marked as text for spreadsheets (a leading `'`) is read as the text it was.
//! A trial is counted once: a file named twice, or a participant's trial number found twice
//! (where the logs have a `trial` column), is refused with both places. A practice trial (a
//! row whose `practice` column, where the logs have one, is 1) is no data, and is left out. A
//! dry run's trial (`dry_run` 1: answered while nothing played) is no data either: refused,
//! unless the caller asks to read dry runs ([`DryRuns::Read`]), and then counted.

use std::collections::HashMap;
use std::path::Path;

use super::error::{shown, AnalysisError};
use sake_glug_io::read::{self, InputKind};
use sake_glug_io::text::{from_csv_cell, quoted};

/// The column every analysis reads first: who answered.
const PARTICIPANT: &str = "participant";
/// The column that numbers a participant's trials, read where a log has it.
const TRIAL: &str = "trial";
/// The column that marks a practice trial (1), read where a log has it.
const PRACTICE: &str = "practice";
/// The column that marks a dry run's trial (1), read where a log has it.
const DRY_RUN: &str = "dry_run";

/// Whether an analysis reads the trials of a dry run (`experiment --dry-run`, answered while
/// nothing played): refused by default, for they are no listening result; read when asked
/// (`--dry-run-logs`), and counted in the analysis, which says so.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum DryRuns {
    /// A dry run's trial is refused, naming its file and line.
    #[default]
    Refused,
    /// A dry run's trials are read as any, and counted.
    Read,
}

/// The rows an analysis reads, and how many of them are a dry run's.
pub(crate) struct Rows<const N: usize> {
    /// Every row read, in order.
    pub rows: Vec<LogRow<N>>,
    /// How many of them a dry run answered.
    pub dry_run_trials: usize,
}

/// One row of a log: where it is, and the fields of the columns asked for, trimmed, in the order
/// asked for.
pub(crate) struct LogRow<const N: usize> {
    /// The log it came from, as messages show it.
    pub file: String,
    /// Its line in the file (1 is the header).
    pub line: u64,
    /// The fields, in the order of the columns asked for.
    pub fields: [String; N],
}

impl<const N: usize> LogRow<N> {
    /// An error about the field of `column` on this row.
    pub fn error(&self, column: &'static str, message: impl Into<String>) -> AnalysisError {
        AnalysisError::Field {
            file: self.file.clone(),
            line: self.line,
            column,
            message: message.into(),
        }
    }

    /// The field of the `index`th column asked for, as a message quotes it: escaped, cut short.
    pub fn quoted(&self, index: usize) -> String {
        format!("`{}`", quoted(&self.fields[index]))
    }
}

/// Every row of every log, the fields of `columns` (the first of which is the participant's);
/// blank lines are skipped, a dry run's trials refused or counted as `dry_runs` says.
pub(crate) fn read_rows<const N: usize>(
    files: &[impl AsRef<Path>],
    columns: [&'static str; N],
    dry_runs: DryRuns,
) -> Result<Rows<N>, AnalysisError> {
    debug_assert_eq!(columns.first(), Some(&PARTICIPANT));
    refuse_repeated_files(files)?;
    let mut rows = Rows {
        rows: Vec::new(),
        dry_run_trials: 0,
    };
    let mut trials: HashMap<(String, String), (String, u64)> = HashMap::new();
    for file in files {
        read_file(file.as_ref(), columns, dry_runs, &mut rows, &mut trials)?;
    }
    Ok(rows)
}

/// Refuses a file named twice (by another path, a link: the same device and inode).
fn refuse_repeated_files(files: &[impl AsRef<Path>]) -> Result<(), AnalysisError> {
    let mut seen: HashMap<(u64, u64), &Path> = HashMap::new();
    for file in files {
        let file = file.as_ref();
        // A file that cannot be read is refused by the reader, with its reason.
        let Some(identity) = identity(file) else {
            continue;
        };
        if let Some(first) = seen.insert(identity, file) {
            return Err(AnalysisError::read(
                file,
                format!(
                    "the same file as {}: each log is read once, or its trials would count twice",
                    shown(first)
                ),
            ));
        }
    }
    Ok(())
}

/// The device and inode of `file`, which name it whatever the path.
fn identity(file: &Path) -> Option<(u64, u64)> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        std::fs::metadata(file)
            .ok()
            .map(|metadata| (metadata.dev(), metadata.ino()))
    }
    #[cfg(not(unix))]
    {
        let _ = file;
        None
    }
}

fn read_file<const N: usize>(
    file: &Path,
    columns: [&'static str; N],
    dry_runs: DryRuns,
    rows: &mut Rows<N>,
    trials: &mut HashMap<(String, String), (String, u64)>,
) -> Result<(), AnalysisError> {
    let name = shown(file);
    let input = read::open(file, InputKind::STUDY_LOG)
        .map_err(|error| AnalysisError::read(file, error.failure))?;
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .from_reader(std::io::BufReader::new(input));
    let headers = reader
        .headers()
        .map_err(|error| row_error(&name, &error, 1))?
        .clone();
    let column = |wanted: &str| headers.iter().position(|header| header.trim() == wanted);
    let mut indices = [0; N];
    for (slot, wanted) in indices.iter_mut().zip(columns) {
        *slot = column(wanted).ok_or_else(|| AnalysisError::MissingColumn {
            file: name.clone(),
            column: wanted,
            needed: columns.map(|column| format!("`{column}`")).join(", "),
        })?;
    }
    let trial_column = column(TRIAL);
    let practice_column = column(PRACTICE);
    let dry_run_column = column(DRY_RUN);
    for record in reader.records() {
        let record = record.map_err(|error| row_error(&name, &error, 0))?;
        let line = record.position().map_or(0, |position| position.line());
        let field = |index: usize| from_csv_cell(record.get(index).unwrap_or("").trim()).to_owned();
        if practice_column.is_some_and(|index| field(index) == "1") {
            continue;
        }
        if dry_run_column.is_some_and(|index| field(index) == "1") {
            if dry_runs == DryRuns::Refused {
                return Err(AnalysisError::Row {
                    file: name,
                    line,
                    message: "a dry run's trial (`dry_run` is 1): it was answered while nothing \
                              played, so it is no listening result; --dry-run-logs (Python: \
                              dry_run_logs=True) analyses a dry run's log, said to be one"
                        .into(),
                });
            }
            rows.dry_run_trials += 1;
        }
        let fields = indices.map(field);
        if let Some(trial) = trial_column.map(field).filter(|trial| !trial.is_empty()) {
            let key = (fields[0].clone(), trial);
            if let Some((first_file, first_line)) = trials.get(&key) {
                return Err(AnalysisError::Row {
                    file: name,
                    line,
                    message: format!(
                        "participant `{}`, trial `{}` again (first at {first_file}, line \
                         {first_line}): a trial is counted once; is a log given twice?",
                        quoted(&key.0),
                        quoted(&key.1)
                    ),
                });
            }
            trials.insert(key, (name.clone(), line));
        }
        rows.rows.push(LogRow {
            file: name.clone(),
            line,
            fields,
        });
    }
    Ok(())
}

fn row_error(file: &str, error: &csv::Error, fallback_line: u64) -> AnalysisError {
    let line = error
        .position()
        .map_or(fallback_line, |position| position.line());
    AnalysisError::Row {
        file: file.to_owned(),
        line,
        message: csv_message(error),
    }
}

/// The csv crate's message without the position it adds, which the error names already.
fn csv_message(error: &csv::Error) -> String {
    match error.kind() {
        csv::ErrorKind::Io(error) => error.to_string(),
        csv::ErrorKind::Utf8 { .. } => "a field is not UTF-8 text".into(),
        csv::ErrorKind::UnequalLengths {
            expected_len, len, ..
        } => format!("{len} fields where the header has {expected_len}"),
        _ => error.to_string(),
    }
}
