//! The sounding components of all units, in a bank of fixed capacity allocated once: the default,
//! real-time synthesis path.

use super::partial::Partial;
use super::pour::UnitOnset;
use super::synthesis::Synthesis;

/// More components than this never sound at once. Past it, a new component replaces the weakest
/// sounding one if it is louder, and is given up otherwise: a bottle pours a handful of units at
/// a time, so this only bites in stress cases (B near 0, pocket volumes near zero).
pub const MAX_PARTIALS: usize = 256;
/// At most this many components start per grid period (8 units per 64 samples, 6000 units/s at
/// 48 kHz, 500 times a real bottle's rate); the rest are given up before anything is computed.
/// Without it a flood of onsets (pour time and pocket volume at their minimums) costs a component
/// start and a scan of the full bank per onset, and rendering falls far behind real time.
pub const MAX_STARTS_PER_PERIOD: u32 = 16;

pub struct VoiceBank {
    partials: Vec<Partial>,
    sample_rate: f64,
    given_up: u64,
    /// Component starts left in the current grid period.
    starts_left: u32,
}

impl VoiceBank {
    fn insert(&mut self, partial: Partial) {
        if self.partials.len() < MAX_PARTIALS {
            self.partials.push(partial);
            return;
        }
        self.given_up += 1;
        let weakest = self
            .partials
            .iter_mut()
            .min_by(|a, b| a.level().total_cmp(&b.level()))
            .expect("a full bank is not empty");
        if weakest.level() < partial.level() {
            *weakest = partial;
        }
    }
}

impl Synthesis for VoiceBank {
    fn new(sample_rate: f64) -> Self {
        Self {
            partials: Vec::with_capacity(MAX_PARTIALS),
            sample_rate,
            given_up: 0,
            starts_left: MAX_STARTS_PER_PERIOD,
        }
    }

    fn clear(&mut self) {
        self.partials.clear();
        self.given_up = 0;
        self.starts_left = MAX_STARTS_PER_PERIOD;
    }

    fn is_empty(&self) -> bool {
        self.partials.is_empty()
    }

    fn len(&self) -> usize {
        self.partials.len()
    }

    fn given_up(&self) -> u64 {
        self.given_up
    }

    fn start_unit(&mut self, onset: &UnitOnset) {
        for index in 0..2 {
            if self.starts_left == 0 {
                self.given_up += 1;
                continue;
            }
            self.starts_left -= 1;
            if let Some(partial) = Partial::start(onset, index, self.sample_rate) {
                self.insert(partial);
            }
        }
    }

    #[inline]
    fn render(&mut self, span_start: u64, out: &mut [f32]) {
        for partial in &self.partials {
            partial.render(span_start, out);
        }
    }

    fn advance(&mut self, period_start: u64) {
        self.starts_left = MAX_STARTS_PER_PERIOD;
        self.partials.retain_mut(|partial| partial.advance(period_start));
    }
}
