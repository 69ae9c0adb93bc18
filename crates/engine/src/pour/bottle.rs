//! The bottle's residual volume and its tilt-dependent drain (MODEL.md §2, §3, §8).

use crate::config::{DrainMode, ModelConfig};
use crate::controls::ControlValues;
use crate::curves::CurveSegment;

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

impl Outflow {
    /// Nothing poured from an empty bottle.
    pub const NONE: Self = Self {
        volume_before_ml: 0.0,
        amount_ml: 0.0,
        submerged: false,
        refilled: false,
    };
}

/// The levels of one sample, set by its tilt, pour time and capacity (MODEL.md §2, §3).
#[derive(Debug, Clone, Copy)]
pub struct Levels {
    /// r(θ)·C: the liquid above it pours.
    pub rest_ml: f64,
    /// s(θ)·C: above it the mouth is submerged and the pour glugs.
    pub submerged_ml: f64,
    /// k(θ)/fs: the most that can leave in one sample.
    pub max_outflow_per_sample_ml: f64,
}

impl Levels {
    /// One sample of the drain (MODEL.md §3, §8), the only statement of it: every way of stepping
    /// the pour takes its samples with this, the closed forms of `super::span` included. V starts
    /// at `volume_ml`, or at the fill level `fill_ml()` after a refill and at every sample of
    /// follow mode; the outflow is min(k/fs, max(V − r·C, 0)); the mouth is submerged while
    /// V > s·C; in simulate mode V falls by the outflow. Returns the outflow and V after it.
    #[inline(always)]
    pub fn drain(
        &self,
        volume_ml: f64,
        fill_ml: impl FnOnce() -> f64,
        refilled: bool,
        drain: DrainMode,
    ) -> (Outflow, f64) {
        let volume_before_ml = if refilled || drain == DrainMode::Follow {
            fill_ml()
        } else {
            volume_ml
        };
        let amount_ml = self
            .max_outflow_per_sample_ml
            .min((volume_before_ml - self.rest_ml).max(0.0));
        let volume_after_ml = match drain {
            DrainMode::Simulate => volume_before_ml - amount_ml,
            DrainMode::Follow => volume_before_ml,
        };
        let outflow = Outflow {
            volume_before_ml,
            amount_ml,
            submerged: volume_before_ml > self.submerged_ml,
            refilled,
        };
        (outflow, volume_after_ml)
    }

    /// [`Levels::drain`] of a sample that refills nothing, from a V that is the fill level
    /// already in follow mode.
    #[inline(always)]
    pub fn drain_on(&self, volume_ml: f64, drain: DrainMode) -> (Outflow, f64) {
        self.drain(volume_ml, || volume_ml, false, drain)
    }
}

/// V at fill level `fill_percent` (MODEL.md §8).
#[inline(always)]
pub fn fill_ml(fill_percent: f64, capacity_ml: f64) -> f64 {
    fill_percent / 100.0 * capacity_ml
}

/// The levels of each sample of a span (see [`Bottle::levels_of_span`]).
pub struct SpanLevels {
    rest_ml: [f64; SPAN],
    submerged_ml: [f64; SPAN],
    max_outflow_ml: [f64; SPAN],
}

/// The most samples a [`SpanLevels`] holds: a grid period.
pub const SPAN: usize = crate::GRID;

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
    /// The levels of sample `index`.
    #[inline]
    pub fn at(&self, index: usize) -> Levels {
        Levels {
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
    /// The tilt, pour time and capacity that `levels` are of (under the curves of the constants
    /// last set: see [`Bottle::forget_levels`]).
    levels_key: [f64; 3],
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
                rest_ml: 0.0,
                submerged_ml: 0.0,
                max_outflow_per_sample_ml: 0.0,
            },
            levels_key: [f64::NAN; 3],
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

    /// Works the levels out again at the next step: the constants changed, the curves perhaps.
    /// The curves' segments start over too, as they may have fewer pieces now.
    pub fn forget_levels(&mut self) {
        self.levels_key = [f64::NAN; 3];
        self.segments = [CurveSegment::default(); 3];
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
            && [controls.tilt_deg, controls.pour_time_s, capacity_ml] == self.levels_key
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
        let levels = self.levels(controls, config);
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
        let fill_changed = fill_percent != self.last_fill_percent;
        self.last_fill_percent = fill_percent;
        let refilled = self.refill_pending || (config.drain == DrainMode::Simulate && fill_changed);
        self.refill_pending = false;
        let fill = || fill_ml(fill_percent, config.capacity_ml);
        let (outflow, volume_ml) = levels.drain(self.volume_ml, fill, refilled, config.drain);
        self.volume_ml = volume_ml;
        outflow
    }

    /// The levels of every sample of a span whose tilt (and perhaps pour time) changes from
    /// sample to sample, into `levels`: the very values [`Bottle::step`] would work out one by
    /// one, in loops that vectorise (a curve is interpolated over the whole span when every tilt
    /// of it falls in one segment). The last sample's levels become the bottle's.
    pub fn levels_of_span(
        &mut self,
        tilts: &[f64],
        pour_times: &[f64],
        config: &ModelConfig,
        levels: &mut SpanLevels,
    ) {
        let len = tilts.len();
        let (capacity_ml, curves) = (config.capacity_ml, &config.curves);
        let [rest, submerged, flow] = &mut self.segments;
        curves.rest.fill(tilts, &mut levels.rest_ml[..len], rest);
        (curves.submerged).fill(tilts, &mut levels.submerged_ml[..len], submerged);
        (curves.drain).fill(tilts, &mut levels.max_outflow_ml[..len], flow);
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
            self.levels = levels.at(last);
            self.levels_key = [tilts[last], pour_times[last], capacity_ml];
        }
    }

    /// [`Bottle::step`] again under the controls of the previous step: no refill can be pending
    /// and no level can have changed, so only the volume moves.
    #[inline]
    pub fn step_steady(&mut self, drain: DrainMode) -> Outflow {
        let (outflow, volume_ml) = self.levels.drain_on(self.volume_ml, drain);
        self.volume_ml = volume_ml;
        outflow
    }

    #[inline]
    fn levels(&mut self, controls: &ControlValues, config: &ModelConfig) -> Levels {
        let (capacity_ml, curves) = (config.capacity_ml, &config.curves);
        let key = [controls.tilt_deg, controls.pour_time_s, capacity_ml];
        if key != self.levels_key {
            let tilt = controls.tilt_deg;
            let [rest, submerged, flow] = &mut self.segments;
            let rate_ml_per_s = capacity_ml / controls.pour_time_s * curves.drain.at_in(tilt, flow);
            self.levels = Levels {
                rest_ml: curves.rest.at_in(tilt, rest) * capacity_ml,
                submerged_ml: curves.submerged.at_in(tilt, submerged) * capacity_ml,
                max_outflow_per_sample_ml: rate_ml_per_s / self.sample_rate,
            };
            self.levels_key = key;
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
    fn one_sample_of_drain_keeps_the_models_boundaries() {
        let levels = Levels {
            rest_ml: 100.0,
            submerged_ml: 150.0,
            max_outflow_per_sample_ml: 2.0,
        };
        let fill_ml = 250.0;
        let sample = |volume_ml, refilled, drain| {
            let (outflow, after) = levels.drain(volume_ml, || fill_ml, refilled, drain);
            (
                outflow.volume_before_ml,
                outflow.amount_ml,
                outflow.submerged,
                after,
            )
        };
        use DrainMode::{Follow, Simulate};
        // Nothing flows at the rest level; above it, what lies above it, at most k/fs.
        assert_eq!(sample(100.0, false, Simulate), (100.0, 0.0, false, 100.0));
        assert_eq!(sample(101.0, false, Simulate), (101.0, 1.0, false, 100.0));
        // At the submerged level the mouth is clear; only above it is it under the liquid.
        assert_eq!(sample(150.0, false, Simulate), (150.0, 2.0, false, 148.0));
        assert_eq!(sample(150.5, false, Simulate), (150.5, 2.0, true, 148.5));
        // A refill starts from the fill level; follow mode starts there at every sample and
        // does not lower V.
        assert_eq!(sample(120.0, true, Simulate), (250.0, 2.0, true, 248.0));
        assert_eq!(sample(120.0, false, Follow), (250.0, 2.0, true, 250.0));
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
