//! OSC over loopback UDP into the real plugin: a packet sent to its port moves the bottle through
//! `process()`, as a MIDI CC would; garbage is counted and ignored; the setting is saved.

use std::net::UdpSocket;
use std::sync::atomic::Ordering::Relaxed;
use std::time::{Duration, Instant};

use rosc::{OscMessage, OscPacket, OscType};

use crate::host::{peak, TestHost};
use sake_glug::device::{Axis, LiveControls, LiveReader};
use sake_glug::engine::Control;
use sake_glug::plugin::OscStatus;
use sake_glug::SakeGlug;

const RATE: f32 = 48_000.0;

/// A port that was free a moment ago.
fn free_port() -> u16 {
    let socket = UdpSocket::bind("127.0.0.1:0").expect("bind an ephemeral port");
    socket.local_addr().expect("its address").port()
}

/// A plugin listening for OSC on a free port, activated in a test host.
fn listening_host(axis: Axis) -> (TestHost, u16) {
    let plugin = SakeGlug::default();
    let port = free_port();
    plugin.glug_params().osc.set(port, axis);
    let host = TestHost::with_plugin(plugin, RATE, 2);
    match host.plugin.osc().status() {
        OscStatus::Listening(address) => assert_eq!(address.port(), port),
        other => panic!("the plugin should listen on {port}: {other:?}"),
    }
    (host, port)
}

fn packet(address: &str, args: Vec<OscType>) -> Vec<u8> {
    rosc::encoder::encode(&OscPacket::Message(OscMessage {
        addr: address.to_owned(),
        args,
    }))
    .expect("encode")
}

/// Sends `packets` to the plugin and waits until its socket thread has read all of them.
fn send(host: &TestHost, port: u16, packets: &[Vec<u8>]) {
    let client = UdpSocket::bind("127.0.0.1:0").expect("client socket");
    let stats = host.plugin.osc().stats();
    let expected = stats.packets.load(Relaxed) + packets.len() as u64;
    for bytes in packets {
        client
            .send_to(bytes, ("127.0.0.1", port))
            .expect("send over loopback");
    }
    let deadline = Instant::now() + Duration::from_secs(5);
    while stats.packets.load(Relaxed) < expected {
        assert!(
            Instant::now() < deadline,
            "the listener read {} of {expected} packets",
            stats.packets.load(Relaxed)
        );
        std::thread::sleep(Duration::from_millis(2));
    }
}

fn volume_ml(host: &TestHost) -> f64 {
    host.plugin
        .renderer()
        .expect("activated")
        .engine()
        .volume_ml()
}

#[test]
fn osc_tilt_from_a_loopback_client_pours_the_bottle() {
    let (mut host, port) = listening_host(Axis::PlusY);
    assert_eq!(peak(&host.render_mono(9_600, 512)), 0.0, "upright: silent");
    send(
        &host,
        port,
        &[packet("/sakeglug/tilt", vec![OscType::Float(135.0)])],
    );
    let poured = host.render_mono(48_000, 512);
    assert!(peak(&poured) > 0.01, "tilted by OSC: glugs");
    assert_eq!(host.plugin.feed().tilt_deg.load(Relaxed), 135.0);
    let after_a_second = volume_ml(&host);
    assert!(
        (after_a_second - 240.0).abs() < 1.0,
        "60 ml/s at 135°: {after_a_second} ml left"
    );

    // The host moving the parameter takes tilt back, as after a MIDI CC.
    host.set_text("tilt", "10");
    host.render_mono(4_800, 512);
    assert_eq!(host.plugin.feed().tilt_deg.load(Relaxed), 10.0);
    // The same OSC value again takes it over again.
    send(
        &host,
        port,
        &[packet("/sakeglug/tilt", vec![OscType::Float(135.0)])],
    );
    host.render_mono(4_800, 512);
    assert_eq!(host.plugin.feed().tilt_deg.load(Relaxed), 135.0);
}

#[test]
fn a_phone_gravity_vector_tilts_the_bottle() {
    let (mut host, port) = listening_host(Axis::PlusY);
    // GyrOSC (Core Motion: gravity points down), the phone's top edge (+y, the bottle's mouth)
    // 135° from up: up is (0, cos 135°, sin 135°) in the phone's frame, and GyrOSC sends the
    // opposite, (0, 0.707, −0.707).
    let s = std::f32::consts::FRAC_1_SQRT_2;
    send(
        &host,
        port,
        &[packet(
            "/gyrosc/grav",
            vec![OscType::Float(0.0), OscType::Float(s), OscType::Float(-s)],
        )],
    );
    host.render_mono(4_800, 512);
    let tilt = host.plugin.feed().tilt_deg.load(Relaxed);
    assert!((tilt - 135.0).abs() < 1e-3, "tilt {tilt}");
    // Sensors2OSC (Android, pointing up) with the phone upright: 0°.
    send(
        &host,
        port,
        &[packet(
            "/gravity",
            vec![
                OscType::Float(0.0),
                OscType::Float(9.81),
                OscType::Float(0.0),
            ],
        )],
    );
    host.render_mono(4_800, 512);
    assert_eq!(host.plugin.feed().tilt_deg.load(Relaxed), 0.0);
}

#[test]
fn garbage_is_counted_and_ignored() {
    let (mut host, port) = listening_host(Axis::PlusZ);
    let garbage = [
        b"\x9f\x01garbage bytes\xff".to_vec(),
        Vec::new(),
        packet("/sakeglug/tilt", vec![OscType::String("135".into())]),
        packet("/sakeglug/tilt", vec![OscType::Float(f32::NAN)]),
        packet("/accxyz", vec![OscType::Float(0.0); 3]),
        b"#bundle\0\0\0\0\0".to_vec(),
    ];
    send(&host, port, &garbage);
    let malformed = |host: &TestHost| host.plugin.osc().stats().malformed.load(Relaxed);
    assert_eq!(malformed(&host), garbage.len() as u64);
    let last = host
        .plugin
        .osc()
        .stats()
        .last_error()
        .expect("an error is kept");
    assert!(last.contains("bundle"), "{last}");
    assert_eq!(
        peak(&host.render_mono(9_600, 512)),
        0.0,
        "nothing moved the bottle"
    );
    assert_eq!(host.plugin.feed().tilt_deg.load(Relaxed), 0.0);

    // The listener is still there and takes the next good packet.
    send(
        &host,
        port,
        &[packet("/sakeglug/tilt", vec![OscType::Double(120.0)])],
    );
    assert!(peak(&host.render_mono(48_000, 512)) > 0.0);
    assert_eq!(malformed(&host), garbage.len() as u64);
    let packets = host.plugin.osc().stats().packets.load(Relaxed);
    assert_eq!(packets, garbage.len() as u64 + 1);
}

#[test]
fn fill_viscosity_and_refill_over_osc() {
    let (mut host, port) = listening_host(Axis::PlusZ);
    send(
        &host,
        port,
        &[packet("/sakeglug/tilt", vec![OscType::Float(135.0)])],
    );
    host.render_mono(48_000, 512);
    assert!(volume_ml(&host) < 245.0);
    // Values outside a control's range are clamped to it; in simulate mode a new fill level
    // refills the bottle (MODEL.md §8).
    send(
        &host,
        port,
        &[
            packet("/sakeglug/fill", vec![OscType::Int(50)]),
            packet("/sakeglug/viscosity", vec![OscType::Float(7.0)]),
            packet("/sakeglug/tilt", vec![OscType::Float(-40.0)]),
        ],
    );
    host.render_mono(512, 512);
    assert_eq!(volume_ml(&host), 150.0, "refilled to 50 % of 300 ml");
    assert_eq!(host.plugin.feed().tilt_deg.load(Relaxed), 0.0);
    let live = host.plugin.osc().live();
    assert_eq!(live.value(Control::Viscosity), Some(1.0));
    assert_eq!(live.value(Control::Tilt), Some(0.0));
    // Poured, then refilled by /sakeglug/refill alone.
    send(
        &host,
        port,
        &[packet("/sakeglug/tilt", vec![OscType::Float(150.0)])],
    );
    host.render_mono(24_000, 512);
    assert!(volume_ml(&host) < 140.0);
    send(&host, port, &[packet("/sakeglug/refill", vec![])]);
    host.render_mono(1, 1);
    let refilled = volume_ml(&host);
    assert!(refilled > 149.9, "refilled to 150 ml: {refilled}");
}

#[test]
fn the_osc_setting_is_saved_and_a_taken_port_is_reported() {
    let (host, port) = listening_host(Axis::MinusX);
    let fields = {
        let params =
            host.plugin.glug_params().clone() as std::sync::Arc<dyn nice_plug::prelude::Params>;
        params.serialize_fields()
    };
    assert_eq!(fields["osc_port"], port.to_string());
    let restored = SakeGlug::default();
    let params = restored.glug_params().clone() as std::sync::Arc<dyn nice_plug::prelude::Params>;
    params.deserialize_fields(&fields);
    assert_eq!(restored.glug_params().osc.port(), port);
    assert_eq!(restored.glug_params().osc.axis(), Axis::MinusX);
    // A second instance on the same port cannot bind it, and says so.
    let second = TestHost::with_plugin(restored, RATE, 2);
    match second.plugin.osc().status() {
        OscStatus::Failed {
            port: failed,
            error,
        } => {
            assert_eq!(failed, port);
            assert!(!error.is_empty());
        }
        other => panic!("the port is taken: {other:?}"),
    }
}

#[test]
fn the_live_reader_sees_every_new_value_once() {
    let live = LiveControls::default();
    let mut reader = LiveReader::default();
    assert_eq!(reader.poll(&live), Default::default());
    live.set(Control::Tilt, 100.0);
    live.set(Control::Tilt, 120.0);
    live.refill();
    live.refill();
    let changes = reader.poll(&live);
    let set: Vec<_> = changes.set_values().collect();
    assert_eq!(set, [(Control::Tilt, 120.0)]);
    assert!(changes.refill);
    assert_eq!(reader.poll(&live), Default::default(), "nothing new");
    // The same value again is news: it takes the control back from the parameter.
    live.set(Control::Tilt, 120.0);
    live.set(Control::Fill, f64::NAN);
    live.set(Control::Fill, 250.0);
    let changes = reader.poll(&live);
    let set: Vec<_> = changes.set_values().collect();
    assert_eq!(set, [(Control::Tilt, 120.0), (Control::Fill, 100.0)]);
    assert!(!changes.refill);
}
