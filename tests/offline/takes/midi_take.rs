//! Standard MIDI File takes: exact sample placement, merging, the tempo map, and refusals.

use midly::num::{u15, u24, u28, u4, u7};
use midly::{
    Format, Fps, Header, MetaMessage, MidiMessage, Smf, Timing, TrackEvent, TrackEventKind,
};
use proptest::prelude::*;

use sake_glug_device::midi::MidiInput;
use sake_glug_device::midi_take::{read_midi_take, TakeError, TimedInput, MAX_TAKE_SECONDS};

/// A file of `tracks`, each a list of (delta ticks, event), End of Track added.
fn smf(format: Format, timing: Timing, tracks: &[Vec<(u32, TrackEventKind<'static>)>]) -> Vec<u8> {
    let mut file = Smf::new(Header::new(format, timing));
    for track in tracks {
        let mut events: Vec<TrackEvent> = track
            .iter()
            .map(|&(delta, kind)| TrackEvent {
                delta: u28::new(delta),
                kind,
            })
            .collect();
        events.push(TrackEvent {
            delta: u28::new(0),
            kind: TrackEventKind::Meta(MetaMessage::EndOfTrack),
        });
        file.tracks.push(events);
    }
    let mut bytes = Vec::new();
    file.write_std(&mut bytes).unwrap();
    bytes
}

fn ppq(ticks_per_quarter: u16) -> Timing {
    Timing::Metrical(u15::new(ticks_per_quarter))
}

fn cc(channel: u8, controller: u8, value: u8) -> TrackEventKind<'static> {
    TrackEventKind::Midi {
        channel: u4::new(channel),
        message: MidiMessage::Controller {
            controller: u7::new(controller),
            value: u7::new(value),
        },
    }
}

fn note_on(channel: u8, velocity: u8) -> TrackEventKind<'static> {
    TrackEventKind::Midi {
        channel: u4::new(channel),
        message: MidiMessage::NoteOn {
            key: u7::new(60),
            vel: u7::new(velocity),
        },
    }
}

fn tempo(us_per_quarter: u32) -> TrackEventKind<'static> {
    TrackEventKind::Meta(MetaMessage::Tempo(u24::new(us_per_quarter)))
}

fn cc_input(channel: u8, cc: u8, value: u8) -> MidiInput {
    MidiInput::Cc { channel, cc, value }
}

fn samples(inputs: &[TimedInput]) -> Vec<u64> {
    inputs.iter().map(|timed| timed.sample).collect()
}

#[test]
fn format_0_places_messages_on_their_first_sample() {
    // 480 ticks per quarter at the default 500 000 µs: a tick is 1/960 s, 50 samples at 48 kHz
    // and 45.9375 at 44.1 kHz.
    let bytes = smf(
        Format::SingleTrack,
        ppq(480),
        &[vec![
            (0, cc(0, 16, 1)),
            // On a boundary: 31 ticks are exactly 1550 samples, where floats give 1551.
            (31, cc(0, 16, 2)),
            // Velocity 0 is a note-off, and dropped.
            (1, note_on(3, 0)),
            (0, note_on(15, 100)),
            (
                0,
                TrackEventKind::Midi {
                    channel: u4::new(0),
                    message: MidiMessage::PitchBend {
                        bend: midly::PitchBend::from_int(0),
                    },
                },
            ),
        ]],
    );
    let take = read_midi_take(&bytes, 48_000).unwrap();
    assert_eq!(
        take,
        vec![
            TimedInput {
                sample: 0,
                input: cc_input(0, 16, 1)
            },
            TimedInput {
                sample: 1550,
                input: cc_input(0, 16, 2)
            },
            TimedInput {
                sample: 1600,
                input: MidiInput::NoteOn { channel: 15 }
            },
        ]
    );
    // Between samples: 31 ticks are 1424.0625 samples, 32 are 1470.
    assert_eq!(
        samples(&read_midi_take(&bytes, 44_100).unwrap()),
        [0, 1425, 1470]
    );
}

#[test]
fn format_1_follows_a_tempo_change_in_another_track_and_merges_in_order() {
    let conductor = vec![(0, tempo(500_000)), (480, tempo(250_000)), (0, cc(9, 1, 1))];
    let controls = vec![
        // 0.5 s + 1/1920 s: 24 025 samples at 48 kHz; 22 072.97 at 44.1 kHz.
        (481, cc(0, 16, 10)),
        // 0.75 s: on a boundary at both rates.
        (479, cc(0, 17, 20)),
        // At the same tick as the tempo change: after track 1's CC there.
        (0, cc(0, 18, 30)),
    ];
    let mut controls_first_at_480 = vec![(480, cc(1, 2, 2))];
    controls_first_at_480.extend([(1, cc(0, 16, 10)), (479, cc(0, 17, 20))]);
    let bytes = smf(Format::Parallel, ppq(480), &[conductor, controls]);
    let take = read_midi_take(&bytes, 48_000).unwrap();
    assert_eq!(samples(&take), [24_000, 24_025, 36_000, 36_000]);
    assert_eq!(take[0].input, cc_input(9, 1, 1));
    assert_eq!(take[2].input, cc_input(0, 17, 20));
    assert_eq!(take[3].input, cc_input(0, 18, 30));
    assert_eq!(
        samples(&read_midi_take(&bytes, 44_100).unwrap()),
        [22_050, 22_073, 33_075, 33_075]
    );

    // Equal times: track order first, then file order within a track.
    let bytes = smf(
        Format::Parallel,
        ppq(480),
        &[
            vec![(480, tempo(250_000)), (0, cc(9, 1, 1))],
            controls_first_at_480,
        ],
    );
    let take = read_midi_take(&bytes, 48_000).unwrap();
    let order: Vec<MidiInput> = take.iter().map(|timed| timed.input).collect();
    assert_eq!(
        order,
        [
            cc_input(9, 1, 1),
            cc_input(1, 2, 2),
            cc_input(0, 16, 10),
            cc_input(0, 17, 20)
        ]
    );
    assert_eq!(samples(&take), [24_000, 24_000, 24_025, 36_000]);
}

#[test]
fn smpte_timing_counts_fixed_ticks_and_ignores_tempo() {
    // 25 fps × 40 ticks: a tick is 1 ms.
    let bytes = smf(
        Format::SingleTrack,
        Timing::Timecode(Fps::Fps25, 40),
        &[vec![(0, tempo(250_000)), (3, cc(0, 16, 1))]],
    );
    assert_eq!(samples(&read_midi_take(&bytes, 48_000).unwrap()), [144]);
    // 29.97 fps is 30000/1001: 30 frames last 1.001 s.
    let bytes = smf(
        Format::SingleTrack,
        Timing::Timecode(Fps::Fps29, 2),
        &[vec![(60, cc(0, 16, 1)), (1, cc(0, 16, 2))]],
    );
    // 1.001 s exactly, then 1.001 s + 1001/60000 s = 48 048.8 samples.
    assert_eq!(
        samples(&read_midi_take(&bytes, 48_000).unwrap()),
        [48_048, 48_849]
    );
}

#[test]
fn garbage_truncated_and_format_2_files_are_refused_clearly() {
    let message = |bytes: &[u8]| read_midi_take(bytes, 48_000).unwrap_err().to_string();

    let garbage = message(b"this is a CSV file, not MIDI");
    assert!(
        garbage.starts_with("not a Standard MIDI File: invalid midi"),
        "{garbage}"
    );
    assert!(message(&[]).starts_with("not a Standard MIDI File"));
    assert!(message(b"RIFF\0\0\0\0RMIDdata").contains("RIFF"));

    let whole = smf(
        Format::Parallel,
        ppq(480),
        &[
            vec![(0, tempo(500_000))],
            vec![(10, cc(0, 16, 1)), (10, cc(0, 16, 2))],
        ],
    );
    assert_eq!(read_midi_take(&whole, 48_000).unwrap().len(), 2);
    let cut = message(&whole[..whole.len() - 3]);
    assert!(
        cut.starts_with("truncated MIDI file: track 2 declares"),
        "{cut}"
    );
    let cut_in_header = message(&whole[..10]);
    assert!(
        cut_in_header.starts_with("not a Standard MIDI File"),
        "{cut_in_header}"
    );
    // The header (14 bytes), track 1 (8 + 11) from byte 14, track 2 (8 + 11) from byte 33.
    assert_eq!(whole.len(), 52);
    let cut = message(&whole[..33 + 4]);
    assert!(
        cut.contains("ends 4 bytes into the header of chunk 3"),
        "{cut}"
    );
    let cut = message(&whole[..33]);
    assert!(
        cut.contains("the header declares 2 tracks but the file holds 1"),
        "{cut}"
    );
    // A chunk of another type, cut short, is named by its type with control bytes escaped.
    let mut odd_chunk = whole[..33].to_vec();
    odd_chunk.extend(b"\x1b]0;\0\0\0\x10");
    let cut = message(&odd_chunk);
    assert!(
        cut.ends_with("chunk 3 (\\u{1b}]0;) declares 16 bytes but only 0 remain"),
        "{cut}"
    );

    // A corrupt event inside a whole chunk: track 2's first status byte made undefined.
    let mut corrupt = whole.clone();
    assert_eq!(corrupt[33 + 8 + 1], 0xB0);
    corrupt[33 + 8 + 1] = 0xF4;
    let corrupt = message(&corrupt);
    assert!(
        corrupt.starts_with("track 2: the event at byte 0"),
        "{corrupt}"
    );

    let sequential = smf(Format::Sequential, ppq(480), &[vec![(0, cc(0, 16, 1))]]);
    assert_eq!(
        read_midi_take(&sequential, 48_000),
        Err(TakeError::SequentialFormat)
    );
    assert!(message(&sequential).contains("format 2 (sequential)"));

    let zero_ppq = smf(Format::SingleTrack, ppq(0), &[vec![(0, cc(0, 16, 1))]]);
    assert_eq!(read_midi_take(&zero_ppq, 48_000), Err(TakeError::ZeroPpq));
    let zero_frame = smf(
        Format::SingleTrack,
        Timing::Timecode(Fps::Fps30, 0),
        &[vec![(0, cc(0, 16, 1))]],
    );
    assert_eq!(
        read_midi_take(&zero_frame, 48_000),
        Err(TakeError::ZeroTicksPerFrame)
    );
    let stopped = smf(Format::SingleTrack, ppq(480), &[vec![(5, tempo(0))]]);
    assert_eq!(
        read_midi_take(&stopped, 48_000),
        Err(TakeError::ZeroTempo { track: 1, tick: 5 })
    );
    assert_eq!(read_midi_take(&whole, 0), Err(TakeError::ZeroSampleRate));

    // An SMPTE rate byte of 0x80 made midly overflow negating it (found by the fuzz tests).
    let mut odd_rate = whole.clone();
    odd_rate[12] = 0x80;
    assert_eq!(
        read_midi_take(&odd_rate, 48_000),
        Err(TakeError::BadFrameRate { byte: 0x80 })
    );
    odd_rate[12] = 0xE0;
    assert!(message(&odd_rate).contains("frame rate byte 0xe0"));
}

#[test]
fn takes_past_a_day_are_refused() {
    // A quarter note of 16.7 s at 1 tick per quarter: 2²⁸ − 1 ticks are about 142 years.
    let bytes = smf(
        Format::SingleTrack,
        ppq(1),
        &[vec![(0, tempo(0xFF_FFFF)), ((1 << 28) - 1, cc(0, 16, 1))]],
    );
    let error = read_midi_take(&bytes, 48_000).unwrap_err();
    assert!(
        matches!(error, TakeError::TooLong { track: 1, .. }),
        "{error}"
    );
    assert!(
        error.to_string().contains("past the 86400 s limit"),
        "{error}"
    );
    // Under a day is read: 5399 quarter notes of 16 s are 86 384 s.
    let bytes = smf(
        Format::SingleTrack,
        ppq(1),
        &[vec![(0, tempo(16_000_000)), (5_399, cc(0, 16, 1))]],
    );
    assert_eq!(samples(&read_midi_take(&bytes, 1).unwrap()), [86_384]);
}

proptest! {
    /// Each message lands on the first sample at or after its time, whatever the division,
    /// tempo and rate: sample − 1 < t · fs ≤ sample, checked in integers.
    #[test]
    fn a_message_lands_on_the_first_sample_at_or_after_it(
        ticks_per_quarter in 1_u16..=0x7FFF,
        tempo_us in 1_u32..=0xFF_FFFF,
        sample_rate in 1_u32..=384_000,
        delta in prop_oneof![0_u32..100_000, 0_u32..(1 << 28)],
    ) {
        let bytes = smf(
            Format::SingleTrack,
            ppq(ticks_per_quarter),
            &[vec![(0, tempo(tempo_us)), (delta, cc(0, 16, 1))]],
        );
        // t · fs · ppq · 10⁶, and the same for a sample's time.
        let time = u128::from(delta) * u128::from(tempo_us) * u128::from(sample_rate);
        let unit = u128::from(ticks_per_quarter) * 1_000_000;
        let result = read_midi_take(&bytes, sample_rate);
        if time > u128::from(MAX_TAKE_SECONDS) * u128::from(sample_rate) * unit {
            prop_assert!(matches!(result, Err(TakeError::TooLong { .. })), "{result:?}");
            return Ok(());
        }
        let sample = u128::from(result.unwrap()[0].sample);
        prop_assert!(sample * unit >= time);
        prop_assert!(sample == 0 || (sample - 1) * unit < time);
    }
}
