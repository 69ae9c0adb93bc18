//! The sounding components of a synthesis path, in a bank of fixed capacity allocated once, and
//! the rules for letting new ones in (the caps of MODEL.md §11). Every path is a [`Bank`]
//! and admits components the same way, so paths differ only in their [`BankComponent`]: how one
//! component is rendered.

use super::component::Component;
use super::{Synthesis, GRID};
use crate::pour::UnitOnset;

/// More components than this never sound at once. Past it, a new component replaces the weakest
/// sounding one if it is louder, and is given up otherwise: a bottle pours a handful of units at
/// a time, so this only bites in stress cases (B near 0, pocket volumes near zero).
pub const MAX_COMPONENTS: usize = 256;
/// The start budget holds at most this many units: a burst of this many may start at once.
pub const START_BURST_UNITS: f64 = 8.0;
/// The start budget refills by this many units per second of (onset) time: 500 times a real
/// bottle's glug rate. Units beyond the budget are given up whole, before anything is computed:
/// without it a flood of onsets (pour time and pocket volume at their minimums) costs a component
/// start and a scan of the full bank per onset, and rendering falls far behind real time. Counted
/// in time, not in samples, so the voicing does not depend on the sample rate.
pub const STARTS_PER_SECOND: f64 = 6000.0;

/// A component as one synthesis path renders it: what its [`Bank`] holds.
pub trait BankComponent: Sized {
    /// What the path keeps beside its components, in the bank's order (the anchored path: their
    /// per-period state as arrays, and the period summed over the components that sound from its
    /// start); `()` for none. Made once, when the bank is (it may allocate); the bank tells it of
    /// every change to its components through the hooks below, so it is never made again.
    type Shared: Default;
    /// The component from its first sample on.
    fn start(component: Component) -> Self;
    /// Any measure that orders components by loudness, of one not yet in a bank.
    fn level(&self) -> f64;
    /// The same measure, of `components[index]` in a bank.
    fn level_in(components: &[Self], _shared: &Self::Shared, index: usize) -> f64 {
        components[index].level()
    }
    /// The last of `components` has just joined the bank.
    fn joined(_shared: &mut Self::Shared, _components: &[Self]) {}
    /// `components[index]` has just been replaced by a new one.
    fn replaced(_shared: &mut Self::Shared, _components: &[Self], _index: usize) {}
    /// Every component has been dropped.
    fn cleared(_shared: &mut Self::Shared) {}
    /// Moves every component to the grid period starting at `period_start`, dropping the silent
    /// ones and keeping the others in their order.
    fn advance_all(components: &mut Vec<Self>, shared: &mut Self::Shared, period_start: u64);
    /// Writes the sum of every component of a bank, in its order and from +0, to `out`, which
    /// starts at absolute sample `span_start` and lies within one grid period.
    fn write_all(
        components: &mut [Self],
        shared: &mut Self::Shared,
        span_start: u64,
        out: &mut [f32],
    );
    /// [`Synthesis::period_sum`] of a bank: `None` on a path that keeps no sum.
    fn period_sum<'a>(
        _components: &'a [Self],
        _shared: &'a mut Self::Shared,
        _span_start: u64,
    ) -> Option<(&'a [f32; GRID], u64)> {
        None
    }
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

/// A synthesis path: the sounding components of kind `C`, allocation-free after `new()`.
pub struct Bank<C: BankComponent> {
    sounding: Vec<C>,
    shared: C::Shared,
    sample_rate: f64,
    /// Components given up because the bank was full or the start budget was spent (both
    /// components of a unit refused by the budget count).
    given_up: u64,
    budget: StartBudget,
    /// The most components that sounded at once since [`Synthesis::take_peak_len`] last read it.
    peak_len: usize,
}

impl<C: BankComponent> Synthesis for Bank<C> {
    fn new(sample_rate: f64) -> Self {
        Self {
            sounding: Vec::with_capacity(MAX_COMPONENTS),
            shared: C::Shared::default(),
            sample_rate,
            given_up: 0,
            budget: StartBudget::FULL,
            peak_len: 0,
        }
    }

    fn clear(&mut self) {
        self.sounding.clear();
        C::cleared(&mut self.shared);
        self.given_up = 0;
        self.budget = StartBudget::FULL;
    }

    fn is_empty(&self) -> bool {
        self.sounding.is_empty()
    }

    fn len(&self) -> usize {
        self.sounding.len()
    }

    fn given_up(&self) -> u64 {
        self.given_up
    }

    fn take_peak_len(&mut self) -> usize {
        let peak = self.peak_len.max(self.sounding.len());
        self.peak_len = self.sounding.len();
        peak
    }

    /// Starts the audible components of `onset` if the start budget admits the unit; a refused
    /// unit is given up whole.
    fn start_unit(&mut self, onset: &UnitOnset) -> bool {
        let time_s = (onset.sample as f64 + onset.fraction) / self.sample_rate;
        if !self.budget.admit(time_s) {
            self.given_up += 2;
            return false;
        }
        let mut sounds = false;
        for index in 0..2 {
            if let Some(component) = Component::of(onset, index, self.sample_rate) {
                sounds |= self.insert(C::start(component));
            }
        }
        sounds
    }

    #[inline]
    fn synthesize(&mut self, span_start: u64, out: &mut [f32]) {
        C::write_all(&mut self.sounding, &mut self.shared, span_start, out);
    }

    #[inline(always)]
    fn period_sum(&mut self, span_start: u64) -> Option<(&[f32; GRID], u64)> {
        C::period_sum(&self.sounding, &mut self.shared, span_start)
    }

    fn advance(&mut self, period_start: u64) {
        C::advance_all(&mut self.sounding, &mut self.shared, period_start);
    }
}

impl<C: BankComponent> Bank<C> {
    /// Lets `new` in; returns whether it sounds (it is given up if the bank is full of louder
    /// components).
    fn insert(&mut self, new: C) -> bool {
        if self.sounding.len() < MAX_COMPONENTS {
            self.sounding.push(new);
            C::joined(&mut self.shared, &self.sounding);
            self.peak_len = self.peak_len.max(self.sounding.len());
            return true;
        }
        self.given_up += 1;
        let level = |index| C::level_in(&self.sounding, &self.shared, index);
        let weakest = (0..self.sounding.len())
            .min_by(|&a, &b| level(a).total_cmp(&level(b)))
            .expect("a full bank is not empty");
        let louder = level(weakest) < new.level();
        if louder {
            self.sounding[weakest] = new;
            C::replaced(&mut self.shared, &self.sounding, weakest);
        }
        louder
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
