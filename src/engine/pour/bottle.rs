//! The bottle's residual volume and its tilt-dependent drain (MODEL.md §2, §3, §8).

use super::curves::{FLOW, REST, SUBMERGED};
use crate::engine::config::{ControlValues, DrainMode, ModelConfig};

/// What one sample of pouring did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outflow {
    /// V at the start of the sample, after any refill.
    pub volume_before_ml: f64,
    /// Liquid that left the bottle during the sample.
    pub amount_ml: f64,
    /// Whether the mouth was under the liquid at the start of the sample (V > s(θ)·C).
    pub submerged: bool,
    /// Whether the bottle was (re)filled at the start of this sample.
    pub refilled: bool,
}

/// Levels that depend only on tilt, pour time and capacity, kept until one of those changes.
#[derive(Debug, Clone, Copy)]
struct Levels {
    key: [f64; 3],
    rest_ml: f64,
    submerged_ml: f64,
    max_outflow_per_sample_ml: f64,
}

pub struct Bottle {
    sample_rate: f64,
    volume_ml: f64,
    refill_pending: bool,
    last_fill_percent: f64,
    levels: Levels,
}

impl Bottle {
    pub fn new(sample_rate: f64) -> Self {
        Self {
            sample_rate,
            volume_ml: 0.0,
            refill_pending: true,
            last_fill_percent: f64::NAN,
            levels: Levels {
                key: [f64::NAN; 3],
                rest_ml: 0.0,
                submerged_ml: 0.0,
                max_outflow_per_sample_ml: 0.0,
            },
        }
    }

    pub fn volume_ml(&self) -> f64 {
        self.volume_ml
    }

    /// Fills the bottle to the fill level that the next sample carries.
    pub fn refill(&mut self) {
        self.refill_pending = true;
    }

    /// Advances one sample; `controls` must be sanitised.
    #[inline]
    pub fn step(&mut self, controls: &ControlValues, config: &ModelConfig) -> Outflow {
        let fill_ml = controls.fill_percent / 100.0 * config.capacity_ml;
        let fill_changed = controls.fill_percent != self.last_fill_percent;
        self.last_fill_percent = controls.fill_percent;
        let refilled = self.refill_pending || (config.drain == DrainMode::Simulate && fill_changed);
        self.refill_pending = false;
        if refilled || config.drain == DrainMode::Follow {
            self.volume_ml = fill_ml;
        }

        let levels = self.levels(controls, config.capacity_ml);
        let volume_before_ml = self.volume_ml;
        let amount_ml = levels
            .max_outflow_per_sample_ml
            .min((volume_before_ml - levels.rest_ml).max(0.0));
        if config.drain == DrainMode::Simulate {
            self.volume_ml = volume_before_ml - amount_ml;
        }
        Outflow {
            volume_before_ml,
            amount_ml,
            submerged: volume_before_ml > levels.submerged_ml,
            refilled,
        }
    }

    /// [`Bottle::step`] again under the controls of the previous step: no refill can be pending
    /// and no level can have changed, so only the volume moves. Same arithmetic, same result.
    #[inline]
    pub fn step_steady(&mut self, drain: DrainMode) -> Outflow {
        let levels = &self.levels;
        let volume_before_ml = self.volume_ml;
        let amount_ml = levels
            .max_outflow_per_sample_ml
            .min((volume_before_ml - levels.rest_ml).max(0.0));
        if drain == DrainMode::Simulate {
            self.volume_ml = volume_before_ml - amount_ml;
        }
        Outflow {
            volume_before_ml,
            amount_ml,
            submerged: volume_before_ml > levels.submerged_ml,
            refilled: false,
        }
    }

    #[inline]
    fn levels(&mut self, controls: &ControlValues, capacity_ml: f64) -> Levels {
        let key = [controls.tilt_deg, controls.pour_time_s, capacity_ml];
        if key != self.levels.key {
            let tilt = controls.tilt_deg;
            let rate_ml_per_s = capacity_ml / controls.pour_time_s * FLOW.at(tilt);
            self.levels = Levels {
                key,
                rest_ml: REST.at(tilt) * capacity_ml,
                submerged_ml: SUBMERGED.at(tilt) * capacity_ml,
                max_outflow_per_sample_ml: rate_ml_per_s / self.sample_rate,
            };
        }
        self.levels
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn controls(tilt_deg: f64) -> ControlValues {
        ControlValues {
            tilt_deg,
            ..ControlValues::default()
        }
    }

    #[test]
    fn upright_bottle_never_pours() {
        let config = ModelConfig::default();
        let mut bottle = Bottle::new(48_000.0);
        for _ in 0..48_000 {
            let outflow = bottle.step(&controls(0.0), &config);
            assert_eq!(outflow.amount_ml, 0.0);
        }
        assert_eq!(bottle.volume_ml(), 300.0);
    }

    #[test]
    fn tilted_bottle_drains_to_its_rest_level_and_stops() {
        let config = ModelConfig::default();
        let mut bottle = Bottle::new(1_000.0);
        for _ in 0..60_000 {
            bottle.step(&controls(90.0), &config);
        }
        assert!((bottle.volume_ml() - 0.333 * 300.0).abs() < 1e-9);
    }

    #[test]
    fn follow_mode_holds_volume_at_the_fill_level() {
        let config = ModelConfig {
            drain: DrainMode::Follow,
            ..ModelConfig::default()
        };
        let mut bottle = Bottle::new(1_000.0);
        let c = ControlValues {
            tilt_deg: 135.0,
            fill_percent: 50.0,
            ..ControlValues::default()
        };
        for _ in 0..100 {
            let outflow = bottle.step(&c, &config);
            assert_eq!(outflow.volume_before_ml, 150.0);
            assert!((outflow.amount_ml - 300.0 / 5.0 / 1_000.0).abs() < 1e-15);
        }
    }

    #[test]
    fn a_change_of_fill_refills_in_simulate_mode() {
        let config = ModelConfig::default();
        let mut bottle = Bottle::new(1_000.0);
        let mut c = controls(135.0);
        for _ in 0..1_000 {
            bottle.step(&c, &config);
        }
        assert!(bottle.volume_ml() < 300.0 - 59.0);
        c.fill_percent = 80.0;
        let outflow = bottle.step(&c, &config);
        assert!(outflow.refilled);
        assert_eq!(outflow.volume_before_ml, 240.0);
    }
}
