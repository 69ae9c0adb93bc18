//! Each unit's eq. 1 (MODEL.md §5, §13): two exponentially decaying sinusoids from a common onset,
//! q(τ) = A1·e^(−B1τ)·sin(2πf1τ) + A2·e^(−B2τ)·sin(2πf2τ), fitted to the recording in the window
//! from just before its onset to just before the next unit's. The start: the two poles of a
//! matrix pencil (nalgebra's SVD and eigenvalues) nearest the recording's spectral peaks, the
//! onset from a grid and the amplitudes by linear least squares; then all seven numbers refined
//! together by Levenberg-Marquardt (the `levenberg-marquardt` crate). Units are fitted in order,
//! each fitted unit subtracted from the recording before the next is fitted, so that a unit
//! starting while the last one rings is fitted alone.

use std::f64::consts::TAU;

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, OMatrix, Owned, SVector, U7};

type Vector7 = SVector<f64, 7>;
use num_complex::Complex;

use super::onsets::detect_onsets;
use super::spectrum::Spectrum;

/// The fitted window starts this long before the detected onset (s): the silence before a unit
/// pins its onset.
const BEFORE_ONSET_S: f64 = 0.004;
/// …and ends this long before the next detected onset (s), which may lie late by as much.
const BEFORE_NEXT_S: f64 = 0.004;
/// The longest window (s): the components are 50 dB down by then at 40 /s.
const LONGEST_WINDOW_S: f64 = 0.15;
/// The shortest window (s) a unit is fitted in: less than a period of the low component says
/// little about it.
const SHORTEST_WINDOW_S: f64 = 0.012;
/// The onset grid of the starting guess: this range around the detected onset (s), in steps.
const ONSET_GRID_S: (f64, f64, f64) = (-0.004, 0.002, 0.00025);
/// The pencil sees at most this much of a unit (s): its loud start.
const PENCIL_S: f64 = 0.04;
/// Samples per period of the highest component the pencil keeps (it decimates to this).
const PENCIL_SAMPLES_PER_PERIOD: f64 = 8.0;
/// A pencil pole within this frequency ratio of a spectral peak is taken for that component.
const POLE_MATCH_RATIO: f64 = 1.3;
/// The decay assumed where the pencil finds none (1/s): the model's default B2.
const DECAY_GUESS_PER_S: f64 = 40.0;
/// A unit whose fit explains less than this share of its window's energy is rejected.
const MIN_R_SQUARED: f64 = 0.5;
/// A fitted onset further than this from the detected one is rejected (s).
const MAX_ONSET_SHIFT_S: f64 = 0.006;
/// The highest decay rate kept (1/s).
const MAX_DECAY_PER_S: f64 = 5_000.0;
/// A fitted unit is subtracted until it has decayed by this factor (−80 dB).
const SUBTRACT_UNTIL: f64 = 1e-4;
/// Levenberg-Marquardt gives up after patience × 8 evaluations.
const LM_PATIENCE: usize = 25;

/// One unit's eq. 1, as fitted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitFit {
    /// The onset t_i (s from the recording's first sample).
    pub onset_s: f64,
    /// A1, A2 (the recording's units).
    pub amplitude: [f64; 2],
    /// f1, f2 (Hz), f1 the lower.
    pub frequency_hz: [f64; 2],
    /// B1, B2 (1/s).
    pub decay_per_s: [f64; 2],
    /// The share of its window's energy the fit explains.
    pub r_squared: f64,
    /// The samples fitted, `[first, end)`.
    pub window: (usize, usize),
    /// Where Levenberg-Marquardt started, `[onset (s), A1, A2, f1, f2, B1, B2]` (the pencil's
    /// poles, the onset grid and its amplitudes): another solver started here is compared fairly
    /// (benches/render.rs).
    pub start: [f64; 7],
}

impl UnitFit {
    /// Asum = A1 + A2.
    pub fn amplitude_sum(&self) -> f64 {
        self.amplitude[0] + self.amplitude[1]
    }

    /// c = A1/(A1 + A2) (paper eq. 2).
    pub fn viscosity(&self) -> f64 {
        self.amplitude[0] / self.amplitude_sum()
    }

    /// q(t) at `time_s`.
    pub fn value_at(&self, time_s: f64) -> f64 {
        let tau = time_s - self.onset_s;
        if tau < 0.0 {
            return 0.0;
        }
        (0..2)
            .map(|k| {
                self.amplitude[k]
                    * (-self.decay_per_s[k] * tau).exp()
                    * (TAU * self.frequency_hz[k] * tau).sin()
            })
            .sum()
    }
}

/// Every unit of one recording.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingUnits {
    /// The units kept, in time order.
    pub units: Vec<UnitFit>,
    /// Onsets detected whose fit was rejected (too short a window, a poor or implausible fit).
    pub rejected: usize,
    /// The spectrum's peaks that started every unit's frequencies (Hz; f1 < f2).
    pub start_hz: [f64; 2],
    /// Whether the spectrum showed only one peak (the other start was guessed).
    pub one_peak: bool,
    /// The recording's spectrum.
    pub spectrum: Spectrum,
}

/// Finds and fits every unit of `samples` (DC removed) at `sample_rate`.
pub fn fit_units(samples: &[f64], sample_rate: u32) -> RecordingUnits {
    let fs = sample_rate as f64;
    let spectrum = Spectrum::of(samples, fs);
    let peaks = spectrum.peaks();
    // The paper's ratio of f2 to f1 guesses the other component when only one shows.
    const RATIO: f64 = 300.0 / 80.0;
    let (start_hz, one_peak) = match peaks.as_slice() {
        [low, high] => ([*low, *high], false),
        [only] if *only < 160.0 => ([*only, only * RATIO], true),
        [only] => ([only / RATIO, *only], true),
        _ => ([80.0, 300.0], true),
    };
    let onsets = detect_onsets(samples, fs, start_hz[0]);
    let mut residual = samples.to_vec();
    let mut units = Vec::with_capacity(onsets.len());
    let mut rejected = 0;
    let step =
        ((fs / (PENCIL_SAMPLES_PER_PERIOD * start_hz[1] * POLE_MATCH_RATIO)) as usize).max(1);
    for (index, &onset) in onsets.iter().enumerate() {
        let first = onset.saturating_sub((BEFORE_ONSET_S * fs) as usize);
        let next = onsets.get(index + 1).copied().unwrap_or(samples.len());
        let end = next
            .saturating_sub((BEFORE_NEXT_S * fs) as usize)
            .min(onset + (LONGEST_WINDOW_S * fs) as usize)
            .min(samples.len());
        if end < first + ((SHORTEST_WINDOW_S + BEFORE_ONSET_S) * fs) as usize {
            rejected += 1;
            continue;
        }
        match fit_unit(&residual, first, end, onset, fs, start_hz, step) {
            Some(unit) => {
                subtract(&mut residual, &unit, fs);
                units.push(unit);
            }
            None => rejected += 1,
        }
    }
    RecordingUnits {
        units,
        rejected,
        start_hz,
        one_peak,
        spectrum,
    }
}

/// Fits the unit detected at `onset` in `signal[first..end]`; `None` if the fit is implausible.
fn fit_unit(
    signal: &[f64],
    first: usize,
    end: usize,
    onset: usize,
    fs: f64,
    start_hz: [f64; 2],
    step: usize,
) -> Option<UnitFit> {
    let pencil_end = end.min(onset + (PENCIL_S * fs) as usize);
    let poles = pencil_poles(&signal[onset..pencil_end], step, fs);
    let mut frequency_hz = start_hz;
    let mut decay_per_s = [DECAY_GUESS_PER_S; 2];
    for k in 0..2 {
        let near = poles
            .iter()
            .filter(|(hz, decay)| {
                (hz / start_hz[k]).max(start_hz[k] / hz) < POLE_MATCH_RATIO
                    && *decay > 0.5
                    && *decay < MAX_DECAY_PER_S
            })
            .min_by(|a, b| {
                (a.0 / start_hz[k])
                    .ln()
                    .abs()
                    .total_cmp(&(b.0 / start_hz[k]).ln().abs())
            });
        if let Some(&(hz, decay)) = near {
            frequency_hz[k] = hz;
            decay_per_s[k] = decay;
        }
    }
    let data = &signal[first..end];
    let detected_s = onset as f64 / fs;
    let (start_s, amplitude) = onset_grid(data, first, fs, detected_s, frequency_hz, decay_per_s);
    let start = [
        start_s,
        amplitude[0],
        amplitude[1],
        frequency_hz[0],
        frequency_hz[1],
        decay_per_s[0],
        decay_per_s[1],
    ];
    let problem = UnitProblem {
        data,
        first,
        fs,
        reference_s: start_s,
        params: Vector7::from_column_slice(&[
            0.0,
            amplitude[0],
            amplitude[1],
            frequency_hz[0],
            frequency_hz[1],
            decay_per_s[0],
            decay_per_s[1],
        ]),
    };
    let (problem, _report) = LevenbergMarquardt::new()
        .with_patience(LM_PATIENCE)
        .minimize(problem);
    let p = problem.params;
    let mut unit = UnitFit {
        onset_s: problem.reference_s + p[0] / 1000.0,
        amplitude: [p[1], p[2]],
        frequency_hz: [p[3], p[4]],
        decay_per_s: [p[5], p[6]],
        r_squared: 0.0,
        window: (first, end),
        start,
    };
    if unit.frequency_hz[0] > unit.frequency_hz[1] {
        unit.amplitude.swap(0, 1);
        unit.frequency_hz.swap(0, 1);
        unit.decay_per_s.swap(0, 1);
    }
    let energy: f64 = data.iter().map(|y| y * y).sum();
    let residual: f64 = problem.residuals()?.norm_squared();
    unit.r_squared = 1.0 - residual / energy.max(1e-300);
    let total = unit.amplitude_sum();
    let plausible = p.iter().all(|value| value.is_finite())
        && total > 0.0
        && unit.amplitude.iter().all(|&a| a >= -0.02 * total)
        && unit
            .frequency_hz
            .iter()
            .all(|&hz| hz > 0.0 && hz < fs / 2.0)
        && unit
            .decay_per_s
            .iter()
            .all(|&b| b > 0.0 && b < MAX_DECAY_PER_S)
        && unit.r_squared >= MIN_R_SQUARED
        && (unit.onset_s - detected_s).abs() <= MAX_ONSET_SHIFT_S;
    for amplitude in &mut unit.amplitude {
        *amplitude = amplitude.max(0.0);
    }
    plausible.then_some(unit)
}

/// The damped poles `(f Hz, B 1/s)`, f > 0, of a matrix pencil of order 4 (two real damped
/// sinusoids) through `segment` taken every `step` samples.
fn pencil_poles(segment: &[f64], step: usize, fs: f64) -> Vec<(f64, f64)> {
    const ORDER: usize = 4;
    let decimated: Vec<f64> = segment.iter().step_by(step).copied().collect();
    let len = decimated.len();
    let pencil = len / 3;
    if pencil < ORDER + 1 || len < pencil + ORDER + 2 {
        return Vec::new();
    }
    let rows = len - pencil;
    let hankel = DMatrix::from_fn(rows, pencil + 1, |i, j| decimated[i + j]);
    let Some(v_t) = hankel.svd(false, true).v_t else {
        return Vec::new();
    };
    let signal_space = v_t.rows(0, ORDER).transpose();
    let v1 = signal_space.rows(0, pencil).into_owned();
    let v2 = signal_space.rows(1, pencil).into_owned();
    let Ok(v1_inverse) = v1.pseudo_inverse(1e-12) else {
        return Vec::new();
    };
    let companion = v1_inverse * v2;
    let decimated_fs = fs / step as f64;
    companion
        .complex_eigenvalues()
        .iter()
        .filter(|z| z.im > 0.0 && z.norm() > 0.0)
        .map(|z| (z.arg() * decimated_fs / TAU, -z.norm().ln() * decimated_fs))
        .collect()
}

/// The onset on a grid around `detected_s` whose least-squares amplitudes (both positive if
/// any onset gives that) leave the least residual; returns it and the amplitudes.
fn onset_grid(
    data: &[f64],
    first: usize,
    fs: f64,
    detected_s: f64,
    frequency_hz: [f64; 2],
    decay_per_s: [f64; 2],
) -> (f64, [f64; 2]) {
    let (from, to, by) = ONSET_GRID_S;
    let mut best: Option<(bool, f64, f64, [f64; 2])> = None;
    let mut columns = [vec![0.0; data.len()], vec![0.0; data.len()]];
    let steps = ((to - from) / by).round() as usize;
    for step in 0..=steps {
        let onset_s = detected_s + from + by * step as f64;
        for (k, column) in columns.iter_mut().enumerate() {
            oscillate(
                column,
                first,
                fs,
                onset_s,
                frequency_hz[k],
                decay_per_s[k],
                |z, _| z.im,
            );
        }
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let (g00, g01, g11) = (
            dot(&columns[0], &columns[0]),
            dot(&columns[0], &columns[1]),
            dot(&columns[1], &columns[1]),
        );
        let (b0, b1) = (dot(&columns[0], data), dot(&columns[1], data));
        let det = g00 * g11 - g01 * g01;
        if det.is_nan() || det.abs() <= 1e-300 {
            continue;
        }
        let amplitude = [(g11 * b0 - g01 * b1) / det, (g00 * b1 - g01 * b0) / det];
        let explained = amplitude[0] * b0 + amplitude[1] * b1;
        let positive = amplitude.iter().all(|&a| a >= 0.0);
        let better = match best {
            None => true,
            Some((best_positive, best_explained, _, _)) => {
                (positive && !best_positive)
                    || (positive == best_positive && explained > best_explained)
            }
        };
        if better {
            best = Some((positive, explained, onset_s, amplitude));
        }
    }
    best.map_or((detected_s, [0.0; 2]), |(_, _, onset_s, amplitude)| {
        (onset_s, amplitude)
    })
}

/// Writes `value(z, τ)` to `out[n]` for z = e^((−B + i2πf)τ), τ = (first + n)/fs − onset_s, by
/// one complex rotation per sample; 0 where τ < 0.
fn oscillate(
    out: &mut [f64],
    first: usize,
    fs: f64,
    onset_s: f64,
    frequency_hz: f64,
    decay_per_s: f64,
    value: impl Fn(Complex<f64>, f64) -> f64,
) {
    let rate = Complex::new(-decay_per_s, TAU * frequency_hz);
    let step = (rate / fs).exp();
    let start = ((onset_s * fs).ceil().max(first as f64) as usize).saturating_sub(first);
    let zeros = start.min(out.len());
    out[..zeros].iter_mut().for_each(|y| *y = 0.0);
    if start >= out.len() {
        return;
    }
    let tau0 = (first + start) as f64 / fs - onset_s;
    let mut z = (rate * tau0).exp();
    for (n, y) in out[start..].iter_mut().enumerate() {
        *y = value(z, tau0 + n as f64 / fs);
        z *= step;
    }
}

/// Subtracts `unit` from `signal` until it has decayed by [`SUBTRACT_UNTIL`].
fn subtract(signal: &mut [f64], unit: &UnitFit, fs: f64) {
    let slowest = unit.decay_per_s[0].min(unit.decay_per_s[1]).max(1.0);
    let first = ((unit.onset_s * fs).ceil().max(0.0) as usize).min(signal.len());
    let end = (first + (-SUBTRACT_UNTIL.ln() / slowest * fs) as usize).min(signal.len());
    let mut model = vec![0.0; end - first];
    for k in 0..2 {
        let amplitude = unit.amplitude[k];
        let mut component = vec![0.0; end - first];
        oscillate(
            &mut component,
            first,
            fs,
            unit.onset_s,
            unit.frequency_hz[k],
            unit.decay_per_s[k],
            |z, _| amplitude * z.im,
        );
        model.iter_mut().zip(&component).for_each(|(m, c)| *m += c);
    }
    signal[first..end]
        .iter_mut()
        .zip(&model)
        .for_each(|(y, m)| *y -= m);
}

/// Eq. 1 in one window, its parameters `[onset shift (ms), A1, A2, f1, f2, B1, B2]`.
struct UnitProblem<'a> {
    data: &'a [f64],
    first: usize,
    fs: f64,
    /// The onset the shift is measured from (s).
    reference_s: f64,
    params: Vector7,
}

impl UnitProblem<'_> {
    fn onset_s(&self) -> f64 {
        self.reference_s + self.params[0] / 1000.0
    }

    /// For each component k, `each(k, n, z, τ)` at every sample n from the onset on.
    fn components(&self, mut each: impl FnMut(usize, usize, Complex<f64>, f64)) {
        let onset_s = self.onset_s();
        let mut column = vec![Complex::new(0.0, 0.0); self.data.len()];
        let mut taus = vec![f64::NAN; self.data.len()];
        for k in 0..2 {
            let (hz, decay) = (self.params[3 + k], self.params[5 + k]);
            let rate = Complex::new(-decay, TAU * hz);
            let step = (rate / self.fs).exp();
            let start = ((onset_s * self.fs).ceil().max(self.first as f64) as usize)
                .saturating_sub(self.first)
                .min(self.data.len());
            let tau0 = (self.first + start) as f64 / self.fs - onset_s;
            let mut z = (rate * tau0).exp();
            for n in start..self.data.len() {
                column[n] = z;
                taus[n] = tau0 + (n - start) as f64 / self.fs;
                z *= step;
            }
            for n in start..self.data.len() {
                each(k, n, column[n], taus[n]);
            }
        }
    }
}

impl LeastSquaresProblem<f64, Dyn, U7> for UnitProblem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, U7>;
    type ParameterStorage = Owned<f64, U7>;

    fn set_params(&mut self, params: &Vector7) {
        self.params = *params;
    }

    fn params(&self) -> Vector7 {
        self.params
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let mut residuals = DVector::from_iterator(self.data.len(), self.data.iter().map(|y| -y));
        let amplitude = [self.params[1], self.params[2]];
        self.components(|k, n, z, _| residuals[n] += amplitude[k] * z.im);
        residuals.iter().all(|r| r.is_finite()).then_some(residuals)
    }

    fn jacobian(&self) -> Option<OMatrix<f64, Dyn, U7>> {
        let mut jacobian = OMatrix::<f64, Dyn, U7>::zeros(self.data.len());
        let amplitude = [self.params[1], self.params[2]];
        let omega = [TAU * self.params[3], TAU * self.params[4]];
        let decay = [self.params[5], self.params[6]];
        self.components(|k, n, z, tau| {
            let a = amplitude[k];
            // d/d onset = −dq/dτ, the onset in ms.
            jacobian[(n, 0)] -= a * (omega[k] * z.re - decay[k] * z.im) / 1000.0;
            jacobian[(n, 1 + k)] = z.im;
            jacobian[(n, 3 + k)] = a * z.re * TAU * tau;
            jacobian[(n, 5 + k)] = -a * z.im * tau;
        });
        jacobian.iter().all(|j| j.is_finite()).then_some(jacobian)
    }
}
