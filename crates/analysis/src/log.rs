//! Study logs as the analyses read them: CSV with a header, of which only the columns an
//! analysis names are read (a log holds many more: the runner logs every stimulus parameter).

use sake_glug_io::read::{self, InputKind};
use std::path::Path;

use super::error::{shown, AnalysisError};
use sake_glug_io::text::printable;

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

    /// The field of the `index`th column asked for, as a message quotes it.
    pub fn quoted(&self, index: usize) -> String {
        format!("`{}`", printable(&self.fields[index]))
    }
}

/// Every row of every log, the fields of `columns`; blank lines are skipped.
pub(crate) fn read_rows<const N: usize>(
    files: &[impl AsRef<Path>],
    columns: [&'static str; N],
) -> Result<Vec<LogRow<N>>, AnalysisError> {
    let mut rows = Vec::new();
    for file in files {
        read_file(file.as_ref(), columns, &mut rows)?;
    }
    Ok(rows)
}

fn read_file<const N: usize>(
    file: &Path,
    columns: [&'static str; N],
    rows: &mut Vec<LogRow<N>>,
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
    let mut indices = [0; N];
    for (slot, column) in indices.iter_mut().zip(columns) {
        *slot = headers
            .iter()
            .position(|header| header.trim() == column)
            .ok_or_else(|| AnalysisError::MissingColumn {
                file: name.clone(),
                column,
                needed: columns.map(|column| format!("`{column}`")).join(", "),
            })?;
    }
    for record in reader.records() {
        let record = record.map_err(|error| row_error(&name, &error, 0))?;
        let line = record.position().map_or(0, |position| position.line());
        let fields = indices.map(|index| record.get(index).unwrap_or("").trim().to_owned());
        rows.push(LogRow {
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
