//! What a synthesis path does: voice the units the pour starts and render their sum.

use super::pour::UnitOnset;

/// A bank of sounding wave-unit components. The engine renders spans that lie within one grid
/// period of [`super::partial::GRID`] samples and calls [`Synthesis::advance`] at each period's
/// start, counted from the last reset (while the bank is empty and the pour rests, only at the
/// last period start before it renders again); a path must give the same samples however spans
/// are cut.
pub trait Synthesis {
    fn new(sample_rate: f64) -> Self;
    /// Silences every component.
    fn clear(&mut self);
    fn is_empty(&self) -> bool;
    /// Components sounding.
    fn len(&self) -> usize;
    /// Components given up because the bank was full.
    fn given_up(&self) -> u64;
    /// Voices a unit that starts during sample `onset.sample`.
    fn start_unit(&mut self, onset: &UnitOnset);
    /// Adds every component into `out`, which starts at absolute sample `span_start` and lies
    /// within one grid period.
    fn render(&mut self, span_start: u64, out: &mut [f32]);
    /// Steps every component to the period starting at `period_start`, dropping silent ones.
    fn advance(&mut self, period_start: u64);
}
