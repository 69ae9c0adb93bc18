//! The analysis of the paper's two studies from their trial logs (docs/studies.md):
//!
//! - paired comparison (§3): the count matrix, Thurstone's Case V scale, Mosteller's test of its
//!   fit and a test of the participants' agreement ([`analyze_paired_logs`]);
//! - constant stimuli (§4.4): a logistic psychometric function fitted by maximum likelihood,
//!   its 25/50/75 % points with parametric-bootstrap 95 % intervals, pooled and per participant
//!   ([`analyze_constant_logs`]);
//! - the plan of a constant-stimuli study: its intervals and their coverage, simulated with
//!   observers of a known curve ([`plan_constant`]);
//! - discrimination (triangle, 2AFC, ABX): the proportion correct with its exact interval, the
//!   test against chance, d′ under the design's decision model with its profile-likelihood
//!   interval, pooled and per participant ([`analyze_discrimination_logs`]), and the plan of
//!   such a study by simulation ([`plan_discrimination`]).
//!
//! A log is CSV with a header; only the columns an analysis names are read. A bad log is
//! refused with its file, line and column ([`AnalysisError`]), never analysed in part.

mod constant;
mod discrimination;
mod discrimination_plan;
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
pub use discrimination::{
    analyze_discrimination_logs, estimate_discrimination, DiscriminationAnalysis,
    DiscriminationDesign, DiscriminationEstimate, CONFIDENCE, DISCRIMINATION_COLUMNS, MAX_D_PRIME,
};
pub use discrimination_plan::{
    plan_discrimination, DiscriminationGoal, DiscriminationPlan, DiscriminationPlanOutcome,
    PlannedSize, MAX_PLAN_TRIALS_EACH,
};
pub use error::AnalysisError;
pub use json::{
    constant_json, discrimination_json, discrimination_plan_json, paired_json, plan_json,
};
pub use log::DryRuns;
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
