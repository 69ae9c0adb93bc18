//! The loaded model's holder (MODEL.md §12.1): the model the editor, the standalone app's
//! `--model` or a saved state loaded, kept for the state as its text, and its loads and clears
//! handed to the audio thread through a lock-free queue, so `process()` neither allocates,
//! locks nor waits. How a model meets the parameters is `model.rs`'s.

use std::sync::Mutex;

use crossbeam_queue::ArrayQueue;

use sake_glug_engine::{ModelConfig, PerControl};
use sake_glug_model_file::ModelFile;

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
    pub fn of(model: &ModelFile) -> Self {
        Self {
            config: *model.config(),
            controls: *model.controls(),
        }
    }
}

/// The plugin's model: the loaded one, for the editor and the state, and its loads and clears on
/// their way to the audio thread.
pub struct LoadedModel {
    /// Read and written off the audio thread only.
    current: Mutex<Option<ModelFile>>,
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
    pub fn set(&self, model: Option<ModelFile>) {
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

    fn lock(&self) -> std::sync::MutexGuard<'_, Option<ModelFile>> {
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
) -> Result<Option<ModelFile>, String> {
    let Some(text) = fields.get(MODEL_KEY) else {
        return Ok(None);
    };
    let text: String = nice_plug::params::persist::deserialize_field(text)
        .map_err(|error| format!("field {MODEL_KEY:?} is not a string: {error}"))?;
    let name = fields
        .get(MODEL_NAME_KEY)
        .and_then(|name| nice_plug::params::persist::deserialize_field::<String>(name).ok())
        .unwrap_or_else(|| "model".to_owned());
    ModelFile::parse(&name, &text)
        .map(Some)
        .map_err(|error| error.to_string())
}
