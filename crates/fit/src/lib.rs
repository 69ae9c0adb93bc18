//! `sake-glug fit`: the paper's method on a user's recordings (MODEL.md §13). A [`FitSession`] names
//! WAV recordings at known tilts with their start volumes or weight logs; [`fit_session`] finds
//! every glug unit, fits each with eq. 1, and turns the units, the drain lines and the rest
//! levels into one model per liquid: a scene file the renderer plays ([`LiquidFit::model_toml`]).
//! [`report_markdown`] gives every estimate with its 95 % interval, [`draw_fit_plot`] the units,
//! the spectrum, Asum against V and V(t); [`write_fit`] writes them all or none.

mod audio;
mod error;
mod estimate;
mod onsets;
#[cfg(feature = "plot")]
mod plot;
mod report;
mod session;
mod spectrum;
mod stats;
mod unit;
mod write;

pub use audio::{Audio, MIN_SAMPLE_RATE_HZ};
pub use error::FitError;
pub use estimate::{
    fit_session, DrainLine, Estimate, FittedCurves, FittedUnit, LiquidFit, RecordingFit, SessionFit,
};
pub use onsets::detect_onsets;
#[cfg(feature = "plot")]
pub use plot::draw_fit_plot;
pub use report::report_markdown;
pub use session::{FitSession, RecordingSpec, WeightSpec, DEFAULT_LIQUID};
pub use spectrum::Spectrum;
pub use stats::Line;
pub use unit::{fit_units, RecordingUnits, UnitFit};
pub use weight::WeightLog;
pub use write::{write_fit, FitOutputs};

mod weight;
