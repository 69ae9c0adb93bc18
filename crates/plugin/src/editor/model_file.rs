//! "Load model…": a model file's path, typed or pasted (a file dialog would need GTK's
//! development files or a desktop portal's D-Bus stack: see docs/guide/sound-designer.md), loaded with a button.
//! Loading sets the model's constants and controls through the host, one gesture per parameter,
//! as the preset menu does, and keeps the model in the state; Clear takes it out.

use std::path::Path;

use nice_plug::context::gui::GuiContext;
use nice_plug::prelude::*;

use super::PathField;
use crate::layering::model_values;
use crate::params::GlugParams;
use sake_glug_model_file::ModelFile;

/// Shows the loaded model's name, the path field and the Load and Clear buttons.
pub fn show(ui: &mut egui::Ui, params: &GlugParams, gui: &GuiContext, field: &mut PathField) {
    ui.label(egui::RichText::new("Model file").strong());
    let loaded = params.loaded_model.name();
    ui.label(match &loaded {
        Some(name) => format!("Loaded: {name}"),
        None => "None: the paper's bottle".to_owned(),
    });
    ui.horizontal(|ui| {
        field.text_edit(ui, "/path/to/model.toml");
        if ui.button("Load model…").clicked() {
            field.refused = load(Path::new(field.path.trim()), params, gui).err();
        }
        if ui
            .add_enabled(loaded.is_some(), egui::Button::new("Clear"))
            .clicked()
        {
            field.refused = None;
            params.loaded_model.set(None);
            super::midi_settings::tell_host(gui);
        }
    });
    field.show_refusal(ui);
}

/// Loads the model at `path`: its parameters through the host, the rest through the state.
/// A model that is refused changes nothing; the message says why.
pub fn load(path: &Path, params: &GlugParams, gui: &GuiContext) -> Result<(), String> {
    let model = ModelFile::load(path).map_err(|error| error.to_string())?;
    apply(&model, params, &gui.param_setter());
    params.loaded_model.set(Some(model));
    super::midi_settings::tell_host(gui);
    Ok(())
}

/// Sets every parameter the model sets, one gesture each.
pub fn apply(model: &ModelFile, params: &GlugParams, setter: &ParamSetter) {
    for (param, value) in model_values(model, params) {
        setter.begin_set_parameter(param);
        setter.set_parameter(param, value);
        setter.end_set_parameter(param);
    }
}
