//! Glug onsets from the outflow (MODEL.md §4): one unit each time a pocket's worth of liquid has
//! left while the mouth is submerged, timed to the sub-sample instant the pocket filled.

use super::bottle::Outflow;
use super::randomness::{UnitDraws, UnitShape};
use crate::config::ModelConfig;

/// More onsets than this in one sample are beyond any bottle (it would glug above fs); the rest of
/// that sample's outflow is counted as skipped units instead of started, so cost stays bounded.
pub const MAX_ONSETS_PER_SAMPLE: u32 = 8;

/// Where in its sample a unit starts, and the residual volume at that instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// x of §4, in [0, 1]: the onset is at t_n + x / fs.
    pub fraction: f64,
    pub volume_ml: f64,
    /// b_i: the pocket volume whose filling started the unit.
    pub pocket_ml: f64,
}

#[derive(Default)]
pub struct OnsetDetector {
    /// g of §4: outflow counted towards the next pocket.
    accumulated_ml: f64,
}

impl OnsetDetector {
    pub fn clear(&mut self) {
        self.accumulated_ml = 0.0;
    }

    /// g: outflow counted towards the next pocket.
    pub fn accumulated_ml(&self) -> f64 {
        self.accumulated_ml
    }

    /// Sets g after steps taken elsewhere in closed form (see `super::span`).
    pub fn set_accumulated_ml(&mut self, accumulated_ml: f64) {
        self.accumulated_ml = accumulated_ml;
    }

    /// Counts one sample's outflow; calls `emit` for every unit that starts in it and returns the
    /// number of units skipped by [`MAX_ONSETS_PER_SAMPLE`].
    #[inline]
    pub fn feed(
        &mut self,
        outflow: &Outflow,
        config: &ModelConfig,
        draws: &mut UnitDraws,
        mut emit: impl FnMut(Crossing, UnitShape),
    ) -> u64 {
        let amount = outflow.amount_ml;
        if !outflow.submerged || amount <= 0.0 {
            return 0;
        }
        let mut before = self.accumulated_ml;
        self.accumulated_ml += amount;
        let mut emitted = 0;
        loop {
            let pocket_ml = draws.next_pocket_ml(config);
            if self.accumulated_ml < pocket_ml {
                return 0;
            }
            if emitted == MAX_ONSETS_PER_SAMPLE {
                let skipped = (self.accumulated_ml / pocket_ml).floor();
                self.accumulated_ml -= skipped * pocket_ml;
                return skipped as u64;
            }
            // Clamped because a pocket volume changed by the user may already lie below `before`.
            let fraction = ((pocket_ml - before) / amount).clamp(0.0, 1.0);
            let crossing = Crossing {
                fraction,
                volume_ml: outflow.volume_before_ml - fraction * amount,
                pocket_ml,
            };
            let shape = draws.next_unit(config, crossing.volume_ml);
            emit(crossing, shape);
            emitted += 1;
            self.accumulated_ml -= pocket_ml;
            before -= pocket_ml;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outflow(amount_ml: f64) -> Outflow {
        Outflow {
            volume_before_ml: 200.0,
            amount_ml,
            submerged: true,
            refilled: false,
        }
    }

    #[test]
    fn crossings_fall_where_each_pocket_fills() {
        let config = ModelConfig::default().deterministic();
        let mut draws = UnitDraws::new(1);
        let mut detector = OnsetDetector::default();
        let mut crossings = Vec::new();
        detector.feed(&outflow(4.0), &config, &mut draws, |c, _| crossings.push(c));
        assert!(crossings.is_empty());
        detector.feed(&outflow(7.0), &config, &mut draws, |c, _| crossings.push(c));
        assert_eq!(crossings.len(), 2);
        assert!((crossings[0].fraction - 1.0 / 7.0).abs() < 1e-15);
        assert!((crossings[1].fraction - 6.0 / 7.0).abs() < 1e-15);
        assert!((crossings[1].volume_ml - (200.0 - 6.0)).abs() < 1e-12);
    }

    #[test]
    fn no_onset_while_the_mouth_is_clear() {
        let config = ModelConfig::default();
        let mut draws = UnitDraws::new(1);
        let mut detector = OnsetDetector::default();
        let clear = Outflow {
            submerged: false,
            ..outflow(100.0)
        };
        let mut count = 0;
        detector.feed(&clear, &config, &mut draws, |_, _| count += 1);
        assert_eq!(count, 0);
    }

    #[test]
    fn a_flood_of_onsets_is_capped_and_counted() {
        let config = ModelConfig::default().deterministic();
        let mut draws = UnitDraws::new(1);
        let mut detector = OnsetDetector::default();
        let mut started = 0;
        let skipped = detector.feed(&outflow(100.0), &config, &mut draws, |_, _| started += 1);
        assert_eq!(started, MAX_ONSETS_PER_SAMPLE);
        assert_eq!(skipped + started as u64, 20);
    }
}
