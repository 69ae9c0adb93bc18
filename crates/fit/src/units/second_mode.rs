//! A unit's second, short mode (MODEL.md §13): a real glug often carries a bright mode (the
//! pocket ringing as a bubble) that dies within a few tens of milliseconds beside a long low one
//! (the headspace's cavity). Over a span of up to 150 ms its spectral peak stands far below the
//! long mode's, so a fit from the span's own peaks finds one mode only. So a unit kept with
//! nothing fitted above its stronger component is looked at again: where what its fit left out of
//! the unit's first [`EARLY_S`] peaks at least [`SEPARATE_MODES`] above that component, both are
//! fitted together there, and the pair is a candidate if the new component decays faster (the
//! short bright mode sought) and the pair explains at least [`MIN_EARLY_GAIN`] of what the unit's
//! fit left of those first [`EARLY_S`], without explaining less of the span. A short mode is a
//! bottle's only where units enough ring it at one pitch ([`agreed`]); elsewhere each unit keeps
//! its own fit.

use super::eq1;
use super::modes::SEPARATE_MODES;
use super::phased;
use super::window::Span;
use super::{at_peak, check, Placed, Strides, UnitFit, GLIDE_LEAVES};
use crate::spectrum::own_peak_above;

/// The early part of a unit where a short mode is sought (s).
const EARLY_S: f64 = 0.04;
/// A short mode's decay where the pencil gives none, and the decay its search is matched to
/// (1/s): −60 dB in 46 ms.
pub(super) const SHORT_DECAY_GUESS_PER_S: f64 = 150.0;
/// The share of what the unit's fit left of the unit's first [`EARLY_S`] that the pair must
/// explain. A short mode carries little of a 150 ms span's energy (a tenth of the amplitude of a
/// long mode, decaying ten times faster, is 0.1 % of it) but a share of what is left early;
/// noise, which a component of four numbers fits only as its share of the hundreds of samples
/// read (1 % at the fewest), stays below it. A room's ring and the last glug's tail leave much
/// early that no mode explains, so the share asked is small and the units' agreement decides.
const MIN_EARLY_GAIN: f64 = 0.05;
/// The pair may explain this share less of the whole span than the one component (its fit is
/// weighted to the early part, where the short mode lives).
const SPAN_SLACK: f64 = 0.02;

/// A short mode is the bottle's if at least this many units ring it…
pub(super) const MIN_AGREEING_UNITS: usize = 3;
/// …and at least this share of the units kept…
const MIN_AGREEING_SHARE: f64 = 0.15;
/// …within this share of their median pitch: a bubble's size, and so its pitch, varies from glug
/// to glug (a real bottle's by 15 %), while what noise lends a fit lies anywhere above the mode.
pub(super) const AGREEING_PITCH: f64 = 0.25;

/// What a unit's fit left of its first [`EARLY_S`], where the short mode would ring.
pub(super) struct EarlyLeft {
    /// Where it starts in the unit's span (samples).
    from: usize,
    pub samples: Vec<f64>,
}

/// What `unit`'s fit left of its first [`EARLY_S`], if the unit has fitted no second mode above
/// its stronger component. A weaker one below is replaced (a low blob an eq. 1 started at hum or
/// the room gives, not the bright mode), and so is one above it but within [`SEPARATE_MODES`]:
/// that is the same mode's glide or beat, which eq. 1's second component takes in where the long
/// mode glides (a development draw's units fitted 195 and 218 Hz for a cavity gliding down to
/// 203 Hz as heard, and its bubble mode at 823 Hz was sought in none of them).
pub(super) fn early_left(span: &Span, unit: &UnitFit) -> Option<EarlyLeft> {
    let main = *unit.stronger()?;
    if unit
        .fitted()
        .any(|c| c.heard_hz >= main.heard_hz * SEPARATE_MODES)
    {
        return None;
    }
    let from = (span.onset - span.first).min(span.samples.len());
    let to = (from + (EARLY_S * span.fs) as usize).min(span.samples.len());
    let samples: Vec<f64> = (from..to)
        .map(|n| span.samples[n] - unit.value_at((span.first + n) as f64 / span.fs))
        .collect();
    (samples.len() >= 16).then_some(EarlyLeft { from, samples })
}

/// `unit`, with the short mode its fit left out where there is one (`Some`: the unit with it),
/// sought in what its fit left early (`early`, of [`early_left`]) from the strongest peak there,
/// or from `pooled_hz` where that is given (the peak of what every unit's fit left,
/// [`crate::spectrum::pooled_peak_above`]).
pub(super) fn with_second_mode(
    span: &Span,
    unit: UnitFit,
    early: &EarlyLeft,
    pooled_hz: Option<f64>,
) -> Option<UnitFit> {
    let main = *unit.stronger()?;
    let (left, from) = (&early.samples, early.from);
    let to = from + left.len();
    // The short mode sought lies above the unit's own; below it lie hum and the skirts of the
    // long mode's misfit.
    let short_hz = match pooled_hz {
        Some(hz) if hz >= main.heard_hz * SEPARATE_MODES => hz,
        Some(_) => return None,
        None => {
            own_peak_above(
                left,
                span.fs,
                main.heard_hz * SEPARATE_MODES,
                SHORT_DECAY_GUESS_PER_S,
                &span.held,
            )?
            .0
        }
    };
    let strides = Strides::for_highest(short_hz.max(main.heard_hz), span.fs);
    let poles = eq1::pencil_poles(left, strides.pencil, span.fs);
    let short = eq1::nearest_pole(&poles, short_hz).unwrap_or((short_hz, SHORT_DECAY_GUESS_PER_S));
    let window = span.window(strides.fit);
    let left_early = left.iter().map(|y| y * y).sum::<f64>();
    let left_by = |fit: &UnitFit| -> f64 {
        (from..to)
            .map(|n| (span.samples[n] - fit.value_at((span.first + n) as f64 / span.fs)).powi(2))
            .sum()
    };
    let pair = |gliding: [bool; 2]| -> Option<UnitFit> {
        let pair = phased::fit(
            &window,
            unit.onset_s,
            &[(main.heard_hz, main.decay_per_s), short],
            &gliding,
            phased::GLIDE_RESTARTS,
        )
        .ok()?;
        let both = UnitFit::of_phased(
            &pair,
            Placed {
                window: (span.first, span.end),
                stride: strides.fit,
                fs: span.fs,
            },
            unit.method,
        );
        // The pair must still be two modes, neither drawn onto the other's frequency, and the
        // new one the short bright mode sought: above the unit's own and decaying faster.
        let two_modes = match both.components {
            [Some(low), Some(high)] => {
                high.heard_hz / low.heard_hz >= SEPARATE_MODES
                    && (low.heard_hz - main.heard_hz).abs() < (high.heard_hz - main.heard_hz).abs()
                    && high.decay_per_s > low.decay_per_s
            }
            _ => false,
        };
        let early_gain = 1.0 - left_by(&both) / left_early.max(1e-300);
        // The unit's own mode must still reach its own f while it rings; the short one may
        // glide more slowly than it rings, and is then the pitch it is heard at
        // (`UnitFit::assign`).
        let low_heard = both.components[0].is_none_or(|low| low.unheard_glide().is_none());
        match check(both, span.fs).and_then(|both| at_peak(span, both)) {
            Ok(both)
                if low_heard
                    && two_modes
                    && early_gain >= MIN_EARLY_GAIN
                    && both.r_squared >= unit.r_squared - SPAN_SLACK =>
            {
                Some(both)
            }
            _ => None,
        }
    };
    // A gliding unit's pair glides too (the bright mode sweeps as the bubble forms); where that
    // fails (a glide out of range, or the unit's own mode no longer reaching its f), the main
    // mode glides and the short one is steady; else the two steady. A unit whose fit put a
    // second component just above its main one (its glide, fitted as two steady components) is
    // a gliding unit too.
    let glide_as_two = unit
        .fitted()
        .any(|c| c.heard_hz > main.heard_hz && c.heard_hz < main.heard_hz * SEPARATE_MODES);
    if main.glide.is_some() || glide_as_two {
        return pair([true, true])
            .or_else(|| pair([true, false]))
            .or_else(|| pair([false, false]));
    }
    // Beside a steady mode the short one glides where that leaves at most GLIDE_LEAVES of what
    // its steady fit leaves early (fitted steady, a mode rising into its pitch decays up to twice
    // as fast as it does: 185 against 88 /s in a development draw; on a steady one a glide
    // explains next to nothing more, and its pitch would wander from unit to unit).
    match (pair([false, false]), pair([false, true])) {
        (Some(steady), Some(glided)) if left_by(&glided) > GLIDE_LEAVES * left_by(&steady) => {
            Some(steady)
        }
        (steady, glided) => glided.or(steady),
    }
}

/// Which of the short modes found (`found[i]`: the pitch of unit i's, Hz) agree, out of `kept`
/// units: those within [`AGREEING_PITCH`] of the found ones' median, if at least
/// [`MIN_AGREEING_UNITS`] and [`MIN_AGREEING_SHARE`] of the units kept; else none (a mode heard
/// in a few units, or at scattered pitches, is noise or a splash, not the bottle's).
pub(super) fn agreed(found: &[Option<f64>], kept: usize) -> Vec<bool> {
    let pitches: Vec<f64> = found.iter().flatten().copied().collect();
    if pitches.is_empty() {
        return vec![false; found.len()];
    }
    let centre = crate::stats::median(&pitches);
    let agrees = |hz: f64| (hz / centre - 1.0).abs() <= AGREEING_PITCH;
    let count = pitches.iter().filter(|&&hz| agrees(hz)).count();
    let enough = count >= MIN_AGREEING_UNITS && count as f64 >= MIN_AGREEING_SHARE * kept as f64;
    found
        .iter()
        .map(|hz| enough && hz.is_some_and(agrees))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::agreed;

    #[test]
    fn short_modes_are_the_bottles_only_where_units_enough_agree_on_their_pitch() {
        // A real bottle's bubbles: three of four units, 15 % apart.
        let bottle = [Some(1094.0), None, Some(1290.0), Some(1346.0)];
        assert_eq!(agreed(&bottle, 4), [true, false, true, true]);
        // One far off the others is left out of them.
        let one_off = [Some(1300.0), Some(1320.0), Some(1280.0), Some(3900.0)];
        assert_eq!(agreed(&one_off, 4), [true, true, true, false]);
        // Scattered pitches (what noise lends a fit) agree on nothing.
        let scattered = [Some(700.0), Some(1300.0), Some(2600.0), Some(4100.0)];
        assert_eq!(agreed(&scattered, 4), [false; 4]);
        // Three a third apart are three pitches, not one bubble's.
        assert_eq!(
            agreed(&[Some(900.0), Some(1300.0), Some(1800.0)], 3),
            [false; 3]
        );
        // Two units, or three of forty, are too few.
        assert_eq!(agreed(&[Some(1300.0), Some(1310.0)], 2), [false; 2]);
        let few = [Some(1300.0), Some(1310.0), Some(1290.0)];
        assert_eq!(agreed(&few, 40), [false; 3]);
    }
}
