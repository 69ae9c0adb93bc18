//! The preset menu: picking a liquid or a bottle sets its parameters through the host, one
//! gesture per parameter, so the host records the change (undo, automation, project saved).

use nice_plug::prelude::*;

use crate::params::GlugParams;
use crate::presets::preset_values;
use sake_glug_engine::{Preset, PRESETS};

/// Shows the menu; `chosen` remembers the last preset picked, for its label.
pub fn show(ui: &mut egui::Ui, params: &GlugParams, setter: &ParamSetter, chosen: &mut usize) {
    ui.horizontal(|ui| {
        ui.label("Preset");
        egui::ComboBox::from_id_salt("preset")
            .selected_text(PRESETS[*chosen].name)
            .width(170.0)
            .show_ui(ui, |ui| {
                for (index, preset) in PRESETS.iter().enumerate() {
                    let picked = ui
                        .selectable_label(index == *chosen, preset.name)
                        .on_hover_text(preset.description)
                        .clicked();
                    if picked {
                        *chosen = index;
                        apply(preset, params, setter);
                    }
                }
            });
    });
}

/// Sets every parameter the preset holds.
pub fn apply(preset: &Preset, params: &GlugParams, setter: &ParamSetter) {
    for (param, value) in preset_values(preset, params) {
        setter.begin_set_parameter(param);
        setter.set_parameter(param, value as f32);
        setter.end_set_parameter(param);
    }
}

#[cfg(test)]
mod tests {
    use std::sync::{Arc, Mutex};

    use nice_plug::context::gui::{GuiContext, GuiContextInner};
    use nice_plug::prelude::*;

    use super::*;
    use sake_glug_engine::{ControlValues, ModelConfig};

    /// A host that applies what the editor sets and counts each gesture's calls.
    #[derive(Default)]
    struct RecordingHost {
        gestures: Mutex<Vec<&'static str>>,
    }

    impl GuiContextInner for RecordingHost {
        fn plugin_api(&self) -> PluginApi {
            PluginApi::Clap
        }
        unsafe fn raw_begin_set_parameter(&self, _param: ParamPtr) {
            self.gestures.lock().unwrap().push("begin");
        }
        unsafe fn raw_set_parameter_normalized(&self, param: ParamPtr, normalized: f32) {
            self.gestures.lock().unwrap().push("set");
            unsafe { param._internal_set_normalized_value(normalized) };
        }
        unsafe fn raw_end_set_parameter(&self, _param: ParamPtr) {
            self.gestures.lock().unwrap().push("end");
        }
        fn get_state(&self) -> PluginState {
            unimplemented!("the preset menu does not read the state")
        }
        fn set_state(&self, _state: PluginState) {}
        fn request_restart(&self) {}
    }

    #[test]
    fn every_preset_reaches_the_engine_through_the_host() {
        for preset in &PRESETS {
            let params = GlugParams::default();
            let host = Arc::new(RecordingHost::default());
            let gui = GuiContext::new(host.clone());
            apply(preset, &params, &gui.param_setter());
            assert_eq!(
                params.model_config(),
                preset.config(ModelConfig::default()),
                "{}",
                preset.name
            );
            assert_eq!(
                params.control_values(),
                preset.controls(ControlValues::default()),
                "{}",
                preset.name
            );
            let gestures = host.gestures.lock().unwrap();
            // Its values, the headspace law's three constants and the glide's four (their
            // defaults where it leaves them out): 15 parameters, each begun, set and ended.
            assert_eq!(gestures.len(), 15 * 3, "one gesture per parameter");
            assert!(gestures.chunks(3).all(|g| g == ["begin", "set", "end"]));
        }
    }
}
