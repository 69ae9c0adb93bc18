//! The default, real-time synthesis path: every component a [`Partial`].

use super::bank::Bank;
use super::partial::Partial;
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
        for partial in self.bank.sounding() {
            partial.synthesize(span_start, out);
        }
    }

    fn advance(&mut self, period_start: u64) {
        self.bank.advance(|partial| partial.advance(period_start));
    }
}
