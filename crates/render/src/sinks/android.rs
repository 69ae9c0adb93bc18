//! Android's vibration formats, both from the same steps of the felt envelope
//! ([`android_steps`]): the vibration XML that `VibrationXmlParser` reads (`.xml`), and the
//! arrays of `VibrationEffect.createWaveform(long[] timings, int[] amplitudes, int repeat)`
//! as JSON (`android-waveform`).

use std::fmt::Write as _;

use serde::Serialize;

use super::read_back::{array, held, ReadBack, Reading, WrittenClip};
use super::{ClipSink, OutputError, OutputFormat, OutputOptions, Sink, SinkContext};
use crate::clips::{glug_count, ClipSource};
use crate::steps::{android_steps, ANDROID_FULL_AMPLITUDE, ANDROID_STEP_MS};

/// `.xml`: Android's vibration XML (`VibrationXmlParser`).
pub(super) const XML_FORMAT: OutputFormat = OutputFormat {
    name: "android-xml",
    extension: "xml",
    by_extension: true,
    built: true,
    open: open_xml,
    read_back: Some(ReadBack::Clip(read_back_xml, xml_document)),
    carries_c: CARRIES_C,
};

/// `android-waveform` (`.json`): the arrays of Android's `VibrationEffect.createWaveform`.
pub(super) const WAVEFORM_FORMAT: OutputFormat = OutputFormat {
    name: "android-waveform",
    extension: "json",
    by_extension: false,
    built: true,
    open: open_waveform,
    read_back: Some(ReadBack::Clip(read_back_waveform, waveform_document)),
    carries_c: CARRIES_C,
};

/// What carries c in either Android file.
const CARRIES_C: &str = "nothing: one motor, amplitude only";

/// Memory a glug takes until the file is written: the glug, its steps (8 at 10 ms between
/// glugs 80 ms apart) and their text.
const BYTES_PER_GLUG: u64 = 1024;

/// The sink of an Android vibration XML output.
pub(super) fn open_xml<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    ClipSink::open(context, xml_document, BYTES_PER_GLUG)
}

/// The XML of `source`.
fn xml_document(source: &ClipSource, _: &OutputOptions) -> String {
    android_xml(source)
}

/// The waveform JSON of `source`.
fn waveform_document(source: &ClipSource, _: &OutputOptions) -> String {
    android_waveform_json(source)
}

/// The sink of an Android waveform (JSON) output.
pub(super) fn open_waveform<'a>(
    context: SinkContext<'a>,
) -> Result<Box<dyn Sink + 'a>, OutputError> {
    ClipSink::open(context, waveform_document, BYTES_PER_GLUG)
}

/// The clip as Android's vibration XML (schema `vibration.xsd`, root `<vibration-effect>` as
/// Android 15's `VibrationXmlParser` reads it): one `<waveform-effect>` of
/// `<waveform-entry durationMs amplitude>`, played once (no `<repeating>`). A comment names
/// the render; the scene's name is left out of it, as a name may hold what a comment cannot.
pub fn android_xml(source: &ClipSource) -> String {
    let steps = android_steps(source);
    let mut xml = String::with_capacity(64 * steps.len() + 256);
    xml.push_str("<?xml version=\"1.0\" encoding=\"utf-8\"?>\n");
    let _ = writeln!(
        xml,
        "<!-- Sake Glug {}: seed {}, {}, envelope in {ANDROID_STEP_MS} ms steps -->",
        env!("CARGO_PKG_VERSION"),
        source.seed,
        glug_count(source)
    );
    xml.push_str("<vibration-effect>\n  <waveform-effect>\n");
    for step in &steps {
        let _ = writeln!(
            xml,
            "    <waveform-entry durationMs=\"{}\" amplitude=\"{}\"/>",
            step.duration_ms, step.amplitude
        );
    }
    xml.push_str("  </waveform-effect>\n</vibration-effect>\n");
    xml
}

#[derive(Serialize)]
struct Waveform {
    timings: Vec<u64>,
    amplitudes: Vec<u8>,
    repeat: i32,
}

/// The clip as the arguments of `VibrationEffect.createWaveform(timings, amplitudes, repeat)`:
/// `{"timings": [ms…], "amplitudes": [0..255…], "repeat": -1}` (played once).
pub fn android_waveform_json(source: &ClipSource) -> String {
    let steps = android_steps(source);
    let waveform = Waveform {
        timings: steps.iter().map(|step| step.duration_ms).collect(),
        amplitudes: steps.iter().map(|step| step.amplitude).collect(),
        repeat: -1,
    };
    serde_json::to_string(&waveform).expect("arrays of integers serialize")
}

/// Android entries `(duration ms, amplitude)` as held levels, and their starts as onsets.
fn android_reading(entries: impl Iterator<Item = (u64, u64)>, lifted: usize) -> Reading {
    let mut at_ms = 0;
    let mut spans = Vec::new();
    for (duration_ms, amplitude) in entries {
        let start = at_ms as f64 / 1000.0;
        at_ms += duration_ms;
        let level = amplitude as f64 / ANDROID_FULL_AMPLITUDE as f64;
        spans.push((start, at_ms as f64 / 1000.0, level));
    }
    Reading {
        from_mark_before: false,
        onsets: spans.iter().map(|span| span.0).collect(),
        limits: format!(
            "{} entries of whole ms and 8-bit amplitude; {lifted} lifted to 1, the lowest level",
            spans.len()
        ),
        envelope: held(spans),
    }
}

/// The waveform JSON read back: its entries.
fn read_back_waveform(clip: &WrittenClip) -> Result<Reading, OutputError> {
    let document = clip.json()?;
    let integers = |key| -> Vec<u64> {
        array(&document, key)
            .iter()
            .map(|v| v.as_u64().unwrap_or(0))
            .collect()
    };
    let (timings, amplitudes) = (integers("/timings"), integers("/amplitudes"));
    let lifted = amplitudes.iter().filter(|&&a| a == 1).count();
    Ok(android_reading(timings.into_iter().zip(amplitudes), lifted))
}

/// The XML read back: it holds the entries of the waveform JSON, the steps of the model's glugs
/// ([`android_steps`]), which are read from them.
fn read_back_xml(clip: &WrittenClip) -> Result<Reading, OutputError> {
    let steps = android_steps(clip.source);
    let lifted = steps.iter().filter(|s| s.amplitude == 1).count();
    Ok(android_reading(
        steps.iter().map(|s| (s.duration_ms, s.amplitude as u64)),
        lifted,
    ))
}
