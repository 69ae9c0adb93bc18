//! An automation lane from a CSV take: a header row naming a `time_s` column, then one row per
//! reading. The lane is a column's values, or the tilt worked out from three gravity columns.

use std::fmt;
use std::path::{Path, PathBuf};

use thiserror::Error;

use super::axis::{tilt_from_gravity, Axis};
use sake_glug_io::text::{cut_short, printable};

/// The column of times, in seconds from the start of the take.
pub const TIME_COLUMN: &str = "time_s";

/// The largest take file read ([`sake_glug_io::InputKind::CSV_LANE`]).
pub const MAX_CSV_LANE_BYTES: u64 = sake_glug_io::InputKind::CSV_LANE.max_bytes;

/// Which values of a CSV take make the lane.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CsvLaneSpec {
    /// The values of the named column, as they are.
    Column(String),
    /// The tilt in degrees from the gravity vector in the named x, y, z columns, the sensor's
    /// `axis` pointing from the bottle's base to its mouth (see [`tilt_from_gravity`]).
    Gravity {
        /// The x, y and z columns.
        columns: [String; 3],
        /// The sensor axis along the bottle.
        axis: Axis,
    },
}

/// A CSV take that cannot be read, with where: the file, the line (from 1, as a text editor
/// counts them, the header being line 1 unless blank lines come before it) and the columns.
#[derive(Debug, Clone, PartialEq)]
pub struct CsvLaneError {
    /// The file, as given to [`read_csv_lane`].
    pub file: PathBuf,
    /// The line, from 1.
    pub line: u64,
    /// The columns at fault: none, one, or the three of a gravity vector.
    pub columns: Vec<String>,
    /// What is wrong there.
    pub fault: CsvFault,
}

impl fmt::Display for CsvLaneError {
    /// `take.csv, line 7, column "ax": "abc" is not a number`.
    fn fmt(&self, formatter: &mut fmt::Formatter) -> fmt::Result {
        let file = self.file.to_string_lossy();
        write!(formatter, "{}, line {}", printable(&file), self.line)?;
        match self.columns.as_slice() {
            [] => {}
            [column] => write!(formatter, ", column {column:?}")?,
            columns => {
                formatter.write_str(", columns ")?;
                for (index, column) in columns.iter().enumerate() {
                    let separator = if index == 0 { "" } else { ", " };
                    write!(formatter, "{separator}{column:?}")?;
                }
            }
        }
        write!(formatter, ": {}", self.fault)
    }
}

impl std::error::Error for CsvLaneError {}

/// What is wrong at the place a [`CsvLaneError`] names. Nothing of the file is quoted but the
/// field at fault, cut short: a scene may name any file, and its error must not show it.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum CsvFault {
    /// The file holds nothing, not even a header.
    #[error("the file is empty: expected a header row with a {TIME_COLUMN} column")]
    Empty,
    /// A header and no data.
    #[error("no data rows after the header")]
    NoRows,
    /// A column the lane needs is not in the header (whose names are not quoted: the file may
    /// be no take at all).
    #[error("no such column in the header")]
    MissingColumn,
    /// A column the lane needs is named more than once, so which one is meant is unclear.
    #[error("named more than once in the header")]
    DuplicateColumn,
    /// The row ends before this column.
    #[error("missing: the row has {found} fields but the header has {expected}")]
    TooFewFields {
        /// The row's fields.
        found: usize,
        /// The header's columns.
        expected: usize,
    },
    /// The row goes on after the last column (often a decimal comma, as in `1,5`).
    #[error("the row has {found} fields but the header has {expected}, this being the last")]
    TooManyFields {
        /// The row's fields.
        found: usize,
        /// The header's columns.
        expected: usize,
    },
    /// A field that does not read as a number (its first characters, with `…` if cut).
    #[error("{0:?} is not a number")]
    NotANumber(String),
    /// A field that reads as infinity or NaN (its first characters, with `…` if cut).
    #[error("{0:?} is not a finite number")]
    NotFinite(String),
    /// A time before the start of the take.
    #[error("the time {0} s is negative")]
    NegativeTime(f64),
    /// A time before the previous row's.
    #[error("the time {time} s is earlier than the {previous} s of the row before")]
    TimeGoesBack {
        /// This row's time.
        time: f64,
        /// The previous row's time.
        previous: f64,
    },
    /// A gravity vector of zero length, which gives no tilt.
    #[error("the gravity vector is zero, so it has no direction")]
    ZeroVector,
    /// Text the CSV reader refuses.
    #[error("unreadable CSV: {}", printable(.0))]
    Unreadable(String),
}

/// Reads the lane `spec` picks from the CSV `text` of `file` (named in errors only) as
/// `(time_s, value)` points, in the file's order.
///
/// Fields are trimmed of spaces, and blank lines skipped; csv skips the UTF-8 byte order mark
/// that spreadsheets may save before the header. Times must be finite, non-negative and
/// non-decreasing (equal times make a step); values finite; every row as long as the header.
pub fn read_csv_lane(
    text: &str,
    file: &Path,
    spec: &CsvLaneSpec,
) -> Result<Vec<(f64, f64)>, CsvLaneError> {
    let fail = |line: u64, columns: &[&str], fault: CsvFault| CsvLaneError {
        file: file.to_path_buf(),
        line,
        columns: columns.iter().map(|name| (*name).to_owned()).collect(),
        fault,
    };
    let mut lines = LineCounter::new(text);
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        // Row lengths are checked here, to name the line and column.
        .flexible(true)
        .from_reader(text.as_bytes());
    let header = reader
        .headers()
        .map_err(|error| unreadable(&error, &mut lines, &fail))?
        .clone();
    let header_line = lines.line_of(header.position());
    if header.is_empty() {
        return Err(fail(header_line, &[], CsvFault::Empty));
    }

    let column_index = |name: &str| -> Result<usize, CsvLaneError> {
        let mut matches = header
            .iter()
            .enumerate()
            .filter(|(_, field)| *field == name);
        match (matches.next(), matches.next()) {
            (Some((index, _)), None) => Ok(index),
            (Some(_), Some(_)) => Err(fail(header_line, &[name], CsvFault::DuplicateColumn)),
            (None, _) => Err(fail(header_line, &[name], CsvFault::MissingColumn)),
        }
    };
    let time_index = column_index(TIME_COLUMN)?;
    let value_names: Vec<&str> = match spec {
        CsvLaneSpec::Column(name) => vec![name],
        CsvLaneSpec::Gravity { columns, .. } => columns.iter().map(String::as_str).collect(),
    };
    let value_indices = value_names
        .iter()
        .map(|name| column_index(name))
        .collect::<Result<Vec<_>, _>>()?;

    let mut points = Vec::new();
    let mut previous_time: Option<f64> = None;
    let mut record = csv::StringRecord::new();
    loop {
        match reader.read_record(&mut record) {
            Ok(true) => {}
            Ok(false) => break,
            Err(error) => return Err(unreadable(&error, &mut lines, &fail)),
        }
        let line = lines.line_of(record.position());
        // A line of spaces only, which csv reads as one empty field, is a blank line.
        if record.len() == 1 && record[0].is_empty() {
            continue;
        }
        if record.len() < header.len() {
            let first_missing = &header[record.len()];
            let fault = CsvFault::TooFewFields {
                found: record.len(),
                expected: header.len(),
            };
            return Err(fail(line, &[first_missing], fault));
        }
        if record.len() > header.len() {
            let last = &header[header.len() - 1];
            let fault = CsvFault::TooManyFields {
                found: record.len(),
                expected: header.len(),
            };
            return Err(fail(line, &[last], fault));
        }
        let number = |index: usize| -> Result<f64, CsvLaneError> {
            let field = &record[index];
            let name = &header[index];
            match field.parse::<f64>() {
                Ok(value) if value.is_finite() => Ok(value),
                Ok(_) => Err(fail(line, &[name], CsvFault::NotFinite(cut_short(field)))),
                Err(_) => Err(fail(line, &[name], CsvFault::NotANumber(cut_short(field)))),
            }
        };

        let time = number(time_index)?;
        if time < 0.0 {
            return Err(fail(line, &[TIME_COLUMN], CsvFault::NegativeTime(time)));
        }
        if let Some(previous) = previous_time.filter(|previous| time < *previous) {
            let fault = CsvFault::TimeGoesBack { time, previous };
            return Err(fail(line, &[TIME_COLUMN], fault));
        }
        previous_time = Some(time);

        let value = match spec {
            CsvLaneSpec::Column(_) => number(value_indices[0])?,
            CsvLaneSpec::Gravity { axis, .. } => {
                let reading = [
                    number(value_indices[0])?,
                    number(value_indices[1])?,
                    number(value_indices[2])?,
                ];
                tilt_from_gravity(reading, *axis)
                    .ok_or_else(|| fail(line, &value_names, CsvFault::ZeroVector))?
            }
        };
        points.push((time, value));
    }
    if points.is_empty() {
        return Err(fail(header_line + 1, &[], CsvFault::NoRows));
    }
    Ok(points)
}

/// A CSV reader error, at the line it names.
fn unreadable(
    error: &csv::Error,
    lines: &mut LineCounter,
    fail: &impl Fn(u64, &[&str], CsvFault) -> CsvLaneError,
) -> CsvLaneError {
    let line = lines.line_of(error.position());
    fail(line, &[], CsvFault::Unreadable(error.to_string()))
}

/// Lines as a text editor counts them (after `\n`, `\r\n` or a lone `\r`), for the records
/// csv reads.
///
/// csv's own line numbers are not usable: a record's position is where reading stopped after
/// the record before, ahead of the line break and any blank lines skipped, so they run short
/// after blank lines and with `\r\n` endings. Its byte offset is exact, though, and the record
/// starts at the first byte from there that is not a line break.
struct LineCounter<'a> {
    text: &'a [u8],
    /// How far lines are counted, and the line there.
    byte: usize,
    line: u64,
}

impl<'a> LineCounter<'a> {
    fn new(text: &'a str) -> Self {
        Self {
            text: text.as_bytes(),
            byte: 0,
            line: 1,
        }
    }

    /// The line of the record whose csv position is `position`; positions must not go back.
    fn line_of(&mut self, position: Option<&csv::Position>) -> u64 {
        let resume = position.map_or(self.byte, |position| {
            usize::try_from(position.byte()).unwrap_or(usize::MAX)
        });
        let resume = resume.clamp(self.byte, self.text.len());
        let breaks = self.text[resume..]
            .iter()
            .take_while(|&&byte| byte == b'\r' || byte == b'\n')
            .count();
        let start = resume + breaks;
        for index in self.byte..start {
            let ends_line = match self.text[index] {
                b'\n' => true,
                b'\r' => self.text.get(index + 1) != Some(&b'\n'),
                _ => false,
            };
            self.line += u64::from(ends_line);
        }
        self.byte = start;
        self.line
    }
}
