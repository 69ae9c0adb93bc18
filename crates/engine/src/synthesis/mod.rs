//! Synthesis: the units the pour starts, their components summed (MODEL.md §5–6, §9).
//!
//! A unit (one glug) sounds as two components, each a decaying sinusoid ([`component`]). Three
//! paths implement [`Synthesis`], each a [`bank`] of its own kind of component sharing the
//! admission rules: the default anchored path ([`AnchoredF32`], real time, f32), and the recursive
//! oscillators in f32 and f64 ([`RecursiveF32`], [`RecursiveF64`]) that the accuracy report
//! compares with it. [`reference`] is no path at all: the f64 closed form summed at every sample,
//! the yardstick of the others.

mod anchored;
mod bank;
mod component;
mod recursive;
pub mod reference;

pub use anchored::{AnchoredF32, GRID};
pub use bank::{MAX_COMPONENTS, STARTS_PER_SECOND, START_BURST_UNITS};
pub use component::SILENT_DECAY_EXPONENT;
pub use recursive::{RecursiveF32, RecursiveF64, REANCHOR_SAMPLES};

use crate::pour::UnitOnset;

/// A bank of sounding unit components. The engine renders spans that lie within one grid period
/// of [`GRID`] samples and calls [`Synthesis::advance`] at each period's start, counted from the
/// last reset (while the bank is empty and the pour rests, only at the last period start before
/// it renders again); a path must give the same samples however spans are cut.
pub trait Synthesis {
    /// An empty bank for output at `sample_rate` (Hz); allocates, once.
    fn new(sample_rate: f64) -> Self;
    /// Silences every component.
    fn clear(&mut self);
    /// No component sounds.
    fn is_empty(&self) -> bool;
    /// Components sounding.
    fn len(&self) -> usize;
    /// Components given up because the bank was full or the start budget was spent.
    fn given_up(&self) -> u64;
    /// The most components that sounded at once since the last call; the count then starts
    /// again from those sounding now.
    fn take_peak_len(&mut self) -> usize;
    /// Starts the components of a unit that starts during sample `onset.sample`; returns whether
    /// any of them sounds (MODEL.md §6, §11: none does for a unit given up, or whose components
    /// are all omitted).
    fn start_unit(&mut self, onset: &UnitOnset) -> bool;
    /// Writes the sum of every component, from +0 in the bank's order, to `out` (whatever it
    /// held), which starts at absolute sample `span_start` and lies within one grid period.
    fn synthesize(&mut self, span_start: u64, out: &mut [f32]);
    /// The sum of every component over the grid period that `span_start` lies in, when what
    /// [`Synthesis::synthesize`] writes for any span of the period from there is exactly its
    /// part (no component started since the period's first sample), with a number that is
    /// another whenever the sum is worked out again; `None` otherwise, or on a path that keeps
    /// no such sum.
    fn period_sum(&mut self, _span_start: u64) -> Option<(&[f32; GRID], u64)> {
        None
    }
    /// Steps every component to the period starting at `period_start`, dropping silent ones.
    fn advance(&mut self, period_start: u64);
}
