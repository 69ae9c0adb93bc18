//! Validator of Apple's AHAP patterns ("Representing haptic patterns in AHAP files") and its
//! fixtures. Core Haptics clamps out-of-range values on load; these rules refuse them so a
//! clip plays exactly as written.

// Core Haptics' limit on a continuous event, as the format declares it.
use sake_glug_render::sinks::CORE_HAPTICS_MAX_EVENT_S;
use serde_json::{Map, Value};

use super::{check_fixtures, Violation};

/// A requirement of an AHAP file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Rule {
    MalformedJson,
    MissingVersion,
    MissingPattern,
    NotExactlyOneItemKind,
    MalformedEvent,
    UnknownEventType,
    NegativeTime,
    ContinuousDurationOutOfRange,
    EventParameterOutOfRange,
    MalformedControl,
    TooManyControlPoints,
    ControlPointTimesDecrease,
    ControlValueOutOfRange,
}

impl super::Rule for Rule {
    const ALL: &'static [Self] = &[
        Rule::MalformedJson,
        Rule::MissingVersion,
        Rule::MissingPattern,
        Rule::NotExactlyOneItemKind,
        Rule::MalformedEvent,
        Rule::UnknownEventType,
        Rule::NegativeTime,
        Rule::ContinuousDurationOutOfRange,
        Rule::EventParameterOutOfRange,
        Rule::MalformedControl,
        Rule::TooManyControlPoints,
        Rule::ControlPointTimesDecrease,
        Rule::ControlValueOutOfRange,
    ];

    fn name(&self) -> &'static str {
        match self {
            Rule::MalformedJson => "malformed_json",
            Rule::MissingVersion => "missing_version",
            Rule::MissingPattern => "missing_pattern",
            Rule::NotExactlyOneItemKind => "not_exactly_one_item_kind",
            Rule::MalformedEvent => "malformed_event",
            Rule::UnknownEventType => "unknown_event_type",
            Rule::NegativeTime => "negative_time",
            Rule::ContinuousDurationOutOfRange => "continuous_duration_out_of_range",
            Rule::EventParameterOutOfRange => "event_parameter_out_of_range",
            Rule::MalformedControl => "malformed_control",
            Rule::TooManyControlPoints => "too_many_control_points",
            Rule::ControlPointTimesDecrease => "control_point_times_decrease",
            Rule::ControlValueOutOfRange => "control_value_out_of_range",
        }
    }

    fn description(&self) -> &'static str {
        match self {
            Rule::MalformedJson => "the file is one JSON document",
            Rule::MissingVersion => "Version is a number",
            Rule::MissingPattern => "Pattern is an array",
            Rule::NotExactlyOneItemKind => {
                "every Pattern item is an object holding exactly one of Event, ParameterCurve \
                 and Parameter"
            }
            Rule::MalformedEvent => {
                "an Event has a numeric Time, a string EventType and, if any, EventParameters \
                 as an array of {ParameterID: string, ParameterValue: number}"
            }
            Rule::UnknownEventType => {
                "EventType is HapticTransient, HapticContinuous, AudioContinuous or AudioCustom"
            }
            Rule::NegativeTime => "every Time (event, curve, control point, parameter) is ≥ 0",
            Rule::ContinuousDurationOutOfRange => {
                "a HapticContinuous event has an EventDuration above 0 and at most 30 s"
            }
            Rule::EventParameterOutOfRange => "HapticIntensity and HapticSharpness are in 0..1",
            Rule::MalformedControl => {
                "a ParameterCurve has a string ParameterID, a numeric Time and \
                 ParameterCurveControlPoints as an array of {Time, ParameterValue} numbers; a \
                 Parameter has a string ParameterID, a numeric Time and ParameterValue"
            }
            Rule::TooManyControlPoints => "a ParameterCurve has at most 16 control points",
            Rule::ControlPointTimesDecrease => "control point times never decrease",
            Rule::ControlValueOutOfRange => {
                "HapticIntensityControl values are in 0..1, HapticSharpnessControl values in \
                 -1..1"
            }
        }
    }
}

const ITEM_KINDS: [&str; 3] = ["Event", "ParameterCurve", "Parameter"];
const EVENT_TYPES: [&str; 4] = [
    "HapticTransient",
    "HapticContinuous",
    "AudioContinuous",
    "AudioCustom",
];
const MAX_CONTROL_POINTS: usize = 16;

/// An event as read: `(Time, EventType, EventDuration, [(ParameterID, ParameterValue)])`.
pub struct Event {
    pub time: f64,
    pub event_type: String,
    pub duration: Option<f64>,
    pub parameters: Vec<(String, f64)>,
}

impl Event {
    /// The value of the parameter `id`, if the event sets it.
    pub fn parameter(&self, id: &str) -> Option<f64> {
        self.parameters
            .iter()
            .find(|(parameter_id, _)| parameter_id == id)
            .map(|&(_, value)| value)
    }
}

fn violation(rule: Rule, detail: impl Into<String>) -> Violation<Rule> {
    Violation {
        rule,
        detail: detail.into(),
    }
}

fn number(object: &Map<String, Value>, key: &str) -> Option<f64> {
    object.get(key).and_then(Value::as_f64)
}

/// The range a control (curve or dynamic parameter) must stay in, if the rules know one.
fn control_range(parameter_id: &str) -> Option<std::ops::RangeInclusive<f64>> {
    match parameter_id {
        "HapticIntensityControl" => Some(0.0..=1.0),
        "HapticSharpnessControl" => Some(-1.0..=1.0),
        _ => None,
    }
}

fn read_event(item: &Value, at: &str, violations: &mut Vec<Violation<Rule>>) -> Option<Event> {
    let Some(object) = item.as_object() else {
        violations.push(violation(Rule::MalformedEvent, format!("{at}: {item}")));
        return None;
    };
    let time = number(object, "Time");
    let event_type = object.get("EventType").and_then(Value::as_str);
    let parameters: Option<Vec<(String, f64)>> = match object.get("EventParameters") {
        None => Some(Vec::new()),
        Some(values) => values.as_array().and_then(|values| {
            values
                .iter()
                .map(|p| {
                    let id = p.get("ParameterID").and_then(Value::as_str)?;
                    let value = p.get("ParameterValue").and_then(Value::as_f64)?;
                    Some((id.to_owned(), value))
                })
                .collect()
        }),
    };
    let duration = object.get("EventDuration").map(Value::as_f64);
    let (Some(time), Some(event_type), Some(parameters), None | Some(Some(_))) =
        (time, event_type, parameters, duration)
    else {
        violations.push(violation(Rule::MalformedEvent, format!("{at}: {item}")));
        return None;
    };
    Some(Event {
        time,
        event_type: event_type.to_owned(),
        duration: duration.flatten(),
        parameters,
    })
}

fn check_event(event: &Event, at: &str, violations: &mut Vec<Violation<Rule>>) {
    if event.time < 0.0 {
        violations.push(violation(
            Rule::NegativeTime,
            format!("{at}: {}", event.time),
        ));
    }
    if !EVENT_TYPES.contains(&event.event_type.as_str()) {
        violations.push(violation(
            Rule::UnknownEventType,
            format!("{at}: {}", event.event_type),
        ));
    }
    if event.event_type == "HapticContinuous"
        && !event
            .duration
            .is_some_and(|d| d > 0.0 && d <= CORE_HAPTICS_MAX_EVENT_S)
    {
        violations.push(violation(
            Rule::ContinuousDurationOutOfRange,
            format!("{at}: EventDuration {:?}", event.duration),
        ));
    }
    for (id, value) in &event.parameters {
        let bounded = matches!(id.as_str(), "HapticIntensity" | "HapticSharpness");
        if bounded && !(0.0..=1.0).contains(value) {
            violations.push(violation(
                Rule::EventParameterOutOfRange,
                format!("{at}: {id} {value}"),
            ));
        }
    }
}

fn check_curve(item: &Value, at: &str, violations: &mut Vec<Violation<Rule>>) {
    let object = item.as_object();
    let id = object
        .and_then(|o| o.get("ParameterID"))
        .and_then(Value::as_str);
    let time = object.and_then(|o| number(o, "Time"));
    let points: Option<Vec<(f64, f64)>> = object
        .and_then(|o| o.get("ParameterCurveControlPoints"))
        .and_then(Value::as_array)
        .and_then(|points| {
            points
                .iter()
                .map(|p| {
                    Some((
                        p.get("Time").and_then(Value::as_f64)?,
                        p.get("ParameterValue").and_then(Value::as_f64)?,
                    ))
                })
                .collect()
        });
    let (Some(id), Some(time), Some(points)) = (id, time, points) else {
        violations.push(violation(Rule::MalformedControl, format!("{at}: {item}")));
        return;
    };
    if time < 0.0 || points.iter().any(|&(t, _)| t < 0.0) {
        violations.push(violation(Rule::NegativeTime, at.to_owned()));
    }
    if points.len() > MAX_CONTROL_POINTS {
        violations.push(violation(
            Rule::TooManyControlPoints,
            format!("{at}: {} control points", points.len()),
        ));
    }
    if points.windows(2).any(|pair| pair[1].0 < pair[0].0) {
        violations.push(violation(Rule::ControlPointTimesDecrease, at.to_owned()));
    }
    if let Some(range) = control_range(id) {
        for &(t, value) in &points {
            if !range.contains(&value) {
                violations.push(violation(
                    Rule::ControlValueOutOfRange,
                    format!("{at}: {id} {value} at {t} s"),
                ));
            }
        }
    }
}

fn check_parameter(item: &Value, at: &str, violations: &mut Vec<Violation<Rule>>) {
    let object = item.as_object();
    let id = object
        .and_then(|o| o.get("ParameterID"))
        .and_then(Value::as_str);
    let time = object.and_then(|o| number(o, "Time"));
    let value = object.and_then(|o| number(o, "ParameterValue"));
    let (Some(id), Some(time), Some(value)) = (id, time, value) else {
        violations.push(violation(Rule::MalformedControl, format!("{at}: {item}")));
        return;
    };
    if time < 0.0 {
        violations.push(violation(Rule::NegativeTime, at.to_owned()));
    }
    if control_range(id).is_some_and(|range| !range.contains(&value)) {
        violations.push(violation(
            Rule::ControlValueOutOfRange,
            format!("{at}: {id} {value}"),
        ));
    }
}

/// Checks an AHAP text; returns its well-formed events and every rule it breaks.
fn read(text: &str) -> (Vec<Event>, Vec<Violation<Rule>>) {
    let mut violations = Vec::new();
    let mut events = Vec::new();
    let doc: Value = match serde_json::from_str(text) {
        Ok(doc) => doc,
        Err(e) => return (events, vec![violation(Rule::MalformedJson, e.to_string())]),
    };
    if doc.get("Version").and_then(Value::as_f64).is_none() {
        violations.push(violation(Rule::MissingVersion, "no numeric Version"));
    }
    let Some(pattern) = doc.get("Pattern").and_then(Value::as_array) else {
        violations.push(violation(Rule::MissingPattern, "no Pattern array"));
        return (events, violations);
    };
    for (index, item) in pattern.iter().enumerate() {
        let kinds: Vec<&str> = ITEM_KINDS
            .into_iter()
            .filter(|kind| item.get(kind).is_some())
            .collect();
        let at = format!("Pattern item {index}");
        let [kind] = kinds.as_slice() else {
            violations.push(violation(
                Rule::NotExactlyOneItemKind,
                format!("{at} holds {kinds:?}"),
            ));
            continue;
        };
        let body = &item[kind];
        match *kind {
            "Event" => {
                if let Some(event) = read_event(body, &at, &mut violations) {
                    check_event(&event, &at, &mut violations);
                    events.push(event);
                }
            }
            "ParameterCurve" => check_curve(body, &at, &mut violations),
            _ => check_parameter(body, &at, &mut violations),
        }
    }
    (events, violations)
}

/// Every rule the AHAP text breaks, empty if it is valid.
pub fn validate(text: &str) -> Vec<Violation<Rule>> {
    read(text).1
}

/// The events of an AHAP text, panicking on any rule it breaks.
pub fn parse(text: &str) -> Vec<Event> {
    let (events, violations) = read(text);
    assert!(violations.is_empty(), "invalid AHAP: {violations:#?}");
    events
}

#[test]
fn ahap_fixtures_follow_their_rules() {
    check_fixtures("ahap", validate);
}
