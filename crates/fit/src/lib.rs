//! `sake-glug fit`: the paper's method on a user's recordings (MODEL.md §13). A [`FitSession`] names
//! WAV recordings at known tilts with their start volumes or weight logs (or is made of clips
//! alone, [`FitSession::of_clips`]); [`fit_session`] fits them one at a time, finds every glug
//! unit and fits each (eq. 1, or one or two phased components where eq. 1 as it stands does not
//! describe a real unit), keeps those whose fit explains them, and turns the units, the drain
//! lines and the rest levels into one model per liquid: a scene file the renderer plays
//! ([`LiquidFit::model_toml`]). [`report_markdown`] gives every estimate with its 95 % interval
//! (or why it has none), [`fit_json`] the same numbers as JSON (the CLI's `--json` and Python's
//! `fit()`), [`units_csv`] every detected unit, [`draw_fit_plot`] and [`draw_compare_plot`] the
//! pictures; [`write_fit`] writes them all or none.

mod audio;
mod by_ear;
#[cfg(feature = "plot")]
mod compare_plot;
mod curves;
mod error;
mod estimate;
mod headspace;
mod json;
mod liquid;
pub mod listen;
mod model_toml;
mod onsets;
#[cfg(feature = "plot")]
mod plot;
mod pour;
mod recording;
mod report;
mod session;
mod session_fit;
mod spectrum;
mod stats;
mod units;
mod units_table;
mod weight;
mod write;

pub mod compare;
pub mod comparisons;

pub use audio::{Audio, FIT_BYTES_PER_SAMPLE, MIN_SAMPLE_RATE_HZ};
pub use by_ear::{misses, not_nearer, Listened, ListeningFit, Measure};
#[cfg(feature = "plot")]
pub use compare_plot::draw_compare_plot;
pub use curves::FittedCurves;
pub use error::{FitError, SampleFault};
pub use estimate::{Estimate, Source, MIN_UNITS_FOR_INTERVAL, MIN_UNITS_FOR_MODEL};
pub use headspace::{HeadspaceLaw, ModeLaw};
pub use json::fit_json;
pub use liquid::LiquidFit;
pub use onsets::detect_onsets;
#[cfg(feature = "plot")]
pub use plot::draw_fit_plot;
pub use recording::{DrainLine, FittedUnit, RecordingFit, LOW_EXPLAINED};
pub use report::report_markdown;
pub use session::{FitSession, RecordingSpec, WeightSpec, DEFAULT_LIQUID};
pub use session_fit::{fit_session, SessionFit};
pub use spectrum::{own_peaks, Spectrum};
pub use stats::Line;
pub use units::{
    fit_units, Component, DetectedUnit, Modes, RecordingUnits, Rejection, UnitFit, UnitMethod,
    AT_PEAK_SHARE, MIN_EXPLAINED,
};
pub use units_table::{units_csv, UNIT_COLUMNS};
pub use weight::WeightLog;
pub use write::{write_fit, FitOutputs};
