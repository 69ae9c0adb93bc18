//! Dual-rumble frames (`rumble`, JSON): the two motors of a gamepad, low from the f1
//! component, high from the f2 component ([`rumble_frames`]), at a fixed frame rate.

use serde::Serialize;

use super::read_back::{array, held, number, ReadBack, Reading, WrittenClip};
use super::{ClipSink, OutputError, OutputFormat, OutputOptions, Sink, SinkContext};
use crate::clips::{glug_count, ClipSource};
use crate::steps::rumble_frames;

/// `rumble` (`.json`): frames of a dual-rumble gamepad's two motors.
pub(super) const FORMAT: OutputFormat = OutputFormat {
    name: "rumble",
    extension: "json",
    by_extension: false,
    built: true,
    open,
    read_back: Some(ReadBack::Clip(read_back, document)),
    carries_c: "the motors' balance: low = the f1 part (c·a), high = the f2 part ((1 − c)·a)",
};

/// The default frame rate (Hz): 10 ms, the step of the Android entries and about the fastest a
/// rumble motor's speed is worth updating (SDL and the browsers send the controller a new
/// state at most every few milliseconds).
pub const DEFAULT_RUMBLE_RATE_HZ: f64 = 100.0;

/// The frame rates a rumble file takes (Hz): at least one frame a second, at most one a
/// millisecond.
pub const RUMBLE_RATE_RANGE_HZ: std::ops::RangeInclusive<f64> = 1.0..=1000.0;

/// Memory a glug takes until the file is written: the glug and its frames' text (8 frames at
/// 100 Hz between glugs 80 ms apart, ~45 bytes each).
const BYTES_PER_GLUG: u64 = 1024;

/// The sink of a `rumble` output, at the frame rate of the options: one outside
/// [`RUMBLE_RATE_RANGE_HZ`] is refused.
pub(super) fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    let rate_hz = context.options.platforms.rumble_rate_hz;
    if !RUMBLE_RATE_RANGE_HZ.contains(&rate_hz) {
        return Err(OutputError::RumbleRate {
            path: context.path.to_owned(),
            rate_hz,
        });
    }
    ClipSink::open(context, document, BYTES_PER_GLUG)
}

/// The frames of `source` at the options' rate.
fn document(source: &ClipSource, options: &OutputOptions) -> String {
    rumble_json(source, options.platforms.rumble_rate_hz)
}

#[derive(Serialize)]
struct Rumble {
    description: String,
    rate_hz: f64,
    frames: Vec<Frame>,
}

#[derive(Serialize)]
struct Frame {
    t_ms: f64,
    low: f64,
    high: f64,
}

/// Rounds to 4 decimals: a motor's speed is a 16-bit number at best (XInput, SDL), and 1e-4
/// is finer than any controller's steps while keeping the file a third of full precision's.
fn rounded(x: f64) -> f64 {
    (x * 1e4).round() / 1e4
}

/// The clip as `{"description", "rate_hz", "frames": [{"t_ms", "low", "high"}…]}`, every
/// frame held until the next (the last for one period).
pub fn rumble_json(source: &ClipSource, rate_hz: f64) -> String {
    let frames = rumble_frames(source, rate_hz)
        .into_iter()
        .map(|frame| Frame {
            t_ms: rounded(frame.t_ms),
            low: rounded(frame.low),
            high: rounded(frame.high),
        })
        .collect();
    let rumble = Rumble {
        description: format!(
            "Sake Glug {}: scene {}, seed {}, {}; low = the f1 component's envelope \
             (strong, low-frequency motor), high = the f2 component's (weak, high-frequency \
             motor), each held for 1/rate_hz",
            env!("CARGO_PKG_VERSION"),
            source.scene_name,
            source.seed,
            glug_count(source)
        ),
        rate_hz,
        frames,
    };
    serde_json::to_string(&rumble).expect("numbers and a string serialize")
}

/// The file read back: each frame held for its period (both motors' sum), a glug showing from
/// the start of the frame that carries it.
fn read_back(clip: &WrittenClip) -> Result<Reading, OutputError> {
    let document = clip.json()?;
    let rate_hz = number(&document, "rate_hz");
    let frames = array(&document, "/frames");
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
    Ok(Reading {
        onsets: spans.iter().map(|span| span.0).collect(),
        from_mark_before: true,
        limits: format!("{} frames at {rate_hz} Hz", frames.len()),
        envelope: held(spans),
    })
}
