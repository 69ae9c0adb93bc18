//! The sounding components of a synthesis path, in a bank of fixed capacity allocated once, and
//! the rules for letting new ones in (the voice caps of MODEL.md §11). Every path admits
//! components the same way, so they differ only in how a component is rendered.

use super::component::Component;
use crate::engine::pour::UnitOnset;

/// More components than this never sound at once. Past it, a new component replaces the weakest
/// sounding one if it is louder, and is given up otherwise: a bottle pours a handful of units at
/// a time, so this only bites in stress cases (B near 0, pocket volumes near zero).
pub const MAX_PARTIALS: usize = 256;
/// The start budget holds at most this many units: a burst of this many may start at once.
pub const START_BURST_UNITS: f64 = 8.0;
/// The start budget refills by this many units per second of (onset) time: 500 times a real
/// bottle's glug rate. Units beyond the budget are given up whole, before anything is computed:
/// without it a flood of onsets (pour time and pocket volume at their minimums) costs a component
/// start and a scan of the full bank per onset, and rendering falls far behind real time. Counted
/// in time, not in samples, so the voicing does not depend on the sample rate.
pub const STARTS_PER_SECOND: f64 = 6000.0;

/// What a bank holds: something started from a [`Component`] with a loudness to compare.
pub trait Sounding {
    fn start(component: Component) -> Self;
    /// Any measure that orders components by loudness.
    fn level(&self) -> f64;
    /// Makes the component's state NaN: the fault the stability suite must catch.
    #[cfg(feature = "fault-injection")]
    fn poison(&mut self);
}

/// The start budget of MODEL.md §11: a bucket of at most [`START_BURST_UNITS`] units that refills
/// at [`STARTS_PER_SECOND`], judged at each unit's exact onset time.
#[derive(Debug, Clone, Copy)]
struct StartBudget {
    units: f64,
    /// Onset time (s since the reset) at which `units` was last brought up to date.
    as_of_s: f64,
}

impl StartBudget {
    const FULL: Self = Self {
        units: START_BURST_UNITS,
        as_of_s: 0.0,
    };

    /// Whether a unit with its onset at `time_s` may start; spends one unit of budget if so.
    fn admit(&mut self, time_s: f64) -> bool {
        let elapsed_s = (time_s - self.as_of_s).max(0.0);
        self.units = (self.units + STARTS_PER_SECOND * elapsed_s).min(START_BURST_UNITS);
        self.as_of_s = self.as_of_s.max(time_s);
        if self.units >= 1.0 {
            self.units -= 1.0;
            true
        } else {
            false
        }
    }
}

pub struct Bank<T> {
    sounding: Vec<T>,
    given_up: u64,
    budget: StartBudget,
    /// The most components that sounded at once since [`Bank::take_peak_len`] last read it.
    peak_len: usize,
    #[cfg(feature = "fault-injection")]
    poison_next: bool,
}

impl<T: Sounding> Bank<T> {
    pub fn new() -> Self {
        Self {
            sounding: Vec::with_capacity(MAX_PARTIALS),
            given_up: 0,
            budget: StartBudget::FULL,
            peak_len: 0,
            #[cfg(feature = "fault-injection")]
            poison_next: false,
        }
    }

    pub fn clear(&mut self) {
        self.sounding.clear();
        self.given_up = 0;
        self.budget = StartBudget::FULL;
    }

    pub fn sounding(&self) -> &[T] {
        &self.sounding
    }

    pub fn sounding_mut(&mut self) -> &mut [T] {
        &mut self.sounding
    }

    /// Components given up because the bank was full or the start budget was spent (both
    /// components of a unit refused by the budget count).
    pub fn given_up(&self) -> u64 {
        self.given_up
    }

    /// The most components that sounded at once since the last call (or since the bank was
    /// made); the count starts again from those sounding now.
    pub fn take_peak_len(&mut self) -> usize {
        let peak = self.peak_len.max(self.sounding.len());
        self.peak_len = self.sounding.len();
        peak
    }

    /// Starts the audible components of `onset` if the start budget admits the unit; a refused
    /// unit is given up whole.
    pub fn start_unit(&mut self, onset: &UnitOnset, sample_rate: f64) {
        let time_s = (onset.sample as f64 + onset.fraction) / sample_rate;
        if !self.budget.admit(time_s) {
            self.given_up += 2;
            return;
        }
        for index in 0..2 {
            if let Some(component) = Component::of(onset, index, sample_rate) {
                self.insert(T::start(component));
            }
        }
    }

    /// A new grid period: `keep` decides which components sound on.
    pub fn advance(&mut self, keep: impl FnMut(&mut T) -> bool) {
        self.sounding.retain_mut(keep);
    }

    /// The next component to start will have a NaN state.
    #[cfg(feature = "fault-injection")]
    pub fn poison_next(&mut self) {
        self.poison_next = true;
    }

    #[allow(unused_mut)]
    fn insert(&mut self, mut new: T) {
        #[cfg(feature = "fault-injection")]
        if std::mem::take(&mut self.poison_next) {
            new.poison();
        }
        if self.sounding.len() < MAX_PARTIALS {
            self.sounding.push(new);
            self.peak_len = self.peak_len.max(self.sounding.len());
            return;
        }
        self.given_up += 1;
        let weakest = self
            .sounding
            .iter_mut()
            .min_by(|a, b| a.level().total_cmp(&b.level()))
            .expect("a full bank is not empty");
        if weakest.level() < new.level() {
            *weakest = new;
        }
    }
}

impl<T: Sounding> Default for Bank<T> {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_budget_admits_a_burst_then_the_rate() {
        let mut budget = StartBudget::FULL;
        let burst = (0..20).filter(|_| budget.admit(0.0)).count();
        assert_eq!(burst, 8);
        // A second later the bucket is full again, no fuller.
        let next = (0..20).filter(|_| budget.admit(1.0)).count();
        assert_eq!(next, 8);
        // One unit's worth of time admits one unit (a binary fraction of a second, so the sum
        // is exact), and not two.
        let later = 1.0 + 1.0 / 4096.0;
        const { assert!(STARTS_PER_SECOND / 4096.0 >= 1.0 && STARTS_PER_SECOND / 4096.0 < 2.0) };
        assert!(budget.admit(later));
        assert!(!budget.admit(later));
    }
}
