//! MIDI from the tilt device: 14-bit and 7-bit CCs, channel filter, saved settings, and the rule
//! that whichever moved last (the device or the host's parameter) decides.

use std::sync::atomic::Ordering::Relaxed;

use crate::clap_host::{ClapInstance, MidiCc};
use crate::fuzz::checks::{bytes_of, json_of};
use crate::host::{cc, note_on, peak, Playhead, TestHost};
use nice_plug::prelude::Params;
use sake_glug_device::midi::MidiSetting;
use sake_glug_device::midi::{CcDecoder, MidiMap, Overrides};
use sake_glug_engine::{Control, ControlValues, PerControl};

/// A map with these CCs for tilt (MSB, LSB), viscosity and fill.
fn map_of(channel: Option<u8>, [tilt, tilt_lsb, viscosity, fill]: [Option<u8>; 4]) -> MidiMap {
    MidiMap {
        channel,
        cc: PerControl {
            tilt_deg: tilt,
            viscosity,
            fill_percent: fill,
            pour_time_s: None,
            gain_db: None,
        },
        tilt_lsb,
    }
}

/// Tilt, viscosity and fill as given, the rest at their defaults.
fn values(tilt_deg: f64, viscosity: f64, fill_percent: f64) -> ControlValues {
    ControlValues {
        tilt_deg,
        viscosity,
        fill_percent,
        ..ControlValues::default()
    }
}

#[test]
fn fourteen_bit_tilt_assembles_msb_and_lsb() {
    let map = MidiMap::default();
    let mut decoder = CcDecoder::default();
    let lsb = map.tilt_lsb.expect("14-bit by default");
    assert_eq!(
        decoder.feed(&map, 0, lsb, 5),
        None,
        "an LSB before any MSB only waits"
    );
    let (target, coarse) = decoder.feed(&map, 0, 16, 96).expect("tilt MSB");
    assert_eq!(target, Control::Tilt);
    assert_eq!(
        coarse,
        ((96 << 7) + 5) as f64 / 16383.0 * 180.0,
        "the MSB applies with the last LSB"
    );
    let (_, fine) = decoder.feed(&map, 0, lsb, 64).expect("tilt LSB");
    assert_eq!(fine, ((96 << 7) + 64) as f64 / 16383.0 * 180.0);
    // A host that drops the unchanged LSB still gives the exact angle.
    let (_, next) = decoder.feed(&map, 0, 16, 97).expect("tilt MSB");
    assert_eq!(next, ((97 << 7) + 64) as f64 / 16383.0 * 180.0);
    decoder.reset();
    assert_eq!(
        decoder.feed(&map, 0, lsb, 9),
        None,
        "a reset forgets the MSB"
    );
    let (_, top) = {
        decoder.feed(&map, 0, 16, 127);
        decoder.feed(&map, 0, lsb, 127).expect("tilt LSB")
    };
    assert_eq!(
        top, 180.0,
        "the full 14-bit value reaches the end of the range"
    );
}

#[test]
fn seven_bit_ccs_and_channel_filter() {
    let map = MidiMap {
        channel: Some(2),
        tilt_lsb: None,
        ..MidiMap::default()
    };
    let mut decoder = CcDecoder::default();
    assert_eq!(decoder.feed(&map, 2, 16, 127), Some((Control::Tilt, 180.0)));
    assert_eq!(
        decoder.feed(&map, 2, 17, 0),
        Some((Control::Viscosity, 0.0))
    );
    assert_eq!(decoder.feed(&map, 2, 18, 127), Some((Control::Fill, 100.0)));
    assert_eq!(
        decoder.feed(&map, 3, 16, 64),
        None,
        "another channel is ignored"
    );
    assert_eq!(
        decoder.feed(&map, 2, 48, 64),
        None,
        "no LSB mapped in 7-bit mode"
    );
    assert_eq!(
        decoder.feed(&map, 2, 7, 64),
        None,
        "an unmapped CC is ignored"
    );
}

#[test]
fn saved_settings_round_trip_and_out_of_range_bytes_switch_off() {
    let map = map_of(Some(15), [Some(1), Some(33), None, Some(0)]);
    assert_eq!(MidiMap::from_raw(map.to_raw()), map);
    let garbage = MidiMap::from_raw([16, 128, 200, 127, 255]);
    assert_eq!(garbage, map_of(None, [None, None, Some(127), None]));
}

#[test]
fn whichever_moved_last_wins() {
    let mut overrides = Overrides::default();
    assert_eq!(
        overrides.apply(values(90.0, 0.33, 100.0)),
        values(90.0, 0.33, 100.0)
    );
    overrides.set(Control::Tilt, 135.0);
    assert_eq!(
        overrides.apply(values(90.0, 0.33, 100.0)),
        values(135.0, 0.33, 100.0),
        "the device moved last"
    );
    assert_eq!(
        overrides.apply(values(90.0, 0.33, 100.0)),
        values(135.0, 0.33, 100.0),
        "and stays in charge"
    );
    assert_eq!(
        overrides.apply(values(100.0, 0.33, 100.0)),
        values(100.0, 0.33, 100.0),
        "the host moved the parameter"
    );
}

#[test]
fn ccs_drive_the_plugin_and_a_note_on_refills() {
    let mut host = TestHost::new(48_000.0, 2);
    // Tilt 135° from the device, 14-bit: 135/180·16383 = 12287 = MSB 95, LSB 127.
    host.process(
        64,
        vec![cc(0, 0, 16, 95), cc(1, 0, 48, 127)],
        Playhead::default(),
    );
    let tilt = host.plugin.feed().tilt_deg.load(Relaxed);
    assert!((tilt - 135.0).abs() < 0.02, "tilt from MIDI: {tilt}");
    let out = host.render_mono(48_000 * 2, 512);
    assert!(crate::host::peak(&out) > 0.05, "the device's tilt pours");
    let drained = host.plugin.renderer().expect("active").engine().volume_ml();
    host.process(64, vec![note_on(10)], Playhead::default());
    let refilled = host.plugin.renderer().expect("active").engine().volume_ml();
    assert!(
        refilled > drained,
        "note-on refills: {drained} -> {refilled}"
    );
    // Settings changed in the saved state take effect: the device on CC 1, 7-bit.
    let mut map = MidiMap::default();
    map.cc[Control::Tilt] = Some(1);
    map.tilt_lsb = None;
    host.plugin.glug_params().set_midi_map(map);
    host.process(64, vec![cc(0, 9, 1, 0)], Playhead::default());
    assert_eq!(host.plugin.feed().tilt_deg.load(Relaxed), 0.0);
}

/// MIDI learn: Tilt's row is armed (as the editor's Learn button or the app's `--learn` arms
/// it; nothing in the CLAP or VST3 interface can), the next CC is taken with its channel, the
/// tilt follows it, the saved state keeps it, and a CLAP instance that loads that state through
/// the CLAP state extension pours when a host passes that CC as a CLAP MIDI event.
#[test]
fn midi_learn_takes_the_next_cc_and_its_channel_and_the_state_keeps_it() {
    let mut host = TestHost::new(48_000.0, 2);
    let params = host.plugin.glug_params().clone();
    params.learn.arm(MidiSetting::Cc(Control::Tilt));
    // The device sends CC 20 on channel 4 (3 from 0), 7-bit value 96; 14-bit tilt keeps its
    // LSB CC, whose last value (none yet: 0) completes the angle.
    host.process(64, vec![cc(10, 3, 20, 96)], Playhead::default());
    let map = params.midi_map();
    assert_eq!(map.cc[Control::Tilt], Some(20));
    assert_eq!(map.channel, Some(3));
    assert_eq!(params.learn.armed(), None, "one CC is learnt");
    let tilt = |host: &TestHost| host.plugin.feed().tilt_deg.load(Relaxed) as f64;
    let expected = |msb: u32| (msb << 7) as f64 / 16383.0 * 180.0;
    assert!((tilt(&host) - expected(96)).abs() < 1e-4, "{}", tilt(&host));
    // The tilt follows the learnt CC from then on, and no longer the old one.
    host.process(64, vec![cc(0, 3, 20, 40)], Playhead::default());
    assert!((tilt(&host) - expected(40)).abs() < 1e-4, "{}", tilt(&host));
    host.process(64, vec![cc(0, 3, 16, 100)], Playhead::default());
    assert!(
        (tilt(&host) - expected(40)).abs() < 1e-4,
        "CC 16 is not tilt any more"
    );
    // Another channel is not listened to.
    host.process(64, vec![cc(0, 0, 20, 100)], Playhead::default());
    assert!(
        (tilt(&host) - expected(40)).abs() < 1e-4,
        "channel 1 is not listened to"
    );
    let fields = params.serialize_fields();
    assert_eq!(fields["midi_cc_tilt"], "20");
    assert_eq!(fields["midi_channel"], "3");

    // The learnt map through the CLAP state extension, as a host saves and reopens a project.
    let learnt = ClapInstance::new();
    let mut json = json_of(&learnt.save());
    for (key, value) in &fields {
        json["fields"][key] = serde_json::Value::String(value.clone());
    }
    assert!(learnt.load(&bytes_of(&json)));
    let saved = json_of(&learnt.save());
    assert_eq!(saved["fields"]["midi_cc_tilt"], "20");
    assert_eq!(saved["fields"]["midi_channel"], "3");
    let mut reopened = ClapInstance::new();
    assert!(reopened.load(&learnt.save()));
    reopened.activate(48_000.0);
    // 135° on the learnt CC (7-bit MSB 96 → 135.0°) pours; the same on the old CC 16 does not.
    let on = |cc| {
        [MidiCc {
            at: 0,
            channel: 3,
            cc,
            value: 96,
        }]
    };
    let poured = reopened.render_midi(48_000, 512, &on(20));
    assert!(peak(&poured) > 0.05, "the learnt CC tilts the bottle");
    let mut other = ClapInstance::new();
    assert!(other.load(&learnt.save()));
    other.activate(48_000.0);
    let upright = other.render_midi(48_000, 512, &on(16));
    assert_eq!(peak(&upright), 0.0, "the old CC does not");
}

#[test]
fn learning_a_cc_another_row_had_unmaps_that_row() {
    let mut map = MidiMap::default();
    map.learn(MidiSetting::Cc(Control::Tilt), 0, 17);
    assert_eq!(map.cc[Control::Tilt], Some(17));
    assert_eq!(map.cc[Control::Viscosity], None, "CC 17 was viscosity's");
    assert_eq!(map.channel, Some(0));
    map.learn(MidiSetting::TiltLsb, 15, 49);
    assert_eq!((map.tilt_lsb, map.channel), (Some(49), Some(15)));
}
