//! How the fidelity report (`crate::fidelity`) reads a played format back: each format's
//! entry (`super::OutputFormat::read_back`) names a [`ReadBack`], and the readers of the clips
//! share the helpers here. Beside the formats, so that they depend on it and the report on them,
//! never both ways.

use std::path::Path;

use serde_json::Value;

use super::{OutputError, OutputOptions};
use crate::clips::ClipSource;
use crate::scene::Scene;

/// How the fidelity report reads a played format back; a format not played (the plot, the
/// tables, read by people and programs) declares none and is not measured.
#[derive(Clone, Copy)]
pub(crate) enum ReadBack {
    /// The render's samples themselves: the onsets to the sample, no envelope apart from the
    /// waveform; `limits` says what the platform took of them for a scene.
    Waveform {
        /// The platform limits the file met.
        limits: fn(&Scene) -> String,
        /// The haptic channel it carries beside its audio, if it does.
        haptic: Option<HapticChannel>,
    },
    /// A clip: its onsets and its envelope, read from the file; and the document its sink
    /// writes of a clip (so its drive can be measured before it is written, `--haptic-peak`).
    Clip(
        fn(&WrittenClip) -> Result<Reading, OutputError>,
        fn(&ClipSource, &OutputOptions) -> String,
    ),
}

/// The haptic channel of a waveform file that carries one beside its audio (the DualSense's
/// actuators, Android's haptic channel): `--haptic-peak` drives it as the clips are driven
/// (MODEL.md §19), and the fidelity report reads its peak back from the file.
#[derive(Clone, Copy)]
pub(crate) struct HapticChannel {
    /// The rate (Hz) the file holds it at, for a scene: its peak is measured there.
    pub rate: fn(&Scene) -> u32,
    /// Its strongest drive as the file holds it: the largest |sample| of the haptic channels
    /// (0..1 of full scale), read back from the file.
    pub read_peak: fn(&Path) -> Result<f64, OutputError>,
}

/// The limits column of a waveform its platform takes as it is: "—".
pub(crate) fn no_limits(_: &Scene) -> String {
    "—".to_owned()
}

/// A clip's file as written, and the model's glugs it was written from.
pub(crate) struct WrittenClip<'a> {
    /// The file (named in errors).
    pub path: &'a Path,
    /// Its text.
    pub text: &'a str,
    /// The model's glugs.
    pub source: &'a ClipSource<'a>,
}

impl WrittenClip<'_> {
    /// The file as JSON.
    pub fn json(&self) -> Result<Value, OutputError> {
        serde_json::from_str(self.text).map_err(|error| OutputError::Io {
            path: self.path.to_owned(),
            source: error.into(),
        })
    }
}

/// What a clip's file says of the render, read back: its onsets and its envelope.
pub(crate) struct Reading {
    /// Times (s) the format marks an onset at.
    pub onsets: Vec<f64>,
    /// Whether a glug shows from the last mark before its onset (a rumble frame carries it
    /// from the frame's start), rather than from the nearest mark.
    pub from_mark_before: bool,
    /// The format's level (0..1 of full scale) at a time.
    pub envelope: Box<dyn Fn(f64) -> f64>,
    /// The platform limits the file met.
    pub limits: String,
}

impl Reading {
    /// The strongest drive the format carries (0..1 of full scale): its envelope's largest
    /// value, looked for at every mark and every 0.25 ms (a level is held at least 1 ms, and a
    /// line between breakpoints peaks at one, each an onset's mark).
    pub fn peak_drive(&self, duration_s: f64) -> f64 {
        const EVERY_S: f64 = 0.000_25;
        let grid = (0..=(duration_s / EVERY_S).ceil() as usize).map(|n| n as f64 * EVERY_S);
        self.onsets
            .iter()
            .copied()
            .chain(grid)
            .map(|t| (self.envelope)(t))
            .fold(0.0, f64::max)
    }
}

/// The number at `key` of `value`, 0 if none.
pub(crate) fn number(value: &Value, key: &str) -> f64 {
    value.get(key).and_then(Value::as_f64).unwrap_or(0.0)
}

/// The array at `pointer` in `value`, empty if none.
pub(crate) fn array<'a>(value: &'a Value, pointer: &str) -> &'a [Value] {
    value
        .pointer(pointer)
        .and_then(Value::as_array)
        .map_or(&[], Vec::as_slice)
}

/// Straight lines between `(time, level)` points; 0 outside them.
pub(crate) fn linear(points: Vec<(f64, f64)>) -> Box<dyn Fn(f64) -> f64> {
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
pub(crate) fn held(mut spans: Vec<(f64, f64, f64)>) -> Box<dyn Fn(f64) -> f64> {
    spans.sort_by(|a, b| a.0.total_cmp(&b.0));
    Box::new(move |t| {
        let next = spans.partition_point(|span| span.0 <= t);
        match next.checked_sub(1).map(|i| spans[i]) {
            Some((_, end, level)) if t < end => level,
            _ => 0.0,
        }
    })
}
