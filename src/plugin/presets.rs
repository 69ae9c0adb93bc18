//! The presets as the plugin's parameters: which parameter each value of a [`Preset`] sets (the
//! one mapping, used by the editor's menu and by the preset files), and the state nice-plug
//! saves for a plugin that holds a preset, as a VST3 host's preset file carries it.

use nice_plug::params::internals::ParamPtr;
use nice_plug::plugin::ParamValue;
use nice_plug::prelude::*;

use crate::engine::{Preset, PresetValue};
use crate::plugin::params::GlugParams;
use crate::plugin::SakeGlugVst3;

/// The parameters a preset sets, each with the preset's value for it. Every other parameter
/// (tilt, fill level, gain, spreads, seed, drain, ceiling) is left as it is.
pub fn preset_values<'a>(
    preset: &Preset,
    params: &'a GlugParams,
) -> impl Iterator<Item = (&'a FloatParam, f64)> {
    preset.values.iter().map(move |value| match *value {
        PresetValue::Control(control, value) => (&params.controls[control], value),
        PresetValue::Constant(constant, value) => (params.model.constant(constant), value),
    })
}

/// The state nice-plug saves (`IComponent::getState`, the CLAP state's JSON) for a fresh plugin
/// whose editor menu then picked `preset`: the preset's parameters as the host sets them, every
/// other parameter and persisted field at its default.
pub fn preset_state(preset: &Preset) -> PluginState {
    let params = GlugParams::default();
    for (param, value) in preset_values(preset, &params) {
        // What a host does with the editor's `set_parameter(param, value)`: the normalised
        // value, turned back into the plain value on the parameter's step grid.
        // SAFETY: `param` is a field of `params`, alive for this whole function.
        unsafe {
            param
                .as_ptr()
                ._internal_set_normalized_value(param.preview_normalized(value as f32))
        };
    }
    saved_state(&params)
}

/// What nice-plug's wrappers save for `params` (its `serialize_object`, which is private to the
/// wrapper): every parameter's unmodulated plain value by its ID (an enum by its stable ID), the
/// persisted fields, and the plugin's version. `tests/plugin/vstpreset.rs` checks that the
/// real wrapper, given this state, saves it back byte for byte.
pub fn saved_state(params: &GlugParams) -> PluginState {
    let values = params
        .param_map()
        .into_iter()
        .map(|(id, pointer, _group)| {
            // SAFETY: param_map's pointers point into `params`, borrowed for this whole call.
            let value = unsafe {
                match pointer {
                    ParamPtr::FloatParam(param) => {
                        ParamValue::F32((*param).unmodulated_plain_value())
                    }
                    ParamPtr::IntParam(param) => {
                        ParamValue::I32((*param).unmodulated_plain_value())
                    }
                    ParamPtr::BoolParam(param) => {
                        ParamValue::Bool((*param).unmodulated_plain_value())
                    }
                    ParamPtr::EnumParam(param) => match (*param).unmodulated_plain_id() {
                        Some(id) => ParamValue::String(id.to_owned()),
                        None => ParamValue::I32((*param).unmodulated_plain_value()),
                    },
                }
            };
            (id, value)
        })
        .collect();
    PluginState {
        version: <SakeGlugVst3 as Plugin>::VERSION.to_owned(),
        params: values,
        fields: params.serialize_fields(),
    }
}

/// The bytes nice-plug writes for `state`: its JSON, uncompressed (the plugin is built without
/// nice-plug's `zstd` feature, and the wrapper reads uncompressed JSON either way).
pub fn state_bytes(state: &PluginState) -> Vec<u8> {
    serde_json::to_vec(state).expect("a PluginState always serialises")
}
