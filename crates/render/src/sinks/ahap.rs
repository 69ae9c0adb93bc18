//! Apple Core Haptics' AHAP pattern: a `HapticTransient` at every audible glug's onset, and
//! the ring after it as one `HapticContinuous` event whose intensity a `ParameterCurve` of
//! `HapticIntensityControl` draws down the felt envelope (the glug's decay as a curve).
//!
//! A curve applies to every event of the pattern, transients included: `HapticIntensityControl`
//! multiplies each event's intensity. So each glug's curve starts at its onset, and the
//! transient there is written divided by the curve's value at that time, which it is multiplied
//! by again when it plays.

use serde::Serialize;
use serde_json::Value;

use super::read_back::{array, held, number, ReadBack, Reading, WrittenClip};
use super::{ClipSink, OutputError, OutputFormat, OutputOptions, Sink, SinkContext};
use crate::clips::{
    clip_end_s, envelope_breakpoints, felt_frequency_hz, glug_count, transient_intensity,
    ClipSource, HapticBand, ENVELOPE_FLOOR,
};

/// `.ahap`: an Apple Core Haptics pattern.
pub(super) const FORMAT: OutputFormat = OutputFormat {
    name: "ahap",
    extension: "ahap",
    by_extension: true,
    built: true,
    open,
    read_back: Some(ReadBack::Clip(read_back, document)),
    carries_c: "HapticSharpness (the felt frequency: 1 − c by default)",
};

/// The sink of an `.ahap` output (its sharpness always on the default band).
pub(super) fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    ClipSink::open(context, document, BYTES_PER_GLUG)
}

/// The pattern of `source` (its sharpness always on the default band).
fn document(source: &ClipSource, _: &OutputOptions) -> String {
    ahap_json(source)
}

/// Memory a glug takes until the pattern is written: the glug, its events and their text (a
/// dense render peaks near 1.2 kB a glug).
const BYTES_PER_GLUG: u64 = 1536;

#[derive(Serialize)]
#[serde(rename_all = "PascalCase")]
struct AhapFile {
    version: f64,
    metadata: Metadata,
    pattern: Vec<PatternItem>,
}

#[derive(Serialize)]
#[serde(rename_all = "PascalCase")]
struct Metadata {
    project: String,
    description: String,
}

/// A pattern entry holds exactly one kind of item; serde's external tagging writes
/// `{"Event": {...}}` and `{"ParameterCurve": {...}}`.
#[derive(Serialize)]
enum PatternItem {
    Event(Event),
    ParameterCurve(Curve),
}

impl PatternItem {
    fn time(&self) -> f64 {
        match self {
            Self::Event(event) => event.time,
            Self::ParameterCurve(curve) => curve.time,
        }
    }
}

#[derive(Serialize)]
#[serde(rename_all = "PascalCase")]
struct Event {
    time: f64,
    event_type: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    event_duration: Option<f64>,
    event_parameters: [EventParameter; 2],
}

#[derive(Serialize)]
struct EventParameter {
    #[serde(rename = "ParameterID")]
    parameter_id: &'static str,
    #[serde(rename = "ParameterValue")]
    parameter_value: f64,
}

#[derive(Serialize)]
struct Curve {
    #[serde(rename = "ParameterID")]
    parameter_id: &'static str,
    #[serde(rename = "Time")]
    time: f64,
    #[serde(rename = "ParameterCurveControlPoints")]
    points: Vec<ControlPoint>,
}

#[derive(Serialize)]
struct ControlPoint {
    #[serde(rename = "Time")]
    time: f64,
    #[serde(rename = "ParameterValue")]
    value: f64,
}

/// Core Haptics' limit on the length of one continuous event (s): longer rings are split.
pub const CORE_HAPTICS_MAX_EVENT_S: f64 = 30.0;

/// The most control points a Core Haptics parameter curve is given here: 16, the limit our
/// platform notes record for `CHHapticParameterCurve` (Apple's page on it,
/// developer.apple.com/documentation/corehaptics/chhapticparametercurve, says a curve applies to
/// every event of the pattern) and the AHAP validator of the tests holds. A decay with more is
/// continued by the next curve.
pub const CORE_HAPTICS_MAX_CURVE_POINTS: usize = 16;

/// The sharpness written where nothing rings: the middle of the range.
const SILENT_SHARPNESS: f64 = 0.5;

fn parameters(intensity: f64, sharpness: f64) -> [EventParameter; 2] {
    [
        EventParameter {
            parameter_id: "HapticIntensity",
            parameter_value: intensity.clamp(0.0, 1.0),
        },
        EventParameter {
            parameter_id: "HapticSharpness",
            parameter_value: sharpness.clamp(0.0, 1.0),
        },
    ]
}

/// The intensity control of an envelope level: Core Haptics' intensity is perceptual, its
/// output amplitude growing roughly with the square of the intensity, so `√level`.
fn control_of(level: f64) -> f64 {
    level.max(0.0).sqrt().min(1.0)
}

/// The clip as an AHAP JSON document.
///
/// - Transient per audible glug at its exact onset: played intensity `√peak`
///   ([`transient_intensity`]: Core Haptics' intensity is perceptually close to the square
///   root of amplitude, and Meta's converter writes the same), written divided by the intensity
///   control there (the curve multiplies it); `HapticSharpness` = the position of the glug's
///   felt frequency (weighted without an actuator's compensation) in the default
///   [`HapticBand`] (80..300 Hz), with the default components exactly `1 − c`.
/// - Ring: from each onset ([`envelope_breakpoints`]) to the next, or to where the envelope
///   has fallen below [`ENVELOPE_FLOOR`], one `HapticContinuous` event of intensity 1 and the
///   sharpness of what rings at its start (split at [`CORE_HAPTICS_MAX_EVENT_S`]), and a
///   `HapticIntensityControl` curve through `√` of the envelope's breakpoints, at most
///   [`CORE_HAPTICS_MAX_CURVE_POINTS`] a curve.
pub fn ahap_json(source: &ClipSource) -> String {
    let band = HapticBand::default();
    let breakpoints = envelope_breakpoints(source);
    let mut items: Vec<PatternItem> = Vec::new();

    // The breakpoints cut at every onset: each part is one ring.
    let mut starts: Vec<usize> = breakpoints
        .iter()
        .enumerate()
        .filter(|(_, point)| point.onset_of.is_some())
        .map(|(index, _)| index)
        .collect();
    if starts.first() != Some(&0) {
        starts.insert(0, 0);
    }
    for (part, &first) in starts.iter().enumerate() {
        let last = starts
            .get(part + 1)
            .map_or(breakpoints.len() - 1, |&next| next - 1);
        let points = &breakpoints[first..=last];
        // The ring lasts to the next onset, or ends where it fell below the floor.
        let end_s = match (points.last(), breakpoints.get(last + 1)) {
            (Some(point), _) if point.amplitude < ENVELOPE_FLOOR => point.time_s,
            (_, Some(next)) => next.time_s,
            (Some(point), None) => point.time_s,
            (None, None) => continue,
        };
        let start = &points[0];
        let control_at_start = control_of(start.amplitude);
        if let Some(index) = start.onset_of {
            let glug = &source.glugs[index];
            let played = transient_intensity(glug, source.ceiling);
            let written = if control_at_start > 0.0 {
                played / control_at_start
            } else {
                played
            };
            items.push(PatternItem::Event(Event {
                time: start.time_s,
                event_type: "HapticTransient",
                event_duration: None,
                event_parameters: parameters(written, band.normalise(felt_frequency_hz(glug))),
            }));
        }
        let loudest = points.iter().map(|p| p.amplitude).fold(0.0, f64::max);
        if loudest < ENVELOPE_FLOOR || end_s <= start.time_s {
            continue;
        }
        let sharpness = start
            .felt_frequency_hz
            .map_or(SILENT_SHARPNESS, |hz| band.normalise(hz));
        let mut chunk_start_s = start.time_s;
        while chunk_start_s < end_s {
            let chunk_s = (end_s - chunk_start_s).min(CORE_HAPTICS_MAX_EVENT_S);
            items.push(PatternItem::Event(Event {
                time: chunk_start_s,
                event_type: "HapticContinuous",
                event_duration: Some(chunk_s),
                event_parameters: parameters(1.0, sharpness),
            }));
            chunk_start_s += chunk_s;
        }
        // Consecutive curves share a point, so the line runs on unbroken.
        let mut from = 0;
        while from + 1 < points.len() || from == 0 {
            let to = (from + CORE_HAPTICS_MAX_CURVE_POINTS).min(points.len());
            let time = points[from].time_s;
            items.push(PatternItem::ParameterCurve(Curve {
                parameter_id: "HapticIntensityControl",
                time,
                points: points[from..to]
                    .iter()
                    .map(|point| ControlPoint {
                        time: point.time_s - time,
                        value: control_of(point.amplitude),
                    })
                    .collect(),
            }));
            if to == points.len() {
                break;
            }
            from = to - 1;
        }
    }
    // In time order, a transient before the ring and the curve that start with it (stable).
    items.sort_by(|a, b| a.time().total_cmp(&b.time()));

    let file = AhapFile {
        version: 1.0,
        metadata: Metadata {
            project: "Sake Glug".to_owned(),
            description: format!(
                "Glugs of liquid poured from a sake bottle: scene {}, seed {}, {} over {} s; \
                 sharpness 0..1 spans {} Hz of felt frequency",
                source.scene_name,
                source.seed,
                glug_count(source),
                clip_end_s(source),
                band,
            ),
        },
        pattern: items,
    };
    serde_json::to_string_pretty(&file).expect("a pattern of plain numbers and strings serializes")
}

/// The pattern read back: its transients as onsets; its envelope the continuous events'
/// intensity times the intensity control the curves draw (linear between their points, held
/// after the last until the next curve), squared (an intensity is `√level`).
fn read_back(clip: &WrittenClip) -> Result<Reading, OutputError> {
    let document = clip.json()?;
    let pattern = array(&document, "/Pattern");
    let events: Vec<&Value> = pattern
        .iter()
        .filter_map(|item| item.get("Event"))
        .collect();
    let mut curves: Vec<(f64, Vec<(f64, f64)>)> = pattern
        .iter()
        .filter_map(|item| item.get("ParameterCurve"))
        .filter(|curve| {
            curve.get("ParameterID").and_then(Value::as_str) == Some("HapticIntensityControl")
        })
        .map(|curve| {
            let time = number(curve, "Time");
            let points = array(curve, "/ParameterCurveControlPoints")
                .iter()
                .map(|p| (time + number(p, "Time"), number(p, "ParameterValue")))
                .collect();
            (time, points)
        })
        .collect();
    curves.sort_by(|a, b| a.0.total_cmp(&b.0));
    let longest_curve = curves.iter().map(|c| c.1.len()).max().unwrap_or(0);
    let kind =
        |event: &Value| event.get("EventType").and_then(Value::as_str) == Some("HapticTransient");
    let intensity = |event: &Value| {
        array(event, "/EventParameters")
            .iter()
            .find(|p| p.get("ParameterID").and_then(Value::as_str) == Some("HapticIntensity"))
            .map_or(0.0, |p| number(p, "ParameterValue"))
    };
    let continuous = held(
        events
            .iter()
            .filter(|e| !kind(e))
            .map(|e| {
                let start = number(e, "Time");
                (start, start + number(e, "EventDuration"), intensity(e))
            })
            .collect(),
    );
    let split = events
        .iter()
        .filter(|e| !kind(e) && number(e, "EventDuration") >= CORE_HAPTICS_MAX_EVENT_S - 1e-9)
        .count();
    let control = move |t: f64| {
        let started = curves.partition_point(|curve| curve.0 <= t);
        let Some((_, points)) = started.checked_sub(1).map(|i| &curves[i]) else {
            return 1.0;
        };
        let next = points.partition_point(|p| p.0 <= t);
        match (next.checked_sub(1).map(|i| points[i]), points.get(next)) {
            (Some(a), Some(b)) => a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0).max(1e-12),
            (Some(a), None) => a.1,
            (None, Some(b)) => b.1,
            (None, None) => 1.0,
        }
    };
    Ok(Reading {
        from_mark_before: false,
        onsets: events
            .iter()
            .filter(|e| kind(e))
            .map(|e| number(e, "Time"))
            .collect(),
        limits: format!(
            "{} events, {} intensity curves of at most {longest_curve} points (Core Haptics: \
             {CORE_HAPTICS_MAX_CURVE_POINTS}); {split} split at {CORE_HAPTICS_MAX_EVENT_S:.0} s",
            events.len(),
            pattern.len() - events.len(),
        ),
        envelope: Box::new(move |t| (continuous(t) * control(t)).powi(2)),
    })
}
