//! Planning a constant-stimuli study (`sake-glug analyze plan constant`): how precisely would a
//! design know its 25/50/75 % points? Many studies of the design are simulated with observers
//! whose psychometric function is known, each is fitted as `analyze constant` fits a log (the
//! same maximum-likelihood curve and BCa intervals, [`fit_psychometric`]), and the intervals are
//! measured against the truth: their median widths, how often they cover it, and where the
//! estimates fall.

use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Serialize;
use statrs::distribution::{Beta, ContinuousCDF};

use super::constant::{
    fit_psychometric, LevelCount, Logistic, PsychometricOptions, MAX_RESAMPLES, POINT_PERCENTS,
};

/// The most studies a plan simulates: enough for a coverage known to ±0.2 %, and a bound on how
/// long one runs.
pub const MAX_STUDIES: u32 = 100_000;

/// The most levels, repetitions a level and participants a planned study has: far past any
/// study of people, and a bound on the trials each simulated study draws.
pub const MAX_PLAN_LEVELS: usize = 1000;
/// See [`MAX_PLAN_LEVELS`].
pub const MAX_PLAN_REPETITIONS: u32 = 10_000;
/// See [`MAX_PLAN_LEVELS`].
pub const MAX_PLAN_PARTICIPANTS: u32 = 1000;

/// The most refits a plan asks for (studies × (resamples + 1)): about an hour on one core of a
/// laptop at the paper's nine levels.
pub const MAX_PLAN_FITS: u64 = 1_000_000_000;

/// A constant-stimuli design and the observers it is simulated with.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConstantPlan {
    /// The comparison levels, each presented `repetitions` times to every participant.
    pub levels: Vec<f64>,
    /// Presentations of each level to each participant.
    pub repetitions: u32,
    /// Participants, pooled into one fit as the paper's fig. 5 pools them.
    pub participants: u32,
    /// The simulated observers' 25 % point: a logistic through it and `p75`, the same for every
    /// participant.
    pub p25: f64,
    /// Their 75 % point.
    pub p75: f64,
    /// Studies simulated.
    pub studies: u32,
    /// Bootstrap resamples of each study's intervals.
    pub resamples: usize,
    /// The seed: the same plan and seed give the same figures on any machine.
    pub seed: u64,
}

/// An argument of a plan that cannot be simulated, named as the command line names it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{argument}: {message}")]
pub struct PlanError {
    /// The argument: `levels`, `p25`, `p75`, `repetitions`, `participants`, `studies`,
    /// `resamples`.
    pub argument: &'static str,
    /// What is wrong with it.
    pub message: String,
}

fn refuse(argument: &'static str, message: impl Into<String>) -> PlanError {
    PlanError {
        argument,
        message: message.into(),
    }
}

/// What the simulated studies give for one point of the psychometric function.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PlannedPoint {
    /// 25, 50 or 75.
    pub percent: u8,
    /// The observers' true point.
    pub truth: f64,
    /// Studies whose 95 % interval holds the truth.
    pub covered: u32,
    /// `covered` over the studies fitted.
    pub coverage: f64,
    /// The 95 % Clopper-Pearson interval of that coverage (how well this many studies know it).
    pub coverage_low: f64,
    /// Its upper end.
    pub coverage_high: f64,
    /// The median width of the studies' 95 % intervals.
    pub median_width: f64,
    /// The median of the studies' estimates.
    pub median_estimate: f64,
    /// The 2.5 % quantile of the studies' estimates: with `estimate_high`, where 95 % of such
    /// studies put the point.
    pub estimate_low: f64,
    /// The 97.5 % quantile.
    pub estimate_high: f64,
}

/// A plan's outcome.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanOutcome {
    /// The plan simulated.
    pub plan: ConstantPlan,
    /// The observers' psychometric function.
    pub observer: Logistic,
    /// Trials each simulated study has.
    pub trials_a_study: u64,
    /// Studies with a fit and intervals; the figures are theirs.
    pub fitted: u32,
    /// Studies without (answers that separate perfectly, a curve that does not rise, most
    /// resamples without a fit), as `analyze constant` would refuse their logs.
    pub unfitted: u32,
    /// The 25, 50 and 75 % points ([`POINT_PERCENTS`]).
    pub points: [PlannedPoint; 3],
}

impl Logistic {
    /// The logistic without lapse whose 25 % and 75 % points are `p25` and `p75` (`p25` below
    /// `p75`): σ(±ln 3) = 3/4 and 1/4, so its slope is 2·ln 3/(p75 − p25) and its 50 % point is
    /// midway.
    pub fn through_quartiles(p25: f64, p75: f64) -> Self {
        let slope = 2.0 * 3f64.ln() / (p75 - p25);
        Self {
            intercept: -slope * (p25 + p75) / 2.0,
            slope,
            lapse: 0.0,
        }
    }
}

impl ConstantPlan {
    /// The plan's arguments checked, each refused by name.
    pub fn check(&self) -> Result<(), PlanError> {
        if self.levels.len() < 2 {
            return Err(refuse(
                "levels",
                format!(
                    "{} level(s): a psychometric fit needs two or more",
                    self.levels.len()
                ),
            ));
        }
        if self.levels.len() > MAX_PLAN_LEVELS {
            return Err(refuse(
                "levels",
                format!("{} levels: at most {MAX_PLAN_LEVELS}", self.levels.len()),
            ));
        }
        if let Some(level) = self.levels.iter().find(|level| !level.is_finite()) {
            return Err(refuse("levels", format!("{level} is not a finite number")));
        }
        if let Some(pair) = self.levels.windows(2).find(|pair| pair[1] <= pair[0]) {
            return Err(refuse(
                "levels",
                format!(
                    "{} follows {}: list the levels rising, each once",
                    pair[1], pair[0]
                ),
            ));
        }
        for (argument, value) in [("p25", self.p25), ("p75", self.p75)] {
            if !value.is_finite() {
                return Err(refuse(argument, format!("{value} is not a finite number")));
            }
        }
        if self.p75 <= self.p25 {
            return Err(refuse(
                "p75",
                format!(
                    "{} is not above the 25 % point {}: the observers' curve must rise",
                    self.p75, self.p25
                ),
            ));
        }
        let counts = [
            ("repetitions", self.repetitions, MAX_PLAN_REPETITIONS),
            ("participants", self.participants, MAX_PLAN_PARTICIPANTS),
            ("studies", self.studies, MAX_STUDIES),
        ];
        for (argument, value, most) in counts {
            if !(1..=most).contains(&value) {
                return Err(refuse(argument, format!("{value}: from 1 to {most}")));
            }
        }
        if !(1..=MAX_RESAMPLES).contains(&self.resamples) {
            return Err(refuse(
                "resamples",
                format!("{}: from 1 to {MAX_RESAMPLES}", self.resamples),
            ));
        }
        let fits = u64::from(self.studies) * (self.resamples as u64 + 1);
        if fits > MAX_PLAN_FITS {
            return Err(refuse(
                "studies",
                format!(
                    "{} studies of {} resamples ask for {fits} fits: at most {MAX_PLAN_FITS} \
                     (hours of work); fewer studies or resamples",
                    self.studies, self.resamples
                ),
            ));
        }
        Ok(())
    }
}

/// Simulates `plan`: each study's answers drawn from the observers' curve, fitted and its
/// intervals checked against the curve's points.
///
/// Study i draws its answers, then the seed of its resamples, from a stream of its own: the
/// plan's seed's generator jumped ahead 2¹²⁸ numbers i times. So a plan's figures depend only on
/// its arguments, and a plan of more studies begins with the studies of a smaller one.
pub fn plan_constant(plan: &ConstantPlan) -> Result<PlanOutcome, PlanError> {
    plan.check()?;
    let observer = Logistic::through_quartiles(plan.p25, plan.p75);
    let chances: Vec<f64> = plan
        .levels
        .iter()
        .map(|&level| observer.probability(level))
        .collect();
    let trials_a_level = plan.participants * plan.repetitions;
    let truths = [plan.p25, (plan.p25 + plan.p75) / 2.0, plan.p75];
    let mut generator = Xoshiro256PlusPlus::seed_from_u64(plan.seed);
    let mut covered = [0u32; 3];
    let mut widths: [Vec<f64>; 3] = Default::default();
    let mut estimates: [Vec<f64>; 3] = Default::default();
    let mut unfitted = 0;
    for _ in 0..plan.studies {
        let mut stream = generator.clone();
        generator.jump();
        let counts: Vec<LevelCount> = plan
            .levels
            .iter()
            .zip(&chances)
            .map(|(&level, &chance)| LevelCount {
                level,
                trials: trials_a_level,
                chosen: (0..trials_a_level)
                    .map(|_| u32::from(stream.random::<f64>() < chance))
                    .sum(),
            })
            .collect();
        let options = PsychometricOptions {
            resamples: plan.resamples,
            seed: stream.random(),
            max_lapse: 0.0,
        };
        let Ok(fit) = fit_psychometric(&counts, &options) else {
            unfitted += 1;
            continue;
        };
        for (index, point) in fit.points.iter().enumerate() {
            let truth = truths[index];
            covered[index] += u32::from(point.low <= truth && truth <= point.high);
            widths[index].push(point.high - point.low);
            estimates[index].push(point.value);
        }
    }
    let fitted = plan.studies - unfitted;
    let points = std::array::from_fn(|index| {
        let (low, high) = clopper_pearson(covered[index], fitted);
        let widths = sorted(&widths[index]);
        let estimates = sorted(&estimates[index]);
        PlannedPoint {
            percent: POINT_PERCENTS[index],
            truth: truths[index],
            covered: covered[index],
            coverage: f64::from(covered[index]) / f64::from(fitted),
            coverage_low: low,
            coverage_high: high,
            median_width: quantile(&widths, 0.5),
            median_estimate: quantile(&estimates, 0.5),
            estimate_low: quantile(&estimates, 0.025),
            estimate_high: quantile(&estimates, 0.975),
        }
    });
    Ok(PlanOutcome {
        plan: plan.clone(),
        observer,
        trials_a_study: plan.levels.len() as u64 * u64::from(trials_a_level),
        fitted,
        unfitted,
        points,
    })
}

pub(crate) fn sorted(values: &[f64]) -> Vec<f64> {
    let mut values = values.to_vec();
    values.sort_by(f64::total_cmp);
    values
}

/// The `q` quantile of sorted `values`, linear between order statistics; NaN when empty.
pub(crate) fn quantile(values: &[f64], q: f64) -> f64 {
    if values.is_empty() {
        return f64::NAN;
    }
    let position = q * (values.len() - 1) as f64;
    let below = position.floor() as usize;
    let above = (below + 1).min(values.len() - 1);
    values[below] + (position - below as f64) * (values[above] - values[below])
}

/// The exact (Clopper-Pearson) 95 % interval of a proportion of `successes` in `trials`, from
/// the beta distribution's quantiles; (NaN, NaN) without trials.
pub(crate) fn clopper_pearson(successes: u32, trials: u32) -> (f64, f64) {
    if trials == 0 {
        return (f64::NAN, f64::NAN);
    }
    let (k, n) = (f64::from(successes), f64::from(trials));
    let low = match successes {
        0 => 0.0,
        _ => Beta::new(k, n - k + 1.0).map_or(f64::NAN, |beta| beta.inverse_cdf(0.025)),
    };
    let high = match successes == trials {
        true => 1.0,
        false => Beta::new(k + 1.0, n - k).map_or(f64::NAN, |beta| beta.inverse_cdf(0.975)),
    };
    (low, high)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_observer_passes_through_its_quartiles() {
        let observer = Logistic::through_quartiles(0.29, 0.42);
        assert!((observer.probability(0.29) - 0.25).abs() < 1e-12);
        assert!((observer.probability(0.42) - 0.75).abs() < 1e-12);
        assert!((observer.probability(0.355) - 0.5).abs() < 1e-12);
    }

    #[test]
    fn clopper_pearson_holds_the_proportion_and_its_ends() {
        let (low, high) = clopper_pearson(95, 100);
        assert!(low < 0.95 && 0.95 < high, "{low} {high}");
        // R's binom.test(95, 100) and scipy's beta.ppf: 0.8871651 0.9835681.
        assert!((low - 0.887_165_1).abs() < 1e-6 && (high - 0.983_568_1).abs() < 1e-6);
        assert_eq!(clopper_pearson(0, 10).0, 0.0);
        assert_eq!(clopper_pearson(10, 10).1, 1.0);
    }
}
