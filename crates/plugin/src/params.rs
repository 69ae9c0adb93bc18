//! The plugin's parameters: stable IDs, ranges taken from the engine's `config` ranges, text that
//! round-trips, and the conversion to the engine's inputs.
//!
//! Every float parameter has a fixed number of decimals. Its value snaps to that step, its text
//! shows exactly those decimals, and the engine receives the decimal number the text shows (as an
//! f64, not the nearest f32). So typing `4.2` in a host and writing `4.2` in a scene file give
//! the engine the same number, and the same samples.

use std::collections::{BTreeMap, HashMap};
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::Arc;

use nice_plug::params::persist::{self, PersistentField};
use nice_plug::plugin::ParamValue;
use nice_plug::prelude::*;

use crate::actuator_setting::{saved_actuator, ActuatorSetting};
use crate::loaded_model::{saved_model, LoadedModel, MODEL_KEY, MODEL_NAME_KEY};
use crate::midi_learn::MidiLearn;
use crate::osc_input::OscSettings;
use sake_glug_device::midi::{MidiMap, MidiSetting};
use sake_glug_engine::config::{self, CEILING_DB};
use sake_glug_engine::{
    Constant, Control, ControlValues, DrainMode, Knob, ModelConfig, PerControl, Quantity,
};

/// The decimal number that `value` shows as on a knob with `decimals` decimals: what the engine
/// receives.
pub fn exact(knob: &Knob, value: f32) -> f64 {
    let scale = 10f64.powi(knob.decimals);
    let rounded = (value as f64 * scale).round() / scale;
    // -0.00 would not round-trip through text.
    if rounded == 0.0 {
        0.0
    } else {
        rounded
    }
}

/// The text for `value`: exactly the knob's decimals, without the unit.
pub fn format(knob: &Knob, value: f32) -> String {
    format!("{:.*}", knob.decimals as usize, exact(knob, value))
}

/// The nice-plug parameter of a quantity: its knob's range, step and skew, its name, unit and
/// default, text that round-trips.
pub fn float_param(quantity: &Quantity) -> FloatParam {
    let knob = quantity.knob;
    let (min, max) = quantity.knob_bounds();
    let (min, max) = (min as f32, max as f32);
    let range = match knob.skew {
        None => FloatRange::Linear { min, max },
        Some(factor) => FloatRange::Skewed {
            min,
            max,
            factor: FloatRange::skew_factor(factor),
        },
    };
    FloatParam::new(quantity.name, quantity.range.default as f32, range)
        .with_unit(quantity.unit)
        .with_step_size(knob.step() as f32)
        .with_value_to_string(Arc::new(move |value| format(&knob, value)))
        .with_string_to_value(Arc::new(parse_number))
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

/// The parameter group of the model's constants and settings.
const MODEL_GROUP: &str = "Model";

/// The Drain mode parameter: the engine's [`DrainMode`] as nice-plug's [`Enum`] (the trait and
/// the engine's type are both foreign here); its IDs are the names scenes use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DrainParam(pub DrainMode);

impl Enum for DrainParam {
    fn variants() -> &'static [&'static str] {
        &["Simulate", "Follow"]
    }

    fn ids() -> Option<&'static [&'static str]> {
        Some(&["simulate", "follow"])
    }

    fn to_index(self) -> usize {
        match self.0 {
            DrainMode::Simulate => 0,
            DrainMode::Follow => 1,
        }
    }

    fn from_index(index: usize) -> Self {
        Self(match index {
            1 => DrainMode::Follow,
            _ => DrainMode::Simulate,
        })
    }
}

/// Every parameter of the plugin, and its saved MIDI and OSC settings. The parameters come from
/// the engine's tables of controls and constants: their ids, names, units, ranges and knobs are
/// declared there once.
pub struct GlugParams {
    /// One parameter per control (the main group, "Pour" on a CLAP remote-control page).
    pub controls: PerControl<FloatParam>,
    /// The Model group: the constants of MODEL.md §5, §7 and §8.
    pub model: ModelParams,
    /// MIDI settings of the tilt device (saved with the state, not automatable), in the order
    /// of [`MidiSetting::all`].
    pub midi: Vec<AtomicU8>,
    /// MIDI learn: the row of the MIDI settings waiting for the device's next CC (not saved).
    pub learn: MidiLearn,
    /// The layout of the saved state ([`STATE_VERSION`]); older states are brought up to date
    /// by [`migrate_state`] before they load.
    pub state_version: AtomicU8,
    /// OSC settings (saved with the state, not automatable).
    pub osc: OscSettings,
    /// The model file loaded, if any (saved with the state as its text, MODEL.md §12.1).
    pub loaded_model: LoadedModel,
    /// The actuator compensated for, if any (saved with the state as a shipped profile's name
    /// or a profile's text, and the felt flag, MODEL.md §18).
    pub actuator: ActuatorSetting,
}

/// The saved state's layout. 0: before states carried a version (the parameters and MIDI
/// fields of 0.1.0). 1: the same with this version field, and the OSC settings (off unless set).
pub const STATE_VERSION: u8 = 1;
/// The persisted field that holds [`STATE_VERSION`].
const STATE_VERSION_KEY: &str = "state_version";

/// Brings a saved state up to [`STATE_VERSION`], one version at a time, before it loads; a
/// state from a newer version loads as it is (its unknown fields are ignored).
pub fn migrate_state(state: &mut PluginState) {
    let saved = state
        .fields
        .get(STATE_VERSION_KEY)
        .and_then(|text| text.parse::<u8>().ok())
        .unwrap_or(0);
    if saved > STATE_VERSION {
        return;
    }
    // 0 → 1: nothing was renamed or rescaled; the state gains its version, and the OSC settings
    // keep their defaults (off). A later change to an ID, range or unit adds its step here.
    state
        .fields
        .insert(STATE_VERSION_KEY.into(), STATE_VERSION.to_string());
}

/// Brings every value of a saved state to one the parameters can hold, before it loads, and logs
/// each change: nice-plug takes a saved value as it is, so an enum index out of range panicked on
/// the next save (inside a C callback: the host died), and a float beyond f32's range (JSON's
/// `1e39`) stayed infinite and saved as `null`, which no load accepts. A float is clamped to its
/// range, an integer too; a value that is not finite, an enum index or id the parameter does not
/// know, or a value of the wrong type loads as the default. The persisted fields load as the
/// plugin would save them again (a MIDI byte out of range as off, a field that does not parse as
/// its default). So a state the plugin saves is always one it loads.
///
/// A state whose model is no model, or whose actuator is no profile, is refused whole: its
/// parameters and fields are emptied, so that loading it changes nothing (nice-plug gives
/// `filter_state` no way to fail a load).
pub fn validate_state(state: &mut PluginState) {
    let refused = match (saved_model(&state.fields), saved_actuator(&state.fields)) {
        (Err(reason), _) => Some(format!("its model: {reason}")),
        (_, Err(reason)) => Some(format!("its actuator: {reason}")),
        _ => None,
    };
    if let Some(reason) = refused {
        nice_warn!("state refused, nothing of it loads: {reason}");
        state.params.clear();
        state.fields.clear();
        return;
    }
    // Fresh parameters: their ranges and defaults, and a scratch copy to read the fields into.
    let scratch = GlugParams::default();
    let params: HashMap<String, ParamPtr> = scratch
        .param_map()
        .into_iter()
        .map(|(id, param, _)| (id, param))
        .collect();
    for (id, value) in &mut state.params {
        // An unknown id is skipped by nice-plug's load, and never saved again.
        let Some(&param) = params.get(id) else {
            continue;
        };
        // SAFETY: `param` points into `scratch`, alive until the end of this function, and is
        // checked once (an id is a key of the map), so it still holds its default.
        if let Err((kept, reason)) = unsafe { checked(param, value) } {
            nice_warn!("state: parameter {id:?} = {value:?} {reason}: loads as {kept:?}");
            *value = kept;
        }
    }
    scratch.deserialize_fields(&state.fields);
    scratch.set_midi_map(scratch.midi_map());
    scratch.osc.set(scratch.osc.port(), scratch.osc.axis());
    for (key, kept) in scratch.serialize_fields() {
        if let Some(saved) = state.fields.get_mut(&key).filter(|saved| **saved != kept) {
            nice_warn!("state: field {key:?} = {saved:?} is out of range: loads as {kept:?}");
            *saved = kept;
        }
    }
}

/// `Ok` if `param` can hold `value` as it is; otherwise the value it loads instead, and why.
///
/// # Safety
///
/// `param` must point to a live parameter that holds its default value and that nothing else
/// uses: trying an enum id sets it.
unsafe fn checked(param: ParamPtr, value: &ParamValue) -> Result<(), (ParamValue, &'static str)> {
    let default = unsafe { default_value(param) };
    let out_of_range = "is out of range";
    match (param, value) {
        (ParamPtr::FloatParam(float), &ParamValue::F32(value)) => {
            let (min, max) = float_bounds(unsafe { &*float }.range());
            if !value.is_finite() {
                Err((default, "is not a finite number"))
            } else if value < min || value > max {
                Err((ParamValue::F32(value.clamp(min, max)), out_of_range))
            } else {
                Ok(())
            }
        }
        (ParamPtr::IntParam(int), &ParamValue::I32(value)) => {
            let (min, max) = int_bounds(unsafe { &*int }.range());
            if (min..=max).contains(&value) {
                Ok(())
            } else {
                Err((ParamValue::I32(value.clamp(min, max)), out_of_range))
            }
        }
        (ParamPtr::EnumParam(choice), &ParamValue::I32(index)) => {
            let known = usize::try_from(index).is_ok_and(|index| index < unsafe { &*choice }.len());
            if known {
                Ok(())
            } else {
                Err((default, "is not one of its choices"))
            }
        }
        // The only way to ask an enum whether it knows an id is to set it: `param` is scratch.
        (ParamPtr::EnumParam(choice), ParamValue::String(id)) => {
            if unsafe { &*choice }.set_from_id(id) {
                Ok(())
            } else {
                Err((default, "is not one of its choices"))
            }
        }
        (ParamPtr::BoolParam(_), ParamValue::Bool(_)) => Ok(()),
        _ => Err((default, "is of the wrong type")),
    }
}

/// What nice-plug saves for `param` at its default value.
///
/// # Safety
///
/// `param` must point to a live parameter that holds its default value.
unsafe fn default_value(param: ParamPtr) -> ParamValue {
    unsafe {
        match param {
            ParamPtr::FloatParam(float) => ParamValue::F32((*float).default_plain_value()),
            ParamPtr::IntParam(int) => ParamValue::I32((*int).default_plain_value()),
            ParamPtr::BoolParam(flag) => ParamValue::Bool((*flag).default_plain_value()),
            ParamPtr::EnumParam(choice) => match (*choice).unmodulated_plain_id() {
                Some(id) => ParamValue::String(id.to_owned()),
                None => ParamValue::I32((*choice).default_plain_value()),
            },
        }
    }
}

/// The lowest and highest value of a float range.
fn float_bounds(range: FloatRange) -> (f32, f32) {
    match range {
        FloatRange::Linear { min, max }
        | FloatRange::Skewed { min, max, .. }
        | FloatRange::SymmetricalSkewed { min, max, .. } => (min, max),
        FloatRange::Reversed(range) => float_bounds(*range),
    }
}

/// The lowest and highest value of an integer range.
fn int_bounds(range: IntRange) -> (i32, i32) {
    match range {
        IntRange::Linear { min, max } => (min, max),
        IntRange::Reversed(range) => int_bounds(*range),
    }
}

/// The Model group of parameters (MODEL.md §5, §7, §8).
pub struct ModelParams {
    /// One parameter per model constant the plugin has one for, in the order of
    /// [`Constant::parameters`] (the others are set by scenes only).
    pub constants: Vec<FloatParam>,
    /// Seed of the random generator, see [`config::SEED`].
    pub seed: IntParam,
    /// Drain mode: simulate or follow.
    pub drain: EnumParam<DrainParam>,
    /// Output ceiling (dB), see [`CEILING_DB`].
    pub ceiling: FloatParam,
}

impl ModelParams {
    /// The parameter of `constant`, which must be one the plugin has.
    pub fn constant(&self, constant: Constant) -> &FloatParam {
        let index = Constant::parameters()
            .position(|parameter| parameter == constant)
            .expect("only a constant with a parameter id has a parameter");
        &self.constants[index]
    }
}

impl Default for GlugParams {
    fn default() -> Self {
        let midi = MidiMap::default();
        Self {
            controls: PerControl::from_fn(|control| float_param(control.quantity())),
            model: ModelParams::default(),
            midi: MidiSetting::all()
                .map(|setting| AtomicU8::new(midi.raw(setting)))
                .collect(),
            learn: MidiLearn::default(),
            state_version: AtomicU8::new(STATE_VERSION),
            osc: OscSettings::default(),
            loaded_model: LoadedModel::default(),
            actuator: ActuatorSetting::default(),
        }
    }
}

impl Default for ModelParams {
    fn default() -> Self {
        Self {
            constants: Constant::parameters()
                .map(|constant| float_param(constant.quantity()))
                .collect(),
            seed: IntParam::new(
                config::SEED.name,
                config::SEED.range.default as i32,
                IntRange::Linear {
                    min: config::SEED.range.min as i32,
                    max: config::SEED.range.max as i32,
                },
            ),
            drain: EnumParam::new(config::DRAIN.name, DrainParam(DrainMode::Simulate)),
            ceiling: float_param(&CEILING_DB),
        }
    }
}

/// Written by hand rather than derived, so that the parameters and fields come from the engine's
/// tables; the ids, order, groups and field names are those the derive gave 0.1.0, so saved
/// states and projects load unchanged.
// SAFETY: every pointer in `param_map` points into `self`, whose parameters never move (the
// vectors are never resized).
unsafe impl Params for GlugParams {
    fn param_map(&self) -> Vec<(String, ParamPtr, String)> {
        let mut map: Vec<(String, ParamPtr, String)> = Control::ALL
            .iter()
            .map(|&control| {
                let id = control.quantity().param_id.to_owned();
                (id, self.controls[control].as_ptr(), String::new())
            })
            .collect();
        map.extend(self.model.param_map().into_iter().map(|(id, ptr, group)| {
            let group = if group.is_empty() {
                MODEL_GROUP.to_owned()
            } else {
                format!("{MODEL_GROUP}/{group}")
            };
            (id, ptr, group)
        }));
        map.extend(self.osc.param_map());
        map
    }

    fn serialize_fields(&self) -> BTreeMap<String, String> {
        let mut fields = BTreeMap::new();
        let persisted = MidiSetting::all()
            .map(|setting| setting.key())
            .zip(&self.midi)
            .chain([(STATE_VERSION_KEY, &self.state_version)]);
        for (key, field) in persisted {
            match field.map(persist::serialize_field) {
                Ok(data) => {
                    fields.insert(key.to_owned(), data);
                }
                Err(error) => nice_debug_assert_failure!("cannot save '{}': {}", key, error),
            }
        }
        fields.extend(self.osc.serialize_fields());
        fields.extend(self.actuator.serialize_fields());
        if let Some((name, text)) = self.loaded_model.saved() {
            for (key, value) in [(MODEL_NAME_KEY, name), (MODEL_KEY, text)] {
                match persist::serialize_field(&value) {
                    Ok(data) => {
                        fields.insert(key.to_owned(), data);
                    }
                    Err(error) => nice_debug_assert_failure!("cannot save '{}': {}", key, error),
                }
            }
        }
        fields
    }

    fn deserialize_fields(&self, serialized: &BTreeMap<String, String>) {
        // Only a refused state has no fields (every other has its version): it changes nothing.
        if serialized.is_empty() {
            return;
        }
        match saved_model(serialized) {
            Ok(model) => self.loaded_model.set(model),
            Err(reason) => nice_warn!("the saved model is kept out: {reason}"),
        }
        match saved_actuator(serialized) {
            Ok(actuator) => self.actuator.set(actuator),
            Err(reason) => nice_warn!("the saved actuator is kept out: {reason}"),
        }
        let persisted = MidiSetting::all()
            .map(|setting| setting.key())
            .zip(&self.midi)
            .chain([(STATE_VERSION_KEY, &self.state_version)]);
        for (key, field) in persisted {
            let Some(data) = serialized.get(key) else {
                continue;
            };
            match persist::deserialize_field(data) {
                Ok(value) => field.set(value),
                Err(error) => nice_debug_assert_failure!("cannot load '{}': {}", key, error),
            }
        }
        self.osc.deserialize_fields(serialized);
    }
}

// SAFETY: every pointer in `param_map` points into `self`, whose parameters never move.
unsafe impl Params for ModelParams {
    fn param_map(&self) -> Vec<(String, ParamPtr, String)> {
        let mut map: Vec<(String, ParamPtr, String)> = Constant::parameters()
            .zip(&self.constants)
            .map(|(constant, param)| {
                let id = constant.quantity().param_id.to_owned();
                (id, param.as_ptr(), String::new())
            })
            .collect();
        map.push((
            config::SEED.param_id.to_owned(),
            self.seed.as_ptr(),
            String::new(),
        ));
        map.push((
            config::DRAIN.param_id.to_owned(),
            self.drain.as_ptr(),
            String::new(),
        ));
        map.push((
            CEILING_DB.param_id.to_owned(),
            self.ceiling.as_ptr(),
            String::new(),
        ));
        map
    }
}

impl GlugParams {
    /// Every control as the parameters set it (before any MIDI or OSC override), as the
    /// decimal number its text shows.
    pub fn control_values(&self) -> ControlValues {
        ControlValues::from_fn(|control| {
            exact(&control.quantity().knob, self.controls[control].value())
        })
    }

    /// The model's constants as the parameters set them, the ceiling converted to linear.
    pub fn model_config(&self) -> ModelConfig {
        let model = &self.model;
        let mut config = ModelConfig {
            seed: model.seed.value().max(0) as u64,
            drain: model.drain.value().0,
            ceiling: 10f64.powf(exact(&CEILING_DB.knob, model.ceiling.value()) / 20.0),
            ..ModelConfig::default()
        };
        for (constant, param) in Constant::parameters().zip(&model.constants) {
            let value = exact(&constant.quantity().knob, param.value());
            constant.set(&mut config, value);
        }
        config
    }

    /// The saved MIDI settings, with anything out of range switched off.
    pub fn midi_map(&self) -> MidiMap {
        MidiMap::from_raw(self.midi.iter().map(|byte| byte.load(Ordering::Relaxed)))
    }

    /// Saves `map` as the MIDI settings.
    pub fn set_midi_map(&self, map: MidiMap) {
        for (setting, byte) in MidiSetting::all().zip(&self.midi) {
            byte.store(map.raw(setting), Ordering::Relaxed);
        }
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
        let knob = |control: Control| control.quantity().knob;
        assert_eq!(exact(&knob(Control::PourTime), 4.2f32), 4.2f64);
        assert_eq!(exact(&knob(Control::Viscosity), 0.33f32), 0.33f64);
        assert_eq!(format(&knob(Control::Gain), -0.001), "0.00");
    }

    #[test]
    fn defaults_match_the_engine() {
        let params = GlugParams::default();
        assert_eq!(params.control_values(), ControlValues::default());
        assert_eq!(params.model_config(), ModelConfig::default());
    }
}
