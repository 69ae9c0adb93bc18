//! The plugin's parameters: stable IDs, ranges taken from the engine's `config` ranges, text that
//! round-trips, and the conversion to the engine's inputs.
//!
//! Every float parameter has a fixed number of decimals. Its value snaps to that step, its text
//! shows exactly those decimals, and the engine receives the decimal number the text shows (as an
//! f64, not the nearest f32). So typing `4.2` in a host and writing `4.2` in a scene file give
//! the engine the same number, and the same samples.

use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::Arc;

use nice_plug::prelude::*;

use crate::device::midi::MidiMap;
use crate::engine::config::{self, Range};
use crate::engine::{ControlValues, DrainMode, ModelConfig};
use crate::plugin::osc_input::OscSettings;

/// How one float parameter is ranged, shown and handed to the engine.
#[derive(Debug, Clone, Copy)]
pub struct Knob {
    /// Parameter name shown by the host.
    pub name: &'static str,
    /// Unit text shown after the value (with its leading space, if any).
    pub unit: &'static str,
    /// Lowest value on the knob.
    pub min: f64,
    /// Highest value on the knob.
    pub max: f64,
    /// Default value.
    pub default: f64,
    /// Decimals shown; the value snaps to steps of 10^−decimals.
    pub decimals: i32,
    /// `None` for a linear knob, else nice-plug's skew exponent (negative: finer at the bottom).
    pub skew: Option<f32>,
}

impl Knob {
    /// A knob over the engine's whole range.
    const fn from_range(
        name: &'static str,
        unit: &'static str,
        range: Range,
        decimals: i32,
    ) -> Self {
        Self {
            name,
            unit,
            min: range.min,
            max: range.max,
            default: range.default,
            decimals,
            skew: None,
        }
    }

    /// A knob narrower than the engine's range, where the full range is absurd on a knob.
    const fn within(self, min: f64, max: f64) -> Self {
        Self { min, max, ..self }
    }

    const fn skewed(self, factor: f32) -> Self {
        Self {
            skew: Some(factor),
            ..self
        }
    }

    fn scale(&self) -> f64 {
        10f64.powi(self.decimals)
    }

    /// The decimal number that `value` shows as: what the engine receives.
    pub fn exact(&self, value: f32) -> f64 {
        let rounded = (value as f64 * self.scale()).round() / self.scale();
        // -0.00 would not round-trip through text.
        if rounded == 0.0 {
            0.0
        } else {
            rounded
        }
    }

    /// The text for `value`: exactly `decimals` decimals, without the unit.
    pub fn format(&self, value: f32) -> String {
        format!("{:.*}", self.decimals as usize, self.exact(value))
    }

    fn range(&self) -> FloatRange {
        let (min, max) = (self.min as f32, self.max as f32);
        match self.skew {
            None => FloatRange::Linear { min, max },
            Some(factor) => FloatRange::Skewed {
                min,
                max,
                factor: FloatRange::skew_factor(factor),
            },
        }
    }

    /// The nice-plug parameter for this knob.
    pub fn param(&self) -> FloatParam {
        let knob = *self;
        FloatParam::new(self.name, self.default as f32, self.range())
            .with_unit(self.unit)
            .with_step_size((1.0 / self.scale()) as f32)
            .with_value_to_string(Arc::new(move |value| knob.format(value)))
            .with_string_to_value(Arc::new(parse_number))
    }
}

/// Reads what a person types into a parameter: a number, with an exponent (`1e3`) or a decimal
/// comma (`5,5`) if they like, then optionally a unit (`135 °`, `-6.5 dB`). Anything else is
/// refused (`None`) rather than cut short: `1-2` or `1,000.5` is not read as 1.
pub fn parse_number(text: &str) -> Option<f32> {
    let text = text.trim();
    let end = text
        .char_indices()
        .find(|&(_, c)| !(c.is_ascii_digit() || matches!(c, '.' | ',' | '-' | '+' | 'e' | 'E')))
        .map_or(text.len(), |(index, _)| index);
    let (number, unit) = text.split_at(end);
    // A unit is letters and symbols after the number, never more digits or signs.
    if unit
        .chars()
        .any(|c| c.is_ascii_digit() || matches!(c, '.' | ',' | '-' | '+'))
    {
        return None;
    }
    // One comma and no point is a decimal comma; a comma beside a point is ambiguous.
    let number = match (number.matches(',').count(), number.contains('.')) {
        (0, _) => number.to_string(),
        (1, false) => number.replace(',', "."),
        _ => return None,
    };
    let value: f32 = number.parse().ok()?;
    value.is_finite().then_some(value)
}

// The main group. Tilt, viscosity and fill use the engine's full ranges.
/// Tilt θ (degrees), 0–180.
pub const TILT: Knob = Knob::from_range("Tilt", "°", config::TILT_DEG, 2);
/// Viscosity ratio c, 0–1.
pub const VISCOSITY: Knob = Knob::from_range("Viscosity", "", config::VISCOSITY, 3);
/// Fill level φ (percent of capacity), 0–100.
pub const FILL: Knob = Knob::from_range("Fill level", " %", config::FILL_PERCENT, 1);
/// Narrower than the engine's 0.01–3600 s: below 0.1 s or above 2 minutes is no pour.
pub const POUR_TIME: Knob = Knob::from_range("Pour time", " s", config::POUR_TIME_S, 2)
    .within(0.1, 120.0)
    .skewed(-1.5);
/// Narrower than the engine's −120…+24 dB, which would make the knob coarse.
pub const GAIN: Knob =
    Knob::from_range("Output gain", " dB", config::GAIN_DB, 2).within(-60.0, 12.0);

// The model group (MODEL.md §5, §7). Frequencies, decays, volumes: narrower than the engine's
// ranges (which only guard against nonsense) but wide enough to reach past Nyquist at 44.1 kHz.
/// Frequency f1 of the first component (Hz).
pub const F1: Knob = Knob::from_range("f1", " Hz", config::F1_HZ, 1)
    .within(10.0, 24_000.0)
    .skewed(-2.0);
/// Frequency f2 of the second component (Hz).
pub const F2: Knob = Knob::from_range("f2", " Hz", config::F2_HZ, 1)
    .within(10.0, 24_000.0)
    .skewed(-2.0);
/// Amplitude decay rate B1 of the first component (1/s).
pub const B1: Knob = Knob::from_range("B1", " /s", config::B1_PER_S, 1)
    .within(1.0, 1_000.0)
    .skewed(-1.5);
/// Amplitude decay rate B2 of the second component (1/s).
pub const B2: Knob = Knob::from_range("B2", " /s", config::B2_PER_S, 1)
    .within(1.0, 1_000.0)
    .skewed(-1.5);
/// Mean air-pocket volume b per glug (ml).
pub const POCKET: Knob = Knob::from_range("Pocket volume", " ml", config::POCKET_ML, 2)
    .within(0.1, 100.0)
    .skewed(-1.5);
/// Bottle capacity C (ml).
pub const CAPACITY: Knob = Knob::from_range("Capacity", " ml", config::CAPACITY_ML, 0)
    .within(10.0, 5_000.0)
    .skewed(-1.5);
/// Relative spread j_t of each unit's pocket volume, 0–0.95.
pub const TIMING_JITTER: Knob = Knob::from_range("Timing spread", "", config::TIMING_JITTER, 3);
/// Relative spread j_f of each unit's f1, f2, 0–1.
pub const FREQ_JITTER: Knob = Knob::from_range("Frequency spread", "", config::FREQ_JITTER, 3);
/// Log-normal spread σ of each unit's B1, B2, 0–3.
pub const DECAY_SIGMA: Knob = Knob::from_range("Decay spread", "", config::DECAY_SIGMA, 3);
/// The output ceiling in dB (0 dB = the engine's default ±1.0); −60 dB is the engine's 0.001.
pub const CEILING_DB: Knob = Knob {
    name: "Output ceiling",
    unit: " dB",
    min: -60.0,
    max: 0.0,
    default: 0.0,
    decimals: 1,
    skew: None,
};
/// Largest value of the Seed parameter.
pub const SEED_MAX: i32 = 999_999;

/// The Drain mode parameter is the engine's own [`DrainMode`]; its IDs are the names scenes use.
impl Enum for DrainMode {
    fn variants() -> &'static [&'static str] {
        &["Simulate", "Follow"]
    }

    fn ids() -> Option<&'static [&'static str]> {
        Some(&["simulate", "follow"])
    }

    fn to_index(self) -> usize {
        match self {
            DrainMode::Simulate => 0,
            DrainMode::Follow => 1,
        }
    }

    fn from_index(index: usize) -> Self {
        match index {
            1 => DrainMode::Follow,
            _ => DrainMode::Simulate,
        }
    }
}

/// Every parameter of the plugin, and its saved MIDI settings.
#[derive(Params)]
pub struct GlugParams {
    /// Tilt θ (degrees), see [`TILT`].
    #[id = "tilt"]
    pub tilt: FloatParam,
    /// Viscosity ratio c, see [`VISCOSITY`].
    #[id = "visc"]
    pub viscosity: FloatParam,
    /// Fill level φ (percent of capacity), see [`FILL`].
    #[id = "fill"]
    pub fill: FloatParam,
    /// Pour time T (s), see [`POUR_TIME`].
    #[id = "pour"]
    pub pour_time: FloatParam,
    /// Output gain (dB), see [`GAIN`].
    #[id = "gain"]
    pub gain: FloatParam,

    /// The Model group: the constants of MODEL.md §5, §7 and §8.
    #[nested(group = "Model")]
    pub model: ModelParams,

    /// MIDI settings of the tilt device (saved with the state, not automatable).
    #[persist = "midi_channel"]
    pub midi_channel: AtomicU8,
    /// CC number of tilt (its MSB when tilt is 14-bit); 128 or more means unmapped.
    #[persist = "midi_cc_tilt"]
    pub midi_cc_tilt: AtomicU8,
    /// CC number of tilt's LSB; 128 or more means 7-bit tilt.
    #[persist = "midi_cc_tilt_lsb"]
    pub midi_cc_tilt_lsb: AtomicU8,
    /// CC number of viscosity; 128 or more means unmapped.
    #[persist = "midi_cc_viscosity"]
    pub midi_cc_viscosity: AtomicU8,
    /// CC number of the fill level; 128 or more means unmapped.
    #[persist = "midi_cc_fill"]
    pub midi_cc_fill: AtomicU8,
    /// The layout of the saved state ([`STATE_VERSION`]); older states are brought up to date
    /// by [`migrate_state`] before they load.
    #[persist = "state_version"]
    pub state_version: AtomicU8,

    /// OSC settings (saved with the state, not automatable).
    #[nested]
    pub osc: OscSettings,
}

/// The saved state's layout. 0: before states carried a version (the parameters and MIDI
/// fields of 0.1.0). 1: the same with this version field, and the OSC settings (off unless set).
pub const STATE_VERSION: u8 = 1;

/// Brings a saved state up to [`STATE_VERSION`], one version at a time, before it loads; a
/// state from a newer version loads as it is (its unknown fields are ignored).
pub fn migrate_state(state: &mut PluginState) {
    let saved = state
        .fields
        .get("state_version")
        .and_then(|text| text.parse::<u8>().ok())
        .unwrap_or(0);
    if saved > STATE_VERSION {
        return;
    }
    // 0 → 1: nothing was renamed or rescaled; the state gains its version, and the OSC settings
    // keep their defaults (off). A later change to an ID, range or unit adds its step here.
    state
        .fields
        .insert("state_version".into(), STATE_VERSION.to_string());
}

/// The Model group of parameters (MODEL.md §5, §7, §8).
#[derive(Params)]
pub struct ModelParams {
    /// Frequency f1 (Hz), see [`F1`].
    #[id = "f1"]
    pub f1: FloatParam,
    /// Frequency f2 (Hz), see [`F2`].
    #[id = "f2"]
    pub f2: FloatParam,
    /// Decay rate B1 (1/s), see [`B1`].
    #[id = "b1"]
    pub b1: FloatParam,
    /// Decay rate B2 (1/s), see [`B2`].
    #[id = "b2"]
    pub b2: FloatParam,
    /// Pocket volume b (ml), see [`POCKET`].
    #[id = "pocket"]
    pub pocket: FloatParam,
    /// Capacity C (ml), see [`CAPACITY`].
    #[id = "cap"]
    pub capacity: FloatParam,
    /// Timing spread j_t, see [`TIMING_JITTER`].
    #[id = "tjit"]
    pub timing_jitter: FloatParam,
    /// Frequency spread j_f, see [`FREQ_JITTER`].
    #[id = "fjit"]
    pub freq_jitter: FloatParam,
    /// Decay spread σ, see [`DECAY_SIGMA`].
    #[id = "dsig"]
    pub decay_sigma: FloatParam,
    /// Seed of the random generator, 0 to [`SEED_MAX`].
    #[id = "seed"]
    pub seed: IntParam,
    /// Drain mode: simulate or follow.
    #[id = "drain"]
    pub drain: EnumParam<DrainMode>,
    /// Output ceiling (dB), see [`CEILING_DB`].
    #[id = "ceil"]
    pub ceiling: FloatParam,
}

impl Default for GlugParams {
    fn default() -> Self {
        let midi = MidiMap::default().to_raw();
        Self {
            tilt: TILT.param(),
            viscosity: VISCOSITY.param(),
            fill: FILL.param(),
            pour_time: POUR_TIME.param(),
            gain: GAIN.param(),
            model: ModelParams::default(),
            midi_channel: AtomicU8::new(midi[0]),
            midi_cc_tilt: AtomicU8::new(midi[1]),
            midi_cc_tilt_lsb: AtomicU8::new(midi[2]),
            midi_cc_viscosity: AtomicU8::new(midi[3]),
            midi_cc_fill: AtomicU8::new(midi[4]),
            state_version: AtomicU8::new(STATE_VERSION),
            osc: OscSettings::default(),
        }
    }
}

impl Default for ModelParams {
    fn default() -> Self {
        Self {
            f1: F1.param(),
            f2: F2.param(),
            b1: B1.param(),
            b2: B2.param(),
            pocket: POCKET.param(),
            capacity: CAPACITY.param(),
            timing_jitter: TIMING_JITTER.param(),
            freq_jitter: FREQ_JITTER.param(),
            decay_sigma: DECAY_SIGMA.param(),
            seed: IntParam::new(
                "Seed",
                ModelConfig::default().seed as i32,
                IntRange::Linear {
                    min: 0,
                    max: SEED_MAX,
                },
            ),
            drain: EnumParam::new("Drain mode", DrainMode::Simulate),
            ceiling: CEILING_DB.param(),
        }
    }
}

impl GlugParams {
    /// The per-sample inputs as the parameters set them (before any MIDI override).
    pub fn control_values(&self) -> ControlValues {
        ControlValues {
            tilt_deg: TILT.exact(self.tilt.value()),
            viscosity: VISCOSITY.exact(self.viscosity.value()),
            fill_percent: FILL.exact(self.fill.value()),
            pour_time_s: POUR_TIME.exact(self.pour_time.value()),
        }
    }

    /// The output gain as the engine receives it (dB).
    pub fn gain_db(&self) -> f64 {
        GAIN.exact(self.gain.value())
    }

    /// The model's constants as the parameters set them, the ceiling converted to linear.
    pub fn model_config(&self) -> ModelConfig {
        let model = &self.model;
        ModelConfig {
            capacity_ml: CAPACITY.exact(model.capacity.value()),
            pocket_ml: POCKET.exact(model.pocket.value()),
            frequency_hz: [F1.exact(model.f1.value()), F2.exact(model.f2.value())],
            decay_per_s: [B1.exact(model.b1.value()), B2.exact(model.b2.value())],
            timing_jitter: TIMING_JITTER.exact(model.timing_jitter.value()),
            freq_jitter: FREQ_JITTER.exact(model.freq_jitter.value()),
            decay_sigma: DECAY_SIGMA.exact(model.decay_sigma.value()),
            seed: model.seed.value().max(0) as u64,
            drain: model.drain.value(),
            ceiling: 10f64.powf(CEILING_DB.exact(model.ceiling.value()) / 20.0),
        }
    }

    /// The saved MIDI settings, with anything out of range switched off.
    pub fn midi_map(&self) -> MidiMap {
        MidiMap::from_raw([
            self.midi_channel.load(Ordering::Relaxed),
            self.midi_cc_tilt.load(Ordering::Relaxed),
            self.midi_cc_tilt_lsb.load(Ordering::Relaxed),
            self.midi_cc_viscosity.load(Ordering::Relaxed),
            self.midi_cc_fill.load(Ordering::Relaxed),
        ])
    }

    /// Saves `map` as the MIDI settings.
    pub fn set_midi_map(&self, map: MidiMap) {
        let raw = map.to_raw();
        self.midi_channel.store(raw[0], Ordering::Relaxed);
        self.midi_cc_tilt.store(raw[1], Ordering::Relaxed);
        self.midi_cc_tilt_lsb.store(raw[2], Ordering::Relaxed);
        self.midi_cc_viscosity.store(raw[3], Ordering::Relaxed);
        self.midi_cc_fill.store(raw[4], Ordering::Relaxed);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_number_ignores_units_and_rejects_garbage() {
        assert_eq!(parse_number("135.00°"), Some(135.0));
        assert_eq!(parse_number(" -6.50 dB"), Some(-6.5));
        assert_eq!(parse_number("+3"), Some(3.0));
        assert_eq!(parse_number("dB"), None);
        assert_eq!(parse_number(""), None);
        assert_eq!(parse_number("1-2"), None, "never cut short");
        assert_eq!(parse_number("1e3"), Some(1000.0));
        assert_eq!(parse_number("2.5E-1 s"), Some(0.25));
        assert_eq!(parse_number("5,5"), Some(5.5));
        assert_eq!(parse_number("5,5 %"), Some(5.5));
        assert_eq!(
            parse_number("1,000.5"),
            None,
            "a comma beside a point is ambiguous"
        );
        assert_eq!(parse_number("1.2.3"), None);
        assert_eq!(parse_number("12 dB 3"), None);
        assert_eq!(parse_number("e5"), None);
        assert_eq!(parse_number("1e999"), None, "not finite");
    }

    #[test]
    fn exact_gives_the_decimal_the_text_shows() {
        assert_eq!(POUR_TIME.exact(4.2f32), 4.2f64);
        assert_eq!(VISCOSITY.exact(0.33f32), 0.33f64);
        assert_eq!(GAIN.format(-0.001), "0.00");
    }

    #[test]
    fn defaults_match_the_engine() {
        let params = GlugParams::default();
        assert_eq!(params.control_values(), ControlValues::default());
        assert_eq!(params.gain_db(), config::GAIN_DB.default);
        assert_eq!(params.model_config(), ModelConfig::default());
    }
}
