//! Listening studies (feature `study`): the paper's two designs, and discrimination (2AFC,
//! triangle, ABX), run on any actuator.
//!
//! A [`Spec`] file names the stimuli (scenes, presets or model files with scene keys over them,
//! or recordings) and the design; [`plan_trials`] orders a participant's trials from a seed;
//! [`render_stimuli`] renders each stimulus once with the offline renderer (or reads a
//! recording) and matches their levels; a [`StudySession`]
//! presents the trials through a [`Presenter`] (with feature `audio` a JACK server or an ALSA
//! device, whose samples come from one mix; or [`DryRun`] for a dry run, which names the
//! files [`write_dry_run`] writes and marks the log's rows), reads each answer and appends it to the [`TrialLog`] at once.
//! `sake-glug analyze` reads that log.

#[cfg(feature = "audio")]
mod alsa_out;
mod dry_run;
#[cfg(feature = "audio")]
mod jack_out;
mod log;
#[cfg(feature = "audio")]
mod mix;
mod recording;
mod session;
mod spec;
mod stimuli;
mod trials;

use std::path::PathBuf;

#[cfg(feature = "audio")]
pub use alsa_out::{AlsaOutput, AlsaPlayer};
pub use dry_run::{check_dry_run_folder, write_dry_run, DryRun, DryRunFiles, TRIAL_LIST};
#[cfg(feature = "audio")]
pub use jack_out::{JackOutput, JackPlayer};
pub use log::{header as log_header, LogRow, TrialLog};
pub use recording::{Recording, RECORDING_RATES_HZ};
pub use session::{Onsets, Place, Presented, Presenter, Silent, StudySession};
pub use spec::{
    level_keys, Channels, Design, Discriminate, Equalize, Source, Spec, Stimulus,
    DISCRIMINATE_DESIGNS, MAX_NOISE_DBFS, MAX_PRACTICE, MAX_TRIALS, MIN_NOISE_DBFS, STANDARD,
    STIMULUS_KEYS,
};
pub use stimuli::{level_of, render_stimuli, Rendered};
pub use trials::{order_seed, plan_practice, plan_trials, Trial};

/// Why a study could not run, or stopped.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// An input file (the spec) could not be read: missing, not a regular file, too large.
    #[error(transparent)]
    Read(#[from] sake_glug_io::ReadError),
    /// A file could not be read or written.
    #[error("{}: {source}", shown(.path))]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The spec is not valid: the message names the key.
    #[error("{}: {message}", shown(.path))]
    Spec {
        /// The spec file.
        path: PathBuf,
        /// What was wrong, and where.
        message: String,
    },
    /// A stimulus could not be made into a scene or rendered.
    #[error("{}: stimulus `{name}`: {message}", shown(.path))]
    Stimulus {
        /// The spec file.
        path: PathBuf,
        /// The stimulus's name.
        name: String,
        /// What was wrong (the scene's message names the key).
        message: String,
    },
    /// A new session's log already exists.
    #[error(
        "{} already exists: pass --resume to continue its session, or name a new log",
        shown(.0)
    )]
    LogExists(PathBuf),
    /// Another session holds the log's lock.
    #[error(
        "{}: another session is writing to this log (it is locked); wait for it to end, or \
         name another log",
        shown(.0)
    )]
    LogInUse(PathBuf),
    /// `--resume` with no log.
    #[error("{}: no such log, so nothing to resume; leave out --resume to start", shown(.0))]
    NothingToResume(PathBuf),
    /// A log that cannot be resumed.
    #[error("{}, line {line}: {message}", shown(.path))]
    Log {
        /// The log.
        path: PathBuf,
        /// The line, from 1.
        line: u64,
        /// What was wrong.
        message: String,
    },
    /// The answers ended before the trials.
    #[error(
        "the answers ended (stdin closed) after {answered} of {total} trials; the log keeps \
         them, and --resume continues"
    )]
    InputClosed {
        /// Trials answered, in this run and before.
        answered: usize,
        /// Trials in the session.
        total: usize,
    },
    /// The dry run's folder.
    #[error("--dry-run {}: {message}", shown(.path))]
    DryRunFolder {
        /// The folder.
        path: PathBuf,
        /// What was wrong.
        message: String,
    },
    /// The stimuli cannot be held in memory.
    #[error("{0}")]
    Memory(String),
    /// The audio interface.
    #[error("{0}")]
    Audio(String),
}

/// A path as a message shows it: control characters escaped.
fn shown(path: &std::path::Path) -> String {
    sake_glug_io::text::printable(&path.to_string_lossy()).into_owned()
}
