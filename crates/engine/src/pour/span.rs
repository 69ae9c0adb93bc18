//! Many samples of the pour at once under constant controls, with the very numbers the
//! per-sample step of MODEL.md §3–4 gives.
//!
//! Under constant controls almost every sample is *plain*: the same outflow a, no onset, V
//! falling by a (simulate mode) and g rising by a (mouth submerged). A run of plain samples is
//! taken in closed form ([`BinadeSteps`]); it ends where a sample is not plain or the closed form
//! would no longer be exact: an onset (g reaching the next pocket), V reaching the rest level
//! (the outflow shrinks) or the submerged level (the glugs stop), V or g leaving its binade. That
//! sample is then stepped on its own, and a new run is planned from there.

use super::bottle::{Levels, Outflow};
use super::exact::{BinadeSteps, Direction};
use crate::config::DrainMode;

/// A stretch of plain samples starting at the pour's current state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlainRun {
    /// Plain samples left in the stretch.
    pub samples_left: u64,
    /// Each of them as the per-sample drain takes the first: the same outflow and mouth, only V
    /// at the start differs.
    pub outflow: Outflow,
    /// What V falls by in each (0 if it does not move).
    pub volume_step: f64,
    /// What g rises by in each (0 if it does not move).
    pub accumulated_step: f64,
}

/// The state a run is planned from.
pub struct PourState<'a> {
    pub volume_ml: f64,
    pub accumulated_ml: f64,
    pub levels: &'a Levels,
    pub drain: DrainMode,
    /// The pocket volume the next onset waits for.
    pub pocket_ml: f64,
}

impl PlainRun {
    /// The plain samples from `state` on, or `None` if the very next sample is not plain (or
    /// not one the closed form covers): it is then stepped on its own.
    pub fn plan(state: &PourState) -> Option<Self> {
        let levels = state.levels;
        let volume = state.volume_ml;
        let (outflow, _) = levels.drain_on(volume, state.drain);
        let Outflow {
            amount_ml,
            submerged,
            ..
        } = outflow;
        if amount_ml == 0.0 {
            // Nothing flows, so nothing moves, for as long as the controls hold.
            return Some(Self {
                samples_left: u64::MAX,
                outflow,
                volume_step: 0.0,
                accumulated_step: 0.0,
            });
        }
        let mut samples = u64::MAX;
        let mut volume_step = 0.0;
        if state.drain == DrainMode::Simulate {
            // Only the full outflow k is the same from sample to sample; below it each differs.
            let max_outflow = levels.max_outflow_per_sample_ml;
            if amount_ml < max_outflow {
                return None;
            }
            let steps = BinadeSteps::of(volume, amount_ml, Direction::Down)?;
            volume_step = steps.step;
            samples = steps.max_steps;
            if volume_step > 0.0 {
                // Sample j as the per-sample step takes it, from V_j.
                let sample = |j: u64| {
                    let volume_j = steps.after(volume, j, Direction::Down);
                    levels.drain_on(volume_j, state.drain).0
                };
                // Sample j is plain while its outflow is the full k, and glugs alike while the
                // mouth stays submerged.
                let full_outflow = |j: u64| sample(j).amount_ml == max_outflow;
                let estimate = (volume - levels.rest_ml - max_outflow) / volume_step + 1.0;
                samples = samples.min(count_while(estimate, samples, full_outflow));
                if submerged {
                    let above = |j: u64| sample(j).submerged;
                    let estimate = (volume - levels.submerged_ml) / volume_step + 1.0;
                    samples = samples.min(count_while(estimate, samples, above));
                }
            }
        }
        let mut accumulated_step = 0.0;
        if submerged {
            let accumulated = state.accumulated_ml;
            let steps = BinadeSteps::of(accumulated, amount_ml, Direction::Up)?;
            accumulated_step = steps.step;
            samples = samples.min(steps.max_steps);
            // Sample j starts no unit while g after it, g_(j+1), is still below the pocket.
            let below_pocket =
                |j: u64| steps.after(accumulated, j + 1, Direction::Up) < state.pocket_ml;
            let estimate = if accumulated_step > 0.0 {
                (state.pocket_ml - accumulated) / accumulated_step
            } else {
                f64::INFINITY
            };
            samples = samples.min(count_while(estimate, samples, below_pocket));
        }
        (samples > 0).then_some(Self {
            samples_left: samples,
            outflow,
            volume_step,
            accumulated_step,
        })
    }
}

/// How many samples j = 0, 1, … in a row satisfy `holds`, which once false stays false, up to
/// `cap`; `estimate` is a close guess that is checked, so only its accuracy matters for speed.
fn count_while(estimate: f64, cap: u64, holds: impl Fn(u64) -> bool) -> u64 {
    let guess = if estimate >= cap as f64 {
        cap
    } else if estimate > 0.0 {
        estimate as u64
    } else {
        0
    };
    if guess == 0 || holds(guess - 1) {
        return guess;
    }
    // The guess overshot, most often by one where the bound is reached exactly.
    if guess == 1 || holds(guess - 2) {
        return guess - 1;
    }
    // Far off: the answer lies below, where `holds(lo - 1)` is known (or lo = 0).
    let (mut lo, mut hi) = (0, guess - 2);
    while lo < hi {
        let mid = lo + (hi - lo).div_ceil(2);
        if holds(mid - 1) {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    lo
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn count_while_finds_the_first_failure_from_any_guess() {
        for first_false in [0u64, 1, 2, 7, 64, 1000] {
            for guess in [0.0, 0.5, 1.0, 6.0, 63.9, 64.0, 999.0, 5000.0, f64::INFINITY] {
                let counted = count_while(guess, 4096, |j| j < first_false);
                let guess_floor = (guess.min(4096.0)) as u64;
                // Never more than the truth; the truth whenever the guess reaches it.
                assert!(counted <= first_false, "{first_false} from {guess}");
                if guess_floor >= first_false {
                    assert_eq!(counted, first_false.min(4096), "{first_false} from {guess}");
                }
            }
        }
    }
}
