//! OSC over loopback UDP into the real plugin: a packet sent to its port moves the bottle through
//! `process()`, as a MIDI CC would; garbage is counted and ignored; the setting is saved; a port
//! opens only when the user allows it in the session, on loopback unless asked, never because a
//! loaded state asks for it.

use std::net::{IpAddr, Ipv4Addr, SocketAddr, UdpSocket};
use std::sync::atomic::Ordering::Relaxed;
use std::time::{Duration, Instant};

use rosc::{OscMessage, OscPacket, OscType};

use crate::clap_host::ClapInstance;
use crate::host::{peak, TestHost};
use sake_glug_device::{Axis, LiveControls, LiveReader};
use sake_glug_engine::Control;
use sake_glug_plugin::SakeGlug;
use sake_glug_plugin::{OscStatus, DEFAULT_OSC_INTERFACE};

const RATE: f32 = 48_000.0;

/// A port that was free a moment ago.
fn free_port() -> u16 {
    let socket = UdpSocket::bind("127.0.0.1:0").expect("bind an ephemeral port");
    socket.local_addr().expect("its address").port()
}

/// Whether nothing listens on UDP `port`, on any address: the port can be bound on all of them.
fn port_is_closed(port: u16) -> bool {
    UdpSocket::bind((Ipv4Addr::UNSPECIFIED, port)).is_ok()
}

/// A plugin listening for OSC on a free port, as the user turned it on in the editor (the port,
/// then allowed), activated in a test host.
fn listening_host(axis: Axis) -> (TestHost, u16) {
    let plugin = SakeGlug::default();
    let port = free_port();
    plugin.glug_params().osc.set(port, axis);
    plugin.osc().allow(port);
    let host = TestHost::with_plugin(plugin, RATE, 2);
    match host.plugin.osc().status() {
        OscStatus::Listening(address) => {
            assert_eq!(address, SocketAddr::new(DEFAULT_OSC_INTERFACE, port))
        }
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
    let deadline = Instant::now() + Duration::from_secs(30);
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

/// The saved fields of a plugin, as a host's project keeps them.
fn saved_fields(plugin: &SakeGlug) -> std::collections::BTreeMap<String, String> {
    let params = plugin.glug_params().clone() as std::sync::Arc<dyn nice_plug::prelude::Params>;
    params.serialize_fields()
}

/// A new instance with `fields` loaded, as a host loads a project.
fn loaded(fields: &std::collections::BTreeMap<String, String>) -> SakeGlug {
    let plugin = SakeGlug::default();
    let params = plugin.glug_params().clone() as std::sync::Arc<dyn nice_plug::prelude::Params>;
    params.deserialize_fields(fields);
    plugin
}

#[test]
fn the_osc_setting_is_saved_and_a_taken_port_is_reported() {
    let (host, port) = listening_host(Axis::MinusX);
    let fields = saved_fields(&host.plugin);
    assert_eq!(fields["osc_port"], port.to_string());
    let restored = loaded(&fields);
    assert_eq!(restored.glug_params().osc.port(), port);
    assert_eq!(restored.glug_params().osc.axis(), Axis::MinusX);
    // A second instance on the same port, once its user allows it, cannot bind it, and says so.
    restored.osc().allow(port);
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
fn a_loaded_state_that_wants_osc_opens_no_port_until_the_user_allows_it() {
    let port = free_port();
    let saving = SakeGlug::default();
    saving.glug_params().osc.set(port, Axis::MinusZ);
    let fields = saved_fields(&saving);

    let host = TestHost::with_plugin(loaded(&fields), RATE, 2);
    let osc = host.plugin.osc();
    assert_eq!(osc.status(), OscStatus::Waiting { port });
    assert!(
        port_is_closed(port),
        "the project opened port {port} by itself"
    );
    // Activated again (a new sample rate, a state loaded again): still closed.
    let host = TestHost::with_plugin(host.plugin, RATE * 2.0, 2);
    let osc = host.plugin.osc();
    assert!(port_is_closed(port));
    // The state keeps its wish: saved again, the same fields.
    assert_eq!(saved_fields(&host.plugin), fields);

    // The user agrees (the editor's button): the port opens, on loopback only.
    osc.allow(port);
    osc.follow(&host.plugin.glug_params().osc);
    let loopback = SocketAddr::new(DEFAULT_OSC_INTERFACE, port);
    assert_eq!(osc.status(), OscStatus::Listening(loopback));
    assert!(!port_is_closed(port));
    // A network interface's address is free: nothing listens beyond this computer.
    if let Some(outside) = non_loopback_address() {
        assert!(UdpSocket::bind((outside, port)).is_ok(), "{outside}:{port}");
    }

    // Every interface only when the user picks it.
    osc.set_interface(IpAddr::V4(Ipv4Addr::UNSPECIFIED));
    osc.follow(&host.plugin.glug_params().osc);
    match osc.status() {
        OscStatus::Listening(address) => assert!(address.ip().is_unspecified(), "{address}"),
        other => panic!("listening on every interface: {other:?}"),
    }

    // Another state, which wants another port, closes this one and waits in turn.
    let other_port = free_port();
    let mut other_fields = fields.clone();
    other_fields.insert("osc_port".into(), other_port.to_string());
    let params =
        host.plugin.glug_params().clone() as std::sync::Arc<dyn nice_plug::prelude::Params>;
    params.deserialize_fields(&other_fields);
    let host = TestHost::with_plugin(host.plugin, RATE, 2);
    assert_eq!(
        host.plugin.osc().status(),
        OscStatus::Waiting { port: other_port }
    );
    assert!(port_is_closed(port) && port_is_closed(other_port));
}

/// An address of this machine other than loopback, if it has one: the one it would send from.
fn non_loopback_address() -> Option<IpAddr> {
    let probe = UdpSocket::bind("0.0.0.0:0").ok()?;
    probe.connect("192.0.2.1:9").ok()?;
    let address = probe.local_addr().ok()?.ip();
    (!address.is_loopback() && !address.is_unspecified()).then_some(address)
}

/// The JSON inside a CLAP state (the stream carries an 8-byte length first), and back.
fn clap_json(bytes: &[u8]) -> serde_json::Value {
    serde_json::from_slice(&bytes[8..]).expect("the state is JSON")
}

fn clap_bytes(json: &serde_json::Value) -> Vec<u8> {
    let text = serde_json::to_vec(json).expect("JSON");
    let mut bytes = (text.len() as u64).to_le_bytes().to_vec();
    bytes.extend(text);
    bytes
}

#[test]
fn a_project_that_wants_osc_loads_its_values_but_opens_no_port() {
    // A state as the last release saved it, with OSC on a port: the same field names and values.
    let port = free_port();
    let mut json = clap_json(&ClapInstance::new().save());
    json["fields"]["osc_port"] = port.to_string().into();
    json["fields"]["osc_axis"] = "5".into();
    let mut instance = ClapInstance::new();
    assert!(instance.load(&clap_bytes(&json)));
    instance.activate(48_000.0);
    instance.render(4_800, 480);
    assert!(
        port_is_closed(port),
        "loading the project opened UDP port {port}"
    );
    let saved = clap_json(&instance.save());
    assert_eq!(saved["fields"]["osc_port"], port.to_string());
    assert_eq!(saved["fields"]["osc_axis"], "5");
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
