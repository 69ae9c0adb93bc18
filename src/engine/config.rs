//! The model's constants and the allowed range of every input, shared by the engine's sanitising,
//! the scene validator and the plugin's parameters so that all three agree.

/// An input's allowed closed range and its default (MODEL.md).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// Lowest allowed value.
    pub min: f64,
    /// Highest allowed value.
    pub max: f64,
    /// Value of a left-out input, and what NaN becomes.
    pub default: f64,
}

impl Range {
    const fn new(min: f64, max: f64, default: f64) -> Self {
        Self { min, max, default }
    }

    /// Whether `value` lies in the closed range `[min, max]` (false for NaN).
    pub fn contains(&self, value: f64) -> bool {
        value >= self.min && value <= self.max
    }

    /// Brings any f64 into range: NaN becomes the default, ±∞ and outliers the nearest bound.
    #[inline]
    pub fn sanitize(&self, value: f64) -> f64 {
        if value.is_nan() {
            self.default
        } else {
            value.clamp(self.min, self.max)
        }
    }
}

/// Sample rate fs of a render (Hz).
pub const SAMPLE_RATE_HZ: Range = Range::new(1_000.0, 768_000.0, 48_000.0);
/// Tilt θ of the bottle (degrees): 0 upright, 90 horizontal, 180 upside down.
pub const TILT_DEG: Range = Range::new(0.0, 180.0, 0.0);
/// Viscosity ratio c (dimensionless, 0…1): the share of the f1 component; water 0.33.
pub const VISCOSITY: Range = Range::new(0.0, 1.0, 0.33);
/// Fill level φ (percent of capacity C) that the bottle is (re)filled to.
pub const FILL_PERCENT: Range = Range::new(0.0, 100.0, 100.0);
/// Pour time T (s): how long a full bottle takes to empty at the reference tilt 135°.
pub const POUR_TIME_S: Range = Range::new(0.01, 3600.0, 5.0);
/// Output gain (dB): G = 10^(gain/20).
pub const GAIN_DB: Range = Range::new(-120.0, 24.0, -6.0);
/// Bottle capacity C (ml).
pub const CAPACITY_ML: Range = Range::new(1.0, 100_000.0, 300.0);
/// Mean volume b of the air pocket one glug lets in (ml).
pub const POCKET_ML: Range = Range::new(0.001, 1_000.0, 5.0);
/// Frequency f1 of the first component, the air pocket bouncing in the neck (Hz).
pub const F1_HZ: Range = Range::new(0.0, 400_000.0, 80.0);
/// Frequency f2 of the second component, the free pocket's Minnaert ring (Hz).
pub const F2_HZ: Range = Range::new(0.0, 400_000.0, 300.0);
/// Amplitude decay rate B1 of the first component (1/s).
pub const B1_PER_S: Range = Range::new(0.0, 1e9, 45.0);
/// Amplitude decay rate B2 of the second component (1/s).
pub const B2_PER_S: Range = Range::new(0.0, 1e9, 40.0);
/// Below 1 so that a pocket volume b·(1 + j·u) is always positive.
pub const TIMING_JITTER: Range = Range::new(0.0, 0.95, 0.15);
/// Relative spread j_f of each unit's f1, f2 (dimensionless): f·(1 + j_f·u), u in [−1, 1].
pub const FREQ_JITTER: Range = Range::new(0.0, 1.0, 0.05);
/// Log-normal spread σ of each unit's B1, B2 (dimensionless): B·exp(σ·z), z standard normal.
pub const DECAY_SIGMA: Range = Range::new(0.0, 3.0, 0.35);
/// Hard output ceiling (linear amplitude): every output sample stays within ±ceiling.
pub const CEILING: Range = Range::new(0.001, 1.0, 1.0);
/// How long the output gain and the ceiling take to reach a new value (s), MODEL.md §6: long
/// enough that a jump does not click (the 80 Hz component turns by a quarter of its period in it),
/// short enough to follow a fader.
pub const OUTPUT_RAMP_S: f64 = 0.010;

/// How the residual volume evolves (MODEL.md §8). Scenes name it in lower case (`"simulate"`,
/// `"follow"`); the plugin's Drain mode parameter is this same type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DrainMode {
    /// V drains by the outflow of §3.
    #[default]
    Simulate,
    /// V is the fill level at every sample; the outflow only drives the onsets.
    Follow,
}

/// The constants of the model that do not change sample by sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelConfig {
    /// Bottle capacity C (ml).
    pub capacity_ml: f64,
    /// Mean air-pocket volume b per glug (ml).
    pub pocket_ml: f64,
    /// f1, f2 of §5.
    pub frequency_hz: [f64; 2],
    /// B1, B2 of §5 (amplitude decay rates).
    pub decay_per_s: [f64; 2],
    /// Relative spread j_t of each unit's pocket volume (§7).
    pub timing_jitter: f64,
    /// Relative spread j_f of each unit's f1, f2 (§7).
    pub freq_jitter: f64,
    /// Log-normal spread σ of each unit's B1, B2 (§7).
    pub decay_sigma: f64,
    /// Seed of the random generator of §7, applied again at every reset.
    pub seed: u64,
    /// How the residual volume evolves: simulate or follow (§8).
    pub drain: DrainMode,
    /// The hard output ceiling of §6 (linear).
    pub ceiling: f64,
}

impl Default for ModelConfig {
    fn default() -> Self {
        Self {
            capacity_ml: CAPACITY_ML.default,
            pocket_ml: POCKET_ML.default,
            frequency_hz: [F1_HZ.default, F2_HZ.default],
            decay_per_s: [B1_PER_S.default, B2_PER_S.default],
            timing_jitter: TIMING_JITTER.default,
            freq_jitter: FREQ_JITTER.default,
            decay_sigma: DECAY_SIGMA.default,
            seed: 1,
            drain: DrainMode::Simulate,
            ceiling: CEILING.default,
        }
    }
}

impl ModelConfig {
    /// The same constants with every random spread at zero (MODEL.md §7, "deterministic").
    pub fn deterministic(self) -> Self {
        Self {
            timing_jitter: 0.0,
            freq_jitter: 0.0,
            decay_sigma: 0.0,
            ..self
        }
    }

    /// Every field brought into its range, so that no input can make the engine misbehave.
    pub fn sanitized(self) -> Self {
        Self {
            capacity_ml: CAPACITY_ML.sanitize(self.capacity_ml),
            pocket_ml: POCKET_ML.sanitize(self.pocket_ml),
            frequency_hz: [
                F1_HZ.sanitize(self.frequency_hz[0]),
                F2_HZ.sanitize(self.frequency_hz[1]),
            ],
            decay_per_s: [
                B1_PER_S.sanitize(self.decay_per_s[0]),
                B2_PER_S.sanitize(self.decay_per_s[1]),
            ],
            timing_jitter: TIMING_JITTER.sanitize(self.timing_jitter),
            freq_jitter: FREQ_JITTER.sanitize(self.freq_jitter),
            decay_sigma: DECAY_SIGMA.sanitize(self.decay_sigma),
            ceiling: CEILING.sanitize(self.ceiling),
            ..self
        }
    }
}

/// The per-sample inputs of the model (MODEL.md §1), as one sample sees them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlValues {
    /// Tilt θ (degrees).
    pub tilt_deg: f64,
    /// Viscosity ratio c (0…1).
    pub viscosity: f64,
    /// Fill level φ (percent of capacity).
    pub fill_percent: f64,
    /// Pour time T of a full bottle at 135° (s).
    pub pour_time_s: f64,
}

impl Default for ControlValues {
    fn default() -> Self {
        Self {
            tilt_deg: TILT_DEG.default,
            viscosity: VISCOSITY.default,
            fill_percent: FILL_PERCENT.default,
            pour_time_s: POUR_TIME_S.default,
        }
    }
}

impl ControlValues {
    /// Every value brought into its range (see [`Range::sanitize`]).
    #[inline]
    pub fn sanitized(self) -> Self {
        Self {
            tilt_deg: TILT_DEG.sanitize(self.tilt_deg),
            viscosity: VISCOSITY.sanitize(self.viscosity),
            fill_percent: FILL_PERCENT.sanitize(self.fill_percent),
            pour_time_s: POUR_TIME_S.sanitize(self.pour_time_s),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sanitize_maps_nan_to_default_and_infinities_to_bounds() {
        assert_eq!(TILT_DEG.sanitize(f64::NAN), 0.0);
        assert_eq!(TILT_DEG.sanitize(f64::INFINITY), 180.0);
        assert_eq!(POUR_TIME_S.sanitize(f64::NEG_INFINITY), 0.01);
        assert_eq!(VISCOSITY.sanitize(-3.0), 0.0);
        assert_eq!(VISCOSITY.sanitize(0.5), 0.5);
    }

    #[test]
    fn deterministic_zeroes_every_spread_only() {
        let config = ModelConfig::default().deterministic();
        assert_eq!(
            (config.timing_jitter, config.freq_jitter, config.decay_sigma),
            (0.0, 0.0, 0.0)
        );
        assert_eq!(config.pocket_ml, 5.0);
    }
}
