//! Validator of the `android-waveform` JSON: the arguments of Android's
//! `VibrationEffect.createWaveform(long[] timings, int[] amplitudes, int repeat)` and the
//! checks its documentation and `Waveform.validate` make, and its fixtures.

use serde_json::Value;

use super::{check_fixtures, Violation};

rules! {
    MalformedJson => "malformed_json": "the file is one JSON document",
    MissingField => "missing_field":
        "timings and amplitudes are arrays of integers and repeat is an integer",
    LengthsDiffer => "lengths_differ": "timings and amplitudes have the same length",
    NegativeTiming => "negative_timing": "every timing is at least 0 ms",
    AmplitudeOutOfRange => "amplitude_out_of_range":
        "every amplitude is from 0 to 255, or -1 (DEFAULT_AMPLITUDE)",
    NoNonZeroTiming => "no_non_zero_timing": "at least one timing is above 0 ms",
    RepeatOutOfRange => "repeat_out_of_range": "repeat is -1 or an index into timings",
}

/// A waveform as read: `(timing ms, amplitude)` pairs.
pub type Entries = Vec<(i64, i64)>;

fn integers(value: Option<&Value>) -> Option<Vec<i64>> {
    value?.as_array()?.iter().map(Value::as_i64).collect()
}

fn read(text: &str, violations: &mut Vec<Violation<Rule>>) -> Entries {
    let document: Value = match serde_json::from_str(text) {
        Ok(document) => document,
        Err(e) => {
            violations.push(violation(Rule::MalformedJson, e.to_string()));
            return Vec::new();
        }
    };
    let timings = integers(document.get("timings"));
    let amplitudes = integers(document.get("amplitudes"));
    let repeat = document.get("repeat").and_then(Value::as_i64);
    let (Some(timings), Some(amplitudes), Some(repeat)) = (timings, amplitudes, repeat) else {
        violations.push(violation(
            Rule::MissingField,
            "timings, amplitudes or repeat",
        ));
        return Vec::new();
    };
    if timings.len() != amplitudes.len() {
        violations.push(violation(
            Rule::LengthsDiffer,
            format!("{} timings, {} amplitudes", timings.len(), amplitudes.len()),
        ));
    }
    for (index, &timing) in timings.iter().enumerate() {
        if timing < 0 {
            violations.push(violation(Rule::NegativeTiming, format!("timing {index}")));
        }
    }
    for (index, &amplitude) in amplitudes.iter().enumerate() {
        if amplitude != -1 && !(0..=255).contains(&amplitude) {
            violations.push(violation(
                Rule::AmplitudeOutOfRange,
                format!("amplitude {index}: {amplitude}"),
            ));
        }
    }
    if !timings.iter().any(|&timing| timing > 0) {
        violations.push(violation(Rule::NoNonZeroTiming, "every timing is 0"));
    }
    if repeat != -1 && !(0..timings.len() as i64).contains(&repeat) {
        violations.push(violation(
            Rule::RepeatOutOfRange,
            format!("repeat {repeat}"),
        ));
    }
    timings.into_iter().zip(amplitudes).collect()
}

/// Every rule the text breaks, empty if it is valid.
pub fn validate(text: &str) -> Vec<Violation<Rule>> {
    let mut violations = Vec::new();
    read(text, &mut violations);
    violations
}

/// The entries of a valid file, panicking on any rule it breaks.
pub fn parse(text: &str) -> Entries {
    let mut violations = Vec::new();
    let entries = read(text, &mut violations);
    assert!(
        violations.is_empty(),
        "invalid Android waveform: {violations:#?}"
    );
    entries
}

#[test]
fn android_waveform_fixtures_follow_their_rules() {
    check_fixtures("android-waveform", validate);
}
