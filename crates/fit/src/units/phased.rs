//! A unit eq. 1 as it stands does not describe (MODEL.md §13): one or two decaying components,
//! each A·e^(−Bτ)·sin(2πfτ + φ) with a phase of its own, from a common onset, started at the
//! peaks of the unit's own spectrum. A component's phase is linear in it (S·sin + C·cos, with
//! A = √(S² + C²) and φ = atan2(C, S)), so the onset is taken from a grid around the detected one
//! by linear least squares at the starting frequencies; then S, C, f and B of every component
//! are refined together by Levenberg-Marquardt over the window's samples. A gliding unit (a
//! bubble's pitch sweeps into its mode as it forms) is fitted with each component gliding as
//! MODEL.md §5.2 has it, from ρ·f into f with a time constant τ_g: its phase
//! 2π(fτ + D·(1 − e^(−τ/τ_g))) + φ, D = (ρ − 1)·f·τ_g cycles. τ_g and ρ are set on a grid, then D
//! and τ_g are refined with the rest; the frequency it is heard at is its frequency at the
//! centre of its energy in the window.

use std::f64::consts::TAU;

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned};

use super::window::Window;
use super::{glide_ranges, Component, Rejection, UnitGlide};

/// The onset grid: this range around the detected onset (s), in steps.
const ONSET_GRID_S: (f64, f64, f64) = (-0.004, 0.002, 0.00025);
/// A glide's time constants tried (s): from a sweep within a few cycles to one through a glug.
const GLIDE_TIMES_S: [f64; 6] = [0.003, 0.006, 0.012, 0.025, 0.05, 0.1];
/// A glide's ratios tried: 2^x for x on a grid of this many octaves either side of none…
const GLIDE_OCTAVES: f64 = 1.2;
/// …in this many steps (even, so that no glide is on it).
const GLIDE_RATIO_STEPS: usize = 24;
/// Levenberg-Marquardt holds a glide's ratio and time constant within the model's ranges
/// (`glug.f1_glide_ratio`, `glug.f1_glide_ms`) widened by this factor either way: beyond them a
/// glide is no sweep a listener hears but a free phase (a huge ratio over a few samples), with
/// which a fit lends one mode's numbers to another. A glide held there lies outside the model's
/// range, so the unit's checks reject it. (Held within 2^±1.5 and 1–200 ms instead, and kept
/// there, the development family found the bright mode more often, f2 78 → 83 %, but a potion
/// clip's units then led the listening fit farther from it than the default bottle.)
const GLIDE_BOUND_SLACK: f64 = 1.05;
/// Where Levenberg-Marquardt leaves a glide held at the bound of the model's range (in a unit's
/// glide refit or a short mode's pair), it starts again from the grid's best at up to this many
/// other time constants, in the order the grid ranks them: from the grid's best it can run into
/// a free phase (τ_g at the bound, over a period or two), a worse fit than its sweep over
/// milliseconds (a development draw: 84 against 97 % of the window explained), from which it does
/// not climb out.
pub(super) const GLIDE_RESTARTS: usize = 2;
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

/// One component's numbers, to start from or as refined: its own f (Hz), B (1/s), and its
/// glide's D = (ρ − 1)·f·τ_g (cycles) at the time constant τ_g (s; 0 for a steady component).
#[derive(Debug, Clone, Copy)]
struct Numbers {
    hz: f64,
    decay: f64,
    glide_cycles: f64,
    glide_s: f64,
}

impl Numbers {
    fn steady(hz: f64, decay: f64) -> Self {
        Self {
            hz,
            decay,
            glide_cycles: 0.0,
            glide_s: 0.0,
        }
    }

    /// The share of its glide's D the phase has added by τ (∂cycles/∂D).
    fn reach(&self, tau: f64) -> f64 {
        if self.glide_s > 0.0 {
            1.0 - (-tau / self.glide_s).exp()
        } else {
            0.0
        }
    }

    /// The cycles its phase has turned through by τ.
    fn cycles(&self, tau: f64) -> f64 {
        self.hz * tau + self.glide_cycles * self.reach(tau)
    }

    /// Its glide as the model states it (ρ, τ_g), if it glides.
    fn glide(&self) -> Option<UnitGlide> {
        (self.glide_s > 0.0).then(|| UnitGlide {
            ratio: 1.0 + self.glide_cycles / (self.hz * self.glide_s),
            time_s: self.glide_s,
        })
    }
}

/// Fits `starts.len()` components started at `starts` (f Hz, B 1/s) to `window`, the onset near
/// `detected_s`, component k gliding (MODEL.md §5.2) if `gliding[k]` (steady where `gliding` is
/// shorter).
pub(super) fn fit(
    window: &Window,
    detected_s: f64,
    starts: &[(f64, f64)],
    gliding: &[bool],
    glide_restarts: usize,
) -> Result<PhasedFit, Rejection> {
    let not_finite = || Rejection::NotFinite;
    let gliding: Vec<bool> = (0..starts.len())
        .map(|k| gliding.get(k).copied().unwrap_or(false))
        .collect();
    let glide = gliding.contains(&true);
    let steady: Vec<Numbers> = starts
        .iter()
        .map(|&(hz, decay)| Numbers::steady(hz, decay))
        .collect();
    let (onset_s, _) = onset_grid(window, detected_s, &steady).ok_or_else(not_finite)?;
    let refined = |ranks: &[usize]| -> Option<Refined> {
        let mut starts = steady.clone();
        if glide {
            set_glides(window, onset_s, &mut starts, &gliding, ranks);
        }
        refine_with_onset(window, detected_s, starts, &gliding)
    };
    // Each glide from the grid's best; a glide held at a bound from the grid's next time
    // constants in turn (up to `glide_restarts`), the others as they were, until none is held.
    let mut ranks = vec![0; steady.len()];
    let mut fitted = refined(&ranks);
    let mut last = fitted.as_ref().map(|f| f.held_glides(&gliding));
    for _ in 0..glide_restarts {
        let Some(held) = last.filter(|held| held.contains(&true)) else {
            break;
        };
        for (rank, held) in ranks.iter_mut().zip(held) {
            *rank += usize::from(held);
        }
        let again = refined(&ranks);
        last = again.as_ref().map(|f| f.held_glides(&gliding));
        if last.as_ref().is_some_and(|held| !held.contains(&true)) {
            fitted = again;
            break;
        }
    }
    let fitted = fitted.ok_or_else(not_finite)?;
    let span_s = span_of(window, fitted.onset_s);
    let components = fitted
        .numbers
        .iter()
        .zip(&fitted.amplitudes)
        .map(|(numbers, &(sine, cosine))| {
            let Numbers { hz, decay, .. } = *numbers;
            let glide = numbers.glide();
            // The centre of its energy in the window: 1/(2B) after the onset, or the window's
            // middle if it decays more slowly.
            let centre_s = (0.5 / decay.max(1e-9)).min(0.5 * span_s);
            Component {
                frequency_hz: hz,
                glide,
                heard_hz: hz * glide.map_or(1.0, |g| g.factor(centre_s)),
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
    numbers: Vec<Numbers>,
    /// Each component's S, C.
    amplitudes: Vec<(f64, f64)>,
    sum_of_squares: f64,
}

impl Refined {
    /// For each component, whether Levenberg-Marquardt left its glide outside the model's range
    /// (held at its bound): no sweep, and the unit's checks reject it.
    fn held_glides(&self, gliding: &[bool]) -> Vec<bool> {
        let (ratios, times_ms) = glide_ranges();
        self.numbers
            .iter()
            .zip(gliding)
            .map(|(numbers, &glides)| {
                glides
                    && numbers.glide().is_some_and(|g| {
                        !(ratios.contains(g.ratio) && times_ms.contains(1e3 * g.time_s))
                    })
            })
            .collect()
    }
}

/// The onset and the rest refined in turn from `starts`: the onset on the grid at the last fit's
/// numbers, then the rest by Levenberg-Marquardt at that onset.
fn refine_with_onset(
    window: &Window,
    detected_s: f64,
    starts: Vec<Numbers>,
    gliding: &[bool],
) -> Option<Refined> {
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
        let Some(refined) = refine(window, onset_s, &at, &amplitudes, gliding) else {
            break;
        };
        if fitted
            .as_ref()
            .is_some_and(|f| f.sum_of_squares <= refined.sum_of_squares)
        {
            break;
        }
        at.clone_from(&refined.numbers);
        fitted = Some(refined);
    }
    fitted
}

/// The onset on the grid around `detected_s` whose linear fit at `starts` leaves the least, and
/// its amplitudes.
fn onset_grid(window: &Window, detected_s: f64, starts: &[Numbers]) -> Option<(f64, DVector<f64>)> {
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

/// A glide's phase runs far from a steady one's within a window, so each component's glide is
/// first set on a grid of time constants and ratios, its own f chosen for each so that it sweeps
/// through the steady start's frequency at the centre of its energy (where a steady fit, its
/// phase free, matches it best). Each trial is a linear fit; the other components' columns and
/// their products are the same for every trial, so they are taken once.
///
/// `ranks[k]` 0 takes component k's best trial; r, its best at the time constant whose best ranks
/// r-th (a start for Levenberg-Marquardt in another basin).
fn set_glides(
    window: &Window,
    onset_s: f64,
    starts: &mut [Numbers],
    gliding: &[bool],
    ranks: &[usize],
) {
    let span_s = span_of(window, onset_s);
    let first = window.first_after(onset_s);
    let taus: Vec<f64> = (first..window.data.len())
        .map(|n| window.time_s(n) - onset_s)
        .collect();
    let data = &window.data[first..];
    let column = |numbers: &Numbers, part: fn(f64) -> f64| -> Vec<f64> {
        taus.iter()
            .map(|&tau| (-numbers.decay * tau).exp() * part(TAU * numbers.cycles(tau)))
            .collect()
    };
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    for k in (0..starts.len()).filter(|&k| gliding[k]) {
        let Numbers { hz, decay, .. } = starts[k];
        let others: Vec<Vec<f64>> = starts
            .iter()
            .enumerate()
            .filter(|&(j, _)| j != k)
            .flat_map(|(_, numbers)| [column(numbers, f64::sin), column(numbers, f64::cos)])
            .collect();
        let size = others.len() + 2;
        // The normal equations' block of the other columns, and their products with the data.
        let mut normal = DMatrix::zeros(size, size);
        let mut projected = DVector::zeros(size);
        for (i, a) in others.iter().enumerate() {
            projected[i + 2] = dot(a, data);
            for (j, b) in others.iter().enumerate().skip(i) {
                normal[(i + 2, j + 2)] = dot(a, b);
                normal[(j + 2, i + 2)] = normal[(i + 2, j + 2)];
            }
        }
        let envelope: Vec<f64> = taus.iter().map(|&tau| (-decay * tau).exp()).collect();
        let centre_s = (0.5 / decay.max(1e-9)).min(0.5 * span_s);
        // The best trial at each time constant.
        let mut best_at: Vec<(f64, Numbers)> = Vec::with_capacity(GLIDE_TIMES_S.len());
        let (mut sine, mut cosine) = (vec![0.0; taus.len()], vec![0.0; taus.len()]);
        for &glide_s in &GLIDE_TIMES_S {
            let mut best: Option<(f64, Numbers)> = None;
            let reach: Vec<f64> = taus
                .iter()
                .map(|&tau| 1.0 - (-tau / glide_s).exp())
                .collect();
            let left = (-centre_s / glide_s).exp();
            for step in 0..=GLIDE_RATIO_STEPS {
                let octaves = GLIDE_OCTAVES * (2.0 * step as f64 / GLIDE_RATIO_STEPS as f64 - 1.0);
                let ratio = octaves.exp2();
                let own_hz = hz / (1.0 + (ratio - 1.0) * left);
                let trial = Numbers {
                    hz: own_hz,
                    decay,
                    glide_cycles: (ratio - 1.0) * own_hz * glide_s,
                    glide_s,
                };
                for (n, &tau) in taus.iter().enumerate() {
                    let cycles = trial.hz * tau + trial.glide_cycles * reach[n];
                    let (im, re) = (TAU * cycles).sin_cos();
                    sine[n] = envelope[n] * im;
                    cosine[n] = envelope[n] * re;
                }
                let mut trial_normal = normal.clone();
                let mut trial_projected = projected.clone();
                for (i, a) in [&sine, &cosine].into_iter().enumerate() {
                    trial_projected[i] = dot(a, data);
                    trial_normal[(i, 0)] = dot(a, &sine);
                    trial_normal[(i, 1)] = dot(a, &cosine);
                    for (j, b) in others.iter().enumerate() {
                        trial_normal[(i, j + 2)] = dot(a, b);
                        trial_normal[(j + 2, i)] = trial_normal[(i, j + 2)];
                    }
                }
                let Some(factor) = trial_normal.cholesky() else {
                    continue;
                };
                // The sum of squares left, less the data's (the same for every trial).
                let left_over = -factor.solve(&trial_projected).dot(&trial_projected);
                if left_over.is_finite() && best.as_ref().is_none_or(|b| left_over < b.0) {
                    best = Some((left_over, trial));
                }
            }
            best_at.extend(best);
        }
        best_at.sort_by(|a, b| a.0.total_cmp(&b.0));
        if let Some(&(_, trial)) = best_at.get(ranks[k].min(best_at.len().saturating_sub(1))) {
            starts[k] = trial;
        }
    }
}

/// Levenberg-Marquardt from `starts` and `amplitudes` at `onset_s`.
fn refine(
    window: &Window,
    onset_s: f64,
    starts: &[Numbers],
    amplitudes: &DVector<f64>,
    gliding: &[bool],
) -> Option<Refined> {
    let per = if gliding.contains(&true) { 6 } else { 4 };
    let mut params = DVector::zeros(per * starts.len());
    for (k, numbers) in starts.iter().enumerate() {
        params[per * k] = amplitudes[2 * k];
        params[per * k + 1] = amplitudes[2 * k + 1];
        params[per * k + 2] = numbers.hz;
        params[per * k + 3] = numbers.decay;
        if gliding[k] {
            params[per * k + 4] = numbers.glide_cycles;
            params[per * k + 5] = numbers.glide_s.ln();
        }
    }
    let problem = PhasedProblem {
        window,
        onset_s,
        params,
        per,
        gliding,
    };
    let (problem, _report) = LevenbergMarquardt::new()
        .with_patience(LM_PATIENCE)
        .minimize(problem);
    let sum_of_squares = problem.residuals()?.norm_squared();
    let finite = problem.params.iter().all(|v| v.is_finite()) && sum_of_squares.is_finite();
    let p = &problem.params;
    finite.then(|| Refined {
        onset_s,
        numbers: (0..starts.len()).map(|k| problem.numbers(k)).collect(),
        amplitudes: (0..starts.len())
            .map(|k| (p[per * k], p[per * k + 1]))
            .collect(),
        sum_of_squares,
    })
}

/// The time from `onset_s` to the window's last sample (s).
fn span_of(window: &Window, onset_s: f64) -> f64 {
    (window.time_s(window.data.len().saturating_sub(1)) - onset_s).max(0.0)
}

/// The least-squares S, C of each component at `onset_s` with its other numbers as in `starts`,
/// and the sum of squares left.
fn linear_fit(window: &Window, onset_s: f64, starts: &[Numbers]) -> Option<(f64, DVector<f64>)> {
    let rows = window.data.len();
    let mut columns = DMatrix::zeros(rows, 2 * starts.len());
    for (k, numbers) in starts.iter().enumerate() {
        for n in window.first_after(onset_s)..rows {
            let tau = window.time_s(n) - onset_s;
            let envelope = (-numbers.decay * tau).exp();
            let (im, re) = (TAU * numbers.cycles(tau)).sin_cos();
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

/// The components `[S, C, f, B]` each (and a glide's D and ln τ_g, if `per` is 6), at a fixed
/// onset, over every sample of the window.
struct PhasedProblem<'a> {
    window: &'a Window,
    onset_s: f64,
    params: DVector<f64>,
    per: usize,
    /// Which components glide (a steady one's D and ln τ_g are held at none).
    gliding: &'a [bool],
}

impl PhasedProblem<'_> {
    /// Component k's numbers as the parameters have them, its glide held within the bounds
    /// ([`GLIDE_BOUND_OCTAVES`], [`GLIDE_BOUND_S`]), and whether its D and its τ_g are held.
    fn held_numbers(&self, k: usize) -> (Numbers, [bool; 2]) {
        let p = &self.params.as_slice()[self.per * k..self.per * (k + 1)];
        if !self.gliding[k] {
            return (Numbers::steady(p[2], p[3]), [true; 2]);
        }
        let (ratios, times_ms) = glide_ranges();
        let glide_s = p[5].exp().clamp(
            1e-3 * times_ms.min / GLIDE_BOUND_SLACK,
            1e-3 * times_ms.max * GLIDE_BOUND_SLACK,
        );
        let cycles_per_ratio = p[2].abs() * glide_s;
        let lowest = (ratios.min / GLIDE_BOUND_SLACK - 1.0) * cycles_per_ratio;
        let highest = (ratios.max * GLIDE_BOUND_SLACK - 1.0) * cycles_per_ratio;
        let glide_cycles = p[4].clamp(lowest, highest);
        let numbers = Numbers {
            hz: p[2],
            decay: p[3],
            glide_cycles,
            glide_s,
        };
        (numbers, [glide_cycles != p[4], glide_s != p[5].exp()])
    }

    /// Component k's numbers as the fit plays them.
    fn numbers(&self, k: usize) -> Numbers {
        self.held_numbers(k).0
    }

    /// For every sample n, `each(n, r_n, J_n)`: the residual (the model less the recording) and
    /// the row of the Jacobian (zero before the onset).
    fn rows(&self, mut each: impl FnMut(usize, f64, &[f64])) {
        let per = self.per;
        let count = self.params.len() / per;
        let (numbers, held): (Vec<Numbers>, Vec<[bool; 2]>) =
            (0..count).map(|k| self.held_numbers(k)).unzip();
        let mut row = vec![0.0; self.params.len()];
        for (n, &y) in self.window.data.iter().enumerate() {
            let tau = self.window.time_s(n) - self.onset_s;
            row.iter_mut().for_each(|v| *v = 0.0);
            if tau < 0.0 {
                each(n, -y, &row);
                continue;
            }
            let mut model = 0.0;
            for (k, component) in numbers.iter().enumerate() {
                let (sine, cosine) = (self.params[per * k], self.params[per * k + 1]);
                let envelope = (-component.decay * tau).exp();
                let (im, re) = (TAU * component.cycles(tau)).sin_cos();
                let (im, re) = (envelope * im, envelope * re);
                model += sine * im + cosine * re;
                let turning = sine * re - cosine * im;
                row[per * k] = im;
                row[per * k + 1] = re;
                row[per * k + 2] = TAU * tau * turning;
                row[per * k + 3] = -tau * (sine * im + cosine * re);
                if per == 6 {
                    // A number held at its bound does not move the model.
                    let left = (-tau / component.glide_s).exp();
                    row[per * k + 4] = if held[k][0] {
                        0.0
                    } else {
                        TAU * (1.0 - left) * turning
                    };
                    // ∂/∂ln τ_g of D·(1 − e^(−τ/τ_g)): −D·(τ/τ_g)·e^(−τ/τ_g).
                    row[per * k + 5] = if held[k][1] {
                        0.0
                    } else {
                        -TAU * component.glide_cycles * (tau / component.glide_s) * left * turning
                    };
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

    /// `components` from `onset_s` on, `read` samples at `fs`, every `stride`-th.
    fn window_of(
        components: &[Component],
        onset_s: f64,
        read: usize,
        fs: f64,
        stride: usize,
    ) -> Window {
        let data = (0..read)
            .map(|n| {
                let tau = (stride * n) as f64 / fs - onset_s;
                if tau < 0.0 {
                    0.0
                } else {
                    components.iter().map(|c| c.value(tau)).sum()
                }
            })
            .collect();
        Window {
            data,
            first: 0,
            stride,
            fs,
        }
    }

    /// A component out of phase and a second, fitted from starts 5 % off, come back exactly.
    #[test]
    fn two_components_with_phases_of_their_own_come_back() {
        let fs = 22_050.0;
        let truth = [
            Component {
                frequency_hz: 440.0,
                glide: None,
                heard_hz: 440.0,
                decay_per_s: 60.0,
                amplitude: 0.5,
                phase: 1.2,
                in_span: 0.0,
            },
            Component {
                frequency_hz: 1300.0,
                glide: None,
                heard_hz: 1300.0,
                decay_per_s: 90.0,
                amplitude: 0.2,
                phase: -2.0,
                in_span: 0.0,
            },
        ];
        let onset_s = 0.004;
        let window = window_of(&truth, onset_s, 2000, fs, 1);
        let fitted = fit(
            &window,
            onset_s + 0.001,
            &[(420.0, 40.0), (1360.0, 40.0)],
            &[],
            0,
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

    /// A glide slower than its ring is no resonance the fit may keep (its own f is never heard);
    /// one within it is.
    #[test]
    fn a_glide_slower_than_its_ring_is_rejected() {
        let component = |time_s: f64| Component {
            frequency_hz: 600.0,
            glide: Some(UnitGlide { ratio: 0.7, time_s }),
            heard_hz: 550.0,
            decay_per_s: 100.0,
            amplitude: 0.5,
            phase: 0.0,
            in_span: 0.0,
        };
        assert_eq!(component(0.015).unheard_glide(), None);
        assert!(matches!(
            component(0.05).unheard_glide(),
            Some(Rejection::GlideUnheard { .. })
        ));
    }

    /// A bubble whose pitch sweeps up from 420 into 600 Hz (ρ = 0.7, τ_g = 15 ms): its glide comes
    /// back from a start at the frequency it sweeps through at the centre of its energy (522 Hz at
    /// 12.5 ms), its own f within 1 % and ρ within 3 %, though the grid holds neither.
    #[test]
    fn a_rising_pitch_comes_back_as_a_glide() {
        let fs = 44_100.0;
        let truth = Component {
            frequency_hz: 600.0,
            glide: Some(UnitGlide {
                ratio: 0.7,
                time_s: 0.015,
            }),
            heard_hz: f64::NAN,
            decay_per_s: 40.0,
            amplitude: 0.5,
            phase: 0.3,
            in_span: 0.0,
        };
        let onset_s = 0.004;
        let stride = 2;
        let window = window_of(&[truth], onset_s, (0.08 * fs) as usize / stride, fs, stride);
        let fitted = fit(&window, onset_s, &[(530.0, 40.0)], &[true], 0)
            .unwrap_or_else(|_| panic!("no fit"));
        let got = fitted.components[0];
        let glide = got.glide.unwrap_or_else(|| panic!("no glide: {got:?}"));
        assert!(fitted.explained > 0.99, "{}", fitted.explained);
        assert!((got.frequency_hz / 600.0 - 1.0).abs() < 0.01, "{got:?}");
        assert!((glide.ratio / 0.7 - 1.0).abs() < 0.03, "{got:?}");
    }

    /// Levenberg-Marquardt plays a glide held within the model's ranges, widened a little, and
    /// does not move a number held there: a huge D over a few samples is a free phase, not a
    /// sweep. So a glide held at a bound lies outside the model's range, and the unit's checks
    /// reject it; a steady component never glides.
    #[test]
    fn a_glide_is_held_just_beyond_the_models_ranges() {
        let window = Window {
            data: vec![0.0; 8],
            first: 0,
            stride: 1,
            fs: 8000.0,
        };
        // [S, C, f, B, D, ln τ_g] for a component at 500 Hz: D of 10⁶ cycles over 1 µs, and a
        // steady one with the same numbers.
        let params = DVector::from_column_slice(&[
            1.0, 0.0, 500.0, 40.0, 1e6, -13.8, 1.0, 0.0, 500.0, 40.0, 1e6, -13.8,
        ]);
        let problem = PhasedProblem {
            window: &window,
            onset_s: 0.0,
            params,
            per: 6,
            gliding: &[true, false],
        };
        let (held, which) = problem.held_numbers(0);
        let (ratios, times_ms) = glide_ranges();
        let ratio = 1.0 + held.glide_cycles / (held.hz * held.glide_s);
        assert_eq!(which, [true, true]);
        assert!((1e3 * held.glide_s / times_ms.min * GLIDE_BOUND_SLACK - 1.0).abs() < 1e-9);
        assert!(
            (ratio / ratios.max / GLIDE_BOUND_SLACK - 1.0).abs() < 1e-9,
            "{ratio}"
        );
        assert!(!ratios.contains(ratio) && !times_ms.contains(1e3 * held.glide_s));
        let (steady, _) = problem.held_numbers(1);
        assert_eq!((steady.glide_cycles, steady.glide_s), (0.0, 0.0));
    }

    /// A gliding component beside a steady one (a cavity sweeping into 544 Hz, a short bubble
    /// at 1030 Hz): fitted with the first gliding and the second steady, both come back.
    #[test]
    fn a_glide_and_a_steady_component_come_back_together() {
        let fs = 11_025.0;
        let cavity = Component {
            frequency_hz: 544.0,
            glide: Some(UnitGlide {
                ratio: 1.33,
                time_s: 0.017,
            }),
            heard_hz: f64::NAN,
            decay_per_s: 13.0,
            amplitude: 0.5,
            phase: 0.3,
            in_span: 0.0,
        };
        let bubble = Component {
            frequency_hz: 1030.0,
            glide: None,
            decay_per_s: 150.0,
            amplitude: 0.4,
            phase: -1.0,
            ..cavity
        };
        let onset_s = 0.004;
        let window = window_of(&[cavity, bubble], onset_s, (0.1 * fs) as usize, fs, 1);
        let fitted = fit(
            &window,
            onset_s,
            &[(560.0, 13.0), (1000.0, 150.0)],
            &[true, false],
            0,
        )
        .unwrap_or_else(|_| panic!("no fit"));
        assert!(fitted.explained > 0.999, "{}", fitted.explained);
        let [low, high] = [fitted.components[0], fitted.components[1]];
        let glide = low.glide.unwrap_or_else(|| panic!("no glide: {low:?}"));
        assert!((low.frequency_hz / 544.0 - 1.0).abs() < 0.01, "{low:?}");
        assert!((glide.ratio / 1.33 - 1.0).abs() < 0.03, "{low:?}");
        assert_eq!(high.glide, None);
        assert!((high.frequency_hz / 1030.0 - 1.0).abs() < 0.01, "{high:?}");
        assert!((high.decay_per_s / 150.0 - 1.0).abs() < 0.05, "{high:?}");
    }
}
