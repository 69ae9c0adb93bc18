//! Where units start (MODEL.md §13): the energy just after a sample against the energy of the
//! period before it. A unit starting rises far above what rang before (a decaying ring never
//! does), so the ratio peaks within a millisecond or two of each onset; the unit fit then places
//! the onset exactly.

/// The window after a sample (s): a few periods of the high component, a quarter of the low one.
const AFTER_S: f64 = 0.003;
/// The shortest window before a sample (s); at least one period of the lowest component.
const BEFORE_MIN_S: f64 = 0.012;
/// A rise of the mean energy by this factor (6 dB) marks an onset.
const RISE: f64 = 4.0;
/// An onset's energy must be this many times the noise's (12 dB)…
const ABOVE_NOISE: f64 = 16.0;
/// …and at least this fraction of the loudest window's (−50 dB).
const ABOVE_LOUDEST: f64 = 1e-5;
/// The noise is the energy of the quietest windows: 1 in this many.
const NOISE_QUANTILE: usize = 100;
/// Two onsets are at least this far apart (s).
const MIN_SEPARATION_S: f64 = 0.010;

/// The samples near which units start in `samples` (DC removed) at `sample_rate`, given the
/// lowest component's frequency `low_hz` (its period sets the window before), in order.
pub fn detect_onsets(samples: &[f32], sample_rate: f64, low_hz: f64) -> Vec<usize> {
    let after = ((AFTER_S * sample_rate).round() as usize).max(2);
    let before = ((BEFORE_MIN_S.max(1.0 / low_hz.max(1.0)) * sample_rate).round() as usize).max(2);
    if samples.len() < after + before + 1 {
        return Vec::new();
    }
    let square = |n: usize| f64::from(samples[n]).powi(2);
    let sum = |from: usize, len: usize| (from..from + len).map(square).sum::<f64>();
    // The noise: the quietest hundredth of the windows (a pour whose rings overlap is quiet only
    // before its first glug); the loudest window.
    let mut windows: Vec<f64> = (0..samples.len() / after)
        .map(|i| sum(i * after, after) / after as f64)
        .collect();
    windows.sort_by(f64::total_cmp);
    let noise = windows[windows.len() / NOISE_QUANTILE];
    let loudest = windows[windows.len() - 1];
    let gate = (ABOVE_NOISE * noise).max(ABOVE_LOUDEST * loudest);
    // The noise also keeps the ratio finite and steady where both windows are quiet.
    let floor = 4.0 * noise + 1e-30;

    let separation = ((MIN_SEPARATION_S * sample_rate) as usize).max(1);
    let mut onsets: Vec<(usize, f64)> = Vec::new();
    // Both windows' sums slide a sample at a time (no array as long as the recording), summed
    // afresh every RESUM samples so that rounding cannot build up.
    const RESUM: usize = 1 << 16;
    let (mut behind, mut ahead) = (0.0, 0.0);
    for n in before..samples.len() - after {
        if (n - before).is_multiple_of(RESUM) {
            (behind, ahead) = (sum(n - before, before), sum(n, after));
        } else {
            behind += square(n - 1) - square(n - 1 - before);
            ahead += square(n + after - 1) - square(n - 1);
        }
        let ahead_mean = ahead.max(0.0) / after as f64;
        if ahead_mean < gate {
            continue;
        }
        let ratio = ahead_mean / (behind.max(0.0) / before as f64 + floor);
        if ratio < RISE {
            continue;
        }
        match onsets.last_mut() {
            Some(last) if n - last.0 < separation => {
                if ratio > last.1 {
                    *last = (n, ratio);
                }
            }
            _ => onsets.push((n, ratio)),
        }
    }
    onsets.into_iter().map(|(n, _)| n).collect()
}
