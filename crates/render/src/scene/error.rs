//! Why a scene was refused: [`SceneError`], each naming the key or the file, outside text
//! escaped.

use std::path::{Path, PathBuf};

use sake_glug_device::csv_lane::CsvLaneError;
use sake_glug_device::midi_take::TakeError;
use sake_glug_engine::ValueError;
use sake_glug_io::read::ReadFailure;
use sake_glug_io::text::printable;

/// Why a scene was refused. Text from the scene or a file it names is shown with its control
/// characters escaped ([`printable`]).
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file could not be read: missing, not a regular file, too large, not UTF-8.
    #[error("cannot read scene file {}: {source}", shown(path))]
    Read {
        /// The file's path.
        path: PathBuf,
        /// Why not.
        source: ReadFailure,
    },
    /// The file of a CSV lane could not be read.
    #[error("cannot read CSV lane `{key}` file {}: {source}", shown(path))]
    CsvFile {
        /// The scene key.
        key: &'static str,
        /// The file's path.
        path: PathBuf,
        /// Why not.
        source: ReadFailure,
    },
    /// The file of a MIDI take could not be read.
    #[error("cannot read MIDI take {}: {source}", shown(path))]
    TakeFile {
        /// The file's path.
        path: PathBuf,
        /// Why not.
        source: ReadFailure,
    },
    /// Not valid TOML, an unknown key or a value of the wrong type: the parser's message, its
    /// control characters escaped.
    #[error("invalid scene: {0}")]
    Syntax(String),
    /// A value the model cannot take: out of range, V0 not below the capacity, or no curve.
    #[error(transparent)]
    Value(#[from] ValueError),
    /// A CSV lane could not be read: the error names the file, line and column.
    #[error("`{key}`: {source}")]
    Csv {
        /// The scene key.
        key: &'static str,
        /// What was wrong, and where.
        source: CsvLaneError,
    },
    /// A CSV lane's table is not one of the two forms.
    #[error("`{key}`: {}", printable(message))]
    CsvForm {
        /// The scene key.
        key: &'static str,
        /// What was wrong.
        message: String,
    },
    /// The MIDI take is not one the renderer reads.
    #[error("midi take {}: {source}", shown(path))]
    Take {
        /// The take's path.
        path: PathBuf,
        /// What was wrong.
        source: TakeError,
    },
    /// A `[variations]` table that cannot be drawn from: its message names the key.
    #[error(transparent)]
    Variations(#[from] super::variations_table::VariationError),
    /// A value that must be a whole number (the sample rate) has a fraction.
    #[error("`{key}` = {value} is not a whole number: {what}")]
    NotWhole {
        /// The scene key (also for the command line's override of it).
        key: &'static str,
        /// The value given.
        value: f64,
        /// Why it must be whole, in the message.
        what: &'static str,
    },
    /// An automation point whose time is not finite, is negative or comes before the previous
    /// point's.
    #[error("`{key}`: point {index} is at {time_s} s; point times must be finite, at least 0 and in order")]
    PointTime {
        /// The scene key.
        key: &'static str,
        /// Index of the point in the list, from 0.
        index: usize,
        /// The point's time (s).
        time_s: f64,
    },
}

/// A path for a message.
pub(super) fn shown(path: &Path) -> String {
    printable(&path.to_string_lossy()).into_owned()
}

/// A [`SceneError::Syntax`] whose message may quote the scene.
pub(super) fn syntax(message: &str) -> SceneError {
    SceneError::Syntax(printable(message).into_owned())
}
