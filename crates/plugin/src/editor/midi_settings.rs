//! The MIDI panel: which channel and CCs the tilt device uses (saved with the state), each CC
//! row with a "Learn" button: the next CC the device sends is taken, with its channel.

use nice_plug::context::gui::GuiContext;

use crate::midi_learn::learnable;
use crate::params::GlugParams;
use sake_glug_device::midi::{MidiMap, MidiSetting, OFF};

/// What the panel remembers between frames: the map when a learn was armed, to see it change.
#[derive(Debug, Default)]
pub struct MidiPanel {
    armed_over: Option<MidiMap>,
}

/// What a VST3 host offers instead: it passes the plugin no CCs (see `SakeGlugPlugin`).
pub const VST3_LEARN: &str = "In a VST3 host, CCs do not reach the plugin: use the host's own \
    MIDI learn on the Tilt parameter (arm it, move the device); the host then moves Tilt.";

/// Shows the panel; returns whether the map changed in this frame (the user's edit, or a CC
/// learnt). `raw_midi`: the format passes CCs (CLAP, the standalone app), so Learn can work.
pub fn show(ui: &mut egui::Ui, params: &GlugParams, panel: &mut MidiPanel, raw_midi: bool) -> bool {
    let mut map = params.midi_map();
    let before = map;
    let armed = params.learn.armed();
    // A learn that ended since the last frame: the audio thread took a CC, or it was cancelled.
    let learnt = match (panel.armed_over, armed) {
        (Some(over), None) => {
            panel.armed_over = None;
            over != map
        }
        _ => false,
    };
    if armed.is_some() && ui.input(|input| input.key_pressed(egui::Key::Escape)) {
        params.learn.cancel();
        panel.armed_over = None;
    }
    ui.label("MIDI device");
    egui::Grid::new("midi_settings")
        .num_columns(3)
        .spacing([8.0, 4.0])
        .show(ui, |ui| {
            ui.label("Channel");
            let mut channel = map.channel.map_or(0, |channel| channel + 1);
            ui.add(
                egui::DragValue::new(&mut channel)
                    .range(0..=16)
                    .custom_formatter(|value, _| {
                        if value < 0.5 {
                            "any".to_owned()
                        } else {
                            format!("{value:.0}")
                        }
                    }),
            );
            map.channel = (channel > 0).then(|| channel - 1);
            ui.end_row();
            for setting in MidiSetting::all().filter(|&setting| learnable(setting)) {
                let raw = map.raw(setting);
                let mut cc = (raw <= setting.max()).then_some(raw);
                cc_row(ui, &setting.label(), &mut cc);
                map.set_raw(setting, cc.unwrap_or(OFF));
                learn_button(ui, params, panel, setting, armed, raw_midi, before);
                ui.end_row();
            }
        });
    if raw_midi {
        if armed.is_some() {
            ui.label("Move the control on the device (Escape or Learn again cancels).");
        }
    } else {
        ui.label(VST3_LEARN);
    }
    if map != before {
        params.set_midi_map(map);
    }
    map != before || learnt
}

/// The row's "Learn" button: arms it, or cancels when it is armed.
fn learn_button(
    ui: &mut egui::Ui,
    params: &GlugParams,
    panel: &mut MidiPanel,
    setting: MidiSetting,
    armed: Option<MidiSetting>,
    raw_midi: bool,
    map: MidiMap,
) {
    let waiting = armed == Some(setting);
    let label = if waiting { "Learning…" } else { "Learn" };
    let clicked = ui
        .add_enabled(raw_midi, egui::Button::selectable(waiting, label))
        .on_disabled_hover_text(VST3_LEARN)
        .clicked();
    if clicked {
        if waiting {
            params.learn.cancel();
            panel.armed_over = None;
        } else {
            params.learn.arm(setting);
            panel.armed_over = Some(map);
        }
    }
}

/// Tells the host that the project changed after an edit of the MIDI settings. They are saved
/// fields, not parameters, and nice-plug has no "state is dirty" call: restoring the current
/// state makes the wrapper ask the host to rescan the parameters' values (CLAP) or restart
/// them (VST3), which hosts take as a change to save.
pub fn tell_host(gui: &GuiContext) {
    gui.set_state(gui.get_state());
}

/// A CC number 0–127, or "off" (shown one below 0).
fn cc_row(ui: &mut egui::Ui, label: &str, cc: &mut Option<u8>) {
    ui.label(label);
    let mut value: i32 = cc.map_or(-1, i32::from);
    ui.add(
        egui::DragValue::new(&mut value)
            .range(-1..=127)
            .custom_formatter(|value, _| {
                if value < -0.5 {
                    "off".to_owned()
                } else {
                    format!("{value:.0}")
                }
            }),
    );
    *cc = u8::try_from(value).ok();
}

#[cfg(test)]
mod tests {
    use std::sync::{Arc, Mutex};

    use nice_plug::context::gui::GuiContextInner;
    use nice_plug::prelude::*;

    use super::*;
    use sake_glug_device::midi::MidiMap;

    /// A host that hands out the plugin's fields as its state and records what it is given.
    struct StateHost {
        params: Arc<GlugParams>,
        restored: Mutex<Vec<PluginState>>,
    }

    impl GuiContextInner for StateHost {
        fn plugin_api(&self) -> PluginApi {
            PluginApi::Vst3
        }
        unsafe fn raw_begin_set_parameter(&self, _param: ParamPtr) {}
        unsafe fn raw_set_parameter_normalized(&self, _param: ParamPtr, _normalized: f32) {}
        unsafe fn raw_end_set_parameter(&self, _param: ParamPtr) {}
        fn get_state(&self) -> PluginState {
            PluginState {
                version: String::new(),
                params: Default::default(),
                fields: self.params.serialize_fields(),
            }
        }
        fn set_state(&self, state: PluginState) {
            self.restored.lock().unwrap().push(state);
        }
        fn request_restart(&self) {}
    }

    #[test]
    fn an_edit_reaches_the_host_as_a_state_change() {
        let params = Arc::new(GlugParams::default());
        let host = Arc::new(StateHost {
            params: params.clone(),
            restored: Mutex::new(Vec::new()),
        });
        params.set_midi_map(MidiMap {
            channel: Some(3),
            ..MidiMap::default()
        });
        tell_host(&GuiContext::new(host.clone()));
        let restored = host.restored.lock().unwrap();
        assert_eq!(restored.len(), 1, "the host is told once");
        assert_eq!(restored[0].fields["midi_channel"], "3");
    }
}
