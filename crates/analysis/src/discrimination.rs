//! Discrimination studies: can people tell two stimuli apart (a recording and its fitted model)?
//! Each trial is right or wrong; the proportion correct is turned into d′ through the design's
//! own decision model (docs/studies.md):
//!
//! - triangle (oddity): three stimuli, two alike, "which one is different?"; the differencing
//!   model of Frijters (1979) and Ennis (1993): the observer picks the stimulus farthest from the
//!   other two, P_c(d′) = 2∫₀^∞ [Φ(−√3·z + d′·√(2/3)) + Φ(−√3·z − d′·√(2/3))]·φ(z) dz, 1/3 at 0;
//! - 2AFC: "which one is the recording?", P_c = Φ(d′/√2), so d′ = √2·z(P_c);
//! - ABX: "is X the same as A or as B?", the differencing model of Macmillan & Creelman:
//!   P_c = Φ(d′/√2)·Φ(d′/√6) + Φ(−d′/√2)·Φ(−d′/√6).
//!
//! d′ is the maximum-likelihood estimate (the inverse of the proportion correct, 0 at or below
//! chance); its 95 % interval is the profile-likelihood interval: every d′ ≥ 0 whose proportion
//! correct the likelihood-ratio test against the binomial does not reject at 5 %.

use std::path::Path;
use std::sync::OnceLock;

use serde::Serialize;
use statrs::distribution::{Binomial, ContinuousCDF, DiscreteCDF, Normal};

use super::error::AnalysisError;
use super::log::{read_rows, DryRuns, Rows};
use super::plan::clopper_pearson;

/// The columns the discrimination analysis reads.
pub const DISCRIMINATION_COLUMNS: [&str; 3] = ["participant", "design", "correct"];

/// The largest d′ reported as a number: past it every design answers right but for less than
/// 10⁻¹² of the trials, which no study of people can tell from always.
pub const MAX_D_PRIME: f64 = 15.0;

/// The confidence of the intervals and the level of the test.
pub const CONFIDENCE: f64 = 0.95;

/// A discrimination design and its decision model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DiscriminationDesign {
    /// Three stimuli, two alike: which one is different? (oddity, differencing model).
    Triangle,
    /// Two stimuli: which one is the named one? (two-alternative forced choice).
    TwoAfc,
    /// A, B, then X: is X the same as A or as B? (differencing model).
    Abx,
}

/// Written by its name, as the log and the command line write it.
impl Serialize for DiscriminationDesign {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
}

impl DiscriminationDesign {
    /// Every design, in the order the help lists them.
    pub const ALL: [Self; 3] = [Self::Triangle, Self::TwoAfc, Self::Abx];

    /// Its name in the spec, the log and the command line (the study's `Design` names it so).
    pub fn name(self) -> &'static str {
        match self {
            Self::Triangle => "triangle",
            Self::TwoAfc => "2afc",
            Self::Abx => "abx",
        }
    }

    /// The design named `name`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|design| design.name() == name)
    }

    /// The names of every design, for messages.
    pub fn names() -> String {
        let names: Vec<String> = Self::ALL
            .iter()
            .map(|design| format!("`{}`", design.name()))
            .collect();
        names.join(", ")
    }

    /// The proportion correct of a guesser: 1/3 for the triangle, 1/2 for the others.
    pub fn chance(self) -> f64 {
        match self {
            Self::Triangle => 1.0 / 3.0,
            Self::TwoAfc | Self::Abx => 0.5,
        }
    }

    /// The decision model, as reports name it.
    pub fn decision_model(self) -> &'static str {
        match self {
            Self::Triangle => "triangle, differencing model (Frijters 1979, Ennis 1993)",
            Self::TwoAfc => "2AFC, d′ = √2·z(p)",
            Self::Abx => "ABX, differencing model (Macmillan & Creelman 2005)",
        }
    }

    /// The proportion correct of an observer of sensitivity `d_prime` (≥ 0).
    pub fn proportion_correct(self, d_prime: f64) -> f64 {
        let d_prime = d_prime.max(0.0);
        match self {
            Self::Triangle => triangle_proportion_correct(d_prime),
            Self::TwoAfc => phi(d_prime / 2f64.sqrt()),
            Self::Abx => {
                let (a, b) = (phi(d_prime / 2f64.sqrt()), phi(d_prime / 6f64.sqrt()));
                a * b + (1.0 - a) * (1.0 - b)
            }
        }
    }

    /// The d′ whose proportion correct is `proportion`: 0 at or below chance, infinite at 1
    /// (and past [`MAX_D_PRIME`]'s proportion).
    pub fn d_prime(self, proportion: f64) -> f64 {
        if proportion <= self.chance() {
            return 0.0;
        }
        if proportion >= self.proportion_correct(MAX_D_PRIME) {
            return f64::INFINITY;
        }
        match self {
            Self::TwoAfc => 2f64.sqrt() * standard_normal().inverse_cdf(proportion),
            _ => invert(|d| self.proportion_correct(d), proportion, 0.0, MAX_D_PRIME),
        }
    }
}

fn standard_normal() -> Normal {
    Normal::standard()
}

fn phi(x: f64) -> f64 {
    standard_normal().cdf(x)
}

/// The triangle's proportion correct (Frijters 1979, eq. 1; Ennis 1993): the observer calls odd
/// the stimulus whose distances to the other two are the largest.
fn triangle_proportion_correct(d_prime: f64) -> f64 {
    let (root3, shift) = (3f64.sqrt(), d_prime * (2.0f64 / 3.0).sqrt());
    let density = |z: f64| (-0.5 * z * z).exp() / (2.0 * std::f64::consts::PI).sqrt();
    let integrand = |z: f64| (phi(-root3 * z + shift) + phi(-root3 * z - shift)) * density(z);
    (2.0 * integrate_half_line(integrand)).clamp(1.0 / 3.0, 1.0)
}

/// ∫₀^∞ f over a smooth f weighted by the normal density: Gauss–Legendre on unit panels up to
/// z = 12, past which φ is below 10⁻³¹.
fn integrate_half_line(f: impl Fn(f64) -> f64) -> f64 {
    let (nodes, weights) = gauss_legendre();
    let mut sum = 0.0;
    for panel in 0..12 {
        let middle = f64::from(panel) + 0.5;
        for (node, weight) in nodes.iter().zip(weights) {
            sum += 0.5 * weight * f(middle + 0.5 * node);
        }
    }
    sum
}

/// The 16 nodes and weights of Gauss–Legendre quadrature on [−1, 1], by Newton's method on the
/// Legendre polynomial (exact for polynomials of degree 31: on a unit panel the integrand's
/// error is far below 10⁻¹⁴).
fn gauss_legendre() -> &'static (Vec<f64>, Vec<f64>) {
    static RULE: OnceLock<(Vec<f64>, Vec<f64>)> = OnceLock::new();
    RULE.get_or_init(|| {
        const N: usize = 16;
        let mut nodes = Vec::with_capacity(N);
        let mut weights = Vec::with_capacity(N);
        for i in 0..N {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (N as f64 + 0.5)).cos();
            let mut derivative = 0.0;
            for _ in 0..100 {
                // P_N(x) and P_{N−1}(x) by the three-term recurrence.
                let (mut p, mut previous) = (1.0, 0.0);
                for k in 1..=N {
                    let k = k as f64;
                    (p, previous) = (((2.0 * k - 1.0) * x * p - (k - 1.0) * previous) / k, p);
                }
                derivative = N as f64 * (x * p - previous) / (x * x - 1.0);
                let step = p / derivative;
                x -= step;
                if step.abs() < 1e-15 {
                    break;
                }
            }
            nodes.push(x);
            weights.push(2.0 / ((1.0 - x * x) * derivative * derivative));
        }
        (nodes, weights)
    })
}

/// The x in [low, high] where the rising `f` reaches `target` (f(low) ≤ target ≤ f(high)):
/// regula falsi with the Illinois step, each step kept inside its bracket.
fn invert(f: impl Fn(f64) -> f64, target: f64, mut low: f64, mut high: f64) -> f64 {
    let (mut f_low, mut f_high) = (f(low) - target, f(high) - target);
    let mut side = 0;
    for _ in 0..200 {
        if high - low < 1e-13 {
            break;
        }
        let mut x = (low * f_high - high * f_low) / (f_high - f_low);
        if !(x > low && x < high) {
            x = 0.5 * (low + high);
        }
        let value = f(x) - target;
        if value == 0.0 {
            return x;
        }
        if value < 0.0 {
            (low, f_low) = (x, value);
            if side == -1 {
                f_high *= 0.5;
            }
            side = -1;
        } else {
            (high, f_high) = (x, value);
            if side == 1 {
                f_low *= 0.5;
            }
            side = 1;
        }
    }
    0.5 * (low + high)
}

/// What one set of trials (a participant's, or everyone's) says.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DiscriminationEstimate {
    /// Trials.
    pub trials: u32,
    /// Trials answered right.
    pub correct: u32,
    /// `correct` over `trials`.
    pub proportion: f64,
    /// The exact (Clopper–Pearson) 95 % interval of the proportion: its lower end.
    pub proportion_low: f64,
    /// Its upper end.
    pub proportion_high: f64,
    /// The one-sided exact binomial test against chance: P(at least `correct` right | guessing).
    pub p_value: f64,
    /// The maximum-likelihood d′: 0 at or below chance, infinite when every answer is right.
    pub d_prime: f64,
    /// The profile-likelihood 95 % interval of d′, `None` when it is empty (answers so far below
    /// chance that no d′ ≥ 0 explains them); its upper end may be infinite.
    pub d_prime_interval: Option<(f64, f64)>,
}

impl DiscriminationEstimate {
    /// Whether the test against chance rejects at 5 %: people told the stimuli apart.
    pub fn told_apart(&self) -> bool {
        self.p_value < 1.0 - CONFIDENCE
    }

    /// The plain sentence of what the trials say.
    pub fn sentence(&self, design: DiscriminationDesign) -> String {
        let number = |d: f64| match d.is_finite() {
            true => format!("{d:.2}"),
            false => "∞".into(),
        };
        let Some((low, high)) = self.d_prime_interval else {
            return format!(
                "fewer right than guessing gives ({} of {}, chance {:.0} %, as if the answers \
                 were keyed wrong): the {} decision model does not hold; check the answer key",
                self.correct,
                self.trials,
                100.0 * design.chance(),
                design.name()
            );
        };
        if self.told_apart() {
            if self.d_prime.is_infinite() {
                return format!(
                    "people told them apart (every answer right: d′ > {} with 95 % confidence)",
                    number(low)
                );
            }
            return format!(
                "people told them apart (d′ = {} [{}, {}])",
                number(self.d_prime),
                number(low),
                number(high)
            );
        }
        if high.is_infinite() {
            return format!(
                "not distinguishable at this sample size, and too few trials ({}) to bound d′",
                self.trials
            );
        }
        format!(
            "not distinguishable at this sample size (d′ < {} with 95 % confidence)",
            number(high)
        )
    }
}

/// The estimate of `correct` right answers in `trials` trials of `design`.
pub fn estimate_discrimination(
    design: DiscriminationDesign,
    correct: u32,
    trials: u32,
) -> DiscriminationEstimate {
    debug_assert!(correct <= trials && trials > 0);
    let proportion = f64::from(correct) / f64::from(trials);
    let (proportion_low, proportion_high) = clopper_pearson(correct, trials);
    let p_value = match correct {
        0 => 1.0,
        _ => Binomial::new(design.chance(), u64::from(trials))
            .map_or(f64::NAN, |binomial| binomial.sf(u64::from(correct) - 1)),
    };
    let (low, high) = likelihood_interval(correct, trials);
    let chance = design.chance();
    let d_prime_interval = (high >= chance).then(|| (design.d_prime(low), design.d_prime(high)));
    DiscriminationEstimate {
        trials,
        correct,
        proportion,
        proportion_low,
        proportion_high,
        p_value,
        d_prime: design.d_prime(proportion),
        d_prime_interval,
    }
}

/// The likelihood-ratio 95 % interval of a binomial proportion: every p whose deviance
/// 2·(ℓ(p̂) − ℓ(p)) is at most χ²₁(0.95). The profile-likelihood interval of d′ is its image
/// through the design's psychometric function, which is monotone.
fn likelihood_interval(correct: u32, trials: u32) -> (f64, f64) {
    let (k, n) = (f64::from(correct), f64::from(trials));
    let log_likelihood = |p: f64| {
        let right = if correct == 0 { 0.0 } else { k * p.ln() };
        let wrong = if correct == trials {
            0.0
        } else {
            (n - k) * (1.0 - p).ln()
        };
        right + wrong
    };
    let estimate = k / n;
    let best = log_likelihood(estimate);
    let critical = chi_square_critical();
    let deviance = |p: f64| 2.0 * (best - log_likelihood(p));
    let low = match correct {
        0 => 0.0,
        _ => bisect(|p| critical - deviance(p), 0.0, estimate),
    };
    let high = match correct == trials {
        true => 1.0,
        false => bisect(|p| deviance(p) - critical, estimate, 1.0),
    };
    (low, high)
}

/// χ²₁'s 95 % quantile: (z₀.₉₇₅)².
fn chi_square_critical() -> f64 {
    static CRITICAL: OnceLock<f64> = OnceLock::new();
    *CRITICAL.get_or_init(|| {
        let z = standard_normal().inverse_cdf(0.5 + CONFIDENCE / 2.0);
        z * z
    })
}

/// The x in (low, high) where `f` turns from negative to positive (f(low) < 0 < f(high)
/// as limits), to the last bit.
fn bisect(f: impl Fn(f64) -> f64, mut low: f64, mut high: f64) -> f64 {
    for _ in 0..200 {
        let middle = 0.5 * (low + high);
        if middle <= low || middle >= high {
            break;
        }
        if f(middle) < 0.0 {
            low = middle;
        } else {
            high = middle;
        }
    }
    0.5 * (low + high)
}

/// A discrimination study analysed: pooled and per participant.
#[derive(Debug, Clone, PartialEq)]
pub struct DiscriminationAnalysis {
    /// The design every trial was of.
    pub design: DiscriminationDesign,
    /// Every participant's trials together.
    pub pooled: DiscriminationEstimate,
    /// Each participant's, in the order they first appear.
    pub participants: Vec<(String, DiscriminationEstimate)>,
    /// How many trials a dry run answered (nothing played): read only with [`DryRuns::Read`].
    pub dry_run_trials: usize,
}

/// Reads discrimination logs (columns [`DISCRIMINATION_COLUMNS`], others ignored): every row of
/// one design, `correct` 1 or 0; a dry run's trials as `dry_runs` says.
pub fn analyze_discrimination_logs(
    files: &[impl AsRef<Path>],
    dry_runs: DryRuns,
) -> Result<DiscriminationAnalysis, AnalysisError> {
    let Rows {
        rows,
        dry_run_trials,
    } = read_rows(files, DISCRIMINATION_COLUMNS, dry_runs)?;
    let mut design: Option<(DiscriminationDesign, String, u64)> = None;
    let mut participants: Vec<(String, u32, u32)> = Vec::new();
    for row in &rows {
        if row.fields[0].is_empty() {
            return Err(row.error(DISCRIMINATION_COLUMNS[0], "empty"));
        }
        let this = DiscriminationDesign::from_name(&row.fields[1]).ok_or_else(|| {
            row.error(
                DISCRIMINATION_COLUMNS[1],
                format!(
                    "{} is not a discrimination design ({})",
                    row.quoted(1),
                    DiscriminationDesign::names()
                ),
            )
        })?;
        match &design {
            Some((first, file, line)) if *first != this => {
                return Err(row.error(
                    DISCRIMINATION_COLUMNS[1],
                    format!(
                        "`{}`, where {file}, line {line} is `{}`: each design has its own \
                         decision model, so analyse the logs of each design apart",
                        this.name(),
                        first.name()
                    ),
                ))
            }
            Some(_) => {}
            None => design = Some((this, row.file.clone(), row.line)),
        }
        let correct = match row.fields[2].as_str() {
            "1" => 1,
            "0" => 0,
            _ => {
                return Err(row.error(
                    DISCRIMINATION_COLUMNS[2],
                    format!("{}: 1 if the answer was right, 0 if not", row.quoted(2)),
                ))
            }
        };
        match participants
            .iter_mut()
            .find(|(name, _, _)| *name == row.fields[0])
        {
            Some((_, right, trials)) => {
                *right += correct;
                *trials += 1;
            }
            None => participants.push((row.fields[0].clone(), correct, 1)),
        }
    }
    let Some((design, _, _)) = design else {
        return Err(AnalysisError::design(files, "no trials"));
    };
    let (correct, trials) = participants
        .iter()
        .fold((0, 0), |(right, all), (_, r, t)| (right + r, all + t));
    Ok(DiscriminationAnalysis {
        design,
        pooled: estimate_discrimination(design, correct, trials),
        participants: participants
            .into_iter()
            .map(|(name, right, trials)| (name, estimate_discrimination(design, right, trials)))
            .collect(),
        dry_run_trials,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chance_is_each_designs_guessing_rate_at_zero() {
        for design in DiscriminationDesign::ALL {
            // The normal distribution's cdf (statrs's erfc) is good to about 10⁻¹¹ relative.
            let at_zero = design.proportion_correct(0.0);
            assert!(
                (at_zero - design.chance()).abs() < 1e-10,
                "{design:?}: {at_zero}"
            );
        }
    }

    #[test]
    fn d_prime_inverts_the_proportion_correct() {
        for design in DiscriminationDesign::ALL {
            for d in [0.1, 0.5, 1.0, 2.0, 3.0, 5.0] {
                let back = design.d_prime(design.proportion_correct(d));
                assert!((back - d).abs() < 1e-8, "{design:?} {d}: {back}");
            }
        }
    }

    #[test]
    fn the_likelihood_interval_holds_the_estimate() {
        let (low, high) = likelihood_interval(30, 100);
        assert!(low < 0.3 && 0.3 < high, "{low} {high}");
        assert_eq!(likelihood_interval(0, 10).0, 0.0);
        assert_eq!(likelihood_interval(10, 10).1, 1.0);
        // A deviance of exactly the critical value at both ends.
        let deviance = |p: f64| {
            let (k, n) = (30.0, 100.0);
            let at = |q: f64| k * f64::ln(q) + (n - k) * f64::ln(1.0 - q);
            2.0 * (at(0.3) - at(p))
        };
        assert!((deviance(low) - 3.841_458_820_694_124).abs() < 1e-9);
        assert!((deviance(high) - 3.841_458_820_694_124).abs() < 1e-9);
    }
}
