//! One MIDI decoder for the plugin and the renderer: a recorded take rendered offline gives the
//! samples the plugin gives, through its real `process()`, when the same messages arrive at the
//! same sample offsets. The channel filter holds for note-ons too.

use midly::num::{u15, u24, u28, u4, u7};
use midly::{Format, Header, MetaMessage, MidiMessage, Smf, Timing, TrackEvent, TrackEventKind};
use nice_plug::prelude::*;
use sake_glug_device::midi::{MidiInput, MidiMap};
use sake_glug_plugin::SakeGlug;
use sake_glug_render::{render_scene_to_vec, Scene};

use crate::host::{Playhead, TestHost};

const PPQ: u16 = 480;

fn cc_event(delta: u32, channel: u8, controller: u8, value: u8) -> TrackEvent<'static> {
    TrackEvent {
        delta: u28::new(delta),
        kind: TrackEventKind::Midi {
            channel: u4::new(channel),
            message: MidiMessage::Controller {
                controller: u7::new(controller),
                value: u7::new(value),
            },
        },
    }
}

fn note_on_event(delta: u32, channel: u8) -> TrackEvent<'static> {
    TrackEvent {
        delta: u28::new(delta),
        kind: TrackEventKind::Midi {
            channel: u4::new(channel),
            message: MidiMessage::NoteOn {
                key: u7::new(60),
                vel: u7::new(100),
            },
        },
    }
}

/// A take as a tilt device records it: a tempo change in track 1; in track 2, 14-bit tilt
/// rising from 90° to 140° in steps of 37 ticks (not on sample boundaries), a viscosity CC, a
/// note-on on another channel (filtered out) and a refill on the device's channel.
fn take() -> Vec<u8> {
    let end = TrackEvent {
        delta: u28::new(0),
        kind: TrackEventKind::Meta(MetaMessage::EndOfTrack),
    };
    let tempo = |delta: u32, us: u32| TrackEvent {
        delta: u28::new(delta),
        kind: TrackEventKind::Meta(MetaMessage::Tempo(u24::new(us))),
    };
    let tempo_track = vec![tempo(0, 500_000), tempo(600, 430_000), end];
    let mut device = Vec::new();
    for step in 0..=40u32 {
        let position = (90.0 + 50.0 * step as f64 / 40.0) / 180.0 * 16383.0;
        let position = position.round() as u32;
        device.push(cc_event(
            if step == 0 { 0 } else { 37 },
            2,
            16,
            (position >> 7) as u8,
        ));
        device.push(cc_event(0, 2, 48, (position & 127) as u8));
    }
    device.push(cc_event(200, 2, 17, 90));
    device.push(note_on_event(900, 5));
    device.push(note_on_event(1500, 2));
    device.push(end);
    let smf = Smf {
        header: Header::new(Format::Parallel, Timing::Metrical(u15::new(PPQ))),
        tracks: vec![tempo_track, device],
    };
    let mut bytes = Vec::new();
    smf.write_std(&mut bytes).unwrap();
    bytes
}

fn plugin_event(sample_in_block: u32, input: MidiInput) -> PluginNoteEvent<SakeGlug> {
    match input {
        MidiInput::NoteOn { channel } => NoteEvent::NoteOn {
            timing: sample_in_block,
            voice_id: nice_plug::midi::VoiceID::Wildcard,
            channel: nice_plug::midi::Channel::Number(channel),
            key: nice_plug::midi::Key::Number(60),
            velocity: 0.8,
        },
        MidiInput::Cc { channel, cc, value } => NoteEvent::MidiCC {
            timing: sample_in_block,
            channel,
            cc,
            value: value as f32 / 127.0,
        },
    }
}

#[test]
fn a_take_rendered_offline_equals_the_plugin_fed_the_same_messages() {
    let directory = tempfile::tempdir().unwrap();
    std::fs::write(directory.path().join("take.mid"), take()).unwrap();
    let scene = Scene::parse_in(
        "duration_s = 6.0\nmidi_take = \"take.mid\"\n[midi]\nmidi_channel = 2\n",
        directory.path(),
    )
    .unwrap();
    let events = &scene.take.as_ref().unwrap().events;
    assert_eq!(events.len(), 2 * 41 + 3);
    let (offline, _) = render_scene_to_vec(&scene).unwrap();
    assert!(offline.iter().any(|y| y.abs() > 0.05), "the take pours");

    for block in [64, 511, 4096] {
        let mut host = TestHost::new(scene.sample_rate as f32, 1);
        host.plugin.glug_params().set_midi_map(MidiMap {
            channel: Some(2),
            ..MidiMap::default()
        });
        let mut plugin = Vec::new();
        let mut next = 0;
        while plugin.len() < offline.len() {
            let start = plugin.len() as u64;
            let len = block.min(offline.len() - plugin.len());
            let mut block_events = Vec::new();
            while let Some(event) = events.get(next).filter(|e| e.sample < start + len as u64) {
                block_events.push(plugin_event((event.sample - start) as u32, event.input));
                next += 1;
            }
            plugin.extend_from_slice(&host.process(len, block_events, Playhead::default())[0]);
        }
        let first_difference = offline.iter().zip(&plugin).position(|(a, b)| a != b);
        assert_eq!(
            first_difference, None,
            "block {block}: the plugin differs from the offline render"
        );
    }
}

#[test]
fn a_note_on_on_another_channel_does_not_refill() {
    let mut host = TestHost::new(48_000.0, 1);
    host.plugin.glug_params().set_midi_map(MidiMap {
        channel: Some(2),
        ..MidiMap::default()
    });
    host.set_text("tilt", "135");
    host.render_mono(48_000 * 6, 4096);
    let empty = host.plugin.renderer().unwrap().engine().volume_ml();
    assert!(empty < 90.0, "the bottle poured out: {empty} ml left");
    let other_channel = plugin_event(0, MidiInput::NoteOn { channel: 5 });
    host.process(64, vec![other_channel], Playhead::default());
    let after = host.plugin.renderer().unwrap().engine().volume_ml();
    assert!(
        after <= empty,
        "a note-on on channel 6 refilled: {after} ml"
    );
    let own_channel = plugin_event(0, MidiInput::NoteOn { channel: 2 });
    host.process(64, vec![own_channel], Playhead::default());
    let refilled = host.plugin.renderer().unwrap().engine().volume_ml();
    assert!(
        refilled > 290.0,
        "a note-on on channel 3 refills: {refilled} ml"
    );
}
