//! The analysis of the paper's two studies from their trial logs (docs/studies.md):
//!
//! - paired comparison (§3): the count matrix, Thurstone's Case V scale, Mosteller's test of its
//!   fit and a test of the participants' agreement ([`analyze_paired_logs`]);
//! - constant stimuli (§4.4): a logistic psychometric function fitted by maximum likelihood,
//!   its 25/50/75 % points with parametric-bootstrap 95 % intervals, pooled and per participant
//!   ([`analyze_constant_logs`]);
//! - the plan of a constant-stimuli study: its intervals and their coverage, simulated with
//!   observers of a known curve ([`plan_constant`]).
//!
//! A log is CSV with a header; only the columns an analysis names are read. A bad log is
//! refused with its file, line and column ([`AnalysisError`]), never analysed in part.

mod constant;
mod error;
mod json;
mod log;
mod paired;
mod plan;
#[cfg(feature = "plot")]
mod plot;

pub use constant::{
    analyze_constant_logs, count_levels, fit_psychometric, ConstantAnalysis, LevelCount, Logistic,
    Placement, PointEstimate, PsychometricFit, PsychometricFitError, PsychometricOptions,
    CONSTANT_COLUMNS, MAX_LAPSE, MAX_RESAMPLES, POINT_PERCENTS,
};
pub use error::AnalysisError;
pub use json::{constant_json, paired_json, plan_json};
pub use paired::{
    analyze_paired_logs, scale_paired, ChiSquareTest, PairedAnalysis, PairedTrial,
    MAX_PAIRED_STIMULI, PAIRED_COLUMNS,
};
pub use plan::{
    plan_constant, ConstantPlan, PlanError, PlanOutcome, PlannedPoint, MAX_PLAN_FITS,
    MAX_PLAN_LEVELS, MAX_PLAN_PARTICIPANTS, MAX_PLAN_REPETITIONS, MAX_STUDIES,
};
#[cfg(feature = "plot")]
pub use plot::{draw_constant_plot, draw_paired_plot};
