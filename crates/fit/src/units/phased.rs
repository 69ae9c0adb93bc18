//! A unit eq. 1 as it stands does not describe (MODEL.md §13): one or two decaying components,
//! each A·e^(−Bτ)·sin(2πfτ + φ) with a phase of its own, from a common onset, started at the
//! peaks of the unit's own spectrum. A component's phase is linear in it (S·sin + C·cos, with
//! A = √(S² + C²) and φ = atan2(C, S)), so the onset is taken from a grid around the detected one
//! by linear least squares at the starting frequencies; then S, C, f and B of every component
//! are refined together by Levenberg-Marquardt over the window's samples. A gliding unit (a
//! bubble's pitch rises as it rises) is fitted with a glide g of each component's frequency as
//! well, its phase 2π(fτ + gτ²/2) + φ; the frequency it is heard at is then its frequency at the
//! centre of its energy in the window.

use std::f64::consts::TAU;

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned};

use super::window::Window;
use super::{Component, Rejection};

/// The onset grid: this range around the detected onset (s), in steps.
const ONSET_GRID_S: (f64, f64, f64) = (-0.004, 0.002, 0.00025);
/// A glide's start is set on a grid of this share either side of its estimate…
const GLIDE_GRID: f64 = 0.5;
/// …in this many steps…
const GLIDE_GRID_STEPS: usize = 40;
/// …holding its frequency this long after the onset (s), where its estimate is surest.
const GLIDE_HELD_S: f64 = 0.01;
/// The onset and the other numbers are refined in turn at most this many times.
const ONSET_ROUNDS: usize = 3;
/// Levenberg-Marquardt gives up after patience × (parameters + 1) evaluations.
const LM_PATIENCE: usize = 30;

/// A phased fit.
pub(super) struct PhasedFit {
    /// The onset (s).
    pub onset_s: f64,
    /// Its components.
    pub components: Vec<Component>,
    /// The share of the window's energy it explains.
    pub explained: f64,
}

/// Fits `starts.len()` components started at `starts` (f Hz, B 1/s) to `window`, the onset near
/// `detected_s`, each with a glide of its frequency if `glide`.
pub(super) fn fit(
    window: &Window,
    detected_s: f64,
    starts: &[(f64, f64)],
    glide: bool,
) -> Result<PhasedFit, Rejection> {
    let not_finite = || Rejection::NotFinite;
    let per = if glide { 5 } else { 4 };
    // Each component's (f at the onset, g, B) to start from.
    let mut starts: Vec<(f64, f64, f64)> = starts
        .iter()
        .map(|&(hz, decay)| {
            let (onset_hz, rate) = if glide {
                glide_start(window, detected_s, hz)
            } else {
                (hz, 0.0)
            };
            (onset_hz, rate, decay)
        })
        .collect();
    let (onset_s, _) = onset_grid(window, detected_s, &starts).ok_or_else(not_finite)?;
    if glide {
        set_glides(window, onset_s, &mut starts);
    }
    // The onset and the rest are refined in turn: the onset on the grid at the last fit's
    // frequencies, then the rest by Levenberg-Marquardt at that onset.
    let mut fitted: Option<Refined> = None;
    let mut at = starts;
    for _ in 0..ONSET_ROUNDS {
        let Some((onset_s, amplitudes)) = onset_grid(window, detected_s, &at) else {
            break;
        };
        if fitted
            .as_ref()
            .is_some_and(|f| (f.onset_s - onset_s).abs() < 1e-9)
        {
            break;
        }
        let Some(refined) = refine(window, onset_s, &at, &amplitudes, per) else {
            break;
        };
        if fitted
            .as_ref()
            .is_some_and(|f| f.sum_of_squares <= refined.sum_of_squares)
        {
            break;
        }
        at = refined.starts(per);
        fitted = Some(refined);
    }
    let fitted = fitted.ok_or_else(not_finite)?;
    let p = &fitted.params;
    let span_s = span_of(window, fitted.onset_s);
    let components = (0..p.len() / per)
        .map(|k| {
            let (sine, cosine) = (p[per * k], p[per * k + 1]);
            let (hz, decay) = (p[per * k + 2], p[per * k + 3]);
            let rate = if glide { p[per * k + 4] } else { 0.0 };
            // The centre of its energy in the window: 1/(2B) after the onset, or the window's
            // middle if it decays more slowly.
            let centre_s = (0.5 / decay.max(1e-9)).min(0.5 * span_s);
            Component {
                frequency_hz: hz,
                glide_hz_per_s: rate,
                heard_hz: hz + rate * centre_s,
                decay_per_s: decay,
                amplitude: sine.hypot(cosine),
                phase: cosine.atan2(sine),
                in_span: 0.0,
            }
        })
        .collect();
    Ok(PhasedFit {
        onset_s: fitted.onset_s,
        components,
        explained: 1.0 - fitted.sum_of_squares / window.energy().max(1e-300),
    })
}

/// One round of Levenberg-Marquardt at a fixed onset.
struct Refined {
    onset_s: f64,
    params: DVector<f64>,
    sum_of_squares: f64,
}

impl Refined {
    /// Its components' (f, g, B).
    fn starts(&self, per: usize) -> Vec<(f64, f64, f64)> {
        let p = &self.params;
        (0..p.len() / per)
            .map(|k| {
                let rate = if per == 5 { p[per * k + 4] } else { 0.0 };
                (p[per * k + 2], rate, p[per * k + 3])
            })
            .collect()
    }
}

/// The onset on the grid around `detected_s` whose linear fit at `starts` leaves the least, and
/// its amplitudes.
fn onset_grid(
    window: &Window,
    detected_s: f64,
    starts: &[(f64, f64, f64)],
) -> Option<(f64, DVector<f64>)> {
    let (from, to, by) = ONSET_GRID_S;
    let steps = ((to - from) / by).round() as usize;
    let mut best: Option<(f64, f64, DVector<f64>)> = None;
    for step in 0..=steps {
        let onset_s = detected_s + from + by * step as f64;
        let Some((residual, amplitudes)) = linear_fit(window, onset_s, starts) else {
            continue;
        };
        if best.as_ref().is_none_or(|b| residual < b.0) {
            best = Some((residual, onset_s, amplitudes));
        }
    }
    best.map(|(_, onset_s, amplitudes)| (onset_s, amplitudes))
}

/// A glide's phase runs as g·τ²: a start a tenth off is a cycle off by the window's end, so each
/// glide is first set on a grid around its estimate (its early frequency held).
fn set_glides(window: &Window, onset_s: f64, starts: &mut [(f64, f64, f64)]) {
    for k in 0..starts.len() {
        let (hz, rate, decay) = starts[k];
        let held_s = GLIDE_HELD_S.min(0.25 * span_of(window, onset_s));
        let mut best: Option<(f64, (f64, f64, f64))> = None;
        for step in 0..=GLIDE_GRID_STEPS {
            let scale = 1.0 + GLIDE_GRID * (2.0 * step as f64 / GLIDE_GRID_STEPS as f64 - 1.0);
            let trial_rate = rate * scale;
            let trial = (hz + (rate - trial_rate) * held_s, trial_rate, decay);
            let mut trial_starts = starts.to_vec();
            trial_starts[k] = trial;
            if let Some((residual, _)) = linear_fit(window, onset_s, &trial_starts) {
                if best.as_ref().is_none_or(|b| residual < b.0) {
                    best = Some((residual, trial));
                }
            }
        }
        if let Some((_, trial)) = best {
            starts[k] = trial;
        }
    }
}

/// Levenberg-Marquardt from `starts` and `amplitudes` at `onset_s`.
fn refine(
    window: &Window,
    onset_s: f64,
    starts: &[(f64, f64, f64)],
    amplitudes: &DVector<f64>,
    per: usize,
) -> Option<Refined> {
    let mut params = DVector::zeros(per * starts.len());
    for (k, &(hz, rate, decay)) in starts.iter().enumerate() {
        params[per * k] = amplitudes[2 * k];
        params[per * k + 1] = amplitudes[2 * k + 1];
        params[per * k + 2] = hz;
        params[per * k + 3] = decay;
        if per == 5 {
            params[per * k + 4] = rate;
        }
    }
    let problem = PhasedProblem {
        window,
        onset_s,
        params,
        per,
    };
    let (problem, _report) = LevenbergMarquardt::new()
        .with_patience(LM_PATIENCE)
        .minimize(problem);
    let sum_of_squares = problem.residuals()?.norm_squared();
    let finite = problem.params.iter().all(|v| v.is_finite()) && sum_of_squares.is_finite();
    finite.then_some(Refined {
        onset_s,
        params: problem.params,
        sum_of_squares,
    })
}

/// The time from `onset_s` to the window's last sample (s).
fn span_of(window: &Window, onset_s: f64) -> f64 {
    (window.time_s(window.data.len().saturating_sub(1)) - onset_s).max(0.0)
}

/// Where a glide starts: the strongest peak near `hz` (within an octave) in the window's first
/// and second half after the onset, the rate between their middles (Hz/s) and the frequency it
/// gives at the onset; `hz` and no glide if either half shows none.
fn glide_start(window: &Window, onset_s: f64, hz: f64) -> (f64, f64) {
    let start = window.first_after(onset_s);
    let rest = &window.data[start..];
    if rest.len() < 8 {
        return (hz, 0.0);
    }
    let fs = window.fs / window.stride as f64;
    let half = rest.len() / 2;
    let near = |samples: &[f64]| {
        crate::spectrum::own_peaks(samples, fs)
            .into_iter()
            .map(|(peak, _)| peak)
            .find(|peak| (peak / hz).max(hz / peak) < 2.0)
    };
    let half_s = half as f64 / fs;
    match (near(&rest[..half]), near(&rest[half..])) {
        (Some(early), Some(late)) => {
            let glide = (late - early) / half_s;
            (early - glide * 0.5 * half_s, glide)
        }
        _ => (hz, 0.0),
    }
}

/// The least-squares S, C of each component at `onset_s` with f, g, B as in `starts`, and the
/// sum of squares left.
fn linear_fit(
    window: &Window,
    onset_s: f64,
    starts: &[(f64, f64, f64)],
) -> Option<(f64, DVector<f64>)> {
    let rows = window.data.len();
    let mut columns = DMatrix::zeros(rows, 2 * starts.len());
    for (k, &(hz, glide, decay)) in starts.iter().enumerate() {
        for n in window.first_after(onset_s)..rows {
            let tau = window.time_s(n) - onset_s;
            let envelope = (-decay * tau).exp();
            let (im, re) = (TAU * (hz + 0.5 * glide * tau) * tau).sin_cos();
            columns[(n, 2 * k)] = envelope * im;
            columns[(n, 2 * k + 1)] = envelope * re;
        }
    }
    // The normal equations: a few columns, so a small Cholesky factorisation.
    let data = DVector::from_column_slice(&window.data);
    let normal = columns.tr_mul(&columns);
    let projected = columns.tr_mul(&data);
    let amplitudes = normal.cholesky()?.solve(&projected);
    let residual = data.norm_squared() - amplitudes.dot(&projected);
    (residual.is_finite() && amplitudes.iter().all(|a| a.is_finite()))
        .then_some((residual.max(0.0), amplitudes))
}

/// The components `[S, C, f, B]` each (and g, if `per` is 5), at a fixed onset, over every sample
/// of the window.
struct PhasedProblem<'a> {
    window: &'a Window,
    onset_s: f64,
    params: DVector<f64>,
    per: usize,
}

impl PhasedProblem<'_> {
    /// For every sample n, `each(n, r_n, J_n)`: the residual (the model less the recording) and
    /// the row of the Jacobian (zero before the onset).
    fn rows(&self, mut each: impl FnMut(usize, f64, &[f64])) {
        let per = self.per;
        let count = self.params.len() / per;
        let mut row = vec![0.0; self.params.len()];
        for (n, &y) in self.window.data.iter().enumerate() {
            let tau = self.window.time_s(n) - self.onset_s;
            row.iter_mut().for_each(|v| *v = 0.0);
            if tau < 0.0 {
                each(n, -y, &row);
                continue;
            }
            let mut model = 0.0;
            for k in 0..count {
                let p = &self.params.as_slice()[per * k..per * k + per];
                let (sine, cosine, hz, decay) = (p[0], p[1], p[2], p[3]);
                let glide = if per == 5 { p[4] } else { 0.0 };
                let envelope = (-decay * tau).exp();
                let (im, re) = (TAU * (hz + 0.5 * glide * tau) * tau).sin_cos();
                let (im, re) = (envelope * im, envelope * re);
                model += sine * im + cosine * re;
                let turning = sine * re - cosine * im;
                row[per * k] = im;
                row[per * k + 1] = re;
                row[per * k + 2] = TAU * tau * turning;
                row[per * k + 3] = -tau * (sine * im + cosine * re);
                if per == 5 {
                    row[per * k + 4] = 0.5 * TAU * tau * tau * turning;
                }
            }
            each(n, model - y, &row);
        }
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for PhasedProblem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, params: &DVector<f64>) {
        self.params.copy_from(params);
    }

    fn params(&self) -> DVector<f64> {
        self.params.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let mut residuals = DVector::zeros(self.window.data.len());
        self.rows(|n, residual, _| residuals[n] = residual);
        residuals.iter().all(|r| r.is_finite()).then_some(residuals)
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let mut jacobian = DMatrix::zeros(self.window.data.len(), self.params.len());
        self.rows(|n, _, row| {
            for (j, &value) in row.iter().enumerate() {
                jacobian[(n, j)] = value;
            }
        });
        jacobian.iter().all(|v| v.is_finite()).then_some(jacobian)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A component out of phase and a second, fitted from starts 5 % off, come back exactly.
    #[test]
    fn two_components_with_phases_of_their_own_come_back() {
        let fs = 22_050.0;
        let truth = [
            Component {
                frequency_hz: 440.0,
                glide_hz_per_s: 0.0,
                heard_hz: 440.0,
                decay_per_s: 60.0,
                amplitude: 0.5,
                phase: 1.2,
                in_span: 0.0,
            },
            Component {
                frequency_hz: 1300.0,
                glide_hz_per_s: 0.0,
                heard_hz: 1300.0,
                decay_per_s: 90.0,
                amplitude: 0.2,
                phase: -2.0,
                in_span: 0.0,
            },
        ];
        let onset_s = 0.004;
        let data: Vec<f64> = (0..2000)
            .map(|n| {
                let tau = n as f64 / fs - onset_s;
                if tau < 0.0 {
                    0.0
                } else {
                    truth.iter().map(|c| c.value(tau)).sum()
                }
            })
            .collect();
        let window = Window {
            data,
            first: 0,
            stride: 1,
            fs,
        };
        let fitted = fit(
            &window,
            onset_s + 0.001,
            &[(420.0, 40.0), (1360.0, 40.0)],
            false,
        )
        .unwrap_or_else(|_| panic!("no fit"));
        assert!(fitted.explained > 0.999_99, "{}", fitted.explained);
        for (got, want) in fitted.components.iter().zip(&truth) {
            assert!(
                (got.frequency_hz / want.frequency_hz - 1.0).abs() < 1e-6,
                "{got:?}"
            );
            assert!(
                (got.decay_per_s / want.decay_per_s - 1.0).abs() < 1e-4,
                "{got:?}"
            );
            assert!(
                (got.amplitude / want.amplitude - 1.0).abs() < 1e-4,
                "{got:?}"
            );
        }
    }

    /// A bubble whose pitch rises from 600 to 900 Hz in 50 ms: its glide comes back (within 3 %;
    /// the onset lies on a grid of 0.25 ms, which the frequency at the onset makes up for).
    #[test]
    fn a_rising_pitch_comes_back_as_a_glide() {
        let fs = 44_100.0;
        let truth = Component {
            frequency_hz: 600.0,
            glide_hz_per_s: 6_000.0,
            heard_hz: f64::NAN,
            decay_per_s: 40.0,
            amplitude: 0.5,
            phase: 0.3,
            in_span: 0.0,
        };
        let onset_s = 0.004;
        let stride = 2;
        let data: Vec<f64> = (0..(0.06 * fs) as usize / stride)
            .map(|n| {
                let tau = (stride * n) as f64 / fs - onset_s;
                if tau < 0.0 {
                    0.0
                } else {
                    truth.value(tau)
                }
            })
            .collect();
        let window = Window {
            data,
            first: 0,
            stride,
            fs,
        };
        let fitted =
            fit(&window, onset_s, &[(700.0, 40.0)], true).unwrap_or_else(|_| panic!("no fit"));
        let got = fitted.components[0];
        assert!(fitted.explained > 0.99, "{}", fitted.explained);
        assert!((got.glide_hz_per_s / 6_000.0 - 1.0).abs() < 0.03, "{got:?}");
        let at_10_ms = got.frequency_hz + got.glide_hz_per_s * (fitted.onset_s - onset_s + 0.01);
        assert!((at_10_ms / 660.0 - 1.0).abs() < 0.01, "{got:?}");
    }
}
