//! The sounding components of a synthesis path, in a bank of fixed capacity allocated once, and
//! the rules for letting new ones in. Every path admits components the same way, so they differ
//! only in how a component is rendered.

use super::component::Component;
use crate::engine::pour::UnitOnset;

/// More components than this never sound at once. Past it, a new component replaces the weakest
/// sounding one if it is louder, and is given up otherwise: a bottle pours a handful of units at
/// a time, so this only bites in stress cases (B near 0, pocket volumes near zero).
pub const MAX_PARTIALS: usize = 256;
/// At most this many components start per grid period (8 units per 64 samples, 6000 units/s at
/// 48 kHz, 500 times a real bottle's rate); the rest are given up before anything is computed.
/// Without it a flood of onsets (pour time and pocket volume at their minimums) costs a component
/// start and a scan of the full bank per onset, and rendering falls far behind real time.
pub const MAX_STARTS_PER_PERIOD: u32 = 16;

/// What a bank holds: something started from a [`Component`] with a loudness to compare.
pub trait Sounding {
    fn start(component: Component) -> Self;
    /// Any measure that orders components by loudness.
    fn level(&self) -> f64;
}

pub struct Bank<T> {
    sounding: Vec<T>,
    given_up: u64,
    /// Component starts left in the current grid period.
    starts_left: u32,
}

impl<T: Sounding> Bank<T> {
    pub fn new() -> Self {
        Self {
            sounding: Vec::with_capacity(MAX_PARTIALS),
            given_up: 0,
            starts_left: MAX_STARTS_PER_PERIOD,
        }
    }

    pub fn clear(&mut self) {
        self.sounding.clear();
        self.given_up = 0;
        self.starts_left = MAX_STARTS_PER_PERIOD;
    }

    pub fn sounding(&self) -> &[T] {
        &self.sounding
    }

    pub fn sounding_mut(&mut self) -> &mut [T] {
        &mut self.sounding
    }

    /// Components given up because the bank was full or the period's starts were spent.
    pub fn given_up(&self) -> u64 {
        self.given_up
    }

    /// Starts the audible components of `onset`, within the period's budget.
    pub fn start_unit(&mut self, onset: &UnitOnset, sample_rate: f64) {
        for index in 0..2 {
            if self.starts_left == 0 {
                self.given_up += 1;
                continue;
            }
            self.starts_left -= 1;
            if let Some(component) = Component::of(onset, index, sample_rate) {
                self.insert(T::start(component));
            }
        }
    }

    /// A new grid period: a fresh start budget, and `keep` decides which components sound on.
    pub fn advance(&mut self, keep: impl FnMut(&mut T) -> bool) {
        self.starts_left = MAX_STARTS_PER_PERIOD;
        self.sounding.retain_mut(keep);
    }

    fn insert(&mut self, new: T) {
        if self.sounding.len() < MAX_PARTIALS {
            self.sounding.push(new);
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
