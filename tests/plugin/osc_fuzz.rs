//! Properties over arbitrary and mutated OSC packets and axis names: the decoder never panics,
//! and whatever it returns is either finite controls or an error with a message (and then no
//! control at all).
//!
//! The case count is proptest's: 256 unless the `PROPTEST_CASES` environment variable says
//! otherwise (e.g. `PROPTEST_CASES=100000 cargo test --release --test plugin osc_fuzz`).

use proptest::prelude::*;

use crate::support::fuzz::{edits, mutate};
use rosc::{OscBundle, OscMessage, OscPacket, OscTime, OscType};

use sake_glug_device::axis::Axis;
use sake_glug_device::osc::{decode_osc, OscControl, GRAVITY_SOURCES};

/// A packet with every address, nested, as a phone app might send it.
fn valid_osc() -> Vec<u8> {
    let message = |address: &str, args: Vec<OscType>| {
        OscPacket::Message(OscMessage {
            addr: address.into(),
            args,
        })
    };
    let gravity = || vec![OscType::Float(0.1), OscType::Double(-0.2), OscType::Int(1)];
    let mut inner: Vec<OscPacket> = GRAVITY_SOURCES
        .iter()
        .map(|(address, _)| message(address, gravity()))
        .collect();
    inner.push(message(
        "/other",
        vec![OscType::String("s".into()), OscType::Blob(vec![1, 2, 3])],
    ));
    let inner = OscPacket::Bundle(OscBundle {
        timetag: OscTime::from((1, 2)),
        content: inner,
    });
    rosc::encoder::encode(&OscPacket::Bundle(OscBundle {
        timetag: OscTime::from((0, 0)),
        content: vec![
            message("/sakeglug/tilt", vec![OscType::Float(45.0)]),
            message("/sakeglug/viscosity", vec![OscType::Double(2.0)]),
            message("/sakeglug/fill", vec![OscType::Int(50)]),
            message("/sakeglug/refill", vec![]),
            inner,
        ],
    }))
    .unwrap()
}

fn check_osc(packet: &[u8]) -> Result<(), TestCaseError> {
    for axis in [Axis::PlusZ, Axis::MinusX] {
        let mut controls = Vec::new();
        match decode_osc(packet, axis, &mut |control| controls.push(control)) {
            Ok(()) => {
                let finite = controls.iter().all(|control| match control {
                    OscControl::Set(_, value) => value.is_finite(),
                    OscControl::Refill => true,
                });
                prop_assert!(finite, "{controls:?}");
            }
            Err(error) => {
                prop_assert!(!error.to_string().is_empty());
                prop_assert!(controls.is_empty());
            }
        }
    }
    Ok(())
}

fn osc_argument() -> impl Strategy<Value = OscType> {
    prop_oneof![
        any::<f32>().prop_map(OscType::Float),
        any::<f64>().prop_map(OscType::Double),
        any::<i32>().prop_map(OscType::Int),
        any::<i64>().prop_map(OscType::Long),
        ".{0,8}".prop_map(OscType::String),
        any::<bool>().prop_map(OscType::Bool),
        Just(OscType::Nil),
    ]
}

#[test]
fn the_valid_packet_decodes() {
    let mut controls = Vec::new();
    decode_osc(&valid_osc(), Axis::PlusZ, &mut |control| {
        controls.push(control)
    })
    .expect("the seed of the mutations is valid");
    assert_eq!(controls.len(), 8, "{controls:?}");
}

proptest! {
    // ProptestConfig::default() reads PROPTEST_CASES, else runs 256 cases.
    #![proptest_config(ProptestConfig::default())]

    #[test]
    fn osc_from_arbitrary_bytes(bytes in prop::collection::vec(any::<u8>(), 0..256)) {
        check_osc(&bytes)?;
    }

    #[test]
    fn osc_mutated_from_a_valid_packet(edits in edits(), keep in any::<usize>()) {
        let valid = valid_osc();
        let keep = keep % (valid.len() + 8);
        check_osc(&mutate(valid, &edits, keep))?;
    }

    #[test]
    fn osc_known_addresses_with_arbitrary_arguments(
        address in prop::sample::select(vec![
            "/sakeglug/tilt", "/sakeglug/viscosity", "/sakeglug/fill", "/sakeglug/refill",
            "/gyrosc/grav", "/accxyz", "/gravity", "/acceleration",
        ]),
        args in prop::collection::vec(osc_argument(), 0..5),
    ) {
        let packet = OscPacket::Message(OscMessage { addr: address.into(), args });
        check_osc(&rosc::encoder::encode(&packet).unwrap())?;
    }

    #[test]
    fn axis_from_arbitrary_text(text in prop_oneof![any::<String>(), "[ +-]{0,2}[xyzXYZw]{0,2} ?"]) {
        match text.parse::<Axis>() {
            Ok(axis) => prop_assert_eq!(axis.to_string().parse::<Axis>(), Ok(axis)),
            Err(error) => {
                let quoted = format!("{text:?}");
                prop_assert!(error.to_string().contains(&quoted));
            }
        }
    }
}

// Every kind of packet at once (the libFuzzer target `osc_packet`, fuzz/, searches further with
// coverage guidance).

#[test]
fn fuzz_osc_packets() {
    let valid = valid_osc();
    let keep_limit = valid.len() + 8;
    let known = (
        prop::sample::select(vec![
            "/sakeglug/tilt",
            "/sakeglug/viscosity",
            "/sakeglug/fill",
            "/sakeglug/refill",
            "/gyrosc/grav",
            "/accxyz",
            "/gravity",
            "/acceleration",
        ]),
        prop::collection::vec(osc_argument(), 0..5),
    )
        .prop_map(|(address, args)| {
            let packet = OscPacket::Message(OscMessage {
                addr: address.into(),
                args,
            });
            rosc::encoder::encode(&packet).unwrap()
        });
    let packets = prop_oneof![
        prop::collection::vec(any::<u8>(), 0..256),
        (edits(), any::<usize>()).prop_map(move |(edits, keep)| mutate(
            valid.clone(),
            &edits,
            keep % keep_limit
        )),
        known,
    ];
    crate::support::fuzz::run("OSC packets (decode_osc)", packets, |packet| {
        check_osc(&packet)
    });
}
