//! The default, real-time synthesis path: every component a [`Partial`].

use multiversion::multiversion;

use super::bank::Bank;
use super::partial::{Partial, GRID};
use super::Synthesis;
use crate::engine::pour::UnitOnset;

/// The default synthesis path: anchored partials in f32, allocation-free after `new()`.
pub struct VoiceBank {
    bank: Bank<Partial>,
    sample_rate: f64,
}

impl Synthesis for VoiceBank {
    fn new(sample_rate: f64) -> Self {
        Self {
            bank: Bank::new(),
            sample_rate,
        }
    }

    fn clear(&mut self) {
        self.bank.clear();
    }

    fn is_empty(&self) -> bool {
        self.bank.sounding().is_empty()
    }

    fn len(&self) -> usize {
        self.bank.sounding().len()
    }

    fn given_up(&self) -> u64 {
        self.bank.given_up()
    }

    fn take_peak_len(&mut self) -> usize {
        self.bank.take_peak_len()
    }

    #[cfg(feature = "fault-injection")]
    fn poison_next_component(&mut self) {
        self.bank.poison_next();
    }

    fn start_unit(&mut self, onset: &UnitOnset) {
        self.bank.start_unit(onset, self.sample_rate);
    }

    #[inline]
    fn synthesize(&mut self, span_start: u64, out: &mut [f32]) {
        add_partials(self.bank.sounding(), span_start, out);
    }

    fn advance(&mut self, period_start: u64) {
        self.bank.advance(|partial| partial.advance(period_start));
    }
}

/// Adds every partial into `out`, in the bank's order. The loops are compiled for x86-64's
/// baseline (SSE2: 4 f32 an instruction) and again for AVX2 (8) and AVX-512 (16), and the widest
/// the processor has runs. Every lane does the same IEEE multiplications and additions in the
/// same order (Rust never fuses them), so the samples are the same bits on every path.
///
/// A whole period in which no partial starts is summed with the period held in registers (64
/// f32: 8 AVX2 or 4 AVX-512 registers), so each partial costs its multiplications and additions
/// and no loads and stores of the output.
#[multiversion(targets("x86_64+avx512f+avx512vl+avx2+avx", "x86_64+avx2+avx"))]
fn add_partials(partials: &[Partial], span_start: u64, out: &mut [f32]) {
    if let Ok(period) = <&mut [f32; GRID]>::try_from(&mut *out) {
        if partials
            .iter()
            .all(|partial| partial.anchor_sample() == span_start)
        {
            let mut sum = *period;
            for partial in partials {
                partial.synthesize_period(&mut sum);
            }
            *period = sum;
            return;
        }
    }
    for partial in partials {
        partial.synthesize(span_start, out);
    }
}
