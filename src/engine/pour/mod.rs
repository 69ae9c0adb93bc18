//! The pour: bottle, onsets and random draws together turn controls into a stream of unit onsets
//! (MODEL.md §3, §4, §7, §8). Every synthesis path, fast or reference, is driven by this.

mod bottle;
mod curves;
mod onsets;
mod randomness;

pub use bottle::Outflow;
pub use curves::{TiltCurve, FLOW, REST, SUBMERGED};
pub use onsets::MAX_ONSETS_PER_SAMPLE;
pub use randomness::UnitShape;

use crate::engine::amplitude::unit_amplitude;
use crate::engine::config::{ControlValues, ModelConfig};
use bottle::Bottle;
use onsets::OnsetDetector;
use randomness::UnitDraws;

/// One wave unit as it starts (the inputs of §5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitOnset {
    /// n: the sample during which the unit starts.
    pub sample: u64,
    /// x: the onset is at (n + x) / fs.
    pub fraction: f64,
    /// V_i.
    pub volume_ml: f64,
    /// a(V_i), before the output gain.
    pub amplitude: f64,
    /// c_i, clamped to [0, 1].
    pub viscosity: f64,
    /// f1_i, f2_i, B1_i, B2_i as drawn for this unit (§7).
    pub shape: UnitShape,
}

impl UnitOnset {
    /// A1 = c·a, A2 = (1 − c)·a (paper eq. 2).
    pub fn component_amplitudes(&self) -> [f64; 2] {
        [
            self.viscosity * self.amplitude,
            (1.0 - self.viscosity) * self.amplitude,
        ]
    }
}

/// Counts kept for reports and tests.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PourStats {
    /// Units whose onset came since the last reset, the skipped ones included.
    pub units_started: u64,
    /// Units not voiced because more started within one sample than the engine voices.
    pub units_skipped: u64,
}

/// The pour: bottle, onset accumulator and random draws, turning the controls, sample by
/// sample, into unit onsets.
pub struct Pour {
    config: ModelConfig,
    bottle: Bottle,
    onsets: OnsetDetector,
    draws: UnitDraws,
    stats: PourStats,
}

impl Pour {
    /// A pour at `sample_rate` (Hz) under `config` (brought into range); the bottle fills to the
    /// fill level at the first step.
    pub fn new(sample_rate: f64, config: ModelConfig) -> Self {
        let config = config.sanitized();
        Self {
            config,
            bottle: Bottle::new(sample_rate),
            onsets: OnsetDetector::default(),
            draws: UnitDraws::new(config.seed),
            stats: PourStats::default(),
        }
    }

    /// The constants in use, brought into range.
    pub fn config(&self) -> &ModelConfig {
        &self.config
    }

    /// New constants take effect from the next sample; a new seed at the next reset.
    pub fn set_config(&mut self, config: ModelConfig) {
        self.config = config.sanitized();
    }

    /// MODEL.md §8 reset: refill, re-seed, clear the counts.
    pub fn reset(&mut self) {
        self.bottle.refill();
        self.onsets.clear();
        self.draws.reseed(self.config.seed);
        self.stats = PourStats::default();
    }

    /// MODEL.md §8 refill: the generator goes on.
    pub fn refill(&mut self) {
        self.bottle.refill();
    }

    /// Residual volume V after the last step (ml).
    pub fn volume_ml(&self) -> f64 {
        self.bottle.volume_ml()
    }

    /// The counts since the last reset.
    pub fn stats(&self) -> PourStats {
        self.stats
    }

    /// Advances one sample and calls `emit` for each unit starting in it.
    #[inline]
    pub fn step(
        &mut self,
        sample: u64,
        controls: ControlValues,
        emit: impl FnMut(&UnitOnset),
    ) -> Outflow {
        self.step_sanitized(sample, &controls.sanitized(), emit)
    }

    /// [`Pour::step`] for controls already brought into range, so that a caller stepping many
    /// samples under the same controls sanitises them once.
    #[inline]
    pub fn step_sanitized(
        &mut self,
        sample: u64,
        controls: &ControlValues,
        emit: impl FnMut(&UnitOnset),
    ) -> Outflow {
        let outflow = self.bottle.step(controls, &self.config);
        if outflow.refilled {
            self.onsets.clear();
        }
        self.count_onsets(sample, controls.viscosity, outflow, emit)
    }

    /// [`Pour::step_sanitized`] under the same controls as the previous step and with no refill
    /// asked for since: the bottle skips its checks for changes.
    #[inline]
    pub fn step_steady(
        &mut self,
        sample: u64,
        viscosity: f64,
        emit: impl FnMut(&UnitOnset),
    ) -> Outflow {
        let outflow = self.bottle.step_steady(self.config.drain);
        self.count_onsets(sample, viscosity, outflow, emit)
    }

    #[inline]
    fn count_onsets(
        &mut self,
        sample: u64,
        viscosity: f64,
        outflow: Outflow,
        mut emit: impl FnMut(&UnitOnset),
    ) -> Outflow {
        let capacity_ml = self.config.capacity_ml;
        let mut started = 0;
        let skipped = self.onsets.feed(
            &outflow,
            &self.config,
            &mut self.draws,
            |crossing, shape: UnitShape| {
                started += 1;
                emit(&UnitOnset {
                    sample,
                    fraction: crossing.fraction,
                    volume_ml: crossing.volume_ml,
                    amplitude: unit_amplitude(crossing.volume_ml, capacity_ml),
                    viscosity,
                    shape,
                });
            },
        );
        self.stats.units_started += started + skipped;
        self.stats.units_skipped += skipped;
        outflow
    }
}
