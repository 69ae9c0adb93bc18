//! A unit's second, short mode (MODEL.md §13): a real glug often carries a bright mode (the
//! pocket ringing as a bubble) that dies within a few tens of milliseconds beside a long low one
//! (the headspace's cavity). Over a span of up to 150 ms its spectral peak stands far below the
//! long mode's, so a fit from the span's own peaks finds one mode only. So a unit kept with one
//! component is looked at again: where what its fit left out of the unit's first
//! [`EARLY_S`] peaks at least [`SEPARATE_MODES`] from its component, both are fitted together
//! there, and the pair is kept if the new component lies above the unit's own and decays faster
//! (the short bright mode sought) and the pair explains at least [`MIN_GAIN`] more of the span.

use super::eq1;
use super::modes::SEPARATE_MODES;
use super::phased;
use super::window::Span;
use super::{at_peak, check, Fitted, Placed, Strides, UnitFit};
use crate::spectrum::own_peaks;

/// The early part of a unit where a short mode is sought (s).
const EARLY_S: f64 = 0.04;
/// A short mode's decay where the pencil gives none (1/s): −60 dB in 46 ms.
const SHORT_DECAY_GUESS_PER_S: f64 = 150.0;
/// The share of the span's energy the pair must explain beyond the one component: more than any
/// noise 30 dB down could lend a fit.
const MIN_GAIN: f64 = 0.05;

/// `unit`, with the short mode its fit left out where there is one.
pub(super) fn with_second_mode(span: &Span, unit: UnitFit) -> UnitFit {
    let (Some(main), None) = (unit.components[0], unit.components[1]) else {
        return unit;
    };
    let from = (span.onset - span.first).min(span.samples.len());
    let to = (from + (EARLY_S * span.fs) as usize).min(span.samples.len());
    let left: Vec<f64> = (from..to)
        .map(|n| span.samples[n] - unit.value_at((span.first + n) as f64 / span.fs))
        .collect();
    if left.len() < 16 {
        return unit;
    }
    let apart = |hz: f64| (hz / main.heard_hz).max(main.heard_hz / hz) >= SEPARATE_MODES;
    let Some(&(short_hz, _)) = own_peaks(&left, span.fs).iter().find(|p| apart(p.0)) else {
        return unit;
    };
    let strides = Strides::for_highest(short_hz.max(main.heard_hz), span.fs);
    let poles = eq1::pencil_poles(&left, strides.pencil, span.fs);
    let short = eq1::nearest_pole(&poles, short_hz).unwrap_or((short_hz, SHORT_DECAY_GUESS_PER_S));
    let window = span.window(strides.fit);
    let Ok(pair) = phased::fit(
        &window,
        unit.onset_s,
        &[(main.frequency_hz, main.decay_per_s), short],
        false,
    ) else {
        return unit;
    };
    let both = UnitFit::new(
        Fitted {
            onset_s: pair.onset_s,
            components: &pair.components,
            explained: pair.explained,
        },
        Placed {
            window: (span.first, span.end),
            stride: strides.fit,
            fs: span.fs,
        },
        None,
        unit.method,
    );
    // The pair must still be two modes, neither drawn onto the other's frequency, and the new
    // one the short bright mode sought: above the unit's own and decaying faster.
    let two_modes = match both.components {
        [Some(low), Some(high)] => {
            high.heard_hz / low.heard_hz >= SEPARATE_MODES
                && (low.heard_hz - main.heard_hz).abs() < (high.heard_hz - main.heard_hz).abs()
                && high.decay_per_s > low.decay_per_s
        }
        _ => false,
    };
    match check(both, span.fs).and_then(|both| at_peak(span, both)) {
        Ok(both) if two_modes && both.r_squared >= unit.r_squared + MIN_GAIN => both,
        _ => unit,
    }
}
