//! Validator of the `rumble` JSON, from what the three APIs that play it take: the W3C Gamepad
//! `playEffect("dual-rumble", {duration, strongMagnitude, weakMagnitude})` (magnitudes in
//! 0..1, anything else rejected; Chrome plays at most 5000 ms an effect), SDL's
//! `SDL_RumbleGamepad(low, high, duration_ms)` and XInput's motor speeds (0..65535, scaled from
//! 0..1); and its fixtures.

use serde_json::Value;

use super::{check_fixtures, Violation};

rules! {
    MalformedJson => "malformed_json": "the file is one JSON document",
    MissingField => "missing_field":
        "rate_hz is a number and frames an array of objects with numbers t_ms, low and high",
    RateOutOfRange => "rate_out_of_range":
        "a frame (1000 / rate_hz ms) lasts from 1 ms (SDL's and the browsers' whole \
         milliseconds) to 5000 ms (the longest dual-rumble effect Chrome plays)",
    NoFrames => "no_frames": "there is at least one frame",
    FrameOffTheRate => "frame_off_the_rate":
        "frame k starts at k · 1000 / rate_hz ms (to 0.001 ms): the rate is fixed",
    MagnitudeOutOfRange => "magnitude_out_of_range":
        "low and high are within 0..1, as the Gamepad API's magnitudes must be",
}

/// A rumble file as read.
pub struct Rumble {
    pub rate_hz: f64,
    /// `(t_ms, low, high)` of every frame.
    pub frames: Vec<(f64, f64, f64)>,
}

fn read(text: &str, violations: &mut Vec<Violation<Rule>>) -> Option<Rumble> {
    let document: Value = match serde_json::from_str(text) {
        Ok(document) => document,
        Err(e) => {
            violations.push(violation(Rule::MalformedJson, e.to_string()));
            return None;
        }
    };
    let rate_hz = document.get("rate_hz").and_then(Value::as_f64);
    let frames: Option<Vec<(f64, f64, f64)>> = document
        .get("frames")
        .and_then(Value::as_array)
        .and_then(|frames| {
            frames
                .iter()
                .map(|frame| {
                    let number = |key| frame.get(key).and_then(Value::as_f64);
                    Some((number("t_ms")?, number("low")?, number("high")?))
                })
                .collect()
        });
    let (Some(rate_hz), Some(frames)) = (rate_hz, frames) else {
        violations.push(violation(Rule::MissingField, "rate_hz or frames"));
        return None;
    };
    let period_ms = 1000.0 / rate_hz;
    if !(1.0..=5000.0).contains(&period_ms) {
        violations.push(violation(Rule::RateOutOfRange, format!("{rate_hz} Hz")));
    }
    if frames.is_empty() {
        violations.push(violation(Rule::NoFrames, "no frame"));
    }
    for (k, &(t_ms, low, high)) in frames.iter().enumerate() {
        if (t_ms - k as f64 * period_ms).abs() > 1e-3 {
            violations.push(violation(
                Rule::FrameOffTheRate,
                format!("frame {k} at {t_ms} ms"),
            ));
        }
        if !(0.0..=1.0).contains(&low) || !(0.0..=1.0).contains(&high) {
            violations.push(violation(
                Rule::MagnitudeOutOfRange,
                format!("frame {k}: {low}, {high}"),
            ));
        }
    }
    Some(Rumble { rate_hz, frames })
}

/// Every rule the text breaks, empty if it is valid.
pub fn validate(text: &str) -> Vec<Violation<Rule>> {
    let mut violations = Vec::new();
    read(text, &mut violations);
    violations
}

/// A valid file, panicking on any rule it breaks.
pub fn parse(text: &str) -> Rumble {
    let mut violations = Vec::new();
    let rumble = read(text, &mut violations);
    assert!(violations.is_empty(), "invalid rumble: {violations:#?}");
    rumble.expect("a valid file")
}

#[test]
fn rumble_fixtures_follow_their_rules() {
    check_fixtures("rumble", validate);
}
