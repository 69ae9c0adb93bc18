//! The OSC decoder: every address, bundles, malformed packets, and the per-app sign of gravity
//! vectors.

use rosc::encoder::encode;
use rosc::{OscBundle, OscMessage, OscPacket, OscTime, OscType};

use sake_glug_device::axis::Axis;
use sake_glug_device::osc::{
    decode_osc, OscControl, OscError, Pointing, GRAVITY_SOURCES, MAX_BUNDLE_DEPTH,
};
use sake_glug_engine::Control;

fn message(address: &str, args: Vec<OscType>) -> OscPacket {
    OscPacket::Message(OscMessage {
        addr: address.to_owned(),
        args,
    })
}

fn bundle(content: Vec<OscPacket>) -> OscPacket {
    OscPacket::Bundle(OscBundle {
        timetag: OscTime::from((0, 1)),
        content,
    })
}

fn decode(packet: &[u8], axis: Axis) -> Result<Vec<OscControl>, OscError> {
    let mut controls = Vec::new();
    decode_osc(packet, axis, &mut |control| controls.push(control))?;
    Ok(controls)
}

fn controls_of(packet: &OscPacket, axis: Axis) -> Vec<OscControl> {
    decode(&encode(packet).unwrap(), axis).unwrap()
}

fn error_of(packet: &OscPacket) -> OscError {
    decode(&encode(packet).unwrap(), Axis::PlusZ).unwrap_err()
}

/// The tilt, rounded to a nanodegree so that rounding in acos does not matter.
fn tilt(controls: &[OscControl]) -> f64 {
    match controls {
        [OscControl::Set(Control::Tilt, tilt)] => (tilt * 1e9).round() / 1e9,
        other => panic!("expected one tilt, got {other:?}"),
    }
}

#[test]
fn sake_glug_addresses_take_any_numeric_type() {
    use OscType::{Double, Float, Int, Long};
    let cases = [
        (
            message("/sakeglug/tilt", vec![Float(30.5)]),
            OscControl::Set(Control::Tilt, 30.5),
        ),
        (
            message("/sakeglug/tilt", vec![Double(12.25)]),
            OscControl::Set(Control::Tilt, 12.25),
        ),
        (
            message("/sakeglug/tilt", vec![Long(90)]),
            OscControl::Set(Control::Tilt, 90.0),
        ),
        (
            message("/sakeglug/viscosity", vec![Double(2.5)]),
            OscControl::Set(Control::Viscosity, 2.5),
        ),
        (
            message("/sakeglug/fill", vec![Int(80)]),
            OscControl::Set(Control::Fill, 80.0),
        ),
        (message("/sakeglug/refill", vec![]), OscControl::Refill),
        (
            message(
                "/sakeglug/refill",
                vec![Float(0.0), OscType::String("go".into())],
            ),
            OscControl::Refill,
        ),
    ];
    for (packet, control) in cases {
        assert_eq!(controls_of(&packet, Axis::PlusZ), [control], "{packet:?}");
    }
}

/// A reading as `address` sends it: turned round for apps whose vector points down.
fn as_sent(address: &str, up: [f32; 3]) -> [f32; 3] {
    let (_, pointing) = GRAVITY_SOURCES
        .iter()
        .find(|(known, _)| *known == address)
        .expect("a gravity address");
    match pointing {
        Pointing::Up => up,
        Pointing::Down => up.map(|component| -component),
    }
}

fn gravity(address: &str, up: [f32; 3]) -> OscPacket {
    let [x, y, z] = as_sent(address, up);
    message(
        address,
        vec![OscType::Float(x), OscType::Float(y), OscType::Float(z)],
    )
}

#[test]
fn gravity_vectors_from_every_app_become_tilt() {
    for (address, _) in GRAVITY_SOURCES {
        let upright = gravity(address, [0.0, 0.0, 9.81]);
        assert_eq!(tilt(&controls_of(&upright, Axis::PlusZ)), 0.0, "{address}");
        let on_its_side = gravity(address, [1.0, 0.0, 0.0]);
        assert_eq!(
            tilt(&controls_of(&on_its_side, Axis::PlusZ)),
            90.0,
            "{address}"
        );
        let upside_down = gravity(address, [0.0, 0.0, -1.0]);
        assert_eq!(
            tilt(&controls_of(&upside_down, Axis::PlusZ)),
            180.0,
            "{address}"
        );
        let along_minus_y = gravity(address, [0.0, -0.5, 0.5]);
        assert_eq!(
            tilt(&controls_of(&along_minus_y, Axis::MinusY)),
            45.0,
            "{address}"
        );
    }
    // Mixed numeric types are read as numbers.
    let mixed = message(
        "/gravity",
        vec![OscType::Double(1.0), OscType::Int(0), OscType::Float(0.0)],
    );
    assert_eq!(tilt(&controls_of(&mixed, Axis::PlusZ)), 90.0);
}

#[test]
fn ios_apps_point_down_and_android_apps_up() {
    // A phone held upright along the bottle, its top edge to the mouth (axis +y): Core Motion
    // reports gravity along −y, Android's sensors the reaction along +y. Both read 0°.
    let ios_upright = vec![
        OscType::Float(0.0),
        OscType::Float(-1.0),
        OscType::Float(0.0),
    ];
    let android_upright = vec![
        OscType::Float(0.0),
        OscType::Float(9.81),
        OscType::Float(0.0),
    ];
    for address in ["/gyrosc/grav", "/accxyz"] {
        let packet = message(address, ios_upright.clone());
        assert_eq!(tilt(&controls_of(&packet, Axis::PlusY)), 0.0, "{address}");
    }
    for address in ["/gravity", "/acceleration"] {
        let packet = message(address, android_upright.clone());
        assert_eq!(tilt(&controls_of(&packet, Axis::PlusY)), 0.0, "{address}");
    }
}

#[test]
fn unknown_addresses_are_ignored() {
    let packet = message("/sakeglug/tilt/extra", vec![OscType::String("x".into())]);
    assert_eq!(controls_of(&packet, Axis::PlusZ), []);
    assert_eq!(controls_of(&message("/ping", vec![]), Axis::PlusZ), []);
}

#[test]
fn bundles_apply_in_order_and_nest() {
    let inner = bundle(vec![
        message("/sakeglug/fill", vec![OscType::Float(50.0)]),
        message("/unknown", vec![OscType::Int(1)]),
        bundle(vec![message("/sakeglug/refill", vec![])]),
    ]);
    let packet = bundle(vec![
        message("/sakeglug/tilt", vec![OscType::Float(10.0)]),
        inner,
        message("/sakeglug/viscosity", vec![OscType::Float(3.0)]),
        bundle(vec![]),
    ]);
    assert_eq!(
        controls_of(&packet, Axis::PlusZ),
        [
            OscControl::Set(Control::Tilt, 10.0),
            OscControl::Set(Control::Fill, 50.0),
            OscControl::Refill,
            OscControl::Set(Control::Viscosity, 3.0),
        ]
    );
}

/// A tilt message inside `depth` bundles.
fn nested(depth: usize) -> OscPacket {
    (0..depth).fold(
        message("/sakeglug/tilt", vec![OscType::Float(5.0)]),
        |packet, _| bundle(vec![packet]),
    )
}

#[test]
fn bundle_depth_is_bounded() {
    assert_eq!(
        controls_of(&nested(MAX_BUNDLE_DEPTH), Axis::PlusZ),
        [OscControl::Set(Control::Tilt, 5.0)]
    );
    assert_eq!(
        error_of(&nested(MAX_BUNDLE_DEPTH + 1)),
        OscError::BundlesTooDeep
    );
    // Deeper than rosc could recurse on a small stack, built by hand: each level is the tag,
    // a time tag and the size of the one element.
    let mut packet = encode(&message("/sakeglug/tilt", vec![OscType::Float(5.0)])).unwrap();
    for _ in 0..3_000 {
        let mut outer = b"#bundle\0\0\0\0\0\0\0\0\x01".to_vec();
        outer.extend((packet.len() as u32).to_be_bytes());
        outer.extend(&packet);
        packet = outer;
    }
    assert_eq!(decode(&packet, Axis::PlusZ), Err(OscError::BundlesTooDeep));
}

#[test]
fn wrong_arguments_are_errors_naming_the_address() {
    use OscType::{Float, Int};
    let cases = [
        (
            message("/sakeglug/tilt", vec![Float(1.0), Float(2.0)]),
            "/sakeglug/tilt takes 1 number, not 2 arguments",
        ),
        (
            message("/sakeglug/fill", vec![]),
            "/sakeglug/fill takes 1 number, not 0 arguments",
        ),
        (
            message("/accxyz", vec![Float(1.0), Float(2.0)]),
            "/accxyz takes 3 numbers, not 2 arguments",
        ),
        (
            message("/sakeglug/viscosity", vec![OscType::String("thick".into())]),
            "/sakeglug/viscosity: argument 1 is a string, not a number",
        ),
        (
            message(
                "/gravity",
                vec![Float(0.0), OscType::Bool(true), Float(1.0)],
            ),
            "/gravity: argument 2 is a boolean, not a number",
        ),
        (
            message("/sakeglug/tilt", vec![Float(f32::NAN)]),
            "/sakeglug/tilt: argument 1 is NaN, not a finite number",
        ),
        (
            message(
                "/gyrosc/grav",
                vec![Float(0.0), Float(0.0), OscType::Double(f64::INFINITY)],
            ),
            "/gyrosc/grav: argument 3 is inf, not a finite number",
        ),
        (
            message("/acceleration", vec![Float(0.0), Int(0), Float(-0.0)]),
            "/acceleration: the gravity vector is zero, so it has no direction",
        ),
    ];
    for (packet, expected) in cases {
        assert_eq!(error_of(&packet).to_string(), expected);
    }
}

#[test]
fn a_bad_message_anywhere_in_a_bundle_drops_the_whole_bundle() {
    let packet = bundle(vec![
        message("/sakeglug/tilt", vec![OscType::Float(10.0)]),
        bundle(vec![message(
            "/sakeglug/fill",
            vec![OscType::Float(f32::NAN)],
        )]),
    ]);
    let mut controls = Vec::new();
    let result = decode_osc(&encode(&packet).unwrap(), Axis::PlusZ, &mut |control| {
        controls.push(control)
    });
    assert!(
        matches!(result, Err(OscError::NotFinite { .. })),
        "{result:?}"
    );
    assert_eq!(controls, []);
}

#[test]
fn malformed_packets_are_errors() {
    let malformed = |bytes: &[u8]| decode(bytes, Axis::PlusZ).unwrap_err().to_string();
    assert!(malformed(&[]).starts_with("malformed OSC packet"));
    assert!(malformed(b"\x9f\x01garbage bytes\xff").starts_with("malformed OSC packet"));
    assert!(malformed(b"sakeglug/tilt\0\0\0,f\0\0\0\0\0\0").starts_with("malformed OSC packet"));
    // The type tags promise a float that is not there.
    assert!(malformed(b"/sakeglug/tilt\0\0,f\0\0").starts_with("malformed OSC packet"));

    let tilt = encode(&message("/sakeglug/tilt", vec![OscType::Float(1.0)])).unwrap();
    let mut trailing = tilt.clone();
    trailing.extend([0, 0, 0, 7]);
    assert_eq!(
        malformed(&trailing),
        "4 stray bytes after the OSC message \"/sakeglug/tilt\""
    );

    assert_eq!(
        malformed(b"#bundle\0\0\0\0\0"),
        "an OSC bundle of 12 bytes, too short for its header of 16"
    );
    let mut overrun = b"#bundle\0\0\0\0\0\0\0\0\x01".to_vec();
    overrun.extend(((tilt.len() + 4) as u32).to_be_bytes());
    overrun.extend(&tilt);
    assert_eq!(
        malformed(&overrun),
        "an OSC bundle element declares 28 bytes but only 24 remain"
    );
    let mut stub = b"#bundle\0\0\0\0\0\0\0\0\x01".to_vec();
    stub.extend([0, 0]);
    assert_eq!(
        malformed(&stub),
        "an OSC bundle element declares 0 bytes but only 2 remain"
    );
    // A bundle element that is itself malformed is an error, not skipped.
    let mut bad_element = b"#bundle\0\0\0\0\0\0\0\0\x01".to_vec();
    bad_element.extend(8_u32.to_be_bytes());
    bad_element.extend(b"nonsense");
    assert!(malformed(&bad_element).starts_with("malformed OSC packet"));
}

#[test]
fn deeply_nested_arrays_are_refused_before_they_are_built() {
    let with_arrays = |depth: usize| {
        let mut bytes = b"/x\0\0,".to_vec();
        bytes.extend(std::iter::repeat_n(b'[', depth));
        bytes.extend(std::iter::repeat_n(b']', depth));
        bytes.push(0);
        bytes.resize(bytes.len().div_ceil(4) * 4, 0);
        bytes
    };
    assert_eq!(decode(&with_arrays(8), Axis::PlusZ), Ok(vec![]));
    assert_eq!(
        decode(&with_arrays(9), Axis::PlusZ),
        Err(OscError::ArraysTooDeep)
    );
    assert_eq!(
        decode(&with_arrays(30_000), Axis::PlusZ),
        Err(OscError::ArraysTooDeep)
    );
}
