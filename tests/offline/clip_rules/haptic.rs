//! Validator of Meta's `.haptic` format 1.0 (haptic-file-spec.md, "Validation Rules" of the
//! amplitude and the frequency envelope) and its fixtures.

use serde_json::Value;

use super::{check_fixtures, Violation};

/// A requirement of a `.haptic` file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rule {
    MalformedJson,
    UnsupportedVersion,
    MissingSection,
    MalformedBreakpoint,
    NegativeTime,
    TooFewAmplitudeBreakpoints,
    NoDuration,
    AmplitudeTimesDecrease,
    AmplitudeOutOfRange,
    EmphasisAmplitudeOutOfRange,
    EmphasisBelowEnvelope,
    EmphasisFrequencyOutOfRange,
    FrequencyTimesDecrease,
    FrequencyOutOfRange,
    FrequencyOutsideAmplitudeSpan,
}

impl super::Rule for Rule {
    const ALL: &'static [Self] = &[
        Rule::MalformedJson,
        Rule::UnsupportedVersion,
        Rule::MissingSection,
        Rule::MalformedBreakpoint,
        Rule::NegativeTime,
        Rule::TooFewAmplitudeBreakpoints,
        Rule::NoDuration,
        Rule::AmplitudeTimesDecrease,
        Rule::AmplitudeOutOfRange,
        Rule::EmphasisAmplitudeOutOfRange,
        Rule::EmphasisBelowEnvelope,
        Rule::EmphasisFrequencyOutOfRange,
        Rule::FrequencyTimesDecrease,
        Rule::FrequencyOutOfRange,
        Rule::FrequencyOutsideAmplitudeSpan,
    ];

    fn name(&self) -> &'static str {
        match self {
            Rule::MalformedJson => "malformed_json",
            Rule::UnsupportedVersion => "unsupported_version",
            Rule::MissingSection => "missing_section",
            Rule::MalformedBreakpoint => "malformed_breakpoint",
            Rule::NegativeTime => "negative_time",
            Rule::TooFewAmplitudeBreakpoints => "too_few_amplitude_breakpoints",
            Rule::NoDuration => "no_duration",
            Rule::AmplitudeTimesDecrease => "amplitude_times_decrease",
            Rule::AmplitudeOutOfRange => "amplitude_out_of_range",
            Rule::EmphasisAmplitudeOutOfRange => "emphasis_amplitude_out_of_range",
            Rule::EmphasisBelowEnvelope => "emphasis_below_envelope",
            Rule::EmphasisFrequencyOutOfRange => "emphasis_frequency_out_of_range",
            Rule::FrequencyTimesDecrease => "frequency_times_decrease",
            Rule::FrequencyOutOfRange => "frequency_out_of_range",
            Rule::FrequencyOutsideAmplitudeSpan => "frequency_outside_amplitude_span",
        }
    }

    fn description(&self) -> &'static str {
        match self {
            Rule::MalformedJson => "the file is one JSON document",
            Rule::UnsupportedVersion => {
                "version is an object of integers major, minor and patch, with major 1"
            }
            Rule::MissingSection => {
                "metadata is an object and signals.continuous.envelopes has an amplitude array \
                 (and a frequency array, if any)"
            }
            Rule::MalformedBreakpoint => {
                "every breakpoint is an object with a numeric time and amplitude or frequency; \
                 an emphasis is an object with a numeric amplitude and frequency"
            }
            Rule::NegativeTime => "every breakpoint time is at least 0 s",
            Rule::TooFewAmplitudeBreakpoints => "there are at least two amplitude breakpoints",
            Rule::NoDuration => "the last amplitude breakpoint is later than the first",
            Rule::AmplitudeTimesDecrease => "amplitude breakpoint times never decrease",
            Rule::AmplitudeOutOfRange => "every amplitude is within 0..1",
            Rule::EmphasisAmplitudeOutOfRange => "every emphasis amplitude is within 0..1",
            Rule::EmphasisBelowEnvelope => {
                "every emphasis amplitude is at least the amplitude of its breakpoint"
            }
            Rule::EmphasisFrequencyOutOfRange => "every emphasis frequency is within 0..1",
            Rule::FrequencyTimesDecrease => "frequency breakpoint times never decrease",
            Rule::FrequencyOutOfRange => "every frequency is within 0..1",
            Rule::FrequencyOutsideAmplitudeSpan => {
                "no frequency breakpoint lies outside the amplitude envelope's time span"
            }
        }
    }
}

/// An amplitude breakpoint as read.
pub struct AmplitudePoint {
    pub time: f64,
    pub amplitude: f64,
    /// `(amplitude, frequency)` of the emphasis, if any.
    pub emphasis: Option<(f64, f64)>,
}

/// The envelopes of a `.haptic` file as read: amplitude points and `(time, frequency)` points.
pub struct Envelopes {
    pub amplitude: Vec<AmplitudePoint>,
    pub frequency: Vec<(f64, f64)>,
}

fn violation(rule: Rule, detail: impl Into<String>) -> Violation<Rule> {
    Violation {
        rule,
        detail: detail.into(),
    }
}

fn is_unsigned_integer(value: Option<&Value>) -> bool {
    value.is_some_and(|v| v.is_u64())
}

fn in_unit_range(x: f64) -> bool {
    (0.0..=1.0).contains(&x)
}

/// Reads the envelopes, reporting the structural rules (JSON, version, sections, breakpoint
/// shape) into `violations`. `None` if there is no amplitude envelope to check further.
fn read(text: &str, violations: &mut Vec<Violation<Rule>>) -> Option<Envelopes> {
    let doc: Value = match serde_json::from_str(text) {
        Ok(doc) => doc,
        Err(e) => {
            violations.push(violation(Rule::MalformedJson, e.to_string()));
            return None;
        }
    };
    let version = doc.get("version");
    let version_ok = version.is_some_and(|v| {
        ["major", "minor", "patch"]
            .iter()
            .all(|key| is_unsigned_integer(v.get(key)))
            && v["major"].as_u64() == Some(1)
    });
    if !version_ok {
        violations.push(violation(
            Rule::UnsupportedVersion,
            format!("version {version:?}"),
        ));
    }
    if !doc.get("metadata").is_some_and(Value::is_object) {
        violations.push(violation(Rule::MissingSection, "metadata is not an object"));
    }
    let envelopes = doc.pointer("/signals/continuous/envelopes");
    let Some(amplitude_values) = envelopes
        .and_then(|e| e.get("amplitude"))
        .and_then(Value::as_array)
    else {
        violations.push(violation(
            Rule::MissingSection,
            "no array signals.continuous.envelopes.amplitude",
        ));
        return None;
    };
    // The spec: "If the frequency array is empty [] or omitted, the system uses a default".
    let frequency_values: &[Value] = match envelopes.and_then(|e| e.get("frequency")) {
        None => &[],
        Some(Value::Array(values)) => values,
        Some(_) => {
            violations.push(violation(Rule::MissingSection, "frequency is not an array"));
            &[]
        }
    };

    let mut amplitude = Vec::new();
    for (index, point) in amplitude_values.iter().enumerate() {
        let time = point.get("time").and_then(Value::as_f64);
        let value = point.get("amplitude").and_then(Value::as_f64);
        let emphasis = point.get("emphasis").map(|e| {
            e.get("amplitude")
                .and_then(Value::as_f64)
                .zip(e.get("frequency").and_then(Value::as_f64))
        });
        match (time, value, emphasis) {
            (Some(time), Some(amplitude_value), None) => amplitude.push(AmplitudePoint {
                time,
                amplitude: amplitude_value,
                emphasis: None,
            }),
            (Some(time), Some(amplitude_value), Some(Some(emphasis))) => {
                amplitude.push(AmplitudePoint {
                    time,
                    amplitude: amplitude_value,
                    emphasis: Some(emphasis),
                })
            }
            _ => violations.push(violation(
                Rule::MalformedBreakpoint,
                format!("amplitude breakpoint {index}: {point}"),
            )),
        }
    }
    let mut frequency = Vec::new();
    for (index, point) in frequency_values.iter().enumerate() {
        match (
            point.get("time").and_then(Value::as_f64),
            point.get("frequency").and_then(Value::as_f64),
        ) {
            (Some(time), Some(value)) => frequency.push((time, value)),
            _ => violations.push(violation(
                Rule::MalformedBreakpoint,
                format!("frequency breakpoint {index}: {point}"),
            )),
        }
    }
    Some(Envelopes {
        amplitude,
        frequency,
    })
}

/// Reads a `.haptic` file's envelopes, panicking on any rule it breaks.
pub fn parse(text: &str) -> Envelopes {
    let violations = validate(text);
    assert!(violations.is_empty(), "invalid .haptic: {violations:#?}");
    read(text, &mut Vec::new()).expect("a valid file has envelopes")
}

/// Every rule the `.haptic` text breaks, empty if it is valid.
pub fn validate(text: &str) -> Vec<Violation<Rule>> {
    let mut violations = Vec::new();
    let Some(envelopes) = read(text, &mut violations) else {
        return violations;
    };
    let amplitude = &envelopes.amplitude;

    if amplitude.len() < 2 {
        violations.push(violation(
            Rule::TooFewAmplitudeBreakpoints,
            format!("{} amplitude breakpoints", amplitude.len()),
        ));
    } else if amplitude[amplitude.len() - 1].time - amplitude[0].time <= 0.0 {
        violations.push(violation(Rule::NoDuration, "the envelope spans no time"));
    }
    for (index, point) in amplitude.iter().enumerate() {
        let at = format!("amplitude breakpoint {index} at {} s", point.time);
        if point.time < 0.0 {
            violations.push(violation(Rule::NegativeTime, at.clone()));
        }
        if index > 0 && point.time < amplitude[index - 1].time {
            violations.push(violation(Rule::AmplitudeTimesDecrease, at.clone()));
        }
        if !in_unit_range(point.amplitude) {
            violations.push(violation(
                Rule::AmplitudeOutOfRange,
                format!("{at}: {}", point.amplitude),
            ));
        }
        if let Some((emphasis_amplitude, emphasis_frequency)) = point.emphasis {
            if !in_unit_range(emphasis_amplitude) {
                violations.push(violation(
                    Rule::EmphasisAmplitudeOutOfRange,
                    format!("{at}: {emphasis_amplitude}"),
                ));
            }
            if emphasis_amplitude < point.amplitude {
                violations.push(violation(
                    Rule::EmphasisBelowEnvelope,
                    format!("{at}: {emphasis_amplitude} < {}", point.amplitude),
                ));
            }
            if !in_unit_range(emphasis_frequency) {
                violations.push(violation(
                    Rule::EmphasisFrequencyOutOfRange,
                    format!("{at}: {emphasis_frequency}"),
                ));
            }
        }
    }

    let span = amplitude
        .first()
        .zip(amplitude.last())
        .map(|(first, last)| first.time..=last.time);
    for (index, &(time, frequency)) in envelopes.frequency.iter().enumerate() {
        let at = format!("frequency breakpoint {index} at {time} s");
        if time < 0.0 {
            violations.push(violation(Rule::NegativeTime, at.clone()));
        }
        if index > 0 && time < envelopes.frequency[index - 1].0 {
            violations.push(violation(Rule::FrequencyTimesDecrease, at.clone()));
        }
        if !in_unit_range(frequency) {
            violations.push(violation(
                Rule::FrequencyOutOfRange,
                format!("{at}: {frequency}"),
            ));
        }
        if span.as_ref().is_some_and(|span| !span.contains(&time)) {
            violations.push(violation(Rule::FrequencyOutsideAmplitudeSpan, at));
        }
    }
    violations
}

#[test]
fn haptic_fixtures_follow_their_rules() {
    check_fixtures("haptic", validate);
}
