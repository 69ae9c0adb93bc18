//! Meta Haptics Studio's `.haptic` clip (file format 1.0): a continuous amplitude envelope,
//! a frequency envelope, and an emphasis (transient) at every audible glug's onset.

use serde::Serialize;

use super::read_back::{array, linear, number, ReadBack, Reading, WrittenClip};
use super::{ClipSink, OutputError, OutputFormat, OutputOptions, Sink, SinkContext};
use crate::clips::{
    clip_end_s, clip_onsets, envelope_breakpoints, felt_frequency_hz, glug_count,
    transient_intensity, ClipSource, HapticBand, FULL_SCALE,
};

/// `.haptic`: a Meta Haptics Studio 1.0 clip.
pub(super) const FORMAT: OutputFormat = OutputFormat {
    name: "haptic",
    extension: "haptic",
    by_extension: true,
    built: true,
    open,
    read_back: Some(ReadBack::Clip(read_back, document)),
    carries_c: "emphasis and envelope frequency (the felt frequency on the band: 1 − c by default)",
};

/// The sink of a `.haptic` output, its frequencies on the band of the options.
pub(super) fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    ClipSink::open(context, document, BYTES_PER_GLUG)
}

/// The clip of `source`, its frequencies on the band of the options.
fn document(source: &ClipSource, options: &OutputOptions) -> String {
    haptic_json(source, &options.haptic_band)
}

/// Memory a glug takes until the clip is written: the glug, its breakpoints and their text
/// (a dense render peaks near 0.8 kB a glug).
const BYTES_PER_GLUG: u64 = 1024;

#[derive(Serialize)]
struct HapticFile {
    version: Version,
    metadata: Metadata,
    signals: Signals,
}

#[derive(Serialize)]
struct Version {
    major: u32,
    minor: u32,
    patch: u32,
}

#[derive(Serialize)]
struct Metadata {
    editor: String,
    source: String,
    project: String,
    tags: Vec<String>,
    description: String,
}

#[derive(Serialize)]
struct Signals {
    continuous: Continuous,
}

#[derive(Serialize)]
struct Continuous {
    envelopes: Envelopes,
}

#[derive(Serialize)]
struct Envelopes {
    amplitude: Vec<AmplitudePoint>,
    frequency: Vec<FrequencyPoint>,
}

#[derive(Serialize)]
struct AmplitudePoint {
    time: f64,
    amplitude: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    emphasis: Option<Emphasis>,
}

#[derive(Serialize)]
struct Emphasis {
    amplitude: f64,
    frequency: f64,
}

#[derive(Serialize)]
struct FrequencyPoint {
    time: f64,
    frequency: f64,
}

/// The normalised frequency written while nothing rings yet and no glug follows: the spec's
/// default for a missing frequency envelope.
const SILENT_FREQUENCY: f64 = 0.5;

/// The clip as a `.haptic` JSON document.
///
/// - Amplitude: the felt envelope ([`envelope_breakpoints`]), on the sample scale (full
///   scale = 1), so the clip is as strong as the sound.
/// - Emphasis, one per audible glug at its exact onset: amplitude
///   `max(envelope there, √peak)` ([`transient_intensity`], lifted to the envelope
///   because the spec requires the emphasis to be at least the envelope), frequency the band
///   position of the glug's felt frequency, which falls as the viscosity rises.
/// - Frequency: the band position of the felt frequency of everything ringing, at the same
///   times as the amplitude breakpoints, so it never leaves the amplitude envelope's span.
pub fn haptic_json(source: &ClipSource, band: &HapticBand) -> String {
    let breakpoints = envelope_breakpoints(source);

    let amplitude = breakpoints
        .iter()
        .map(|point| AmplitudePoint {
            time: point.time_s,
            amplitude: point.amplitude,
            emphasis: point.onset_of.map(|index| {
                let glug = &source.glugs[index];
                Emphasis {
                    amplitude: transient_intensity(glug, source.ceiling)
                        .max(point.amplitude)
                        .min(FULL_SCALE),
                    frequency: band.normalise(felt_frequency_hz(glug)),
                }
            }),
        })
        .collect();

    // Before the first glug nothing rings; its own frequency is the most honest lead-in.
    let mut previous = clip_onsets(source).first().map_or(SILENT_FREQUENCY, |&i| {
        band.normalise(felt_frequency_hz(&source.glugs[i]))
    });
    let frequency = breakpoints
        .iter()
        .map(|point| {
            if let Some(hz) = point.felt_frequency_hz {
                previous = band.normalise(hz);
            }
            FrequencyPoint {
                time: point.time_s,
                frequency: previous,
            }
        })
        .collect();

    let file = HapticFile {
        version: Version {
            major: 1,
            minor: 0,
            patch: 0,
        },
        metadata: Metadata {
            editor: concat!("Sake Glug ", env!("CARGO_PKG_VERSION")).to_owned(),
            source: format!("scene {}, seed {}", source.scene_name, source.seed),
            project: "Sake Glug".to_owned(),
            tags: vec![
                "sake-glug".to_owned(),
                "glug".to_owned(),
                source.scene_name.to_owned(),
            ],
            description: format!(
                "Glugs of liquid poured from a sake bottle: scene {}, seed {}, {} over {} s; \
                  frequency 0..1 spans {} Hz",
                source.scene_name,
                source.seed,
                glug_count(source),
                clip_end_s(source),
                band,
            ),
        },
        signals: Signals {
            continuous: Continuous {
                envelopes: Envelopes {
                    amplitude,
                    frequency,
                },
            },
        },
    };
    serde_json::to_string_pretty(&file).expect("a clip of plain numbers and strings serializes")
}

/// The clip read back: its emphases as onsets, its amplitude breakpoints as the envelope.
fn read_back(clip: &WrittenClip) -> Result<Reading, OutputError> {
    let document = clip.json()?;
    let points = array(&document, "/signals/continuous/envelopes/amplitude");
    Ok(Reading {
        from_mark_before: false,
        onsets: points
            .iter()
            .filter(|p| p.get("emphasis").is_some())
            .map(|p| number(p, "time"))
            .collect(),
        envelope: linear(
            points
                .iter()
                .map(|p| (number(p, "time"), number(p, "amplitude")))
                .collect(),
        ),
        limits: format!("{} breakpoints", points.len()),
    })
}
