//! A model file in the plugin (MODEL.md §12.1): loaded by the editor, the standalone app's
//! `--model` or a saved state; kept in the state as its text; its constants and controls set
//! through the parameters, the rest (V0, the amplitude spread, the curves) handed to the audio
//! thread through a lock-free queue, so `process()` neither allocates, locks nor waits.

use std::sync::Mutex;

use crossbeam_queue::ArrayQueue;
use nice_plug::params::InternalParamMut;
use nice_plug::prelude::*;

use crate::engine::{Constant, Control, ControlValues, ModelConfig, PerControl, Quantity};
use crate::model::Model;
use crate::plugin::params::{exact, GlugParams};

/// The persisted fields that hold the loaded model's text and name (absent without one, so a
/// state without a model is byte for byte what it was before models).
pub const MODEL_KEY: &str = "model";
/// See [`MODEL_KEY`].
pub const MODEL_NAME_KEY: &str = "model_name";

/// Loads and clears queued for the audio thread before it takes them: more than the editor can
/// make between two blocks; the oldest is dropped if not (only the newest counts).
const PENDING: usize = 4;

/// What the audio thread needs of a model: its constants and curves, and its controls' values.
/// Plain data (`Copy`), so handing it over allocates nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelLayer {
    /// The default constants with the model's.
    pub config: ModelConfig,
    /// The model's value of each control it gives.
    pub controls: PerControl<Option<f64>>,
}

impl ModelLayer {
    /// The layer of `model`.
    pub fn of(model: &Model) -> Self {
        Self {
            config: *model.config(),
            controls: *model.controls(),
        }
    }
}

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

/// The plugin's model: the loaded one, for the editor and the state, and its loads and clears on
/// their way to the audio thread.
pub struct LoadedModel {
    /// Read and written off the audio thread only.
    current: Mutex<Option<Model>>,
    changes: ArrayQueue<Option<ModelLayer>>,
}

impl Default for LoadedModel {
    fn default() -> Self {
        Self {
            current: Mutex::new(None),
            changes: ArrayQueue::new(PENDING),
        }
    }
}

impl LoadedModel {
    /// Loads `model` (`None`: clears it). Not on the audio thread: it locks.
    pub fn set(&self, model: Option<Model>) {
        self.changes.force_push(model.as_ref().map(ModelLayer::of));
        *self.lock() = model;
    }

    /// The loaded model's name.
    pub fn name(&self) -> Option<String> {
        self.lock().as_ref().map(|model| model.name().to_owned())
    }

    /// The loaded model's name and text, as the state keeps them.
    pub fn saved(&self) -> Option<(String, String)> {
        self.lock()
            .as_ref()
            .map(|model| (model.name().to_owned(), model.text().to_owned()))
    }

    /// The newest load or clear since the last call, if any (`Some(None)`: cleared). Lock-free
    /// and allocation-free: for the audio thread.
    pub fn take_change(&self) -> Option<Option<ModelLayer>> {
        let mut newest = None;
        while let Some(change) = self.changes.pop() {
            newest = Some(change);
        }
        newest
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Option<Model>> {
        // A panic elsewhere while holding it leaves a model that is still whole.
        self.current
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

/// The model's saved name and text in a state's `fields`: `Ok(None)` without one, `Err` with the
/// reason if it is no model.
pub fn saved_model(
    fields: &std::collections::BTreeMap<String, String>,
) -> Result<Option<Model>, String> {
    let Some(text) = fields.get(MODEL_KEY) else {
        return Ok(None);
    };
    let text: String = nice_plug::params::persist::deserialize_field(text)
        .map_err(|error| format!("field {MODEL_KEY:?} is not a string: {error}"))?;
    let name = fields
        .get(MODEL_NAME_KEY)
        .and_then(|name| nice_plug::params::persist::deserialize_field::<String>(name).ok())
        .unwrap_or_else(|| "model".to_owned());
    Model::parse(&name, &text)
        .map(Some)
        .map_err(|error| error.to_string())
}

/// The parameters a model sets, each with the value it is set to: every constant the plugin has
/// a parameter for, the model's or its default (a model replaces the whole bottle), and each
/// control the model gives.
pub fn model_values<'a>(
    model: &Model,
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
pub fn load_unshared(model: &Model, params: &GlugParams) {
    for (param, value) in model_values(model, params) {
        // SAFETY: the parameters are not shared yet: no host, editor or audio thread reads them.
        unsafe { param._internal_set_plain_value(value) };
    }
    params.loaded_model.set(Some(model.clone()));
}
