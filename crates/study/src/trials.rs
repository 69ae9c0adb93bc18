//! The trial order of a session: every ordered pair (paired), every level with the standard
//! first in half of its repetitions (constant), the target first in half the trials (2AFC),
//! either stimulus the odd one at each of the three places (triangle), or each order of A and B
//! with X either (ABX); shuffled from a seed that mixes the spec's seed with the participant's
//! ID, so one participant's order is the same on every run and resume.

use rand::seq::SliceRandom;
use rand::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

use super::spec::{Design, Spec};

/// One trial: which stimulus comes first, second and, in the three-interval designs (triangle,
/// ABX), third (indices into [`Spec::stimuli`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Trial {
    /// The stimulus played first.
    pub first: usize,
    /// The stimulus played second.
    pub second: usize,
    /// The stimulus played third: the triangle's third, ABX's X; `None` in the two-interval
    /// designs.
    pub third: Option<usize>,
}

impl Trial {
    /// A two-interval trial.
    pub fn pair(first: usize, second: usize) -> Self {
        Self {
            first,
            second,
            third: None,
        }
    }

    /// A three-interval trial.
    pub fn triple(first: usize, second: usize, third: usize) -> Self {
        Self {
            first,
            second,
            third: Some(third),
        }
    }

    /// The stimuli in the order played.
    pub fn played(self) -> impl Iterator<Item = usize> {
        [self.first, self.second].into_iter().chain(self.third)
    }

    /// The stimulus at place `place` (1 the first), if the trial has that place.
    pub fn at(self, place: u8) -> Option<usize> {
        self.played().nth(usize::from(place).checked_sub(1)?)
    }
}

/// The seed of a participant's order: FNV-1a (64-bit) over the participant's ID, started from
/// the spec's seed. Stable across platforms and Rust versions (the log keeps it).
pub fn order_seed(spec_seed: u64, participant: &str) -> u64 {
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    participant.bytes().fold(OFFSET ^ spec_seed, |hash, byte| {
        (hash ^ byte as u64).wrapping_mul(PRIME)
    })
}

/// Every trial of a session in the order presented.
///
/// Paired: each ordered pair of distinct stimuli `repetitions` times. Constant: each comparison
/// `repetitions` times, the standard first in ⌊repetitions/2⌋ of them and second in the rest
/// (an odd one left goes to the standard first for every other level, so the whole session
/// stays balanced within one trial). The list is then shuffled from `seed`.
pub fn plan_trials(spec: &Spec, seed: u64) -> Vec<Trial> {
    let mut trials = design_trials(spec);
    trials.shuffle(&mut Xoshiro256PlusPlus::seed_from_u64(seed));
    trials
}

/// The spec's `practice` trials, played before the study's: the design's trials shuffled from
/// a seed of their own (the order seed with its bits flipped, so the practice order is not the
/// study's beginning), taken in turn and begun again when `practice` is more than there are.
pub fn plan_practice(spec: &Spec, seed: u64) -> Vec<Trial> {
    let mut trials = design_trials(spec);
    trials.shuffle(&mut Xoshiro256PlusPlus::seed_from_u64(!seed));
    trials
        .iter()
        .copied()
        .cycle()
        .take(spec.practice as usize)
        .collect()
}

/// The design's trials before shuffling.
fn design_trials(spec: &Spec) -> Vec<Trial> {
    let count = spec.stimuli.len();
    let reps = spec.repetitions as usize;
    let mut trials = Vec::new();
    match spec.design {
        Design::Paired => {
            for _ in 0..reps {
                for first in 0..count {
                    for second in (0..count).filter(|&second| second != first) {
                        trials.push(Trial::pair(first, second));
                    }
                }
            }
        }
        // The target is stimulus 0: first in half the trials, second in the other half.
        Design::TwoAfc => {
            for _ in 0..reps {
                trials.push(Trial::pair(0, 1));
                trials.push(Trial::pair(1, 0));
            }
        }
        // Either stimulus the odd one, at each of the three places: AAB, ABA, BAA, BBA, BAB,
        // ABB, each `repetitions` times.
        Design::Triangle => {
            for _ in 0..reps {
                for (alike, odd) in [(0, 1), (1, 0)] {
                    trials.push(Trial::triple(alike, alike, odd));
                    trials.push(Trial::triple(alike, odd, alike));
                    trials.push(Trial::triple(odd, alike, alike));
                }
            }
        }
        // A then B in either order, X either of them: ABA, ABB, BAA, BAB.
        Design::Abx => {
            for _ in 0..reps {
                for (a, b) in [(0, 1), (1, 0)] {
                    trials.push(Trial::triple(a, b, a));
                    trials.push(Trial::triple(a, b, b));
                }
            }
        }
        Design::Constant => {
            // The standard is stimulus 0.
            for comparison in 1..count {
                let standard_first = reps / 2 + (reps % 2) * (comparison % 2);
                for rep in 0..reps {
                    trials.push(if rep < standard_first {
                        Trial::pair(0, comparison)
                    } else {
                        Trial::pair(comparison, 0)
                    });
                }
            }
        }
    }
    trials
}
