//! Android's vibration formats, both from the same steps of the felt envelope
//! ([`android_steps`]): the vibration XML that `VibrationXmlParser` reads (`.xml`), and the
//! arrays of `VibrationEffect.createWaveform(long[] timings, int[] amplitudes, int repeat)`
//! as JSON (`android-waveform`).

use std::fmt::Write as _;

use serde::Serialize;

use super::{ClipSink, OutputError, Sink, SinkContext};
use crate::clips::{clip_onsets, ClipSource};
use crate::steps::{android_steps, ANDROID_STEP_MS};

/// Memory a glug takes until the file is written: the glug, its steps (8 at 10 ms between
/// glugs 80 ms apart) and their text.
const BYTES_PER_GLUG: u64 = 1024;

/// The sink of an Android vibration XML output.
pub(super) fn open_xml<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    ClipSink::open(context, |source, _| android_xml(source), BYTES_PER_GLUG)
}

/// The sink of an Android waveform (JSON) output.
pub(super) fn open_waveform<'a>(
    context: SinkContext<'a>,
) -> Result<Box<dyn Sink + 'a>, OutputError> {
    ClipSink::open(
        context,
        |source, _| android_waveform_json(source),
        BYTES_PER_GLUG,
    )
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
        "<!-- Sake Glug {}: seed {}, {} glugs, envelope in {ANDROID_STEP_MS} ms steps -->",
        env!("CARGO_PKG_VERSION"),
        source.seed,
        clip_onsets(source).len()
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
