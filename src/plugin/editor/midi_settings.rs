//! The MIDI panel: which channel and CCs the tilt device uses (saved with the state).

use crate::plugin::params::GlugParams;

pub fn show(ui: &mut egui::Ui, params: &GlugParams) {
    let mut map = params.midi_map();
    let before = map;
    ui.label("MIDI device");
    egui::Grid::new("midi_settings")
        .num_columns(2)
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
            cc_row(ui, "Tilt CC (MSB)", &mut map.tilt_msb);
            cc_row(ui, "Tilt LSB CC", &mut map.tilt_lsb);
            cc_row(ui, "Viscosity CC", &mut map.viscosity);
            cc_row(ui, "Fill CC", &mut map.fill);
        });
    if map != before {
        params.set_midi_map(map);
    }
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
    ui.end_row();
}
