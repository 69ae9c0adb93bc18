//! The few robust statistics the estimates use, and the bootstrap of MODEL.md §13.

use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// The `q` quantile (0…1) of `values`, linear between order statistics; NaN if empty.
pub fn quantile(values: &[f64], q: f64) -> f64 {
    let mut finite: Vec<f64> = values.iter().copied().filter(|v| v.is_finite()).collect();
    if finite.is_empty() {
        return f64::NAN;
    }
    let position = q * (finite.len() - 1) as f64;
    let below = position.floor() as usize;
    // The two order statistics by selection, not a sort: the bootstrap takes thousands.
    let (_, &mut low, above) = finite.select_nth_unstable_by(below, f64::total_cmp);
    let high = above.iter().copied().min_by(f64::total_cmp).unwrap_or(low);
    low + (high - low) * (position - below as f64)
}

/// The median.
pub fn median(values: &[f64]) -> f64 {
    quantile(values, 0.5)
}

/// The interquartile range.
pub fn iqr(values: &[f64]) -> f64 {
    quantile(values, 0.75) - quantile(values, 0.25)
}

/// The IQR of a normal distribution in standard deviations.
pub const NORMAL_IQR: f64 = 1.348_979_500_392_163_5;

/// A least-squares line y = slope·x + intercept.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    /// Its slope.
    pub slope: f64,
    /// Its value at x = 0.
    pub intercept: f64,
    /// The share of y's variance it explains.
    pub r_squared: f64,
    /// The slope's standard error.
    pub slope_error: f64,
}

impl Line {
    /// The line through `points` (x, y); `None` with fewer than 3 points or all x equal.
    pub fn through(points: &[(f64, f64)]) -> Option<Self> {
        let n = points.len() as f64;
        if points.len() < 3 {
            return None;
        }
        let mean_x = points.iter().map(|p| p.0).sum::<f64>() / n;
        let mean_y = points.iter().map(|p| p.1).sum::<f64>() / n;
        let sxx: f64 = points.iter().map(|p| (p.0 - mean_x).powi(2)).sum();
        let sxy: f64 = points.iter().map(|p| (p.0 - mean_x) * (p.1 - mean_y)).sum();
        let syy: f64 = points.iter().map(|p| (p.1 - mean_y).powi(2)).sum();
        if sxx.is_nan() || sxx <= 0.0 {
            return None;
        }
        let slope = sxy / sxx;
        let intercept = mean_y - slope * mean_x;
        let residual = (syy - slope * sxy).max(0.0);
        Some(Self {
            slope,
            intercept,
            r_squared: if syy > 0.0 { 1.0 - residual / syy } else { 1.0 },
            slope_error: (residual / (n - 2.0) / sxx).sqrt(),
        })
    }

    /// y at `x`.
    pub fn at(&self, x: f64) -> f64 {
        self.slope * x + self.intercept
    }
}

/// Resamples drawn by the bootstrap.
pub const BOOTSTRAP_RESAMPLES: usize = 200;

/// The 95 % percentile interval of `estimate` over [`BOOTSTRAP_RESAMPLES`] resamples (with
/// replacement) of `items`, from a fixed seed so that a report is the same on every run.
pub fn bootstrap<T: Clone>(items: &[T], estimate: impl Fn(&[T]) -> Vec<f64>) -> Vec<(f64, f64)> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(0x5a6e_0017);
    let mut draws: Vec<Vec<f64>> = Vec::new();
    let mut sample = Vec::with_capacity(items.len());
    for _ in 0..BOOTSTRAP_RESAMPLES {
        sample.clear();
        for _ in 0..items.len() {
            sample.push(items[rng.random_range(0..items.len())].clone());
        }
        for (index, value) in estimate(&sample).into_iter().enumerate() {
            if draws.len() <= index {
                draws.push(Vec::new());
            }
            draws[index].push(value);
        }
    }
    draws
        .iter()
        .map(|values| (quantile(values, 0.025), quantile(values, 0.975)))
        .collect()
}
