//! What can be wrong with a study log or its analysis: every message names the file, and where
//! there is one the line and the column.

use std::path::Path;

use thiserror::Error;

use sake_glug_io::text::printable;

/// A study log that cannot be analysed, or an analysis output that cannot be written.
#[derive(Debug, Error)]
pub enum AnalysisError {
    /// The log could not be opened or read.
    #[error("{file}: {message}")]
    Read {
        /// The log.
        file: String,
        /// What the system said.
        message: String,
    },
    /// The log lacks a column the analysis needs.
    #[error("{file}: no column `{column}` in its header (the analysis needs {needed})")]
    MissingColumn {
        /// The log.
        file: String,
        /// The missing column.
        column: &'static str,
        /// Every column the analysis needs.
        needed: String,
    },
    /// A row that is not CSV as its header says (a row of another length, bad UTF-8).
    #[error("{file}, line {line}: {message}")]
    Row {
        /// The log.
        file: String,
        /// The row's line (1 the header).
        line: u64,
        /// What is wrong.
        message: String,
    },
    /// A field that the analysis cannot use.
    #[error("{file}, line {line}, column `{column}`: {message}")]
    Field {
        /// The log.
        file: String,
        /// The row's line (1 the header).
        line: u64,
        /// The column.
        column: &'static str,
        /// What is wrong with its value.
        message: String,
    },
    /// The trials of all the logs together cannot be analysed (no trial, one stimulus, a pair
    /// never compared, one level).
    #[error("{files}: {message}")]
    Design {
        /// The logs, comma-separated.
        files: String,
        /// What is missing.
        message: String,
    },
    /// An option out of its range.
    #[error("{0}")]
    Option(String),
    /// A plot that could not be drawn or written (nothing is left at its path).
    #[cfg(feature = "plot")]
    #[error(transparent)]
    Plot(#[from] sake_glug_plot::PlotError),
}

impl AnalysisError {
    pub(crate) fn read(file: &Path, error: impl std::fmt::Display) -> Self {
        Self::Read {
            file: shown(file),
            message: error.to_string(),
        }
    }

    pub(crate) fn design(files: &[impl AsRef<Path>], message: impl Into<String>) -> Self {
        let names: Vec<String> = files.iter().map(|file| shown(file.as_ref())).collect();
        // A design message quotes stimulus and participant names, which come from the logs.
        Self::Design {
            files: names.join(", "),
            message: printable(&message.into()).into_owned(),
        }
    }
}

/// A path as messages show it, control characters escaped.
pub(crate) fn shown(path: &Path) -> String {
    printable(&path.display().to_string()).into_owned()
}
