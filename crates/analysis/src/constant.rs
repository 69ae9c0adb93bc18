//! The method of constant stimuli (the paper's §4.4): a standard against comparison levels of one
//! control, the participant names the one that is more so. A logistic psychometric function
//! fitted by maximum likelihood, its 25/50/75 % points with parametric-bootstrap BCa intervals
//! (docs/studies.md).

use std::collections::BTreeMap;
use std::path::Path;

use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Serialize;
use statrs::distribution::{ContinuousCDF, Normal};

use super::error::AnalysisError;
use super::log::{read_rows, DryRuns, Rows};

/// The columns the constant-stimuli analysis reads.
pub const CONSTANT_COLUMNS: [&str; 3] = ["participant", "level", "chose_comparison"];

/// The points of the psychometric function reported, in percent "comparison chosen".
pub const POINT_PERCENTS: [u8; 3] = [25, 50, 75];

/// The largest lapse rate a fit may take: past it the 25 % and 75 % points could fall outside
/// the curve's range.
pub const MAX_LAPSE: f64 = 0.2;

/// The most bootstrap resamples an analysis draws: fifty times the default, far more than a 95 %
/// interval needs, and a bound on how long one runs (and on what a typo like 10**7 asks for).
pub const MAX_RESAMPLES: usize = 100_000;

/// How a psychometric function is fitted and its intervals drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PsychometricOptions {
    /// Bootstrap resamples for the 95 % intervals.
    pub resamples: usize,
    /// The seed of the resamples: the same seed, the same intervals.
    pub seed: u64,
    /// The lapse rate λ is fitted within 0..=`max_lapse` (0: no lapse); the curve then runs
    /// from λ to 1 − λ.
    pub max_lapse: f64,
}

impl Default for PsychometricOptions {
    fn default() -> Self {
        Self {
            resamples: 2000,
            seed: 1,
            max_lapse: 0.0,
        }
    }
}

/// The trials at one level of the comparison.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LevelCount {
    /// The comparison's level.
    pub level: f64,
    /// Trials at this level.
    pub trials: u32,
    /// Trials in which the comparison was chosen.
    pub chosen: u32,
}

impl LevelCount {
    /// The proportion of trials in which the comparison was chosen.
    pub fn proportion(&self) -> f64 {
        f64::from(self.chosen) / f64::from(self.trials)
    }
}

/// ψ(x) = λ + (1 − 2λ)·σ(α + β·x), σ the logistic function, λ the lapse rate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Logistic {
    /// α.
    pub intercept: f64,
    /// β.
    pub slope: f64,
    /// λ.
    pub lapse: f64,
}

impl Logistic {
    /// ψ(x).
    pub fn probability(&self, level: f64) -> f64 {
        self.lapse + (1.0 - 2.0 * self.lapse) * sigmoid(self.intercept + self.slope * level)
    }

    /// The level at which ψ = `proportion`; `None` if the curve never reaches it.
    pub fn level_at(&self, proportion: f64) -> Option<f64> {
        let inner = (proportion - self.lapse) / (1.0 - 2.0 * self.lapse);
        let level = ((inner / (1.0 - inner)).ln() - self.intercept) / self.slope;
        level.is_finite().then_some(level)
    }
}

/// A point of the psychometric function and its 95 % bootstrap interval.
///
/// Only a point within the levels tested is an estimate: the curve beyond them is the logistic's
/// shape, not the data's. A point outside them is reported as such, with no number; an end of
/// the interval outside them, as lying beyond the level it passes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PointEstimate {
    /// The level at the point (an extrapolation unless `placement` is
    /// [`Placement::Within`]).
    pub value: f64,
    /// The lower end of the 95 % BCa interval.
    pub low: f64,
    /// The upper end.
    pub high: f64,
    /// Where the point lies against the levels tested.
    pub placement: Placement,
}

/// Where a point of the curve lies against the levels tested.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Placement {
    /// From the lowest level tested to the highest.
    Within,
    /// Below the lowest level tested.
    BelowLevels,
    /// Above the highest.
    AboveLevels,
}

impl Placement {
    /// Where `level` lies against the levels from `lowest` to `highest`.
    pub fn of(level: f64, lowest: f64, highest: f64) -> Self {
        if level < lowest {
            Self::BelowLevels
        } else if level > highest {
            Self::AboveLevels
        } else {
            Self::Within
        }
    }
}

/// A fitted psychometric function.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PsychometricFit {
    /// The trials, by level.
    pub levels: Vec<LevelCount>,
    /// The maximum-likelihood curve.
    pub curve: Logistic,
    /// The 25, 50 and 75 % points ([`POINT_PERCENTS`]).
    pub points: [PointEstimate; 3],
    /// Resamples drawn.
    pub resamples: usize,
    /// Resamples without a finite fit (their answers separate perfectly), left out of the
    /// intervals.
    pub failed_resamples: usize,
}

impl PsychometricFit {
    /// The lowest and the highest level tested.
    pub fn level_range(&self) -> (f64, f64) {
        let first = self.levels.first().map_or(f64::NAN, |level| level.level);
        let last = self.levels.last().map_or(f64::NAN, |level| level.level);
        (first, last)
    }
}

/// Why a psychometric function has no fit.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PsychometricFitError {
    /// Fewer than two levels.
    #[error("trials at {0} level(s): a fit needs two or more")]
    TooFewLevels(usize),
    /// The answers separate perfectly (or never change): the likelihood has no maximum.
    #[error("no finite fit: the answers switch from never to always at one step (or never change), so the curve would be a step")]
    NoFiniteFit,
    /// The curve that fits best does not rise: the comparison was chosen as often, or less
    /// often, at the higher levels.
    #[error("the fitted curve does not rise (slope {slope:.4} a unit of level): the comparison was not chosen more often at higher levels, so the curve has no 25, 50 or 75 % point to report")]
    NotRising {
        /// The fitted slope β (≤ 0).
        slope: f64,
    },
    /// Most bootstrap resamples had no finite fit.
    #[error("no interval: {failed} of {resamples} resamples had no finite fit (too few trials for this curve)")]
    NoInterval {
        /// Resamples without a fit.
        failed: usize,
        /// Resamples drawn.
        resamples: usize,
    },
}

/// The pooled fit and each participant's.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstantAnalysis {
    /// Every participant's trials together (fig. 5 of the paper).
    pub pooled: PsychometricFit,
    /// Each participant's, in the order they first appear.
    pub participants: Vec<(String, Result<PsychometricFit, PsychometricFitError>)>,
    /// How many trials a dry run answered (nothing played): read only with [`DryRuns::Read`].
    pub dry_run_trials: usize,
}

/// Reads constant-stimuli logs (columns [`CONSTANT_COLUMNS`], others ignored) and fits them; a
/// dry run's trials as `dry_runs` says.
pub fn analyze_constant_logs(
    files: &[impl AsRef<Path>],
    options: &PsychometricOptions,
    dry_runs: DryRuns,
) -> Result<ConstantAnalysis, AnalysisError> {
    if !(0.0..=MAX_LAPSE).contains(&options.max_lapse) {
        return Err(AnalysisError::Option(format!(
            "the lapse rate bound {} is outside 0..={MAX_LAPSE}",
            options.max_lapse
        )));
    }
    if !(1..=MAX_RESAMPLES).contains(&options.resamples) {
        return Err(AnalysisError::Option(format!(
            "{} resamples: from 1 to {MAX_RESAMPLES} are drawn",
            options.resamples
        )));
    }
    let Rows {
        rows,
        dry_run_trials,
    } = read_rows(files, CONSTANT_COLUMNS, dry_runs)?;
    let mut participants: Vec<(String, Vec<(f64, bool)>)> = Vec::new();
    let mut pooled = Vec::with_capacity(rows.len());
    for row in &rows {
        if row.fields[0].is_empty() {
            return Err(row.error(CONSTANT_COLUMNS[0], "empty"));
        }
        let level: f64 = row.fields[1]
            .parse()
            .ok()
            .filter(|level: &f64| level.is_finite())
            .ok_or_else(|| {
                row.error(
                    CONSTANT_COLUMNS[1],
                    format!("{} is not a number", row.quoted(1)),
                )
            })?;
        let chosen = match row.fields[2].as_str() {
            "1" => true,
            "0" => false,
            _ => {
                return Err(row.error(
                    CONSTANT_COLUMNS[2],
                    format!(
                        "{}: 1 if the comparison was chosen, 0 if the standard",
                        row.quoted(2)
                    ),
                ))
            }
        };
        pooled.push((level, chosen));
        match participants
            .iter_mut()
            .find(|(name, _)| *name == row.fields[0])
        {
            Some((_, answers)) => answers.push((level, chosen)),
            None => participants.push((row.fields[0].clone(), vec![(level, chosen)])),
        }
    }
    let pooled_fit = fit_psychometric(&count_levels(&pooled), options)
        .map_err(|error| AnalysisError::design(files, format!("all participants: {error}")))?;
    let participants = participants
        .into_iter()
        .enumerate()
        .map(|(index, (name, answers))| {
            // Each participant's resamples from a seed of its own, all from the one seed.
            let seed = options.seed.wrapping_add(index as u64 + 1);
            let fit = fit_psychometric(
                &count_levels(&answers),
                &PsychometricOptions { seed, ..*options },
            );
            (name, fit)
        })
        .collect();
    Ok(ConstantAnalysis {
        pooled: pooled_fit,
        participants,
        dry_run_trials,
    })
}

/// The answers counted by level, levels rising.
pub fn count_levels(answers: &[(f64, bool)]) -> Vec<LevelCount> {
    let mut by_level: BTreeMap<u64, LevelCount> = BTreeMap::new();
    for &(level, chosen) in answers {
        // Ordered as numbers (finite levels; -0 as 0).
        let key = ordered_key(level + 0.0);
        let count = by_level.entry(key).or_insert(LevelCount {
            level,
            trials: 0,
            chosen: 0,
        });
        count.trials += 1;
        count.chosen += u32::from(chosen);
    }
    by_level.into_values().collect()
}

fn ordered_key(level: f64) -> u64 {
    let bits = level.to_bits();
    if bits >> 63 == 1 {
        !bits
    } else {
        bits | 1 << 63
    }
}

/// The maximum-likelihood logistic of `levels` and its points with bootstrap intervals.
pub fn fit_psychometric(
    levels: &[LevelCount],
    options: &PsychometricOptions,
) -> Result<PsychometricFit, PsychometricFitError> {
    let levels: Vec<LevelCount> = levels.iter().copied().filter(|l| l.trials > 0).collect();
    if levels.len() < 2 {
        return Err(PsychometricFitError::TooFewLevels(levels.len()));
    }
    let scaled = Scaled::of(&levels).ok_or(PsychometricFitError::NoFiniteFit)?;
    let fit = maximum_likelihood(&scaled, options.max_lapse, (0.0, 0.0))
        .ok_or(PsychometricFitError::NoFiniteFit)?;
    if fit.curve.slope <= 0.0 {
        return Err(PsychometricFitError::NotRising {
            slope: fit.curve.slope,
        });
    }
    let values_fitted = points_of(&fit.curve).ok_or(PsychometricFitError::NoFiniteFit)?;
    let mut drawn: [Vec<f64>; 3] = Default::default();
    let mut failed_resamples = 0;
    for points in bootstrap(&levels, &scaled, &fit, options) {
        match points {
            Some(points) => {
                for (values, point) in drawn.iter_mut().zip(points) {
                    values.push(point);
                }
            }
            None => failed_resamples += 1,
        }
    }
    if drawn[0].len() * 2 < options.resamples {
        // Most resamples are steps: their intervals would describe the few that are not.
        return Err(PsychometricFitError::NoInterval {
            failed: failed_resamples,
            resamples: options.resamples,
        });
    }
    let accelerations = accelerations(&scaled, &fit);
    let (lowest, highest) = (levels[0].level, levels[levels.len() - 1].level);
    let points = std::array::from_fn(|index| {
        let values = &mut drawn[index];
        values.sort_by(f64::total_cmp);
        let estimate = values_fitted[index];
        let (low, high) = bca_interval(values, estimate, accelerations[index]);
        PointEstimate {
            value: estimate,
            low,
            high,
            placement: Placement::of(estimate, lowest, highest),
        }
    });
    Ok(PsychometricFit {
        levels,
        curve: fit.curve,
        points,
        resamples: options.resamples,
        failed_resamples,
    })
}

/// Resamples a stream of random numbers draws in turn; each run of them has a stream of its own.
const RESAMPLES_A_STREAM: usize = 64;

/// The parametric bootstrap of `fit`: `options.resamples` sets of answers drawn from its curve,
/// as many trials a level as `levels`, each fitted from the curve's own parameters (the
/// resamples' levels are the data's); the points of each, or `None` for a resample without
/// (no finite fit, or a curve that does not rise).
///
/// The resamples are drawn on every core. Each run of [`RESAMPLES_A_STREAM`] draws from a stream
/// of its own, the seed's generator jumped ahead 2¹²⁸ numbers a run, so the streams never
/// overlap and the result is the same on any number of cores.
fn bootstrap(
    levels: &[LevelCount],
    scaled: &Scaled,
    fit: &Fit,
    options: &PsychometricOptions,
) -> Vec<Option<[f64; 3]>> {
    let chances: Vec<f64> = levels
        .iter()
        .map(|level| fit.curve.probability(level.level))
        .collect();
    let mut generator = Xoshiro256PlusPlus::seed_from_u64(options.seed);
    let runs: Vec<(usize, Xoshiro256PlusPlus)> = (0..options.resamples)
        .step_by(RESAMPLES_A_STREAM)
        .map(|start| {
            let stream = generator.clone();
            generator.jump();
            (RESAMPLES_A_STREAM.min(options.resamples - start), stream)
        })
        .collect();
    let draw_run = |(count, mut rng): (usize, Xoshiro256PlusPlus)| {
        let mut resample = scaled.clone();
        (0..count)
            .map(|_| {
                for ((row, level), &p) in resample.rows.iter_mut().zip(levels).zip(&chances) {
                    row.chosen = (0..level.trials)
                        .map(|_| u32::from(rng.random::<f64>() < p))
                        .sum::<u32>()
                        .into();
                }
                maximum_likelihood(&resample, options.max_lapse, fit.scaled)
                    .filter(|fit| fit.curve.slope > 0.0)
                    .and_then(|fit| points_of(&fit.curve))
            })
            .collect::<Vec<_>>()
    };
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
    let per_core = runs.len().div_ceil(cores).max(1);
    let mut runs = runs.into_iter();
    std::thread::scope(|scope| {
        let workers: Vec<_> = std::iter::from_fn(|| {
            let share: Vec<_> = runs.by_ref().take(per_core).collect();
            (!share.is_empty()).then(|| {
                scope.spawn(move || share.into_iter().flat_map(draw_run).collect::<Vec<_>>())
            })
        })
        .collect();
        workers
            .into_iter()
            .flat_map(|worker| worker.join().expect("a resample does not panic"))
            .collect()
    })
}

/// The 95 % bias-corrected and accelerated (BCa) interval of Efron (1987) from the sorted
/// bootstrap `values` of a point `estimate`: the percentiles moved by the bias (how many
/// resamples fall below the estimate) and the skewness (the `acceleration`). Plain percentiles
/// cover the truth in only 92–94 % of simulated studies of the paper's size; BCa comes closer
/// (docs/studies.md).
fn bca_interval(values: &[f64], estimate: f64, acceleration: f64) -> (f64, f64) {
    let normal = Normal::standard();
    let below = values.iter().filter(|&&value| value < estimate).count() as f64;
    let equal = values.iter().filter(|&&value| value == estimate).count() as f64;
    let fraction = ((below + equal / 2.0) / values.len() as f64)
        .clamp(0.5 / values.len() as f64, 1.0 - 0.5 / values.len() as f64);
    let bias = normal.inverse_cdf(fraction);
    let adjusted = |q: f64| {
        let z = normal.inverse_cdf(q);
        normal.cdf(bias + (bias + z) / (1.0 - acceleration * (bias + z)))
    };
    (
        quantile(values, adjusted(0.025)),
        quantile(values, adjusted(0.975)),
    )
}

/// The acceleration of each point's BCa interval: Efron's a = Σ U³ / (6 (Σ U²)^(3/2)) over the
/// trials, U a trial's empirical influence on the point. For a maximum-likelihood fit that
/// influence is the point's gradient through the inverse information times the trial's score
/// (the infinitesimal jackknife), so every trial costs one product instead of a fit with it
/// left out; trials of one level and one answer share it. With a lapse, λ is held at its fit.
fn accelerations(scaled: &Scaled, fit: &Fit) -> [f64; 3] {
    let (a, b) = fit.scaled;
    let lapse = fit.curve.lapse;
    let info = scaled.evaluate(a, b, lapse).info;
    let determinant = info[0][0] * info[1][1] - info[0][1] * info[0][1];
    POINT_PERCENTS.map(|percent| {
        let q = (f64::from(percent) / 100.0 - lapse) / (1.0 - 2.0 * lapse);
        let u = ((q / (1.0 - q)).ln() - a) / b;
        // The point's gradient in (α, β), through the inverse information.
        let gradient = [-1.0 / b, -u / b];
        let h = [
            (info[1][1] * gradient[0] - info[0][1] * gradient[1]) / determinant,
            (info[0][0] * gradient[1] - info[0][1] * gradient[0]) / determinant,
        ];
        let (mut squares, mut cubes) = (0.0, 0.0);
        for row in &scaled.rows {
            let eta = a + b * row.u;
            let sigma = sigmoid(eta);
            let psi = lapse + (1.0 - 2.0 * lapse) * sigma;
            let weight = weight_of(sigma, psi, lapse);
            let along = weight * (h[0] + h[1] * row.u);
            for (answer, count) in [(1.0, row.chosen), (0.0, row.trials - row.chosen)] {
                let influence = (answer - psi) * along;
                squares += count * influence * influence;
                cubes += count * influence * influence * influence;
            }
        }
        if squares > 0.0 && determinant > 0.0 {
            cubes / (6.0 * squares.powf(1.5))
        } else {
            0.0
        }
    })
}

/// The `q` quantile of sorted `values` (not empty), linear between order statistics.
fn quantile(values: &[f64], q: f64) -> f64 {
    let position = q * (values.len() - 1) as f64;
    let below = position.floor() as usize;
    let above = (below + 1).min(values.len() - 1);
    let fraction = position - below as f64;
    values[below] + fraction * (values[above] - values[below])
}

/// The levels at [`POINT_PERCENTS`] on `curve`.
fn points_of(curve: &Logistic) -> Option<[f64; 3]> {
    let [a, b, c] = POINT_PERCENTS.map(|percent| curve.level_at(f64::from(percent) / 100.0));
    Some([a?, b?, c?])
}

/// A curve fitted by maximum likelihood.
#[derive(Debug, Clone, Copy)]
struct Fit {
    /// The curve, in the levels' units.
    curve: Logistic,
    /// Its log-likelihood.
    log_likelihood: f64,
    /// Its α and β on the scaled levels ([`Scaled`]).
    scaled: (f64, f64),
}

/// One level's trials on the scale the fit works in.
#[derive(Debug, Clone, Copy)]
struct ScaledLevel {
    /// The level, centred and divided by the levels' span.
    u: f64,
    /// Trials.
    trials: f64,
    /// Trials in which the comparison was chosen.
    chosen: f64,
}

/// The levels centred on their trials' mean and scaled to their span, so that the fit's steps
/// are well conditioned whatever the levels' units.
#[derive(Debug, Clone)]
struct Scaled {
    centre: f64,
    span: f64,
    rows: Vec<ScaledLevel>,
}

/// The log-likelihood of α and β, its gradient (the score) and the Fisher information.
struct Evaluation {
    log_likelihood: f64,
    score: [f64; 2],
    info: [[f64; 2]; 2],
}

impl Scaled {
    /// `None` for levels without a span (one level, or levels too far apart for a float).
    fn of(levels: &[LevelCount]) -> Option<Self> {
        let total: f64 = levels.iter().map(|l| f64::from(l.trials)).sum();
        let centre = levels
            .iter()
            .map(|l| l.level * f64::from(l.trials))
            .sum::<f64>()
            / total;
        let (min, max) = levels
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), l| {
                (lo.min(l.level), hi.max(l.level))
            });
        let span = max - min;
        if span <= 0.0 || !span.is_finite() || !centre.is_finite() {
            return None;
        }
        let rows = levels
            .iter()
            .map(|l| ScaledLevel {
                u: (l.level - centre) / span,
                trials: f64::from(l.trials),
                chosen: f64::from(l.chosen),
            })
            .collect();
        Some(Self { centre, span, rows })
    }

    /// Everything a step of the fit needs at α = `a`, β = `b`, in one pass over the levels.
    fn evaluate(&self, a: f64, b: f64, lapse: f64) -> Evaluation {
        let mut evaluation = Evaluation {
            log_likelihood: 0.0,
            score: [0.0; 2],
            info: [[0.0; 2]; 2],
        };
        for &ScaledLevel { u, trials, chosen } in &self.rows {
            let eta = a + b * u;
            let (log_chosen, log_not, sigma) = log_psi_pair(eta, lapse);
            evaluation.log_likelihood += chosen * log_chosen + (trials - chosen) * log_not;
            let psi = lapse + (1.0 - 2.0 * lapse) * sigma;
            let slope = (1.0 - 2.0 * lapse) * sigma * (1.0 - sigma);
            let weight = weight_of(sigma, psi, lapse);
            let residual = (chosen - trials * psi) * weight;
            evaluation.score[0] += residual;
            evaluation.score[1] += residual * u;
            let information = trials * slope * weight;
            evaluation.info[0][0] += information;
            evaluation.info[0][1] += information * u;
            evaluation.info[1][1] += information * u * u;
        }
        evaluation
    }
}

/// dψ/dη over ψ(1 − ψ): exactly 1 without a lapse, where both may underflow.
fn weight_of(sigma: f64, psi: f64, lapse: f64) -> f64 {
    if lapse == 0.0 {
        1.0
    } else {
        (1.0 - 2.0 * lapse) * sigma * (1.0 - sigma) / (psi * (1.0 - psi))
    }
}

/// The maximum-likelihood curve, its search started from α, β = `start` on the scaled levels;
/// with a lapse, λ by golden-section search on the likelihood maximised over α and β (a
/// one-dimensional profile, smooth and bounded).
fn maximum_likelihood(scaled: &Scaled, max_lapse: f64, start: (f64, f64)) -> Option<Fit> {
    if max_lapse == 0.0 {
        return fit_with_lapse(scaled, 0.0, start);
    }
    let golden = (5f64.sqrt() - 1.0) / 2.0;
    let (mut low, mut high) = (0.0, max_lapse);
    let profile = |lapse: f64| {
        fit_with_lapse(scaled, lapse, start).map_or(f64::NEG_INFINITY, |fit| fit.log_likelihood)
    };
    let mut left = high - golden * (high - low);
    let mut right = low + golden * (high - low);
    let (mut left_value, mut right_value) = (profile(left), profile(right));
    while high - low > 1e-5 {
        if left_value >= right_value {
            high = right;
            right = left;
            right_value = left_value;
            left = high - golden * (high - low);
            left_value = profile(left);
        } else {
            low = left;
            left = right;
            left_value = right_value;
            right = low + golden * (high - low);
            right_value = profile(right);
        }
    }
    // The bounds themselves, where the maximum often lies (λ = 0 above all).
    [0.0, (low + high) / 2.0, max_lapse]
        .into_iter()
        .filter_map(|lapse| fit_with_lapse(scaled, lapse, start))
        .max_by(|a, b| a.log_likelihood.total_cmp(&b.log_likelihood))
}

/// A fit has converged once a Newton step would add less than this to the log-likelihood; its
/// parameters are then within about √(this / information) of the maximum before the step and
/// the square of that after it.
const CONVERGED_DECREMENT: f64 = 1e-10;

/// Past this slope (in units of the levels' span) the curve rises from 10⁻²² to 1 − 10⁻²² over
/// the levels: a step, the sign of answers that separate perfectly.
const MAX_SLOPE_PER_SPAN: f64 = 100.0;

/// The maximum-likelihood α and β for a fixed lapse rate by Fisher scoring (for λ = 0 this is
/// Newton's method, IRLS) from `start`, each step halved until the likelihood rises; and that
/// likelihood. Two parameters with analytic derivatives: a general optimiser would add nothing
/// but a dependency. Each step is one pass over the levels (the likelihood, the score and the
/// information together), so a fit costs a few passes.
fn fit_with_lapse(scaled: &Scaled, lapse: f64, start: (f64, f64)) -> Option<Fit> {
    let (mut a, mut b) = start;
    let mut current = scaled.evaluate(a, b, lapse);
    if !current.log_likelihood.is_finite() {
        (a, b) = (0.0, 0.0);
        current = scaled.evaluate(a, b, lapse);
    }
    let mut converged = false;
    for _ in 0..200 {
        let (score, info) = (current.score, current.info);
        let determinant = info[0][0] * info[1][1] - info[0][1] * info[0][1];
        if determinant.is_nan() || determinant <= 0.0 {
            break;
        }
        let mut step = [
            (info[1][1] * score[0] - info[0][1] * score[1]) / determinant,
            (info[0][0] * score[1] - info[0][1] * score[0]) / determinant,
        ];
        // The Newton decrement: what the step would add to the log-likelihood, to second order.
        // Once it is below what the sum over the levels can resolve, comparing likelihoods
        // only measures rounding: the step is taken and the search ends.
        let decrement = score[0] * step[0] + score[1] * step[1];
        if decrement < CONVERGED_DECREMENT {
            // Its likelihood is the current one to within the decrement.
            a += step[0];
            b += step[1];
            converged = true;
            break;
        }
        let mut next = scaled.evaluate(a + step[0], b + step[1], lapse);
        let mut halvings = 0;
        while falls(next.log_likelihood, current.log_likelihood) && halvings < 40 {
            step = [step[0] / 2.0, step[1] / 2.0];
            next = scaled.evaluate(a + step[0], b + step[1], lapse);
            halvings += 1;
        }
        if falls(next.log_likelihood, current.log_likelihood) {
            converged = step[0].abs().max(step[1].abs()) < 1e-9;
            break;
        }
        a += step[0];
        b += step[1];
        current = next;
        if b.abs() > MAX_SLOPE_PER_SPAN {
            return None;
        }
        if step[0].abs().max(step[1].abs()) < 1e-10 {
            converged = true;
            break;
        }
    }
    let curve = Logistic {
        intercept: a - b * scaled.centre / scaled.span,
        slope: b / scaled.span,
        lapse,
    };
    (converged && b.abs() <= MAX_SLOPE_PER_SPAN && b != 0.0 && current.log_likelihood.is_finite())
        .then_some(Fit {
            curve,
            log_likelihood: current.log_likelihood,
            scaled: (a, b),
        })
}

/// Whether a step's log-likelihood `next` is below `current` (or not a number).
fn falls(next: f64, current: f64) -> bool {
    next.is_nan() || next < current
}

fn sigmoid(eta: f64) -> f64 {
    1.0 / (1.0 + (-eta).exp())
}

/// ln(1 + x) for x ≥ 0 to within a few ulps, with the logarithm (Goldberg 1991, theorem 4):
/// several times faster than `f64::ln_1p`, which was most of a fit's time.
fn ln_1p(x: f64) -> f64 {
    let sum = 1.0 + x;
    if sum == 1.0 {
        x
    } else {
        sum.ln() * x / (sum - 1.0)
    }
}

/// ln ψ(η), ln(1 − ψ(η)) and σ(η), with one exponential, and without underflow where there is
/// no lapse (ln σ(η) = −ln(1 + e^(−η)), written for either sign of η).
fn log_psi_pair(eta: f64, lapse: f64) -> (f64, f64, f64) {
    let small = (-eta.abs()).exp();
    let log_one_plus = ln_1p(small);
    let (log_sigma, log_not_sigma, sigma) = if eta > 0.0 {
        (-log_one_plus, -eta - log_one_plus, 1.0 / (1.0 + small))
    } else {
        (eta - log_one_plus, -log_one_plus, small / (1.0 + small))
    };
    if lapse == 0.0 {
        (log_sigma, log_not_sigma, sigma)
    } else {
        let psi = lapse + (1.0 - 2.0 * lapse) * sigma;
        let not_psi = lapse + (1.0 - 2.0 * lapse) * (1.0 - sigma);
        (psi.ln(), not_psi.ln(), sigma)
    }
}
