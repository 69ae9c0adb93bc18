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
use super::log::read_rows;

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
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PointEstimate {
    /// The level at the point.
    pub value: f64,
    /// The lower end of the 95 % BCa interval.
    pub low: f64,
    /// The upper end.
    pub high: f64,
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

/// Why a psychometric function has no fit.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PsychometricFitError {
    /// Fewer than two levels.
    #[error("trials at {0} level(s): a fit needs two or more")]
    TooFewLevels(usize),
    /// The answers separate perfectly (or never change): the likelihood has no maximum.
    #[error("no finite fit: the answers switch from never to always at one step (or never change), so the curve would be a step")]
    NoFiniteFit,
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
}

/// Reads constant-stimuli logs (columns [`CONSTANT_COLUMNS`], others ignored) and fits them.
pub fn analyze_constant_logs(
    files: &[impl AsRef<Path>],
    options: &PsychometricOptions,
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
    let rows = read_rows(files, CONSTANT_COLUMNS)?;
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
    let curve =
        maximum_likelihood(&levels, options.max_lapse).ok_or(PsychometricFitError::NoFiniteFit)?;
    let values_fitted = points_of(&curve).ok_or(PsychometricFitError::NoFiniteFit)?;
    // Parametric bootstrap: new answers drawn from the fitted curve, as many trials a level.
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(options.seed);
    let mut drawn: [Vec<f64>; 3] = Default::default();
    let mut failed_resamples = 0;
    let mut resample = levels.clone();
    for _ in 0..options.resamples {
        for (count, level) in resample.iter_mut().zip(&levels) {
            let p = curve.probability(level.level);
            count.chosen = (0..level.trials)
                .map(|_| u32::from(rng.random::<f64>() < p))
                .sum();
        }
        match maximum_likelihood(&resample, options.max_lapse).and_then(|fit| points_of(&fit)) {
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
    let jackknife = jackknife_points(&levels, options.max_lapse);
    let points = std::array::from_fn(|index| {
        let values = &mut drawn[index];
        values.sort_by(f64::total_cmp);
        let estimate = values_fitted[index];
        let leave_one_out: Vec<(f64, f64)> = jackknife
            .iter()
            .map(|(points, weight)| (points[index], *weight))
            .collect();
        let (low, high) = bca_interval(values, estimate, &leave_one_out);
        PointEstimate {
            value: estimate,
            low,
            high,
        }
    });
    Ok(PsychometricFit {
        levels,
        curve,
        points,
        resamples: options.resamples,
        failed_resamples,
    })
}

/// The 95 % bias-corrected and accelerated (BCa) interval of Efron (1987) from the sorted
/// bootstrap `values` of a point `estimate`: the percentiles moved by the bias (how many
/// resamples fall below the estimate) and the skewness (the acceleration, from the jackknife
/// values `leave_one_out` with their weights). Plain percentiles cover the truth in only 92–94 %
/// of simulated studies of the paper's size; BCa comes closer (docs/studies.md).
fn bca_interval(values: &[f64], estimate: f64, leave_one_out: &[(f64, f64)]) -> (f64, f64) {
    let normal = Normal::standard();
    let below = values.iter().filter(|&&value| value < estimate).count() as f64;
    let equal = values.iter().filter(|&&value| value == estimate).count() as f64;
    let fraction = ((below + equal / 2.0) / values.len() as f64)
        .clamp(0.5 / values.len() as f64, 1.0 - 0.5 / values.len() as f64);
    let bias = normal.inverse_cdf(fraction);
    let total: f64 = leave_one_out.iter().map(|(_, weight)| weight).sum();
    let mean = leave_one_out
        .iter()
        .map(|(value, weight)| value * weight)
        .sum::<f64>()
        / total;
    let (mut squares, mut cubes) = (0.0, 0.0);
    for (value, weight) in leave_one_out {
        let deviation = mean - value;
        squares += weight * deviation * deviation;
        cubes += weight * deviation * deviation * deviation;
    }
    let acceleration = if squares > 0.0 {
        cubes / (6.0 * squares.powf(1.5))
    } else {
        0.0
    };
    let adjusted = |q: f64| {
        let z = normal.inverse_cdf(q);
        normal.cdf(bias + (bias + z) / (1.0 - acceleration * (bias + z)))
    };
    (
        quantile(values, adjusted(0.025)),
        quantile(values, adjusted(0.975)),
    )
}

/// The points fitted with each trial left out in turn, with how many trials give each (every
/// trial of one level and answer gives the same); the fits that fail are left out.
fn jackknife_points(levels: &[LevelCount], max_lapse: f64) -> Vec<([f64; 3], f64)> {
    let mut points = Vec::new();
    for (index, level) in levels.iter().enumerate() {
        for chosen in [true, false] {
            let weight = if chosen {
                level.chosen
            } else {
                level.trials - level.chosen
            };
            if weight == 0 {
                continue;
            }
            let mut left_out = levels.to_vec();
            left_out[index].trials -= 1;
            left_out[index].chosen -= u32::from(chosen);
            let left_out: Vec<LevelCount> = left_out
                .into_iter()
                .filter(|level| level.trials > 0)
                .collect();
            if let Some(fit) = maximum_likelihood(&left_out, max_lapse).and_then(|c| points_of(&c))
            {
                points.push((fit, f64::from(weight)));
            }
        }
    }
    points
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

/// The maximum-likelihood curve; with a lapse, λ by golden-section search on the likelihood
/// maximised over α and β (a one-dimensional profile, smooth and bounded).
fn maximum_likelihood(levels: &[LevelCount], max_lapse: f64) -> Option<Logistic> {
    if max_lapse == 0.0 {
        return fit_with_lapse(levels, 0.0).map(|(curve, _)| curve);
    }
    let golden = (5f64.sqrt() - 1.0) / 2.0;
    let (mut low, mut high) = (0.0, max_lapse);
    let profile = |lapse: f64| fit_with_lapse(levels, lapse).map_or(f64::NEG_INFINITY, |fit| fit.1);
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
        .filter_map(|lapse| fit_with_lapse(levels, lapse))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(curve, _)| curve)
}

/// Past this slope (in units of the levels' span) the curve rises from 10⁻²² to 1 − 10⁻²² over
/// the levels: a step, the sign of answers that separate perfectly.
const MAX_SLOPE_PER_SPAN: f64 = 100.0;

/// The maximum-likelihood α and β for a fixed lapse rate by Fisher scoring (for λ = 0 this is
/// Newton's method, IRLS), each step halved until the likelihood rises; and that likelihood.
/// Two parameters with analytic derivatives: a general optimiser would add nothing but a
/// dependency. The levels are centred and scaled to their span so that the steps are well
/// conditioned.
fn fit_with_lapse(levels: &[LevelCount], lapse: f64) -> Option<(Logistic, f64)> {
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
    if span <= 0.0 || !span.is_finite() {
        return None;
    }
    let scaled: Vec<(f64, f64, f64)> = levels
        .iter()
        .map(|l| {
            (
                (l.level - centre) / span,
                f64::from(l.trials),
                f64::from(l.chosen),
            )
        })
        .collect();
    let log_likelihood = |a: f64, b: f64| -> f64 {
        scaled
            .iter()
            .map(|&(u, n, k)| {
                let eta = a + b * u;
                k * log_psi(eta, lapse) + (n - k) * log_psi(-eta, lapse)
            })
            .sum()
    };
    let (mut a, mut b) = (0.0, 0.0);
    let mut current = log_likelihood(a, b);
    let mut converged = false;
    for _ in 0..200 {
        let (mut score, mut info) = ([0.0; 2], [[0.0; 2]; 2]);
        for &(u, n, k) in &scaled {
            let sigma = sigmoid(a + b * u);
            let psi = lapse + (1.0 - 2.0 * lapse) * sigma;
            let slope = (1.0 - 2.0 * lapse) * sigma * (1.0 - sigma);
            // dψ/dη over ψ(1 − ψ): exactly 1 without a lapse, where both may underflow.
            let weight = if lapse == 0.0 {
                1.0
            } else {
                slope / (psi * (1.0 - psi))
            };
            let residual = (k - n * psi) * weight;
            score[0] += residual;
            score[1] += residual * u;
            let information = n * slope * weight;
            info[0][0] += information;
            info[0][1] += information * u;
            info[1][1] += information * u * u;
        }
        let determinant = info[0][0] * info[1][1] - info[0][1] * info[0][1];
        if determinant.is_nan() || determinant <= 0.0 {
            break;
        }
        let mut step = [
            (info[1][1] * score[0] - info[0][1] * score[1]) / determinant,
            (info[0][0] * score[1] - info[0][1] * score[0]) / determinant,
        ];
        let mut next = log_likelihood(a + step[0], b + step[1]);
        let mut halvings = 0;
        while falls(next, current) && halvings < 40 {
            step = [step[0] / 2.0, step[1] / 2.0];
            next = log_likelihood(a + step[0], b + step[1]);
            halvings += 1;
        }
        if falls(next, current) {
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
        intercept: a - b * centre / span,
        slope: b / span,
        lapse,
    };
    (converged && b.abs() <= MAX_SLOPE_PER_SPAN && b != 0.0 && current.is_finite())
        .then_some((curve, current))
}

/// Whether a step's log-likelihood `next` is below `current` (or not a number).
fn falls(next: f64, current: f64) -> bool {
    next.is_nan() || next < current
}

fn sigmoid(eta: f64) -> f64 {
    1.0 / (1.0 + (-eta).exp())
}

/// ln ψ at η, without underflow where there is no lapse.
fn log_psi(eta: f64, lapse: f64) -> f64 {
    if lapse == 0.0 {
        // ln σ(η) = −ln(1 + e^(−η)), written for either sign of η.
        if eta > 0.0 {
            -(-eta).exp().ln_1p()
        } else {
            eta - eta.exp().ln_1p()
        }
    } else {
        (lapse + (1.0 - 2.0 * lapse) * sigmoid(eta)).ln()
    }
}
