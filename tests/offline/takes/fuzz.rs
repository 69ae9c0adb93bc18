//! Properties over arbitrary and mutated input: the readers never panic, and whatever they
//! return is either well-formed or an error with a message.
//!
//! The case count is proptest's: 256 unless the `PROPTEST_CASES` environment variable says
//! otherwise (e.g. `PROPTEST_CASES=100000 cargo test --release --test offline takes::fuzz`).

use std::path::Path;

use midly::num::{u15, u24, u28, u4, u7};
use midly::{Format, Header, MetaMessage, MidiMessage, Smf, Timing, TrackEvent, TrackEventKind};
use proptest::prelude::*;

use crate::support::fuzz::{edits, mutate};

use sake_glug_device::axis::Axis;
use sake_glug_device::csv_lane::{read_csv_lane, CsvLaneSpec};
use sake_glug_device::midi_take::read_midi_take;

/// A format 1 take with a tempo map, CCs, note-ons and a note-off.
fn valid_midi() -> Vec<u8> {
    let event = |delta: u32, kind| TrackEvent {
        delta: u28::new(delta),
        kind,
    };
    let midi = |message| TrackEventKind::Midi {
        channel: u4::new(2),
        message,
    };
    let end = || event(0, TrackEventKind::Meta(MetaMessage::EndOfTrack));
    let mut smf = Smf::new(Header::new(
        Format::Parallel,
        Timing::Metrical(u15::new(96)),
    ));
    smf.tracks.push(vec![
        event(
            0,
            TrackEventKind::Meta(MetaMessage::Tempo(u24::new(400_000))),
        ),
        event(
            200,
            TrackEventKind::Meta(MetaMessage::Tempo(u24::new(700_000))),
        ),
        end(),
    ]);
    let cc = |controller: u8, value: u8| MidiMessage::Controller {
        controller: u7::new(controller),
        value: u7::new(value),
    };
    let note = |vel: u8| MidiMessage::NoteOn {
        key: u7::new(64),
        vel: u7::new(vel),
    };
    smf.tracks.push(vec![
        event(10, midi(cc(16, 100))),
        event(0, midi(cc(48, 5))),
        event(150, midi(note(90))),
        event(100, midi(note(0))),
        event(1, midi(cc(17, 3))),
        end(),
    ]);
    let mut bytes = Vec::new();
    smf.write_std(&mut bytes).unwrap();
    bytes
}

const VALID_CSV: &str =
    "time_s,ax,ay,az,fill\n0,0,0,9.8,100\n0.5,1,0,1,90\n0.5,-1,2,3,80\n2,0.1,0,-9,0\n";

fn csv_specs() -> [CsvLaneSpec; 3] {
    [
        CsvLaneSpec::Column("fill".into()),
        CsvLaneSpec::Column("time_s".into()),
        CsvLaneSpec::Gravity {
            columns: ["ax".into(), "ay".into(), "az".into()],
            axis: Axis::MinusZ,
        },
    ]
}

fn check_midi(bytes: &[u8], sample_rate: u32) -> Result<(), TestCaseError> {
    match read_midi_take(bytes, sample_rate) {
        Ok(take) => {
            prop_assert!(take.windows(2).all(|pair| pair[0].sample <= pair[1].sample));
        }
        Err(error) => {
            let message = error.to_string();
            prop_assert!(!message.is_empty());
            prop_assert!(!message.contains(char::is_control), "{message:?}");
        }
    }
    Ok(())
}

fn check_csv(text: &str) -> Result<(), TestCaseError> {
    for spec in csv_specs() {
        match read_csv_lane(text, Path::new("fuzz.csv"), &spec) {
            Ok(points) => {
                prop_assert!(!points.is_empty());
                prop_assert!(points
                    .iter()
                    .all(|(t, v)| *t >= 0.0 && t.is_finite() && v.is_finite()));
                prop_assert!(points.windows(2).all(|pair| pair[0].0 <= pair[1].0));
            }
            Err(error) => {
                let message = error.to_string();
                prop_assert!(message.starts_with("fuzz.csv, line "));
                prop_assert!(!message.contains(char::is_control), "{message:?}");
            }
        }
    }
    Ok(())
}

proptest! {
    // ProptestConfig::default() reads PROPTEST_CASES, else runs 256 cases.
    #![proptest_config(ProptestConfig::default())]

    #[test]
    fn midi_from_arbitrary_bytes(bytes in prop::collection::vec(any::<u8>(), 0..256)) {
        check_midi(&bytes, 48_000)?;
    }

    #[test]
    fn midi_with_a_valid_header_and_arbitrary_tracks(
        division in any::<u16>(),
        body in prop::collection::vec(any::<u8>(), 0..256),
    ) {
        let mut bytes = b"MThd\0\0\0\x06\0\x01\0\x02".to_vec();
        bytes.extend(division.to_be_bytes());
        bytes.extend(b"MTrk");
        bytes.extend((body.len() as u32).to_be_bytes());
        bytes.extend(body);
        check_midi(&bytes, 44_100)?;
    }

    #[test]
    fn midi_mutated_from_a_valid_take(
        edits in edits(),
        keep in any::<usize>(),
        sample_rate in any::<u32>(),
    ) {
        let valid = valid_midi();
        let keep = keep % (valid.len() + 8);
        check_midi(&mutate(valid, &edits, keep), sample_rate)?;
    }

    #[test]
    fn csv_from_arbitrary_text(
        header in prop_oneof![Just(""), Just("time_s,ax,ay,az,fill\n")],
        text in "(?s).{0,200}",
    ) {
        check_csv(&format!("{header}{text}"))?;
    }

    #[test]
    fn csv_from_rows_of_number_like_fields(
        header in prop::sample::select(vec![
            "time_s,ax,ay,az,fill", " time_s , ax,ay,az,fill", "time_s,ax,ay,fill,az,ax", "fill,time_s",
        ]),
        rows in prop::collection::vec(
            prop::collection::vec("[-+]?[0-9]{0,3}(\\.[0-9]{0,2})?(e[-+]?[0-9]{1,3})?|nan|inf| |x", 1..7),
            0..6,
        ),
        line_break in prop::sample::select(vec!["\n", "\r\n", "\r", "\n\n"]),
    ) {
        let mut text = header.to_owned();
        for row in rows {
            text.push_str(line_break);
            text.push_str(&row.join(","));
        }
        check_csv(&text)?;
    }

    #[test]
    fn csv_mutated_from_a_valid_lane(edits in edits(), keep in any::<usize>()) {
        let mutated = mutate(VALID_CSV.as_bytes().to_vec(), &edits, keep % (VALID_CSV.len() + 8));
        check_csv(&String::from_utf8_lossy(&mutated))?;
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

// The properties above, over every kind of input at once (the libFuzzer targets `midi_take` and
// `csv_lane`, fuzz/, search further with coverage guidance).

#[test]
fn fuzz_midi_take_files() {
    let valid = valid_midi();
    let keep_limit = valid.len() + 8;
    let bytes = prop_oneof![
        prop::collection::vec(any::<u8>(), 0..256),
        (edits(), any::<usize>()).prop_map(move |(edits, keep)| mutate(
            valid.clone(),
            &edits,
            keep % keep_limit
        )),
    ];
    crate::support::fuzz::run("MIDI take files (read_midi_take)", bytes, |bytes| {
        check_midi(&bytes, 48_000)
    });
}

#[test]
fn fuzz_csv_lanes() {
    let text = prop_oneof![
        "(?s).{0,200}".prop_map(|text| format!("time_s,ax,ay,az,fill\n{text}")),
        (edits(), any::<usize>()).prop_map(|(edits, keep)| {
            let mutated = mutate(
                VALID_CSV.as_bytes().to_vec(),
                &edits,
                keep % (VALID_CSV.len() + 8),
            );
            String::from_utf8_lossy(&mutated).into_owned()
        }),
    ];
    crate::support::fuzz::run("CSV lanes (read_csv_lane)", text, |text| check_csv(&text));
}
