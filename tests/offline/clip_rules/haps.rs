//! Validator of Interhaptics' `.haps` (Razer Haptic Composer, version 5), from the shape
//! Haptic Composer writes and its SDKs read (`m_version`, the three perceptions, melodies of
//! notes with `m_startingPoint`, `m_length` and an `m_hapticEffect` of amplitude and frequency
//! keyframes, times in seconds, frequency in Hz); and its fixtures.

use serde_json::Value;

use super::{check_fixtures, Violation};

rules! {
    MalformedJson => "malformed_json": "the file is one JSON document",
    UnsupportedVersion => "unsupported_version": "m_version is the string \"5\"",
    MissingSection => "missing_section":
        "m_vibration, m_stiffness and m_texture are objects with an m_melodies array, and \
         every melody has an m_notes array",
    MalformedNote => "malformed_note":
        "a note has numbers m_startingPoint and m_length and an object m_hapticEffect; a \
         modulation, if any, has an m_keyframes array of objects with numbers m_time and \
         m_value",
    NegativeTime => "negative_time": "starting points, lengths and keyframe times are at least 0",
    NotesOverlap => "notes_overlap":
        "the notes of a melody are in time order, each ending before the next starts",
    KeyframeTimesDecrease => "keyframe_times_decrease": "keyframe times never decrease",
    KeyframeOutsideNote => "keyframe_outside_note": "every keyframe lies within its note",
    AmplitudeOutOfRange => "amplitude_out_of_range": "every amplitude keyframe is within 0..1",
    FrequencyNotPositive => "frequency_not_positive":
        "every frequency keyframe is a positive number of Hz",
}

/// A note of the vibration as read: start and length (s), amplitude and frequency keyframes.
pub struct Note {
    pub start_s: f64,
    pub length_s: f64,
    pub amplitude: Vec<(f64, f64)>,
    pub frequency: Vec<(f64, f64)>,
}

fn keyframes(modulation: Option<&Value>) -> Option<Vec<(f64, f64)>> {
    let Some(modulation) = modulation else {
        return Some(Vec::new());
    };
    modulation
        .get("m_keyframes")?
        .as_array()?
        .iter()
        .map(|k| Some((k.get("m_time")?.as_f64()?, k.get("m_value")?.as_f64()?)))
        .collect()
}

fn note(value: &Value) -> Option<Note> {
    let effect = value.get("m_hapticEffect").filter(|e| e.is_object())?;
    Some(Note {
        start_s: value.get("m_startingPoint")?.as_f64()?,
        length_s: value.get("m_length")?.as_f64()?,
        amplitude: keyframes(effect.get("m_amplitudeModulation"))?,
        frequency: keyframes(effect.get("m_frequencyModulation"))?,
    })
}

/// The vibration's melodies, each its notes, reporting the structural rules.
fn read(text: &str, violations: &mut Vec<Violation<Rule>>) -> Vec<Vec<Note>> {
    let document: Value = match serde_json::from_str(text) {
        Ok(document) => document,
        Err(e) => {
            violations.push(violation(Rule::MalformedJson, e.to_string()));
            return Vec::new();
        }
    };
    if document.get("m_version").and_then(Value::as_str) != Some("5") {
        violations.push(violation(
            Rule::UnsupportedVersion,
            format!("{:?}", document.get("m_version")),
        ));
    }
    let mut vibration = Vec::new();
    for perception in ["m_vibration", "m_stiffness", "m_texture"] {
        let Some(melodies) = document
            .get(perception)
            .and_then(|p| p.get("m_melodies"))
            .and_then(Value::as_array)
        else {
            violations.push(violation(Rule::MissingSection, perception));
            continue;
        };
        for melody in melodies {
            let Some(notes) = melody.get("m_notes").and_then(Value::as_array) else {
                violations.push(violation(
                    Rule::MissingSection,
                    format!("{perception} melody"),
                ));
                continue;
            };
            let mut read_notes = Vec::new();
            for (index, value) in notes.iter().enumerate() {
                match note(value) {
                    Some(note) => read_notes.push(note),
                    None => violations.push(violation(
                        Rule::MalformedNote,
                        format!("{perception} note {index}"),
                    )),
                }
            }
            if perception == "m_vibration" {
                vibration.push(read_notes);
            }
        }
    }
    vibration
}

/// Every rule the text breaks, empty if it is valid.
pub fn validate(text: &str) -> Vec<Violation<Rule>> {
    let mut violations = Vec::new();
    for notes in read(text, &mut violations) {
        for (index, note) in notes.iter().enumerate() {
            let at = format!("note {index} at {} s", note.start_s);
            let times = note.amplitude.iter().chain(&note.frequency).map(|k| k.0);
            if note.start_s < 0.0 || note.length_s < 0.0 || times.clone().any(|t| t < 0.0) {
                violations.push(violation(Rule::NegativeTime, at.clone()));
            }
            if index > 0 {
                let previous = &notes[index - 1];
                if note.start_s < previous.start_s + previous.length_s - 1e-9 {
                    violations.push(violation(Rule::NotesOverlap, at.clone()));
                }
            }
            for list in [&note.amplitude, &note.frequency] {
                if list.windows(2).any(|pair| pair[1].0 < pair[0].0) {
                    violations.push(violation(Rule::KeyframeTimesDecrease, at.clone()));
                }
            }
            if times.clone().any(|t| t > note.length_s + 1e-9) {
                violations.push(violation(Rule::KeyframeOutsideNote, at.clone()));
            }
            if note.amplitude.iter().any(|k| !(0.0..=1.0).contains(&k.1)) {
                violations.push(violation(Rule::AmplitudeOutOfRange, at.clone()));
            }
            if note.frequency.iter().any(|k| k.1.is_nan() || k.1 <= 0.0) {
                violations.push(violation(Rule::FrequencyNotPositive, at));
            }
        }
    }
    violations
}

/// The vibration's melodies of a valid file, panicking on any rule it breaks.
pub fn parse(text: &str) -> Vec<Vec<Note>> {
    let violations = validate(text);
    assert!(violations.is_empty(), "invalid .haps: {violations:#?}");
    read(text, &mut Vec::new())
}

#[test]
fn haps_fixtures_follow_their_rules() {
    check_fixtures("haps", validate);
}
