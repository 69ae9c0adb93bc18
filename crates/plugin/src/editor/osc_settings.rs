//! The OSC panel: the UDP port and the bottle axis (saved with the state), the address to listen
//! on (this session's), the button that opens the port a loaded project wants, and what came in.

use std::net::{IpAddr, Ipv4Addr};
use std::sync::atomic::Ordering::Relaxed;

use crate::osc_input::{OscInput, OscStatus, DEFAULT_OSC_INTERFACE};
use crate::params::GlugParams;
use sake_glug_device::Axis;

/// Every network interface: a phone on the network can reach the port.
const EVERY_INTERFACE: IpAddr = IpAddr::V4(Ipv4Addr::UNSPECIFIED);
/// Wide enough for the longest choice's name.
const INTERFACE_WIDTH: f32 = 220.0;

pub fn show(ui: &mut egui::Ui, params: &GlugParams, osc: &OscInput) {
    let (mut port, mut axis) = (params.osc.port(), params.osc.axis());
    let mut interface = osc.interface();
    let before = (port, axis, interface);
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
    ui.horizontal(|ui| {
        ui.label("Listen on");
        egui::ComboBox::from_id_salt("osc_interface")
            .width(INTERFACE_WIDTH)
            .selected_text(interface_name(interface))
            .show_ui(ui, |ui| {
                // An address given on the command line stays among the choices.
                let mut choices = vec![DEFAULT_OSC_INTERFACE, EVERY_INTERFACE];
                if !choices.contains(&before.2) {
                    choices.push(before.2);
                }
                for choice in choices {
                    ui.selectable_value(&mut interface, choice, interface_name(choice));
                }
            });
    });
    if (port, axis) != (before.0, before.1) {
        params.osc.set(port, axis);
    }
    if port != before.0 {
        // The user typed the port: that turns OSC on in this session.
        osc.allow(port);
    }
    if interface != before.2 {
        osc.set_interface(interface);
    }
    let mut changed = (port, axis, interface) != before;
    let stats = osc.stats();
    let (packets, malformed) = (stats.packets.load(Relaxed), stats.malformed.load(Relaxed));
    match osc.status() {
        OscStatus::Off => {
            ui.small("off");
        }
        OscStatus::Waiting { port } => {
            ui.label(format!(
                "This project wants OSC on UDP port {port}; it stays closed until you open it."
            ));
            if ui.button(format!("Listen on port {port}")).clicked() {
                osc.allow(port);
                changed = true;
            }
        }
        OscStatus::Listening(address) => {
            let plural = if packets == 1 { "" } else { "s" };
            ui.small(format!(
                "on {address}: {packets} packet{plural}, {malformed} malformed"
            ));
        }
        OscStatus::Failed { port, error } => {
            ui.small(format!("port {port} failed: {error}"));
        }
    }
    if let Some(error) = stats.last_error().filter(|_| malformed > 0) {
        ui.small(format!("last malformed: {error}"));
    }
    if changed {
        // The GUI thread, not the audio thread: binding the socket is allowed here.
        osc.follow(&params.osc);
    }
}

fn interface_name(interface: IpAddr) -> String {
    match interface {
        DEFAULT_OSC_INTERFACE => format!("this computer ({interface})"),
        EVERY_INTERFACE => format!("every interface ({interface})"),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_panel_shows_the_port_a_project_wants_without_opening_it() {
        let port = std::net::UdpSocket::bind("127.0.0.1:0")
            .and_then(|socket| socket.local_addr())
            .expect("a free port")
            .port();
        let (params, osc) = (GlugParams::default(), OscInput::default());
        params.osc.set(port, Axis::PlusY);
        osc.follow(&params.osc);
        let ctx = egui::Context::default();
        for _ in 0..3 {
            let mut output = ctx.run_ui(egui::RawInput::default(), |ui| show(ui, &params, &osc));
            // Nothing uploads the font atlas here.
            output.textures_delta.clear();
        }
        assert_eq!(osc.status(), OscStatus::Waiting { port });
    }
}
