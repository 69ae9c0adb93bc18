//! The OSC panel: the UDP port and the bottle axis (saved with the state), and what came in.

use std::sync::atomic::Ordering::Relaxed;

use crate::device::Axis;
use crate::plugin::osc_input::{OscInput, OscStatus};
use crate::plugin::params::GlugParams;

pub fn show(ui: &mut egui::Ui, params: &GlugParams, osc: &OscInput) {
    let (mut port, mut axis) = (params.osc.port(), params.osc.axis());
    let before = (port, axis);
    ui.label("OSC (phones, sensors)");
    ui.horizontal(|ui| {
        ui.label("UDP port");
        ui.add(
            egui::DragValue::new(&mut port)
                .range(0..=u16::MAX)
                .custom_formatter(|value, _| {
                    if value < 0.5 {
                        "off".to_owned()
                    } else {
                        format!("{value:.0}")
                    }
                }),
        );
        ui.label("Bottle axis");
        egui::ComboBox::from_id_salt("osc_axis")
            .selected_text(axis.to_string())
            .show_ui(ui, |ui| {
                for choice in Axis::ALL {
                    ui.selectable_value(&mut axis, choice, choice.to_string());
                }
            });
    });
    if (port, axis) != before {
        params.osc.set(port, axis);
        // The GUI thread, not the audio thread: binding the socket is allowed here.
        osc.listen(port, axis);
    }
    let stats = osc.stats();
    let (packets, malformed) = (stats.packets.load(Relaxed), stats.malformed.load(Relaxed));
    let status = match osc.status() {
        OscStatus::Off => "off".to_owned(),
        OscStatus::Listening(address) => {
            let plural = if packets == 1 { "" } else { "s" };
            format!("on {address}: {packets} packet{plural}, {malformed} malformed")
        }
        OscStatus::Failed { port, error } => format!("port {port} failed: {error}"),
    };
    ui.small(status);
    if let Some(error) = stats.last_error().filter(|_| malformed > 0) {
        ui.small(format!("last malformed: {error}"));
    }
}
