//! Interhaptics' `.haps` (Razer Haptic Composer, file version 5): the vibration as one note per
//! audible glug, from its onset to the next one, with the felt envelope's breakpoints as
//! amplitude keyframes and the felt frequency (Hz) as frequency keyframes.

use serde::Serialize;

use super::read_back::{array, linear, number, ReadBack, Reading, WrittenClip};
use super::{ClipSink, OutputError, OutputFormat, OutputOptions, Sink, SinkContext};
use crate::clips::{clip_end_s, envelope_breakpoints, glug_count, ClipSource};

/// `.haps`: an Interhaptics / Razer Haptic Composer file (version 5).
pub(super) const FORMAT: OutputFormat = OutputFormat {
    name: "haps",
    extension: "haps",
    by_extension: true,
    built: true,
    open,
    read_back: Some(ReadBack::Clip(read_back, document)),
    carries_c: "frequency keyframes in Hz (the felt frequency, c·f1 + (1 − c)·f2 weighted)",
};

/// Memory a glug takes until the file is written: the glug, its keyframes and their text.
const BYTES_PER_GLUG: u64 = 1536;

/// The sink of a `.haps` output.
pub(super) fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    ClipSink::open(context, document, BYTES_PER_GLUG)
}

/// The file of `source`.
fn document(source: &ClipSource, _: &OutputOptions) -> String {
    haps_json(source)
}

/// The file version this writes, as Haptic Composer writes it (a string).
pub const HAPS_VERSION: &str = "5";

#[derive(Serialize)]
struct HapsFile {
    m_version: &'static str,
    m_description: String,
    #[serde(rename = "m_HDFlag")]
    m_hd_flag: u32,
    /// Seconds, as Haptic Composer's own files.
    m_time_unit: u32,
    m_length_unit: u32,
    m_stiffness: Perception,
    m_texture: Perception,
    m_vibration: Perception,
    m_gain: f64,
}

/// One perception (vibration, stiffness, texture): its melodies and how they are evaluated.
#[derive(Serialize)]
struct Perception {
    m_loop: u32,
    m_maximum: f64,
    m_gain: f64,
    #[serde(rename = "m_signalEvaluationMethod")]
    m_signal_evaluation_method: u32,
    m_melodies: Vec<Melody>,
}

impl Perception {
    fn with(melodies: Vec<Melody>) -> Self {
        Self {
            m_loop: 0,
            m_maximum: 1.0,
            m_gain: 1.0,
            m_signal_evaluation_method: 3,
            m_melodies: melodies,
        }
    }
}

#[derive(Serialize)]
struct Melody {
    m_mute: u32,
    m_gain: f64,
    m_notes: Vec<Note>,
}

#[derive(Serialize)]
struct Note {
    #[serde(rename = "m_startingPoint")]
    m_starting_point: f64,
    m_length: f64,
    m_priority: u32,
    m_gain: f64,
    #[serde(rename = "m_hapticEffect")]
    m_haptic_effect: HapticEffect,
}

#[derive(Serialize)]
struct HapticEffect {
    #[serde(rename = "m_amplitudeModulation")]
    m_amplitude_modulation: Modulation,
    #[serde(rename = "m_frequencyModulation")]
    m_frequency_modulation: Modulation,
}

#[derive(Serialize)]
struct Modulation {
    #[serde(rename = "m_extrapolationStrategy")]
    m_extrapolation_strategy: u32,
    m_keyframes: Vec<Keyframe>,
}

#[derive(Serialize)]
struct Keyframe {
    m_time: f64,
    m_value: f64,
}

fn modulation(keyframes: Vec<Keyframe>) -> Modulation {
    Modulation {
        m_extrapolation_strategy: 0,
        m_keyframes: keyframes,
    }
}

/// The clip as a `.haps` document: in the vibration, one melody of one note per audible glug
/// (its `m_startingPoint` the onset, its `m_length` up to the next onset or the clip's end),
/// whose keyframes (times from the note's start) are the felt envelope's breakpoints
/// ([`envelope_breakpoints`]): amplitude 0..1 on the sample scale, frequency the felt
/// frequency in Hz (the amplitude-weighted mean of f1 and f2 of what rings, which falls as the
/// viscosity rises). Stiffness and texture are empty.
pub fn haps_json(source: &ClipSource) -> String {
    let end_s = clip_end_s(source);
    let breakpoints = envelope_breakpoints(source);
    let starts: Vec<usize> = breakpoints
        .iter()
        .enumerate()
        .filter(|(_, point)| point.onset_of.is_some())
        .map(|(index, _)| index)
        .collect();
    let notes = starts
        .iter()
        .enumerate()
        .map(|(n, &first)| {
            let last = starts.get(n + 1).copied().unwrap_or(breakpoints.len());
            let start_s = breakpoints[first].time_s;
            let stop_s = starts
                .get(n + 1)
                .map_or(end_s, |&next| breakpoints[next].time_s);
            let points = &breakpoints[first..last];
            let mut frequency_hz = points[0].felt_frequency_hz.unwrap_or_default();
            let mut frequency = Vec::with_capacity(points.len());
            for point in points {
                frequency_hz = point.felt_frequency_hz.unwrap_or(frequency_hz);
                frequency.push(Keyframe {
                    m_time: point.time_s - start_s,
                    m_value: frequency_hz,
                });
            }
            Note {
                m_starting_point: start_s,
                m_length: stop_s - start_s,
                m_priority: 0,
                m_gain: 1.0,
                m_haptic_effect: HapticEffect {
                    m_amplitude_modulation: modulation(
                        points
                            .iter()
                            .map(|point| Keyframe {
                                m_time: point.time_s - start_s,
                                m_value: point.amplitude,
                            })
                            .collect(),
                    ),
                    m_frequency_modulation: modulation(frequency),
                },
            }
        })
        .collect();
    let file = HapsFile {
        m_version: HAPS_VERSION,
        m_description: format!(
            "Sake Glug {}: scene {}, seed {}, {} over {} s; one note per audible glug, \
             frequency in Hz",
            env!("CARGO_PKG_VERSION"),
            source.scene_name,
            source.seed,
            glug_count(source),
            end_s
        ),
        m_hd_flag: 0,
        m_time_unit: 0,
        m_length_unit: 7,
        m_stiffness: Perception::with(Vec::new()),
        m_texture: Perception::with(Vec::new()),
        m_vibration: Perception::with(vec![Melody {
            m_mute: 0,
            m_gain: 1.0,
            m_notes: notes,
        }]),
        m_gain: 1.0,
    };
    serde_json::to_string(&file).expect("numbers and strings serialize")
}

/// The file read back: each note's start as an onset, its amplitude keyframes as the envelope.
fn read_back(clip: &WrittenClip) -> Result<Reading, OutputError> {
    let document = clip.json()?;
    let notes = array(&document, "/m_vibration/m_melodies/0/m_notes");
    let mut points = Vec::new();
    for note in notes {
        let start = number(note, "m_startingPoint");
        for keyframe in array(note, "/m_hapticEffect/m_amplitudeModulation/m_keyframes") {
            points.push((
                start + number(keyframe, "m_time"),
                number(keyframe, "m_value"),
            ));
        }
    }
    Ok(Reading {
        from_mark_before: false,
        onsets: notes.iter().map(|n| number(n, "m_startingPoint")).collect(),
        limits: format!("{} notes, {} keyframes", notes.len(), points.len()),
        envelope: linear(points),
    })
}
