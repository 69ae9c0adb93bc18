//! A recording's weight log: a CSV with a header, a time column and a weight column (g), read with
//! the `csv` crate as the CSV lanes are (fields trimmed, rows as long as the header), turned into
//! the residual volume V(t) in ml. A log that rises is refused: a pour only loses liquid; so is
//! one whose volumes do not fit in the bottle (a scale not zeroed for it, or a wrong density or
//! unit), with the figures. A message quotes at most the start of a field.

use super::error::FitError;
use super::session::WeightSpec;
use sake_glug_io::read::{self, InputKind};
use sake_glug_io::text::cut_short;

/// Volumes beyond the bottle by more than this share of its capacity are refused: a scale's
/// noise and a liquid's density known to a few per cent stay within it.
const VOLUME_SLACK: f64 = 0.05;

/// The residual volume over time read from a weight log.
#[derive(Debug, Clone, PartialEq)]
pub struct WeightLog {
    /// `(time_s, volume_ml)`, in time order.
    pub points: Vec<(f64, f64)>,
}

impl WeightLog {
    /// Reads the log `spec` names (for the recording `key`); `start_ml`, if given, is the volume
    /// at its first row (the scale may weigh the bottle too: only the loss counts then), else a
    /// row's volume is its weight over the density. Volumes outside 0 … `capacity_ml` (by more
    /// than [`VOLUME_SLACK`] of it) are refused.
    pub fn read(
        spec: &WeightSpec,
        key: &str,
        start_ml: Option<f64>,
        capacity_ml: f64,
    ) -> Result<Self, FitError> {
        let key = format!("{key}.weight.csv");
        let fail = |line: u64, column: Option<&str>, what: String| FitError::WeightLog {
            key: key.clone(),
            path: spec.csv.clone(),
            line,
            column: column.map(str::to_owned),
            what,
        };
        let text = read::text_within(&spec.csv, InputKind::WEIGHT_LOG.max_bytes)
            .map_err(|failure| fail(0, None, failure.to_string()))?;
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(true)
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let header = reader
            .headers()
            .map_err(|error| fail(1, None, format!("unreadable CSV: {error}")))?
            .clone();
        let index = |name: &str| {
            header
                .iter()
                .position(|field| field == name)
                .ok_or_else(|| fail(1, Some(name), "no such column in the header".into()))
        };
        let (time_index, weight_index) = (index(&spec.time)?, index(&spec.column)?);
        let mut rows: Vec<(u64, f64, f64)> = Vec::new();
        for record in reader.records() {
            let record = record.map_err(|error| {
                let line = error.position().map_or(0, |position| position.line());
                fail(line, None, format!("unreadable CSV: {error}"))
            })?;
            let line = record.position().map_or(0, |position| position.line());
            let number = |index: usize, name: &str| -> Result<f64, FitError> {
                let field = record.get(index).unwrap_or("");
                match field.parse::<f64>() {
                    Ok(value) if value.is_finite() => Ok(value),
                    _ => Err(fail(
                        line,
                        Some(name),
                        format!("{:?} is not a finite number", cut_short(field)),
                    )),
                }
            };
            let time_s = number(time_index, &spec.time)?;
            let grams = number(weight_index, &spec.column)?;
            if let Some(&(_, previous, _)) = rows.last() {
                if time_s <= previous {
                    return Err(fail(
                        line,
                        Some(&spec.time),
                        format!(
                            "the time {time_s} s is not after the {previous} s of the row before"
                        ),
                    ));
                }
            }
            rows.push((line, time_s, grams));
        }
        if rows.len() < 3 {
            return Err(fail(
                0,
                None,
                format!("{} data rows: a drain line needs at least 3", rows.len()),
            ));
        }
        refuse_rising(&rows).map_err(|(line, what)| fail(line, Some(&spec.column), what))?;
        let density = spec.density_g_per_ml;
        let first_grams = rows[0].2;
        let points = rows
            .iter()
            .map(|&(_, time_s, grams)| {
                let volume_ml = match start_ml {
                    Some(start_ml) => start_ml - (first_grams - grams) / density,
                    None => grams / density,
                };
                (time_s, volume_ml)
            })
            .collect::<Vec<(f64, f64)>>();
        let (lowest, highest) = points
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(low, high), p| {
                (low.min(p.1), high.max(p.1))
            });
        let slack = VOLUME_SLACK * capacity_ml;
        if highest > capacity_ml + slack || lowest < -slack {
            let hint = match start_ml {
                None => format!(
                    "a volume is the weight over the density ({density} g/ml) unless start_ml is \
                     given: was the scale zeroed with the empty bottle on it, and are the weights \
                     in grams? (give start_ml to count only the liquid poured)"
                ),
                Some(start_ml) => format!(
                    "the log loses {:.1} ml from start_ml = {start_ml} ml: are the weights in \
                     grams, and the density ({density} g/ml) right?",
                    (first_grams - rows[rows.len() - 1].2) / density
                ),
            };
            return Err(fail(
                0,
                Some(&spec.column),
                format!(
                    "its volumes run from {lowest:.1} to {highest:.1} ml, which a bottle of \
                     {capacity_ml} ml cannot hold; {hint}"
                ),
            ));
        }
        Ok(Self { points })
    }

    /// The volume at `time_s`, linear between rows and held outside them.
    pub fn volume_at(&self, time_s: f64) -> f64 {
        let points = &self.points;
        let after = points.partition_point(|&(t, _)| t <= time_s);
        match after {
            0 => points[0].1,
            n if n == points.len() => points[n - 1].1,
            n => {
                let ((t0, v0), (t1, v1)) = (points[n - 1], points[n]);
                v0 + (v1 - v0) * (time_s - t0) / (t1 - t0)
            }
        }
    }
}

/// Refuses a log whose weight rises above its lowest weight so far by more than the scale's
/// noise: by more than 6 times the noise and more than 0.5 % of the heaviest reading. The noise
/// is the median absolute second difference (zero on a straight drain, so the drain itself does
/// not count), scaled to a standard deviation. Gives the line and why.
fn refuse_rising(rows: &[(u64, f64, f64)]) -> Result<(), (u64, String)> {
    let mut curvature: Vec<f64> = rows
        .windows(3)
        .map(|three| (three[2].2 - 2.0 * three[1].2 + three[0].2).abs())
        .collect();
    curvature.sort_by(f64::total_cmp);
    let noise = 1.4826 * curvature[curvature.len() / 2] / 6f64.sqrt();
    let heaviest = rows.iter().map(|row| row.2.abs()).fold(0.0, f64::max);
    let tolerance = (6.0 * noise).max(0.005 * heaviest);
    let (mut lowest, mut lowest_line) = (rows[0].2, rows[0].0);
    for &(line, _, grams) in rows {
        if grams > lowest + tolerance {
            return Err((
                line,
                format!(
                    "the weight rises to {grams} g from {lowest} g on line {lowest_line}: a pour \
                     only loses liquid (was the log recorded while filling?)"
                ),
            ));
        }
        if grams < lowest {
            (lowest, lowest_line) = (grams, line);
        }
    }
    Ok(())
}
