//! The pour between the units (MODEL.md §13): the intervals between a recording's units, the
//! pocket they tell with a weight log, the drain of a recording without one (the glug count ×
//! the pocket), and each tilt's outflow rate.

use super::recording::{DrainLine, RecordingFit};
use super::stats::{median, Line};

/// An interval between units longer than this many times the median counts a missed unit, one
/// shorter than [`SHORT_INTERVAL`] of it a spurious one: neither tells the pocket.
const LONG_INTERVAL: f64 = 1.6;
const SHORT_INTERVAL: f64 = 0.4;
/// Two tilts closer than this are one (degrees).
pub const SAME_TILT_DEG: f64 = 0.5;

/// The intervals between consecutive glugs of `recording`: its units detected, kept or rejected
/// (a glug no fit described still poured its pocket), those that tell a pocket. A rejected unit's
/// onset is placed only to the glug detector's 25 ms, which a median shrugs off: the pace and the
/// pocket come from these.
pub fn intervals(recording: &RecordingFit) -> Vec<f64> {
    pocket_intervals(recording.detected.iter().map(|unit| unit.onset_s))
}

/// The intervals between consecutive units of `recording` kept, those that tell a pocket: their
/// onsets placed by their fits, for the intervals' scatter (j_t), which a rejected unit's loose
/// onset would widen.
pub fn fitted_intervals(recording: &RecordingFit) -> Vec<f64> {
    pocket_intervals(recording.units.iter().map(|unit| unit.fit.onset_s))
}

/// The intervals between consecutive `onsets_s`, without those that count a missed unit or a
/// spurious one.
fn pocket_intervals(onsets_s: impl Iterator<Item = f64>) -> Vec<f64> {
    let onsets_s: Vec<f64> = onsets_s.collect();
    let all: Vec<f64> = onsets_s.windows(2).map(|pair| pair[1] - pair[0]).collect();
    let typical = median(&all);
    all.into_iter()
        .filter(|&dt| dt < LONG_INTERVAL * typical && dt > SHORT_INTERVAL * typical)
        .collect()
}

/// The pockets b_i = k·Δt_i of the recordings with a weight log.
pub fn pockets(recordings: &[&RecordingFit]) -> Vec<f64> {
    recordings
        .iter()
        .filter_map(|r| {
            Some((
                r.drain.filter(|d| d.from_weight)?.rate_ml_per_s(),
                intervals(r),
            ))
        })
        .flat_map(|(rate, intervals)| intervals.into_iter().map(move |dt| rate * dt))
        .collect()
}

/// A recording without a weight log drains at pocket / median interval from its start volume,
/// pouring from a pocket's time before its first unit detected, kept or not. Units that count
/// past an empty bottle (the recording is not the pour its session says) are given no volume, and
/// that is warned.
pub fn complete_without_weight(
    recording: &mut RecordingFit,
    pocket_ml: f64,
    warnings: &mut Vec<String>,
) {
    if recording.weight.is_some() || recording.units.len() < 3 {
        return;
    }
    let Some(start_ml) = recording.spec.start_ml else {
        return;
    };
    let rate = pocket_ml / median(&intervals(recording));
    if !(rate.is_finite() && rate > 0.0) {
        return;
    }
    // The first glug detected poured its pocket whether or not a fit described it.
    let first_onset_s = recording
        .detected
        .iter()
        .map(|unit| unit.onset_s)
        .fold(recording.units[0].fit.onset_s, f64::min);
    let poured_from = first_onset_s - pocket_ml / rate;
    let line = Line {
        slope: -rate,
        intercept: start_ml + rate * poured_from,
        r_squared: f64::NAN,
        slope_error: f64::NAN,
    };
    let mut past_empty = 0;
    for unit in &mut recording.units {
        let volume_ml = line.at(unit.fit.onset_s);
        unit.volume_ml = if volume_ml >= 0.0 {
            volume_ml
        } else {
            past_empty += 1;
            f64::NAN
        };
    }
    if past_empty > 0 {
        warnings.push(format!(
            "`{}`: its {} units, a {pocket_ml} ml pocket each, pour {:.0} ml, more than its \
             start_ml = {start_ml} ml; the {past_empty} counted past an empty bottle have no \
             volume (a weight log would give the pocket)",
            recording.spec.key,
            recording.units.len(),
            recording.units.len() as f64 * pocket_ml,
        ));
    }
    let span_s = (
        recording.units[0].fit.onset_s,
        recording.units[recording.units.len() - 1].fit.onset_s,
    );
    recording.drain = Some(DrainLine {
        line,
        from_weight: false,
        span_s,
    });
}

/// Each tilt's outflow rate: (tilt, mean k over its recordings), tilts ascending.
pub fn tilt_rates(recordings: &[&RecordingFit]) -> Vec<(f64, f64)> {
    let mut groups: Vec<(f64, Vec<f64>)> = Vec::new();
    for recording in recordings {
        let Some(drain) = recording.drain else {
            continue;
        };
        let tilt = recording.spec.tilt_deg;
        match groups
            .iter_mut()
            .find(|g| (g.0 - tilt).abs() < SAME_TILT_DEG)
        {
            Some(group) => group.1.push(drain.rate_ml_per_s()),
            None => groups.push((tilt, vec![drain.rate_ml_per_s()])),
        }
    }
    let mut rates: Vec<(f64, f64)> = groups
        .into_iter()
        .map(|(tilt, ks)| (tilt, ks.iter().sum::<f64>() / ks.len() as f64))
        .collect();
    rates.sort_by(|a, b| a.0.total_cmp(&b.0));
    rates
}

/// The standard error of the mean rate of the recordings at `tilt` (their lines' errors), if
/// any line has one.
pub fn rate_error(recordings: &[&RecordingFit], tilt: f64) -> Option<f64> {
    let errors: Vec<f64> = recordings
        .iter()
        .filter(|r| (r.spec.tilt_deg - tilt).abs() < SAME_TILT_DEG)
        .filter_map(|r| r.drain.map(|d| d.line.slope_error))
        .filter(|e| e.is_finite())
        .collect();
    (!errors.is_empty())
        .then(|| errors.iter().map(|e| e * e).sum::<f64>().sqrt() / errors.len() as f64)
}
