//! The bottle's residual volume and its tilt-dependent drain (MODEL.md §2, §3, §8).

use super::curves::{CurveSegment, FLOW, REST, SUBMERGED};
use crate::engine::config::{DrainMode, ModelConfig};
use crate::engine::controls::ControlValues;

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
pub struct Levels {
    key: [f64; 3],
    /// r(θ)·C: the liquid above it pours.
    pub rest_ml: f64,
    /// s(θ)·C: above it the mouth is submerged and the pour glugs.
    pub submerged_ml: f64,
    /// k(θ)/fs: the most that can leave in one sample.
    pub max_outflow_per_sample_ml: f64,
}

impl Levels {
    /// The outflow of a sample that starts at `volume_ml` (MODEL.md §3).
    #[inline]
    pub fn outflow_ml(&self, volume_ml: f64) -> f64 {
        self.max_outflow_per_sample_ml
            .min((volume_ml - self.rest_ml).max(0.0))
    }
}

/// The levels of each sample of a span (see [`Bottle::levels_of_span`]).
pub struct SpanLevels {
    rest_ml: [f64; SPAN],
    submerged_ml: [f64; SPAN],
    max_outflow_ml: [f64; SPAN],
}

/// The most samples a [`SpanLevels`] holds: a grid period.
pub const SPAN: usize = crate::engine::GRID;

impl Default for SpanLevels {
    fn default() -> Self {
        Self {
            rest_ml: [0.0; SPAN],
            submerged_ml: [0.0; SPAN],
            max_outflow_ml: [0.0; SPAN],
        }
    }
}

impl SpanLevels {
    /// r·C, s·C and k/fs of sample `index`.
    #[inline]
    pub fn of(&self, index: usize) -> (f64, f64, f64) {
        (
            self.rest_ml[index],
            self.submerged_ml[index],
            self.max_outflow_ml[index],
        )
    }

    /// The levels of sample `index`, whose controls give `key`.
    #[inline]
    pub fn at(&self, index: usize, key: [f64; 3]) -> Levels {
        Levels {
            key,
            rest_ml: self.rest_ml[index],
            submerged_ml: self.submerged_ml[index],
            max_outflow_per_sample_ml: self.max_outflow_ml[index],
        }
    }
}

pub struct Bottle {
    sample_rate: f64,
    volume_ml: f64,
    refill_pending: bool,
    last_fill_percent: f64,
    levels: Levels,
    /// The segments of r, s and h that the last tilt fell in: a tilt that moves a little from
    /// sample to sample rarely leaves them.
    segments: [CurveSegment; 3],
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
            segments: [CurveSegment::default(); 3],
        }
    }

    pub fn volume_ml(&self) -> f64 {
        self.volume_ml
    }

    /// Sets V after steps taken elsewhere in closed form (see `super::span`).
    pub fn set_volume_ml(&mut self, volume_ml: f64) {
        self.volume_ml = volume_ml;
    }

    /// The levels of the last step.
    pub fn current_levels(&self) -> &Levels {
        &self.levels
    }

    /// Whether a [`Bottle::step`] under `controls` would be a [`Bottle::step_steady`]: no refill
    /// pending, the same fill level, and the levels of the last step. (In follow mode V is the
    /// fill level already, set by that step.)
    #[inline]
    pub fn is_steady_under(&self, controls: &ControlValues, capacity_ml: f64) -> bool {
        !self.refill_pending
            && controls.fill_percent == self.last_fill_percent
            && [controls.tilt_deg, controls.pour_time_s, capacity_ml] == self.levels.key
    }

    /// Whether no sample of a span with these fill levels refills the bottle: no refill is
    /// pending, and in simulate mode the fill level stays the last one.
    pub fn refills_none_of(&self, fill_percents: &[f64], drain: DrainMode) -> bool {
        !self.refill_pending
            && (drain == DrainMode::Follow
                || fill_percents
                    .iter()
                    .fold(true, |same, &fill| same & (fill == self.last_fill_percent)))
    }

    /// Takes the state after a span stepped elsewhere, sample by sample with the arithmetic of
    /// [`Bottle::step_with`] (see `Pour::advance_varying`): V, and the last fill level seen.
    pub fn end_span(&mut self, volume_ml: f64, last_fill_percent: f64) {
        self.volume_ml = volume_ml;
        self.last_fill_percent = last_fill_percent;
    }

    /// Fills the bottle to the fill level that the next sample carries.
    pub fn refill(&mut self) {
        self.refill_pending = true;
    }

    /// Advances one sample; `controls` must be sanitised.
    #[inline]
    pub fn step(&mut self, controls: &ControlValues, config: &ModelConfig) -> Outflow {
        let levels = self.levels(controls, config.capacity_ml);
        self.step_with(controls.fill_percent, &levels, config)
    }

    /// [`Bottle::step`] with the levels of its controls worked out already (by
    /// [`Bottle::levels_of_span`]).
    #[inline]
    pub fn step_with(
        &mut self,
        fill_percent: f64,
        levels: &Levels,
        config: &ModelConfig,
    ) -> Outflow {
        let fill_ml = fill_percent / 100.0 * config.capacity_ml;
        let fill_changed = fill_percent != self.last_fill_percent;
        self.last_fill_percent = fill_percent;
        let refilled = self.refill_pending || (config.drain == DrainMode::Simulate && fill_changed);
        self.refill_pending = false;
        if refilled || config.drain == DrainMode::Follow {
            self.volume_ml = fill_ml;
        }

        let volume_before_ml = self.volume_ml;
        let amount_ml = levels.outflow_ml(volume_before_ml);
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

    /// The levels of every sample of a span whose tilt (and perhaps pour time) changes from
    /// sample to sample, into `levels`: the very values [`Bottle::step`] would work out one by
    /// one, in loops that vectorise (a curve is interpolated over the whole span when every tilt
    /// of it falls in one segment). The last sample's levels become the bottle's.
    pub fn levels_of_span(
        &mut self,
        tilts: &[f64],
        pour_times: &[f64],
        capacity_ml: f64,
        levels: &mut SpanLevels,
    ) {
        let len = tilts.len();
        let [rest, submerged, flow] = &mut self.segments;
        REST.fill(tilts, &mut levels.rest_ml[..len], rest);
        SUBMERGED.fill(tilts, &mut levels.submerged_ml[..len], submerged);
        FLOW.fill(tilts, &mut levels.max_outflow_ml[..len], flow);
        let sample_rate = self.sample_rate;
        for (rest, submerged) in levels.rest_ml[..len]
            .iter_mut()
            .zip(&mut levels.submerged_ml[..len])
        {
            *rest *= capacity_ml;
            *submerged *= capacity_ml;
        }
        let flows = levels.max_outflow_ml[..len].iter_mut();
        let first_pour_time = pour_times.first().copied().unwrap_or(f64::NAN);
        if pour_times.iter().all(|&time| time == first_pour_time) {
            // C/T once for the span: the same quotient at every sample.
            let rate_scale = capacity_ml / first_pour_time;
            for flow in flows {
                *flow = rate_scale * *flow / sample_rate;
            }
        } else {
            for (flow, pour_time) in flows.zip(pour_times) {
                *flow = capacity_ml / pour_time * *flow / sample_rate;
            }
        }
        if let Some(last) = len.checked_sub(1) {
            self.levels = levels.at(last, [tilts[last], pour_times[last], capacity_ml]);
        }
    }

    /// [`Bottle::step`] again under the controls of the previous step: no refill can be pending
    /// and no level can have changed, so only the volume moves. Same arithmetic, same result.
    #[inline]
    pub fn step_steady(&mut self, drain: DrainMode) -> Outflow {
        let levels = &self.levels;
        let volume_before_ml = self.volume_ml;
        let amount_ml = levels.outflow_ml(volume_before_ml);
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
            let [rest, submerged, flow] = &mut self.segments;
            let rate_ml_per_s = capacity_ml / controls.pour_time_s * FLOW.at_in(tilt, flow);
            self.levels = Levels {
                key,
                rest_ml: REST.at_in(tilt, rest) * capacity_ml,
                submerged_ml: SUBMERGED.at_in(tilt, submerged) * capacity_ml,
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
