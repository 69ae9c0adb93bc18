//! A model file meets the parameters (MODEL.md §12.1): its constants and controls are set
//! through them, and a parameter that still shows the model's value plays it in full. The rest
//! of the model (V0, the amplitude spread, the curves) reaches the audio thread through
//! `loaded_model.rs`.

use nice_plug::params::InternalParamMut;
use nice_plug::prelude::*;

use crate::loaded_model::ModelLayer;
use crate::params::{exact, GlugParams};
use sake_glug_engine::{Constant, Control, ControlValues, ModelConfig, Quantity};
use sake_glug_model_file::ModelFile;

/// Whether a parameter at `value` shows the model's `model_value` (brought onto the knob), so
/// that the engine plays the model's value in full rather than its rounding on the knob.
pub fn shows(quantity: &Quantity, value: f32, model_value: f64) -> bool {
    exact(&quantity.knob, value) == on_knob(quantity, model_value)
}

/// The value a parameter is set to for the model's `value`: on the knob's range, at its decimals.
pub fn on_knob(quantity: &Quantity, value: f64) -> f64 {
    let (min, max) = quantity.knob_bounds();
    exact(&quantity.knob, value.clamp(min, max) as f32)
}

/// The parameters a model sets, each with the value it is set to: every constant the plugin has
/// a parameter for, the model's or its default (a model replaces the whole bottle), and each
/// control the model gives.
pub fn model_values<'a>(
    model: &ModelFile,
    params: &'a GlugParams,
) -> impl Iterator<Item = (&'a FloatParam, f32)> {
    let config = *model.config();
    let constants = Constant::parameters().map(move |constant| {
        let value = on_knob(constant.quantity(), constant.get(&config));
        (params.model.constant(constant), value as f32)
    });
    let controls = *model.controls();
    let controls = Control::ALL.iter().filter_map(move |&control| {
        controls[control].map(|value| {
            let value = on_knob(control.quantity(), value);
            (&params.controls[control], value as f32)
        })
    });
    constants.chain(controls)
}

/// The constants as the parameters and the model set them: a parameter that shows the model's
/// value plays the model's value in full; one moved away plays its own.
pub fn layered_config(params: &GlugParams, layer: &ModelLayer) -> ModelConfig {
    let own = params.model_config();
    let mut config = ModelConfig {
        seed: own.seed,
        drain: own.drain,
        ceiling: own.ceiling,
        ..layer.config
    };
    for (constant, param) in Constant::parameters().zip(&params.model.constants) {
        let model_value = constant.get(&layer.config);
        if !shows(constant.quantity(), param.value(), model_value) {
            constant.set(&mut config, constant.get(&own));
        }
    }
    config
}

/// The controls as the parameters and the model set them, by the rule of [`layered_config`].
pub fn layered_controls(params: &GlugParams, layer: &ModelLayer) -> ControlValues {
    let own = params.control_values();
    ControlValues::from_fn(|control| match layer.controls[control] {
        Some(value) if shows(control.quantity(), params.controls[control].value(), value) => value,
        _ => own[control],
    })
}

/// Loads `model` into parameters that nothing else holds yet (the standalone app's `--model`,
/// before the wrapper has the plugin): each value set as a loaded state sets it.
pub fn load_unshared(model: &ModelFile, params: &GlugParams) {
    for (param, value) in model_values(model, params) {
        // SAFETY: the parameters are not shared yet: no host, editor or audio thread reads them.
        unsafe { param._internal_set_plain_value(value) };
    }
    params.loaded_model.set(Some(model.clone()));
}
