//! Apple Core Haptics' AHAP pattern: a `HapticTransient` at every audible glug's onset and the
//! ring between onsets as short `HapticContinuous` events that step down the felt envelope.
//!
//! No parameter curves: a curve applies to every event of the pattern, transients included,
//! so it would also scale the clicks. Each continuous event carries its own constant
//! parameters instead.

use serde::Serialize;
use serde_json::Value;

use super::read_back::{array, held, number, ReadBack, Reading, WrittenClip};
use super::{ClipSink, OutputError, OutputFormat, OutputOptions, Sink, SinkContext};
use crate::clips::{
    clip_end_s, clip_onsets, envelope_breakpoints, felt_frequency_hz, transient_intensity,
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
/// `{"Event": {...}}`.
#[derive(Serialize)]
enum PatternItem {
    Event(Event),
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

/// Core Haptics' limit on the length of one continuous event (s): longer steps are split.
pub const CORE_HAPTICS_MAX_EVENT_S: f64 = 30.0;

/// Envelope steps shorter than this (the jump just before an onset) get no continuous event:
/// the transient carries the jump.
const MIN_CONTINUOUS_S: f64 = 0.001;

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

/// The clip as an AHAP JSON document.
///
/// - Transient per audible glug at its exact onset: `HapticIntensity` = `√peak`
///   ([`transient_intensity`]: Core Haptics' intensity is perceptually close to the
///   square root of amplitude, and Meta's converter writes the same), `HapticSharpness` = the
///   position of the glug's felt frequency in the default [`HapticBand`] (80..300 Hz), which
///   with the default components is exactly `1 − c`: a more viscous glug feels duller.
/// - Ring: one `HapticContinuous` event per step of the felt envelope
///   ([`envelope_breakpoints`]) that rises above [`ENVELOPE_FLOOR`], intensity the
///   square root of the step's mean amplitude, sharpness the band position of the felt
///   frequency of what rings at the step's start. Steps longer than
///   `CORE_HAPTICS_MAX_EVENT_S` (Core Haptics' limit) are split.
pub fn ahap_json(source: &ClipSource) -> String {
    let band = HapticBand::default();
    let breakpoints = envelope_breakpoints(source);
    let mut events: Vec<Event> = Vec::new();

    for index in clip_onsets(source) {
        let glug = &source.glugs[index];
        events.push(Event {
            time: glug.onset_s,
            event_type: "HapticTransient",
            event_duration: None,
            event_parameters: parameters(
                transient_intensity(glug, source.ceiling),
                band.normalise(felt_frequency_hz(glug)),
            ),
        });
    }

    for pair in breakpoints.windows(2) {
        let (start, end) = (&pair[0], &pair[1]);
        let duration_s = end.time_s - start.time_s;
        if duration_s < MIN_CONTINUOUS_S || start.amplitude.max(end.amplitude) < ENVELOPE_FLOOR {
            continue;
        }
        let intensity = (0.5 * (start.amplitude + end.amplitude)).sqrt();
        let sharpness = start
            .felt_frequency_hz
            .or(end.felt_frequency_hz)
            .map_or(SILENT_SHARPNESS, |hz| band.normalise(hz));
        let mut chunk_start_s = start.time_s;
        while chunk_start_s < end.time_s {
            let chunk_s = (end.time_s - chunk_start_s).min(CORE_HAPTICS_MAX_EVENT_S);
            events.push(Event {
                time: chunk_start_s,
                event_type: "HapticContinuous",
                event_duration: Some(chunk_s),
                event_parameters: parameters(intensity, sharpness),
            });
            chunk_start_s += chunk_s;
        }
    }
    // In time order, a transient before the ring that starts with it (the sort is stable).
    events.sort_by(|a, b| a.time.total_cmp(&b.time));

    let file = AhapFile {
        version: 1.0,
        metadata: Metadata {
            project: "Sake Glug".to_owned(),
            description: format!(
                "Glugs of liquid poured from a sake bottle: scene {}, seed {}, {} glugs over \
                 {} s; sharpness 0..1 spans {} Hz of felt frequency",
                source.scene_name,
                source.seed,
                clip_onsets(source).len(),
                clip_end_s(source),
                band,
            ),
        },
        pattern: events.into_iter().map(PatternItem::Event).collect(),
    };
    serde_json::to_string_pretty(&file).expect("a pattern of plain numbers and strings serializes")
}

/// The pattern read back: its transients as onsets, its continuous events as the envelope (an
/// event's intensity is the square root of its mean amplitude).
fn read_back(clip: &WrittenClip) -> Result<Reading, OutputError> {
    let document = clip.json()?;
    let events: Vec<&Value> = array(&document, "/Pattern")
        .iter()
        .filter_map(|item| item.get("Event"))
        .collect();
    let kind =
        |event: &Value| event.get("EventType").and_then(Value::as_str) == Some("HapticTransient");
    let intensity = |event: &Value| {
        array(event, "/EventParameters")
            .iter()
            .find(|p| p.get("ParameterID").and_then(Value::as_str) == Some("HapticIntensity"))
            .map_or(0.0, |p| number(p, "ParameterValue"))
    };
    let continuous: Vec<(f64, f64, f64)> = events
        .iter()
        .filter(|e| !kind(e))
        .map(|e| {
            let start = number(e, "Time");
            // The intensity is the square root of the step's mean amplitude.
            (
                start,
                start + number(e, "EventDuration"),
                intensity(e).powi(2),
            )
        })
        .collect();
    let split = continuous
        .iter()
        .filter(|span| span.1 - span.0 >= CORE_HAPTICS_MAX_EVENT_S - 1e-9)
        .count();
    Ok(Reading {
        from_mark_before: false,
        onsets: events
            .iter()
            .filter(|e| kind(e))
            .map(|e| number(e, "Time"))
            .collect(),
        limits: format!(
            "{} events; {split} split at Core Haptics' {CORE_HAPTICS_MAX_EVENT_S:.0} s",
            events.len()
        ),
        envelope: held(continuous),
    })
}
