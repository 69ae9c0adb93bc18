//! Dual-rumble frames (`rumble`, JSON): the two motors of a gamepad, low from the f1
//! component, high from the f2 component ([`rumble_frames`]), at a fixed frame rate.

use serde::Serialize;

use super::{ClipSink, OutputError, Sink, SinkContext};
use crate::clips::{clip_onsets, ClipSource};
use crate::steps::rumble_frames;

/// Memory a glug takes until the file is written: the glug and its frames' text (8 frames at
/// 100 Hz between glugs 80 ms apart, ~45 bytes each).
const BYTES_PER_GLUG: u64 = 1024;

/// The sink of a `rumble` output, at the frame rate of the options.
pub(super) fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    ClipSink::open(
        context,
        |source, options| rumble_json(source, options.platforms.rumble_rate_hz),
        BYTES_PER_GLUG,
    )
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
            "Sake Glug {}: scene {}, seed {}, {} glugs; low = the f1 component's envelope \
             (strong, low-frequency motor), high = the f2 component's (weak, high-frequency \
             motor), each held for 1/rate_hz",
            env!("CARGO_PKG_VERSION"),
            source.scene_name,
            source.seed,
            clip_onsets(source).len()
        ),
        rate_hz,
        frames,
    };
    serde_json::to_string(&rumble).expect("numbers and a string serialize")
}
