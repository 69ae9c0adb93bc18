//! What each format keeps of the model, measured: one render written in every format, each
//! file read back (the steps for the XML, which holds the same entries as the waveform JSON)
//! and held against the model's own glugs: where its onsets fall, how far its envelope strays
//! from the felt envelope, what carries the viscosity c, how big it is, and which platform
//! limits it met. `sake-glug render --fidelity` prints it; the README's table is its output.

use std::path::Path;

use serde_json::Value;

use super::clips::{clip_onsets, ClipSource, Glug};
use super::render::{RenderObserver, RenderSummary};
use super::scene::Scene;
use super::sinks::{Output, OutputError, OutputFormat, OutputOptions, DUALSENSE_RATE_HZ};
use super::steps::{android_steps, ComponentEnvelopes};
use sake_glug_engine::{UnitOnset, Voicing};

/// The envelope is compared where the model's is within this of its loudest (−40 dB): the
/// glugging part, where a difference can be felt; below it every format is near silence.
const GLUGGING_FLOOR: f64 = 0.01;

/// A format's level is floored here (−60 dB) before it is compared in dB, so a step to 0
/// counts as a fall to −60 dB, not as an infinite error.
const LEVEL_FLOOR: f64 = 1e-3;

/// The envelope is compared every millisecond.
const COMPARE_EVERY_S: f64 = 0.001;

/// Core Haptics' limit on one continuous event (s), which the `.ahap` splits at.
const AHAP_EVENT_LIMIT_S: f64 = 30.0;

/// What one format keeps of a render.
#[derive(Debug, Clone, PartialEq)]
pub struct Fidelity {
    /// The format.
    pub format: OutputFormat,
    /// Mean and worst distance (ms) from the model's audible onsets to the format's, or `None`
    /// for a waveform, which holds the onsets to the sample.
    pub onset_error_ms: Option<(f64, f64)>,
    /// Mean |dB| between the format's envelope and the model's felt envelope over the
    /// glugging part, or `None` for a waveform.
    pub envelope_error_db: Option<f64>,
    /// What carries the viscosity c.
    pub carries_c: &'static str,
    /// Size of the file (bytes).
    pub bytes: u64,
    /// The platform limits the file met, measured on this render.
    pub limits: String,
}

/// The formats measured: every one but the plot and the tables (not played), and those this
/// build cannot write.
fn measured_formats() -> impl Iterator<Item = OutputFormat> {
    OutputFormat::ALL.iter().copied().filter(|&format| {
        // The plot and the tables (MODEL.md §14) are read by people and programs, not played:
        // the tables hold the model's own numbers.
        ![OutputFormat::PLOT, OutputFormat::UNITS, OutputFormat::STATE].contains(&format)
            && (cfg!(feature = "ogg") || format != OutputFormat::ANDROID_OGG)
    })
}

/// Renders `scene` once into every format (in a temporary folder) and measures each file.
pub fn measure(
    scene: &Scene,
    scene_name: &str,
    options: &OutputOptions,
) -> Result<Vec<Fidelity>, OutputError> {
    let folder = tempfile::tempdir().map_err(OutputError::io(Path::new("a temporary folder")))?;
    let outputs: Vec<Output> = measured_formats()
        .map(|format| Output {
            format,
            path: folder.path().join(format.file_name("measured")),
        })
        .collect();
    struct Glugs {
        glugs: Vec<Glug>,
        sample_rate: u32,
    }
    impl RenderObserver for &mut Glugs {
        fn unit_started(&mut self, onset: &UnitOnset, voicing: Voicing) {
            let glug = Glug::of_unit(onset, voicing.output_gain, self.sample_rate);
            self.glugs.push(glug);
        }
    }
    let mut glugs = Glugs {
        glugs: Vec::new(),
        sample_rate: scene.sample_rate,
    };
    let report = super::render_to_files(scene, scene_name, &outputs, options, &mut glugs)?;
    let source = ClipSource {
        duration_s: report.summary.duration_s(),
        glugs: &glugs.glugs,
        ceiling: scene.config.ceiling,
        scene_name,
        seed: scene.config.seed,
    };
    outputs
        .iter()
        .zip(&report.files)
        .map(|(output, (_, bytes))| {
            let text =
                || std::fs::read_to_string(&output.path).map_err(OutputError::io(&output.path));
            measure_one(output.format, scene, &source, &report.summary, *bytes, text)
        })
        .collect()
}

/// What a format's file says of the render, read back: its onsets and its envelope.
struct Reading {
    /// Times (s) the format marks an onset at.
    onsets: Vec<f64>,
    /// Whether a glug shows from the last mark before its onset (a rumble frame carries it
    /// from the frame's start), rather than from the nearest mark.
    from_mark_before: bool,
    /// The format's level (0..1 of full scale) at a time.
    envelope: Box<dyn Fn(f64) -> f64>,
    limits: String,
}

fn measure_one(
    format: OutputFormat,
    scene: &Scene,
    source: &ClipSource,
    summary: &RenderSummary,
    bytes: u64,
    text: impl Fn() -> Result<String, OutputError>,
) -> Result<Fidelity, OutputError> {
    let json = || -> Result<Value, OutputError> {
        serde_json::from_str(&text()?).map_err(|e| OutputError::Io {
            path: format.file_name("measured").into(),
            source: e.into(),
        })
    };
    let (reading, carries_c): (Option<Reading>, &'static str) = match format.name() {
        "haptic" => (
            Some(read_haptic(&json()?)),
            "emphasis and envelope frequency (the felt frequency on the band: 1 − c by default)",
        ),
        "ahap" => (
            Some(read_ahap(&json()?)),
            "HapticSharpness (the felt frequency: 1 − c by default)",
        ),
        "haps" => (
            Some(read_haps(&json()?)),
            "frequency keyframes in Hz (the felt frequency, c·f1 + (1 − c)·f2 weighted)",
        ),
        "android-waveform" => (
            Some(read_android(&json()?)),
            "nothing: one motor, amplitude only",
        ),
        "android-xml" => (
            Some(read_steps(source)),
            "nothing: one motor, amplitude only",
        ),
        "rumble" => (
            Some(read_rumble(&json()?)),
            "the motors' balance: low = the f1 part (c·a), high = the f2 part ((1 − c)·a)",
        ),
        "dualsense" => (
            None,
            "the waveform on both actuators (c·a at f1, (1 − c)·a at f2), 16-bit",
        ),
        "android-ogg" => (
            None,
            "the waveform on the haptic channel, Vorbis-coded (lossy)",
        ),
        _ => (None, "the waveform itself (c·a at f1, (1 − c)·a at f2)"),
    };
    let Some(reading) = reading else {
        let limits = match format.name() {
            "dualsense" if scene.sample_rate == DUALSENSE_RATE_HZ => {
                "48 kHz, the scene's own rate (another is resampled: rubato's FFT resampler)"
                    .to_owned()
            }
            "dualsense" => format!(
                "48 kHz, resampled from the scene's {} Hz (rubato's FFT resampler)",
                scene.sample_rate
            ),
            _ => "—".to_owned(),
        };
        return Ok(Fidelity {
            format,
            onset_error_ms: None,
            envelope_error_db: None,
            carries_c,
            bytes,
            limits,
        });
    };
    let onsets: Vec<f64> = clip_onsets(source)
        .into_iter()
        .map(|i| source.glugs[i].onset_s)
        .collect();
    let onset_error_ms = (!onsets.is_empty()).then(|| {
        let distances: Vec<f64> = onsets
            .iter()
            .map(|&onset| distance(&reading, onset) * 1000.0)
            .collect();
        let mean = distances.iter().sum::<f64>() / distances.len() as f64;
        (mean, distances.iter().copied().fold(0.0, f64::max))
    });
    Ok(Fidelity {
        format,
        onset_error_ms,
        envelope_error_db: envelope_error_db(source, summary, &*reading.envelope),
        carries_c,
        bytes,
        limits: reading.limits,
    })
}

/// How far (s) the format puts `onset`: from the nearest mark, or from the last mark before it.
fn distance(reading: &Reading, onset: f64) -> f64 {
    let marks = reading.onsets.iter();
    if reading.from_mark_before {
        marks
            .filter(|&&mark| mark <= onset + 1e-12)
            .map(|mark| onset - mark)
            .fold(f64::INFINITY, f64::min)
    } else {
        marks
            .map(|mark| (mark - onset).abs())
            .fold(f64::INFINITY, f64::min)
    }
}

/// Mean |20·log10(format / model)| every millisecond where the model's felt envelope is
/// within [`GLUGGING_FLOOR`] of its loudest.
fn envelope_error_db(
    source: &ClipSource,
    summary: &RenderSummary,
    envelope: &dyn Fn(f64) -> f64,
) -> Option<f64> {
    let model = ComponentEnvelopes::new(source);
    let times: Vec<f64> = (0..(summary.duration_s() / COMPARE_EVERY_S) as usize)
        .map(|n| n as f64 * COMPARE_EVERY_S)
        .collect();
    let levels: Vec<f64> = times.iter().map(|&t| model.felt_at(t)).collect();
    let loudest = levels.iter().copied().fold(0.0, f64::max);
    let errors: Vec<f64> = times
        .iter()
        .zip(&levels)
        .filter(|(_, &level)| level > 0.0 && level >= GLUGGING_FLOOR * loudest)
        .map(|(&t, &level)| (20.0 * (envelope(t).max(LEVEL_FLOOR) / level).log10()).abs())
        .collect();
    (!errors.is_empty()).then(|| errors.iter().sum::<f64>() / errors.len() as f64)
}

fn number(value: &Value, key: &str) -> f64 {
    value.get(key).and_then(Value::as_f64).unwrap_or(0.0)
}

fn array<'a>(value: &'a Value, pointer: &str) -> &'a [Value] {
    value
        .pointer(pointer)
        .and_then(Value::as_array)
        .map_or(&[], Vec::as_slice)
}

/// Straight lines between `(time, level)` points; 0 outside them.
fn linear(points: Vec<(f64, f64)>) -> Box<dyn Fn(f64) -> f64> {
    Box::new(move |t| {
        let next = points.partition_point(|p| p.0 <= t);
        if next == 0 || next == points.len() {
            return 0.0;
        }
        let (a, b) = (points[next - 1], points[next]);
        a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0).max(1e-12)
    })
}

/// Levels held over `(start, end, level)` spans; 0 outside them.
fn held(mut spans: Vec<(f64, f64, f64)>) -> Box<dyn Fn(f64) -> f64> {
    spans.sort_by(|a, b| a.0.total_cmp(&b.0));
    Box::new(move |t| {
        let next = spans.partition_point(|span| span.0 <= t);
        match next.checked_sub(1).map(|i| spans[i]) {
            Some((_, end, level)) if t < end => level,
            _ => 0.0,
        }
    })
}

fn read_haptic(document: &Value) -> Reading {
    let points = array(document, "/signals/continuous/envelopes/amplitude");
    Reading {
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
    }
}

fn read_ahap(document: &Value) -> Reading {
    let events: Vec<&Value> = array(document, "/Pattern")
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
        .filter(|span| span.1 - span.0 >= AHAP_EVENT_LIMIT_S - 1e-9)
        .count();
    Reading {
        from_mark_before: false,
        onsets: events
            .iter()
            .filter(|e| kind(e))
            .map(|e| number(e, "Time"))
            .collect(),
        limits: format!(
            "{} events; {split} split at Core Haptics' {AHAP_EVENT_LIMIT_S:.0} s",
            events.len()
        ),
        envelope: held(continuous),
    }
}

fn read_haps(document: &Value) -> Reading {
    let notes = array(document, "/m_vibration/m_melodies/0/m_notes");
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
    Reading {
        from_mark_before: false,
        onsets: notes.iter().map(|n| number(n, "m_startingPoint")).collect(),
        limits: format!("{} notes, {} keyframes", notes.len(), points.len()),
        envelope: linear(points),
    }
}

/// Android entries `(duration ms, amplitude)` as held levels, and their starts as onsets.
fn android_reading(entries: impl Iterator<Item = (u64, u64)>, lifted: usize) -> Reading {
    let mut at_ms = 0;
    let mut spans = Vec::new();
    for (duration_ms, amplitude) in entries {
        let start = at_ms as f64 / 1000.0;
        at_ms += duration_ms;
        spans.push((start, at_ms as f64 / 1000.0, amplitude as f64 / 255.0));
    }
    Reading {
        from_mark_before: false,
        onsets: spans.iter().map(|span| span.0).collect(),
        limits: format!(
            "{} entries of whole ms and 8-bit amplitude; {lifted} at the lowest level, 1",
            spans.len()
        ),
        envelope: held(spans),
    }
}

fn read_android(document: &Value) -> Reading {
    let integers = |key| -> Vec<u64> {
        array(document, key)
            .iter()
            .map(|v| v.as_u64().unwrap_or(0))
            .collect()
    };
    let (timings, amplitudes) = (integers("/timings"), integers("/amplitudes"));
    let lifted = amplitudes.iter().filter(|&&a| a == 1).count();
    android_reading(timings.into_iter().zip(amplitudes), lifted)
}

fn read_steps(source: &ClipSource) -> Reading {
    let steps = android_steps(source);
    let lifted = steps.iter().filter(|s| s.amplitude == 1).count();
    android_reading(
        steps.iter().map(|s| (s.duration_ms, s.amplitude as u64)),
        lifted,
    )
}

fn read_rumble(document: &Value) -> Reading {
    let rate_hz = number(document, "rate_hz");
    let frames = array(document, "/frames");
    let period_s = 1.0 / rate_hz;
    let spans: Vec<(f64, f64, f64)> = frames
        .iter()
        .map(|f| {
            let start = number(f, "t_ms") / 1000.0;
            (
                start,
                start + period_s,
                number(f, "low") + number(f, "high"),
            )
        })
        .collect();
    Reading {
        onsets: spans.iter().map(|span| span.0).collect(),
        from_mark_before: true,
        limits: format!("{} frames at {rate_hz} Hz", frames.len()),
        envelope: held(spans),
    }
}

/// The measurements as the Markdown table the README shows.
pub fn fidelity_table(rows: &[Fidelity]) -> String {
    let mut lines = vec![
        "| format | onset error, mean / worst (ms) | envelope error (dB) | what carries c | size | limits met |".to_owned(),
        "|---|---|---|---|---|---|".to_owned(),
    ];
    for row in rows {
        let onset = row
            .onset_error_ms
            .map_or("exact (the samples)".to_owned(), |(mean, worst)| {
                format!("{mean:.2} / {worst:.2}")
            });
        let envelope = row
            .envelope_error_db
            .map_or("— (the waveform)".to_owned(), |db| format!("{db:.1}"));
        lines.push(format!(
            "| `{}` | {onset} | {envelope} | {} | {} | {} |",
            row.format.name(),
            row.carries_c,
            super::human_bytes(row.bytes),
            row.limits
        ));
    }
    lines.join("\n") + "\n"
}
