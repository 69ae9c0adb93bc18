//! The model's constants, each declared once in [`declare_constants!`]'s table below with its scene
//! key, parameter id, range, default and knob, the bottle's curves ([`Curve`]) by their scene
//! keys, and the ranges of the settings that are no plain number (sample rate, seed, ceiling).
//! The engine's sanitising, the scene validator, the plugin's parameters and the presets all read
//! them here, so that all agree.

use super::amplitude::{SilentBelow, PAPERS_SILENT_BELOW_ML};
use super::controls::Control;
use super::curves::{BottleCurves, CurveError, TiltCurve, REFERENCE_TILT_DEG};
use super::glide::Glide;
use super::headspace::Headspace;
use super::quantity::{Knob, Quantity, Range, ValueError};

/// Sample rate fs of a render (Hz).
pub const SAMPLE_RATE_HZ: Range = Range::new(1_000.0, 768_000.0, 48_000.0);
/// Hard output ceiling (linear amplitude): every output sample stays within ±ceiling.
pub const CEILING: Range = Range::new(0.001, 1.0, 1.0);
/// The seed of the random generator of §7 (the plugin's Seed parameter spans it). A scene may
/// give any u64 (`seed`); it takes effect at the next reset.
pub const SEED: Quantity = Quantity {
    name: "Seed",
    unit: "",
    scene_key: "seed",
    param_id: "seed",
    note: "of the random draws of MODEL.md §7; takes effect at the next reset",
    range: Range::new(0.0, 999_999.0, 1.0),
    knob: Knob::full(0),
};
/// The drain mode (§8), a choice rather than a number: its range is its variants' indices.
pub const DRAIN: Quantity = Quantity {
    name: "Drain mode",
    unit: "",
    scene_key: "output.drain",
    param_id: "drain",
    note: "Simulate or Follow (the fill level is the residual volume), MODEL.md §8",
    range: Range::new(0.0, 1.0, 0.0),
    knob: Knob::full(0),
};
/// The output ceiling in dB as the plugin shows the linear [`CEILING`] (0 dB = ±1.0; −60 dB is
/// 0.001). Scenes have no ceiling key.
pub const CEILING_DB: Quantity = Quantity {
    name: "Output ceiling",
    unit: " dB",
    scene_key: "",
    param_id: "ceil",
    note: "hard output limit (0 dB = ±1.0), ramped over 10 ms (MODEL.md §6)",
    range: Range::new(-60.0, 0.0, 0.0),
    knob: Knob::full(1),
};
/// How long the output gain and the ceiling take to reach a new value (s), MODEL.md §6: long
/// enough that a jump does not click (the 80 Hz component turns by a quarter of its period in it),
/// short enough to follow a fader.
pub const OUTPUT_RAMP_S: f64 = 0.010;

/// One model constant: what it is, and where it lives in a [`ModelConfig`].
#[derive(Debug, Clone, Copy)]
pub struct ConstantSpec {
    /// Name, scene key, parameter id, range, default and knob.
    pub quantity: Quantity,
    /// Its value in a configuration.
    pub get: fn(&ModelConfig) -> f64,
    /// Sets it in a configuration.
    pub set: fn(&mut ModelConfig, f64),
}

macro_rules! declare_constants {
    ($( $(#[$doc:meta])* $variant:ident => $spec:expr; )*) => {
        /// A constant of the model that a scene, a preset or the plugin sets (MODEL.md §2–§7, §12).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum Constant {
            $( $(#[$doc])* $variant, )*
        }

        impl Constant {
            /// Every constant, in table order (the order of the plugin's Model group, for those
            /// it has a parameter for).
            pub const ALL: &'static [Constant] = &[$( Constant::$variant ),*];

            /// Everything declared about this constant.
            pub const fn spec(self) -> &'static ConstantSpec {
                static SPECS: &[ConstantSpec] = &[$( $spec ),*];
                &SPECS[self as usize]
            }
        }
    };
}

/// Bottle capacity C (ml): its range bounds V0's too.
const CAPACITY_ML: Range = Range::new(1.0, 100_000.0, 300.0);
/// γ of the headspace law (MODEL.md §5.1): wide enough for a mode that rises (negative) and for
/// more than a Helmholtz cavity's ½, narrow enough that every frequency it gives stays finite.
const HEADSPACE_EXPONENT: Range = Range::new(-3.0, 3.0, 0.0);
/// ρ of the glide (MODEL.md §5.2): two octaves either way; 1 is no glide.
const GLIDE_RATIO: Range = Range::new(0.25, 4.0, 1.0);
/// τ of the glide (MODEL.md §5.2, ms): from a sweep within a few cycles to one through a whole
/// glug.
const GLIDE_MS: Range = Range::new(0.5, 500.0, 20.0);

declare_constants! {
    /// Frequency f1 of the first component, the air pocket bouncing in the neck (Hz).
    F1 => ConstantSpec {
        quantity: Quantity {
            name: "f1",
            unit: " Hz",
            scene_key: "glug.f1_hz",
            param_id: "f1",
            note: "the pocket bouncing in the neck; omitted below 20 Hz or at or above Nyquist",
            range: Range::new(0.0, 400_000.0, 80.0),
            // Narrower than the engine's range (which only guards against nonsense) but wide
            // enough to reach past Nyquist at 44.1 kHz.
            knob: Knob::full(1).within(10.0, 24_000.0).skewed(-2.0),
        },
        get: |config| config.frequency_hz[0],
        set: |config, value| config.frequency_hz[0] = value,
    };
    /// Frequency f2 of the second component, the free pocket's Minnaert ring (Hz).
    F2 => ConstantSpec {
        quantity: Quantity {
            name: "f2",
            unit: " Hz",
            scene_key: "glug.f2_hz",
            param_id: "f2",
            note: "the free pocket's ring; omitted below 20 Hz or at or above Nyquist",
            range: Range::new(0.0, 400_000.0, 300.0),
            knob: Knob::full(1).within(10.0, 24_000.0).skewed(-2.0),
        },
        get: |config| config.frequency_hz[1],
        set: |config, value| config.frequency_hz[1] = value,
    };
    /// Amplitude decay rate B1 of the first component (1/s).
    B1 => ConstantSpec {
        quantity: Quantity {
            name: "B1",
            unit: " /s",
            scene_key: "glug.b1_per_s",
            param_id: "b1",
            note: "amplitude decay rate of the f1 component",
            range: Range::new(0.0, 1e9, 45.0),
            knob: Knob::full(1).within(1.0, 1_000.0).skewed(-1.5),
        },
        get: |config| config.decay_per_s[0],
        set: |config, value| config.decay_per_s[0] = value,
    };
    /// Amplitude decay rate B2 of the second component (1/s).
    B2 => ConstantSpec {
        quantity: Quantity {
            name: "B2",
            unit: " /s",
            scene_key: "glug.b2_per_s",
            param_id: "b2",
            note: "amplitude decay rate of the f2 component",
            range: Range::new(0.0, 1e9, 40.0),
            knob: Knob::full(1).within(1.0, 1_000.0).skewed(-1.5),
        },
        get: |config| config.decay_per_s[1],
        set: |config, value| config.decay_per_s[1] = value,
    };
    /// Mean volume b of the air pocket one glug lets in (ml).
    Pocket => ConstantSpec {
        quantity: Quantity {
            name: "Pocket volume",
            unit: " ml",
            scene_key: "bottle.pocket_ml",
            param_id: "pocket",
            note: "air let in per glug",
            range: Range::new(0.001, 1_000.0, 5.0),
            knob: Knob::full(2).within(0.1, 100.0).skewed(-1.5),
        },
        get: |config| config.pocket_ml,
        set: |config, value| config.pocket_ml = value,
    };
    /// Bottle capacity C (ml).
    Capacity => ConstantSpec {
        quantity: Quantity {
            name: "Capacity",
            unit: " ml",
            scene_key: "bottle.capacity_ml",
            param_id: "cap",
            note: "bottle capacity C",
            range: CAPACITY_ML,
            knob: Knob::full(0).within(10.0, 5_000.0).skewed(-1.5),
        },
        get: |config| config.capacity_ml,
        set: |config, value| config.capacity_ml = value,
    };
    /// Relative spread j_t of each unit's pocket volume: below 1 so that a pocket volume
    /// b·(1 + j·u) is always positive.
    TimingJitter => ConstantSpec {
        quantity: Quantity {
            name: "Timing spread",
            unit: "",
            scene_key: "glug.timing_jitter",
            param_id: "tjit",
            note: "j_t of MODEL.md §7: spread of each pocket",
            range: Range::new(0.0, 0.95, 0.15),
            knob: Knob::full(3),
        },
        get: |config| config.timing_jitter,
        set: |config, value| config.timing_jitter = value,
    };
    /// Relative spread j_f of each unit's f1, f2 (dimensionless): f·(1 + j_f·u), u in [−1, 1].
    FreqJitter => ConstantSpec {
        quantity: Quantity {
            name: "Frequency spread",
            unit: "",
            scene_key: "glug.freq_jitter",
            param_id: "fjit",
            note: "j_f of MODEL.md §7: spread of each unit's f1, f2",
            range: Range::new(0.0, 1.0, 0.05),
            knob: Knob::full(3),
        },
        get: |config| config.freq_jitter,
        set: |config, value| config.freq_jitter = value,
    };
    /// Log-normal spread σ of each unit's B1, B2 (dimensionless): B·exp(σ·z), z standard normal.
    DecaySigma => ConstantSpec {
        quantity: Quantity {
            name: "Decay spread",
            unit: "",
            scene_key: "glug.decay_sigma",
            param_id: "dsig",
            note: "σ of MODEL.md §7: log-normal spread of each unit's B1, B2",
            range: Range::new(0.0, 3.0, 0.35),
            knob: Knob::full(3),
        },
        get: |config| config.decay_sigma,
        set: |config, value| config.decay_sigma = value,
    };
    /// H (ml): the air above a full bottle's liquid, in its neck and shoulder; the headspace
    /// law of MODEL.md §5.1 measures the air above the liquid from it.
    Headspace => ConstantSpec {
        quantity: Quantity {
            name: "Headspace",
            unit: " ml",
            scene_key: "bottle.headspace_ml",
            param_id: "headsp",
            note: "H of MODEL.md §5.1: the air above a full bottle's liquid",
            range: Range::new(0.001, CAPACITY_ML.max, 30.0),
            knob: Knob::full(1).within(1.0, 2_000.0).skewed(-1.5),
        },
        get: |config| config.headspace.headspace_ml,
        set: |config, value| config.headspace.headspace_ml = value,
    };
    /// γ1: how f1 follows the air above the liquid (MODEL.md §5.1); 0 keeps it constant.
    F1Exponent => ConstantSpec {
        quantity: Quantity {
            name: "f1 headspace exponent",
            unit: "",
            scene_key: "glug.f1_headspace_exponent",
            param_id: "f1exp",
            note: "γ1 of MODEL.md §5.1: f1·((H + b)/(H + C − V))^γ1; ½ a Helmholtz cavity, 0 constant",
            range: HEADSPACE_EXPONENT,
            knob: Knob::full(3),
        },
        get: |config| config.headspace.exponent[0],
        set: |config, value| config.headspace.exponent[0] = value,
    };
    /// γ2: how f2 follows the air above the liquid (MODEL.md §5.1); 0 keeps it constant.
    F2Exponent => ConstantSpec {
        quantity: Quantity {
            name: "f2 headspace exponent",
            unit: "",
            scene_key: "glug.f2_headspace_exponent",
            param_id: "f2exp",
            note: "γ2 of MODEL.md §5.1: f2·((H + b)/(H + C − V))^γ2; ½ a Helmholtz cavity, 0 constant",
            range: HEADSPACE_EXPONENT,
            knob: Knob::full(3),
        },
        get: |config| config.headspace.exponent[1],
        set: |config, value| config.headspace.exponent[1] = value,
    };
    /// ρ1: the ratio f1 glides from into its own (MODEL.md §5.2); 1 is no glide.
    F1GlideRatio => ConstantSpec {
        quantity: Quantity {
            name: "f1 glide ratio",
            unit: "",
            scene_key: "glug.f1_glide_ratio",
            param_id: "f1glide",
            note: "ρ1 of MODEL.md §5.2: f1 starts at ρ1·f1 and approaches f1; 1 no glide, \
                   above 1 down, below 1 up",
            range: GLIDE_RATIO,
            knob: Knob::full(3).skewed(-1.0),
        },
        get: |config| config.glide.ratio[0],
        set: |config, value| config.glide.ratio[0] = value,
    };
    /// ρ2: the ratio f2 glides from into its own (MODEL.md §5.2); 1 is no glide.
    F2GlideRatio => ConstantSpec {
        quantity: Quantity {
            name: "f2 glide ratio",
            unit: "",
            scene_key: "glug.f2_glide_ratio",
            param_id: "f2glide",
            note: "ρ2 of MODEL.md §5.2: f2 starts at ρ2·f2 and approaches f2; 1 no glide, \
                   above 1 down, below 1 up",
            range: GLIDE_RATIO,
            knob: Knob::full(3).skewed(-1.0),
        },
        get: |config| config.glide.ratio[1],
        set: |config, value| config.glide.ratio[1] = value,
    };
    /// τ1: the time constant of f1's glide (ms, MODEL.md §5.2).
    F1GlideTime => ConstantSpec {
        quantity: Quantity {
            name: "f1 glide time",
            unit: " ms",
            scene_key: "glug.f1_glide_ms",
            param_id: "f1glms",
            note: "τ1 of MODEL.md §5.2: f1's glide is e^(−τ/τ1) from its end",
            range: GLIDE_MS,
            knob: Knob::full(2).skewed(-1.5),
        },
        get: |config| config.glide.time_ms[0],
        set: |config, value| config.glide.time_ms[0] = value,
    };
    /// τ2: the time constant of f2's glide (ms, MODEL.md §5.2).
    F2GlideTime => ConstantSpec {
        quantity: Quantity {
            name: "f2 glide time",
            unit: " ms",
            scene_key: "glug.f2_glide_ms",
            param_id: "f2glms",
            note: "τ2 of MODEL.md §5.2: f2's glide is e^(−τ/τ2) from its end",
            range: GLIDE_MS,
            knob: Knob::full(2).skewed(-1.5),
        },
        get: |config| config.glide.time_ms[1],
        set: |config, value| config.glide.time_ms[1] = value,
    };
    /// V0 (ml): the residual volume from which down a unit is silent (MODEL.md §12). Its
    /// default is the paper's, scaled with the capacity ([`SilentBelow::PapersFit`]; the range's
    /// default is its value at the default capacity), and it stays below C: both depend on the
    /// capacity, which is why it comes after it in this table.
    SilentBelow => ConstantSpec {
        quantity: Quantity {
            name: "Silent below",
            unit: " ml",
            scene_key: "amplitude.silent_below_ml",
            param_id: "",
            note: "V0 of MODEL.md §12, below C: a(V) reaches 0 there; by default the paper's, \
                   scaled with C",
            range: Range::new(0.0, CAPACITY_ML.max, PAPERS_SILENT_BELOW_ML),
            knob: Knob::full(2),
        },
        get: |config| config.silent_below.ml(config.capacity_ml),
        set: |config, value| config.silent_below = SilentBelow::Ml(value),
    };
    /// Log-normal spread σ_A of each unit's summed amplitude (dimensionless, MODEL.md §12):
    /// Asum·exp(σ_A·z), z standard normal.
    AmplitudeSpread => ConstantSpec {
        quantity: Quantity {
            name: "Amplitude spread",
            unit: "",
            scene_key: "amplitude.spread",
            param_id: "",
            note: "σ_A of MODEL.md §12: log-normal spread of each unit's Asum",
            range: Range::new(0.0, 3.0, 0.0),
            knob: Knob::full(3),
        },
        get: |config| config.amplitude_spread,
        set: |config, value| config.amplitude_spread = value,
    };
}

impl Constant {
    /// The constant's name, scene key, parameter id, range and knob.
    pub const fn quantity(self) -> &'static Quantity {
        &self.spec().quantity
    }

    /// The constant's allowed range and default.
    pub const fn range(self) -> Range {
        self.spec().quantity.range
    }

    /// Its value in `config`.
    pub fn get(self, config: &ModelConfig) -> f64 {
        (self.spec().get)(config)
    }

    /// Sets it to `value` in `config`.
    pub fn set(self, config: &mut ModelConfig, value: f64) {
        (self.spec().set)(config, value)
    }

    /// Whether the plugin has a parameter for it; the others are set by scenes only.
    pub fn is_parameter(self) -> bool {
        !self.quantity().param_id.is_empty()
    }

    /// The constants the plugin has a parameter for, in table order.
    pub fn parameters() -> impl Iterator<Item = Constant> {
        Self::ALL
            .iter()
            .copied()
            .filter(|constant| constant.is_parameter())
    }

    /// Sets its default in `config`: its range's, but V0's follows the capacity.
    fn set_default(self, config: &mut ModelConfig) {
        match self {
            Constant::SilentBelow => config.silent_below = SilentBelow::PapersFit,
            _ => self.set(config, self.range().default),
        }
    }

    /// Brings its value in `config` into range (MODEL.md §11); V0's range ends below the
    /// capacity, which must be in range already.
    fn sanitize(self, config: &mut ModelConfig) {
        match self {
            Constant::SilentBelow => {
                config.silent_below = config.silent_below.sanitized(config.capacity_ml)
            }
            _ => self.set(config, self.range().sanitize(self.get(config))),
        }
    }
}

/// One of the bottle's curves of tilt (MODEL.md §2, §3), which a scene may give as points (§12).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Curve {
    /// r(θ) of §2.
    Rest,
    /// s(θ) of §2.
    Submerged,
    /// h(θ) of §3.
    Drain,
}

impl Curve {
    /// Every curve, in the order a scene's `[curves]` table lists them.
    pub const ALL: [Curve; 3] = [Curve::Rest, Curve::Submerged, Curve::Drain];

    /// Its key in a scene file.
    pub const fn scene_key(self) -> &'static str {
        match self {
            Curve::Rest => "curves.rest",
            Curve::Submerged => "curves.submerged",
            Curve::Drain => "curves.drain",
        }
    }

    /// The curve through `points` (tilt in degrees, value), checked as MODEL.md §12 asks; h
    /// must be 1 at 135°, where a full bottle empties in the pour time.
    pub fn from_points(self, points: &[(f64, f64)]) -> Result<TiltCurve, CurveError> {
        let tilts = Control::Tilt.range();
        let curve = TiltCurve::new(points, tilts.min..=tilts.max)?;
        match self {
            Curve::Drain => curve.through(REFERENCE_TILT_DEG, 1.0),
            Curve::Rest | Curve::Submerged => Ok(curve),
        }
    }

    /// This curve of `curves`.
    pub fn of(self, curves: &BottleCurves) -> &TiltCurve {
        match self {
            Curve::Rest => &curves.rest,
            Curve::Submerged => &curves.submerged,
            Curve::Drain => &curves.drain,
        }
    }

    /// This curve of `curves`, to replace.
    pub fn of_mut(self, curves: &mut BottleCurves) -> &mut TiltCurve {
        match self {
            Curve::Rest => &mut curves.rest,
            Curve::Submerged => &mut curves.submerged,
            Curve::Drain => &mut curves.drain,
        }
    }
}

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
    /// V0 of the amplitude law (§12).
    pub silent_below: SilentBelow,
    /// Log-normal spread σ_A of each unit's summed amplitude (§12).
    pub amplitude_spread: f64,
    /// H and γ1, γ2 of the headspace law (§5.1).
    pub headspace: Headspace,
    /// ρ1, ρ2 and τ1, τ2 of the glide (§5.2).
    pub glide: Glide,
    /// r(θ), s(θ) and h(θ) (§2, §3, §12): inline, so that the constants stay `Copy`.
    pub curves: BottleCurves,
    /// Seed of the random generator of §7, applied again at every reset.
    pub seed: u64,
    /// How the residual volume evolves: simulate or follow (§8).
    pub drain: DrainMode,
    /// The hard output ceiling of §6 (linear).
    pub ceiling: f64,
}

impl Default for ModelConfig {
    fn default() -> Self {
        let mut config = Self {
            capacity_ml: 0.0,
            pocket_ml: 0.0,
            frequency_hz: [0.0; 2],
            decay_per_s: [0.0; 2],
            timing_jitter: 0.0,
            freq_jitter: 0.0,
            decay_sigma: 0.0,
            silent_below: SilentBelow::PapersFit,
            amplitude_spread: 0.0,
            headspace: Headspace {
                headspace_ml: 0.0,
                exponent: [0.0; 2],
            },
            glide: Glide {
                ratio: [0.0; 2],
                time_ms: [0.0; 2],
            },
            curves: BottleCurves::default(),
            seed: SEED.range.default as u64,
            drain: DrainMode::Simulate,
            ceiling: CEILING.default,
        };
        for &constant in Constant::ALL {
            constant.set_default(&mut config);
        }
        config
    }
}

impl ModelConfig {
    /// The amplitude law's zero below the capacity, as a scene or a model file must give it
    /// (MODEL.md §12).
    pub fn check_silent_below(&self) -> Result<(), ValueError> {
        if self.silent_below.fits(self.capacity_ml) {
            Ok(())
        } else {
            Err(ValueError::NotBelow {
                key: Constant::SilentBelow.quantity().scene_key,
                value: Constant::SilentBelow.get(self),
                limit_key: Constant::Capacity.quantity().scene_key,
                limit: self.capacity_ml,
            })
        }
    }

    /// The same constants with every random spread at zero (MODEL.md §7, "deterministic").
    pub fn deterministic(self) -> Self {
        Self {
            timing_jitter: 0.0,
            freq_jitter: 0.0,
            decay_sigma: 0.0,
            amplitude_spread: 0.0,
            ..self
        }
    }

    /// Every field brought into its range, so that no input can make the engine misbehave (the
    /// curves are in range as made: [`TiltCurve`] checks them).
    pub fn sanitized(mut self) -> Self {
        for &constant in Constant::ALL {
            constant.sanitize(&mut self);
        }
        self.ceiling = CEILING.sanitize(self.ceiling);
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sanitize_maps_nan_to_default_and_infinities_to_bounds() {
        let tilt = Range::new(0.0, 180.0, 0.0);
        assert_eq!(tilt.sanitize(f64::NAN), 0.0);
        assert_eq!(tilt.sanitize(f64::INFINITY), 180.0);
        assert_eq!(tilt.sanitize(f64::NEG_INFINITY), 0.0);
        assert_eq!(tilt.sanitize(-3.0), 0.0);
        assert_eq!(tilt.sanitize(90.5), 90.5);
    }

    #[test]
    fn deterministic_zeroes_every_spread_only() {
        let spread = ModelConfig {
            amplitude_spread: 0.4,
            ..ModelConfig::default()
        };
        let config = spread.deterministic();
        assert_eq!(
            (
                config.timing_jitter,
                config.freq_jitter,
                config.decay_sigma,
                config.amplitude_spread
            ),
            (0.0, 0.0, 0.0, 0.0)
        );
        assert_eq!(config.pocket_ml, 5.0);
    }

    #[test]
    fn v0_defaults_to_the_papers_and_follows_the_capacity() {
        let config = ModelConfig::default();
        assert_eq!(config.silent_below, SilentBelow::PapersFit);
        assert_eq!(
            Constant::SilentBelow.get(&config),
            Constant::SilentBelow.range().default
        );
        let mut large = config;
        Constant::Capacity.set(&mut large, 600.0);
        assert_eq!(
            Constant::SilentBelow.get(&large),
            2.0 * PAPERS_SILENT_BELOW_ML
        );
        // Brought into range against the capacity, itself brought in first.
        Constant::SilentBelow.set(&mut large, 1e9);
        Constant::Capacity.set(&mut large, 1e9);
        let sanitized = large.sanitized();
        assert_eq!(sanitized.capacity_ml, CAPACITY_ML.max);
        assert!(sanitized.silent_below.fits(CAPACITY_ML.max));
        assert_eq!(config.sanitized(), config);
    }

    #[test]
    fn the_scene_only_constants_have_no_parameter() {
        let scene_only: Vec<_> = Constant::ALL
            .iter()
            .filter(|constant| !constant.is_parameter())
            .collect();
        assert_eq!(
            scene_only,
            [&Constant::SilentBelow, &Constant::AmplitudeSpread]
        );
        assert_eq!(Constant::parameters().count(), Constant::ALL.len() - 2);
    }

    #[test]
    fn only_h_is_held_to_1_at_135_degrees() {
        let points = [(90.0, 0.5), (180.0, 0.9)];
        assert!(Curve::Rest.from_points(&points).is_ok());
        assert!(Curve::Submerged.from_points(&points).is_ok());
        assert!(matches!(
            Curve::Drain.from_points(&points),
            Err(CurveError::Anchor { .. })
        ));
        let default = BottleCurves::default();
        for curve in Curve::ALL {
            let points = curve.of(&default).points();
            assert_eq!(curve.from_points(points).as_ref(), Ok(curve.of(&default)));
        }
    }
}
