//! Why a fit was refused: every error names the file and, where it has one, the key, line or
//! column at fault. A fit that cannot be made is an error, never a made-up model.

use std::path::{Path, PathBuf};

use sake_glug_io::text::{cut_short, printable};
use sake_glug_io::ReadError;
use sake_glug_render::human_bytes;

/// Why `sake-glug fit` could not fit a model.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// The session file could not be read: missing, not a regular file, too large, not UTF-8.
    #[error(transparent)]
    SessionRead(ReadError),
    /// Not valid TOML, an unknown key or a value of the wrong type.
    #[error("invalid session {}: {message}", shown(path))]
    SessionSyntax {
        /// The session file.
        path: PathBuf,
        /// The parser's message, with the key.
        message: String,
    },
    /// A value of the session outside what the fit can use.
    #[error("session {}: `{key}` = {value}: {why}", shown(path))]
    SessionValue {
        /// The session file.
        path: PathBuf,
        /// The key, with the recording's index (`recording[2].tilt_deg`).
        key: String,
        /// The value given.
        value: f64,
        /// What was expected.
        why: &'static str,
    },
    /// The session names no recording.
    #[error("session {} has no [[recording]]: nothing to fit", shown(path))]
    NoRecording {
        /// The session file.
        path: PathBuf,
    },
    /// A recording could not be opened: missing, not a regular file, too large.
    #[error("`{key}`: {source}")]
    RecordingRead {
        /// The key naming it (`recording[0].audio`).
        key: String,
        /// Why not, with the file.
        source: ReadError,
    },
    /// A recording's WAV file could not be read.
    #[error("`{key}`: cannot read WAV file {}: {source}", shown(path))]
    Wav {
        /// The key naming it (`recording[0].audio`).
        key: String,
        /// The file.
        path: PathBuf,
        /// hound's error (a missing file included).
        source: hound::Error,
    },
    /// A recording sampled too slowly to show the glug's components.
    #[error(
        "`{key}`: {} is sampled at {rate} Hz, below the {min} Hz the fit needs",
        shown(path)
    )]
    RateTooLow {
        /// The key naming it.
        key: String,
        /// The file.
        path: PathBuf,
        /// Its rate (Hz).
        rate: u32,
        /// The lowest rate accepted (Hz).
        min: u32,
    },
    /// A recording too long to fit in the memory there is (refused before it is read).
    #[error(
        "`{key}`: {} holds {samples} samples, whose fit needs {} of memory; {} are available",
        shown(path),
        human_bytes(*needed),
        human_bytes(*available)
    )]
    TooLarge {
        /// The key naming it.
        key: String,
        /// The file.
        path: PathBuf,
        /// Its samples (one channel).
        samples: u64,
        /// The memory its fit needs (bytes).
        needed: u64,
        /// The memory available (bytes).
        available: u64,
    },
    /// A recording whose samples are corrupt: not finite, or an isolated spike.
    #[error("`{key}`: {}: {fault}", shown(path))]
    Samples {
        /// The key naming it.
        key: String,
        /// The file.
        path: PathBuf,
        /// What is wrong with them.
        fault: SampleFault,
    },
    /// A recording with nothing in it.
    #[error(
        "`{key}`: {} is silent (peak {} after its offset is removed)",
        shown(path),
        peak_text(*peak)
    )]
    Silent {
        /// The key naming it.
        key: String,
        /// The file.
        path: PathBuf,
        /// Its peak after the DC offset is removed.
        peak: f64,
    },
    /// A weight log that cannot be read: the file, line and column.
    #[error("`{key}`: {}, line {line}{}: {what}", shown(path), column.as_ref().map(|c| format!(", column {:?}", cut_short(c))).unwrap_or_default())]
    WeightLog {
        /// The key naming it (`recording[0].weight.csv`).
        key: String,
        /// The CSV file.
        path: PathBuf,
        /// The line, from 1 (0: the file as a whole).
        line: u64,
        /// The column at fault, if one is.
        column: Option<String>,
        /// What is wrong there.
        what: String,
    },
    /// A recording with neither a start volume nor a weight log: its volumes are unknown.
    #[error(
        "`{key}`: give `start_ml` or a `weight` log, so that the volume at each glug is known"
    )]
    NoVolume {
        /// The recording (`recording[1]`).
        key: String,
    },
    /// No glug unit was found in any recording of a liquid: there is nothing to fit.
    #[error("no glugs found in {what}: no unit rose above the noise (is it a pour?)")]
    NoGlugs {
        /// The recording or liquid.
        what: String,
    },
    /// Units were found, but eq. 1 describes none of them: the model cannot be fitted.
    #[error(
        "{what}: {detected} unit(s) detected, but the paper's model describes none of them \
         ({reasons}): no model is written"
    )]
    NoUnitDescribed {
        /// The liquid.
        what: String,
        /// Units detected.
        detected: usize,
        /// The reasons they were rejected, each with its count.
        reasons: String,
    },
    /// Too few units for any constant of the glug, and no model fitted by listening sounds nearer
    /// the recordings than the default bottle: writing that bottle would be a made-up result.
    #[error(
        "{what}: the paper's model describes {used} of its {detected} detected unit(s), too few \
         for any constant of its glugs, and no model fitted by listening sounds nearer the \
         recordings than the default bottle: no model is written"
    )]
    NothingNearer {
        /// The liquid.
        what: String,
        /// Units the model describes.
        used: usize,
        /// Units detected.
        detected: usize,
    },
    /// The units explain too little of the recordings, and neither their model nor any fitted by
    /// listening sounds nearer them than the default bottle on every measure a listener is asked
    /// about: writing the nearest would be a made-up result.
    #[error(
        "{what}: the paper's model describes {used} of its {detected} detected unit(s), which \
         explain too little of the recordings, and no model found sounds nearer them than the \
         default bottle on every measure (the nearest has {missed}): no model is written"
    )]
    NoModelNearer {
        /// The liquid.
        what: String,
        /// Units the model describes.
        used: usize,
        /// Units detected.
        detected: usize,
        /// What the nearest model found missed, recording by recording.
        missed: String,
    },
    /// An output file could not be written (nothing was: every file is written all or none).
    #[error("cannot write {}: {message}", shown(path))]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
    /// The plot could not be drawn or written (nor was any other file).
    #[cfg(feature = "plot")]
    #[error(transparent)]
    Plot(#[from] sake_glug_plot::PlotError),
    /// The outputs asked for do not fit the session (one model for several liquids).
    #[error("{0}")]
    Outputs(String),
    /// The inputs named make no one fit: two session files, a session among clips, the clips'
    /// capacity or tilt given with a session, or nothing at all.
    #[error("{0}")]
    Inputs(&'static str),
    /// A clips' option out of its range. `key` is its name in a session file (`capacity_ml`,
    /// `tilt_deg`): the command line's option is `--capacity-ml`, Python's argument the key.
    #[error("--{} {value}: {why}", key.replace('_', "-"))]
    ClipOption {
        /// The session file's key of the option.
        key: &'static str,
        /// The value given.
        value: f64,
        /// What was expected.
        why: &'static str,
    },
}

/// A path for a message.
pub(crate) fn shown(path: &Path) -> String {
    printable(&path.to_string_lossy()).into_owned()
}

/// What is wrong with a recording's samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SampleFault {
    /// Samples that are NaN or infinite (a float WAV only).
    NonFinite {
        /// How many.
        count: usize,
        /// The first's index.
        first: usize,
        /// …and time (s).
        first_s: f64,
    },
    /// One sample far above every other, more than 1 ms away.
    Spike {
        /// Its index.
        at: usize,
        /// …and time (s).
        at_s: f64,
        /// Its value.
        value: f64,
        /// How many times the largest other sample it is.
        ratio: f64,
    },
}

impl std::fmt::Display for SampleFault {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            SampleFault::NonFinite {
                count,
                first,
                first_s,
            } => write!(
                f,
                "{count} sample(s) are not finite numbers (NaN or infinite), the first at sample \
                 {first} ({first_s:.4} s): the file is corrupt"
            ),
            SampleFault::Spike {
                at,
                at_s,
                value,
                ratio,
            } => write!(
                f,
                "an isolated spike of {value:e} at sample {at} ({at_s:.4} s), {ratio:.3e} times \
                 any other sample: a corrupt sample, not a glug"
            ),
        }
    }
}

/// A silent recording's peak as a reader reads it: 0, or its level in dBFS.
fn peak_text(peak: f64) -> String {
    if peak > 0.0 {
        format!("{:.1} dBFS", 20.0 * peak.log10())
    } else {
        "0".to_owned()
    }
}
