//! The paper's eq. 1 as it stands (MODEL.md §5, §13): two exponentially decaying sinusoids from a
//! common onset, each starting at phase 0, q(τ) = A1·e^(−B1τ)·sin(2πf1τ) + A2·e^(−B2τ)·sin(2πf2τ),
//! fitted in the window from just before its onset to just before the next unit's. The start:
//! the two poles of a matrix pencil (nalgebra's SVD and eigenvalues) nearest the starting
//! frequencies, the onset from a grid and the amplitudes by linear least squares; then all seven
//! numbers refined together by Levenberg-Marquardt (the `levenberg-marquardt` crate), given the
//! problem compressed to eight rows. The grid and the refinement read every k-th sample of the
//! window, as many as eq. 1 needs (MODEL.md §13).

use std::f64::consts::TAU;

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Owned, SMatrix, SVector, U7, U8};
use num_complex::Complex;

use super::window::{Span, Window};
use super::{
    Component, Fitted, Placed, Rejection, Strides, UnitFit, UnitMethod, MAX_DECAY_PER_S,
    MIN_EXPLAINED,
};

type Vector7 = SVector<f64, 7>;
type Matrix7 = SMatrix<f64, 7, 7>;

/// The onset grid of the starting guess: this range around the detected onset (s), in steps.
const ONSET_GRID_S: (f64, f64, f64) = (-0.004, 0.002, 0.00025);
/// The pencil sees at most this much of a unit (s): its loud start.
const PENCIL_S: f64 = 0.04;
/// The pencil's Hankel matrix has at most this many columns: a model of order 4 needs few, and
/// the SVD's cost grows with their square.
const PENCIL_MAX_COLUMNS: usize = 16;
/// A pencil pole within this frequency ratio of a starting frequency is taken for that component.
pub(super) const POLE_MATCH_RATIO: f64 = 1.3;
/// The decay assumed where the pencil finds none (1/s): the model's default B2.
pub(super) const DECAY_GUESS_PER_S: f64 = 40.0;
/// A fitted onset further than this from the detected one is rejected (s).
const MAX_ONSET_SHIFT_S: f64 = 0.006;
/// Levenberg-Marquardt gives up after patience × 8 evaluations.
const LM_PATIENCE: usize = 25;

/// Eq. 1 fitted to the unit `span` holds, its frequencies started at `start_hz` (each replaced by
/// the nearest pencil pole); why not if the fit is implausible or explains too little.
pub(super) fn fit(span: &Span, start_hz: [f64; 2], strides: Strides) -> Result<UnitFit, Rejection> {
    let fs = span.fs;
    let poles = pencil_poles(span.after_onset(PENCIL_S), strides.pencil, fs);
    let mut frequency_hz = start_hz;
    let mut decay_per_s = [DECAY_GUESS_PER_S; 2];
    for k in 0..2 {
        if let Some((hz, decay)) = nearest_pole(&poles, start_hz[k]) {
            frequency_hz[k] = hz;
            decay_per_s[k] = decay;
        }
    }
    let window = span.window(strides.fit);
    let detected_s = span.onset_s();
    let (start_s, amplitude) = onset_grid(&window, detected_s, frequency_hz, decay_per_s);
    let start = [
        start_s,
        amplitude[0],
        amplitude[1],
        frequency_hz[0],
        frequency_hz[1],
        decay_per_s[0],
        decay_per_s[1],
    ];
    // The problem's first parameter is the onset's shift from `start_s` (ms), so it starts at 0.
    let mut shifted = Vector7::from_column_slice(&start);
    shifted[0] = 0.0;
    let problem = UnitProblem::new(&window, start_s, shifted);
    let (problem, _report) = LevenbergMarquardt::new()
        .with_patience(LM_PATIENCE)
        .minimize(problem);
    let p = problem.params;
    let onset_s = problem.reference_s + p[0] / 1000.0;
    if !p.iter().all(|value| value.is_finite()) {
        return Err(Rejection::NotFinite);
    }
    let residual = problem
        .residuals()
        .ok_or(Rejection::NotFinite)?
        .norm_squared();
    let explained = 1.0 - residual / window.energy().max(1e-300);
    let total = p[1] + p[2];
    if !(total > 0.0 && p[1] >= -0.02 * total && p[2] >= -0.02 * total) {
        return Err(Rejection::OutOfPhase);
    }
    let components = [0, 1].map(|k| Component {
        frequency_hz: p[3 + k],
        glide: None,
        heard_hz: p[3 + k],
        in_span: 0.0,
        decay_per_s: p[5 + k],
        amplitude: p[1 + k].max(0.0),
        phase: 0.0,
    });
    for component in &components {
        component.check(fs)?;
    }
    if explained < MIN_EXPLAINED {
        return Err(Rejection::Unexplained { share: explained });
    }
    let shift_s = onset_s - detected_s;
    if shift_s.abs() > MAX_ONSET_SHIFT_S {
        return Err(Rejection::OnsetMoved { shift_s });
    }
    Ok(UnitFit::new(
        Fitted {
            onset_s,
            components: &components,
            explained,
        },
        Placed {
            window: (span.first, span.end),
            stride: strides.fit,
            fs,
        },
        Some(start),
        UnitMethod::Eq1,
    ))
}

/// The pencil pole nearest `hz` in frequency, within [`POLE_MATCH_RATIO`] and decaying plausibly.
pub(super) fn nearest_pole(poles: &[(f64, f64)], hz: f64) -> Option<(f64, f64)> {
    poles
        .iter()
        .filter(|(pole_hz, decay)| {
            (pole_hz / hz).max(hz / pole_hz) < POLE_MATCH_RATIO
                && *decay > 0.5
                && *decay < MAX_DECAY_PER_S
        })
        .min_by(|a, b| (a.0 / hz).ln().abs().total_cmp(&(b.0 / hz).ln().abs()))
        .copied()
}

/// The damped poles `(f Hz, B 1/s)`, f > 0, of a matrix pencil of order 4 (two real damped
/// sinusoids) through `segment` taken every `step` samples.
pub(super) fn pencil_poles(segment: &[f64], step: usize, fs: f64) -> Vec<(f64, f64)> {
    const ORDER: usize = 4;
    let decimated: Vec<f64> = segment.iter().step_by(step).copied().collect();
    // An SVD of a matrix holding a NaN never converges.
    if !decimated.iter().all(|v| v.is_finite()) {
        return Vec::new();
    }
    let len = decimated.len();
    let pencil = (len / 3).min(PENCIL_MAX_COLUMNS);
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
    window: &Window,
    detected_s: f64,
    frequency_hz: [f64; 2],
    decay_per_s: [f64; 2],
) -> (f64, [f64; 2]) {
    let (from, to, by) = ONSET_GRID_S;
    let mut best: Option<(bool, f64, f64, [f64; 2])> = None;
    let sums = GridSums::new(window, detected_s + from, frequency_hz, decay_per_s);
    let steps = ((to - from) / by).round() as usize;
    for step in 0..=steps {
        let onset_s = detected_s + from + by * step as f64;
        let [g00, g01, g11, b0, b1] = sums.at(window, onset_s);
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

/// What the onset grid needs of every onset t0 in O(1): each component's column is
/// Im(c_k·E_k(n)) from the onset's first sample on, with E_k(n) = e^(s_k(t_n − T)) from the grid's
/// earliest onset T and the constant c_k = e^(s_k(T − t0)), s_k = −B_k + i2πf_k. So the Gram matrix
/// and the columns' products with the data are sums over the suffix n ≥ n(t0) of products of E and
/// y, here summed once from the window's end (Im(a)·Im(b) = ½Re(a·b̄) − ½Re(a·b)).
struct GridSums {
    rate: [Complex<f64>; 2],
    earliest_s: f64,
    /// For each n (and one past the end): the sums from n on of y·E0, y·E1, E0·Ē0, E1·Ē1, E0²,
    /// E1², E0·Ē1, E0·E1.
    suffix: Vec<[Complex<f64>; 8]>,
}

impl GridSums {
    fn new(
        window: &Window,
        earliest_s: f64,
        frequency_hz: [f64; 2],
        decay_per_s: [f64; 2],
    ) -> Self {
        let rate = [0, 1].map(|k| Complex::new(-decay_per_s[k], TAU * frequency_hz[k]));
        let zero = Complex::new(0.0, 0.0);
        let mut suffix = vec![[zero; 8]; window.data.len() + 1];
        let mut columns = [vec![zero; window.data.len()], vec![zero; window.data.len()]];
        for k in 0..2 {
            window.rotate(earliest_s, frequency_hz[k], decay_per_s[k], |n, z, _| {
                columns[k][n] = z
            });
        }
        for n in (0..window.data.len()).rev() {
            let (e0, e1, y) = (columns[0][n], columns[1][n], window.data[n]);
            let terms = [
                e0 * y,
                e1 * y,
                e0 * e0.conj(),
                e1 * e1.conj(),
                e0 * e0,
                e1 * e1,
                e0 * e1.conj(),
                e0 * e1,
            ];
            let mut sums = suffix[n + 1];
            sums.iter_mut()
                .zip(terms)
                .for_each(|(sum, term)| *sum += term);
            suffix[n] = sums;
        }
        Self {
            rate,
            earliest_s,
            suffix,
        }
    }

    /// `[g00, g01, g11, b0, b1]`: the columns' Gram matrix and their products with the data for
    /// the onset `onset_s` (not before the earliest).
    fn at(&self, window: &Window, onset_s: f64) -> [f64; 5] {
        let [ye0, ye1, e00, e11, e0e0, e1e1, e01, e0e1] = self.suffix[window.first_after(onset_s)];
        let c = self
            .rate
            .map(|rate| (rate * (self.earliest_s - onset_s)).exp());
        [
            0.5 * ((c[0] * c[0].conj() * e00).re - (c[0] * c[0] * e0e0).re),
            0.5 * ((c[0] * c[1].conj() * e01).re - (c[0] * c[1] * e0e1).re),
            0.5 * ((c[1] * c[1].conj() * e11).re - (c[1] * c[1] * e1e1).re),
            (c[0] * ye0).im,
            (c[1] * ye1).im,
        ]
    }
}

/// Eq. 1 in one window, its parameters `[onset shift (ms), A1, A2, f1, f2, B1, B2]`.
///
/// Handed to Levenberg-Marquardt compressed: the step it takes depends on the window's residuals
/// r and Jacobian J only through JᵀJ, Jᵀr and |r|², so the problem it sees is the eight residuals
/// [u; t] with the Jacobian [R; 0], where RᵀR = JᵀJ (Cholesky), u = R⁻ᵀJᵀr and t² = |r|² − |u|²:
/// the same sum of squares and the same linear model of it at every step, from one pass over
/// the window per evaluation instead of a QR factorisation of a window-long J.
struct UnitProblem<'a> {
    window: &'a Window,
    /// The onset the shift is measured from (s).
    reference_s: f64,
    params: Vector7,
    /// The compressed problem at `params`: Levenberg-Marquardt asks for the residuals and then
    /// the Jacobian at the same point.
    compressed: std::cell::Cell<Option<Compressed>>,
}

/// The problem at one point: [`UnitProblem`]'s R and [u; t].
#[derive(Debug, Clone, Copy)]
struct Compressed {
    residuals: SVector<f64, 8>,
    jacobian: SMatrix<f64, 8, 7>,
}

impl UnitProblem<'_> {
    fn new(window: &Window, reference_s: f64, params: Vector7) -> UnitProblem<'_> {
        UnitProblem {
            window,
            reference_s,
            params,
            compressed: std::cell::Cell::new(None),
        }
    }

    fn onset_s(&self) -> f64 {
        self.reference_s + self.params[0] / 1000.0
    }

    /// For every sample n of the window, `each(r_n, J_n)`: its residual (eq. 1 less the
    /// recording) and its row of the Jacobian (zero before the onset).
    fn rows(&self, mut each: impl FnMut(f64, &Vector7)) {
        let onset_s = self.onset_s();
        let data = &self.window.data;
        let start = self.window.first_after(onset_s);
        let silent = Vector7::zeros();
        for &y in &data[..start] {
            each(-y, &silent);
        }
        if start == data.len() {
            return;
        }
        let period = self.window.stride as f64 / self.window.fs;
        let tau0 = self.window.index(start) as f64 / self.window.fs - onset_s;
        let mut z = [Complex::new(0.0, 0.0); 2];
        let mut step = z;
        let mut rate = z;
        for k in 0..2 {
            rate[k] = Complex::new(-self.params[5 + k], TAU * self.params[3 + k]);
            step[k] = (rate[k] * period).exp();
            z[k] = (rate[k] * tau0).exp();
        }
        for (n, &y) in data[start..].iter().enumerate() {
            let tau = tau0 + n as f64 * period;
            let mut row = Vector7::zeros();
            let mut model = 0.0;
            for k in 0..2 {
                let a = self.params[1 + k];
                model += a * z[k].im;
                // d/d onset = −dq/dτ, the onset in ms.
                row[0] -= a * (rate[k] * z[k]).im / 1000.0;
                row[1 + k] = z[k].im;
                row[3 + k] = a * z[k].re * TAU * tau;
                row[5 + k] = -a * z[k].im * tau;
                z[k] *= step[k];
            }
            each(model - y, &row);
        }
    }

    /// The compressed problem at `params` (cached); `None` if anything in it is not finite.
    fn compressed(&self) -> Option<Compressed> {
        if let Some(compressed) = self.compressed.get() {
            return Some(compressed);
        }
        let (mut normal, mut gradient, mut squares) = (Matrix7::zeros(), Vector7::zeros(), 0.0);
        self.rows(|residual, row| {
            normal.syger(1.0, row, row, 1.0);
            gradient.axpy(residual, row, 1.0);
            squares += residual * residual;
        });
        let (upper, explained) = match normal.cholesky() {
            Some(cholesky) => {
                let lower = cholesky.l();
                let explained = lower.solve_lower_triangular(&gradient)?;
                (lower.transpose(), explained)
            }
            // JᵀJ singular (a component with no amplitude moves nothing): R and u from a QR of
            // the whole window, which needs no inverse.
            None => {
                let rows = self.window.data.len();
                let (mut jacobian, mut residuals) = (DMatrix::zeros(rows, 7), DVector::zeros(rows));
                let mut n = 0;
                self.rows(|residual, row| {
                    jacobian.set_row(n, &row.transpose());
                    residuals[n] = residual;
                    n += 1;
                });
                let qr = jacobian.qr();
                let explained = qr.q().tr_mul(&residuals);
                let upper = qr.r();
                (
                    Matrix7::from_fn(|i, j| upper.get((i, j)).copied().unwrap_or(0.0)),
                    Vector7::from_fn(|i, _| explained.get(i).copied().unwrap_or(0.0)),
                )
            }
        };
        let mut residuals = SVector::<f64, 8>::zeros();
        residuals.fixed_rows_mut::<7>(0).copy_from(&explained);
        residuals[7] = (squares - explained.norm_squared()).max(0.0).sqrt();
        let mut jacobian = SMatrix::<f64, 8, 7>::zeros();
        jacobian.fixed_rows_mut::<7>(0).copy_from(&upper);
        let compressed = Compressed {
            residuals,
            jacobian,
        };
        let finite = residuals
            .iter()
            .chain(jacobian.iter())
            .all(|v| v.is_finite());
        finite.then(|| {
            self.compressed.set(Some(compressed));
            compressed
        })
    }
}

impl LeastSquaresProblem<f64, U8, U7> for UnitProblem<'_> {
    type ResidualStorage = Owned<f64, U8>;
    type JacobianStorage = Owned<f64, U8, U7>;
    type ParameterStorage = Owned<f64, U7>;

    fn set_params(&mut self, params: &Vector7) {
        self.params = *params;
        self.compressed.set(None);
    }

    fn params(&self) -> Vector7 {
        self.params
    }

    fn residuals(&self) -> Option<SVector<f64, 8>> {
        self.compressed().map(|c| c.residuals)
    }

    fn jacobian(&self) -> Option<SMatrix<f64, 8, 7>> {
        self.compressed().map(|c| c.jacobian)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The window's samples of one component of eq. 1 from `onset_s`, sample by sample.
    fn column(window: &Window, onset_s: f64, hz: f64, decay: f64) -> Vec<f64> {
        (0..window.data.len())
            .map(|n| {
                let tau = window.index(n) as f64 / window.fs - onset_s;
                if tau < 0.0 {
                    0.0
                } else {
                    (-decay * tau).exp() * (TAU * hz * tau).sin()
                }
            })
            .collect()
    }

    /// A window of `len` samples in −1…1 with no structure a fit could lock on to: n·`prime`
    /// modulo `modulus`, scaled.
    fn scrambled_window(
        len: usize,
        prime: usize,
        modulus: usize,
        first: usize,
        stride: usize,
        fs: f64,
    ) -> Window {
        let data = (0..len)
            .map(|n| ((n * prime) % modulus) as f64 / (modulus / 2) as f64 - 1.0)
            .collect();
        Window {
            data,
            first,
            stride,
            fs,
        }
    }

    #[test]
    fn the_onset_grids_sums_equal_the_columns_products_at_every_onset() {
        let fs = 25_000.0;
        let window = scrambled_window(700, 7919, 113, 1_000, 3, fs);
        let (hz, decay) = ([83.0, 310.0], [31.0, 55.0]);
        let earliest_s = 1_000.0 / fs + 0.0004;
        let sums = GridSums::new(&window, earliest_s, hz, decay);
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        for step in 0..40 {
            // Onsets on and between samples, some past the first of the window.
            let onset_s = earliest_s + step as f64 * 0.000_137;
            let columns = [0, 1].map(|k| column(&window, onset_s, hz[k], decay[k]));
            let direct = [
                dot(&columns[0], &columns[0]),
                dot(&columns[0], &columns[1]),
                dot(&columns[1], &columns[1]),
                dot(&columns[0], &window.data),
                dot(&columns[1], &window.data),
            ];
            for (summed, direct) in sums.at(&window, onset_s).iter().zip(direct) {
                assert!(
                    (summed - direct).abs() <= 1e-9 * direct.abs().max(1.0),
                    "onset {onset_s}: {summed} against {direct}"
                );
            }
        }
    }

    #[test]
    fn the_compressed_problem_keeps_the_sum_of_squares_and_the_normal_equations() {
        let fs = 25_000.0;
        let window = scrambled_window(600, 104_729, 97, 200, 2, fs);
        let params = Vector7::from_column_slice(&[0.3, 0.8, 0.2, 80.0, 300.0, 30.0, 45.0]);
        let problem = UnitProblem::new(&window, 200.0 / fs + 0.001, params);
        let (mut rows, mut residuals) = (Vec::new(), Vec::new());
        problem.rows(|residual, row| {
            residuals.push(residual);
            rows.push(*row);
        });
        let jacobian = DMatrix::from_fn(rows.len(), 7, |i, j| rows[i][j]);
        let residuals = DVector::from_vec(residuals);
        let compressed = problem.compressed().expect("finite");
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * a.abs().max(b.abs()).max(1.0);
        assert!(close(
            compressed.residuals.norm_squared(),
            residuals.norm_squared()
        ));
        let normal = jacobian.transpose() * &jacobian;
        let gradient = jacobian.transpose() * &residuals;
        let compressed_normal = compressed.jacobian.transpose() * compressed.jacobian;
        let compressed_gradient = compressed.jacobian.transpose() * compressed.residuals;
        for i in 0..7 {
            assert!(close(compressed_gradient[i], gradient[i]), "Jᵀr[{i}]");
            for j in 0..7 {
                assert!(
                    close(compressed_normal[(i, j)], normal[(i, j)]),
                    "JᵀJ[{i},{j}]"
                );
            }
        }
    }
}
