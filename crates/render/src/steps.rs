//! What the platform formats are written from: the felt envelope of a clip cut into fixed steps
//! (Android's waveform entries), and the envelopes of the two components on their own (the two
//! motors of a dual-rumble gamepad). One quantiser, shared by every format that steps.
//!
//! Like the clips ([`super::clips`]), these are computed from the model's own units (each
//! glug's onset, A1 = c·a, A2 = (1 − c)·a, B1, B2), never from the waveform.

use super::clips::{clip_end_s, clip_onsets, ClipSource, EnvelopeSum, ENVELOPE_FLOOR};

/// The length (ms) of Android's waveform entries. Meta's Android renderer steps its envelopes
/// by 10 ms; for the model's decays (B ≈ 40–45 /s) a step is a fall of about 4 dB, finer than
/// the 8 dB between the `.haptic` breakpoints, and it spans one or two periods of a phone's
/// resonant actuator (150–250 Hz), which cannot follow faster changes anyway.
pub const ANDROID_STEP_MS: u64 = 10;

/// Android's amplitude scale: 1..255 vibrates (255 = the motor's full strength), 0 is off.
pub const ANDROID_FULL_AMPLITUDE: u8 = 255;

/// Points at which a step's mean envelope is sampled (the midpoints of equal parts): the
/// envelope falls by at most ~36 % over a 10 ms step, so 8 points give its mean to well under
/// a quantisation level.
const MEAN_POINTS: usize = 8;

/// The envelopes of a clip's two components at any time, as they are felt: `[Σ |A1|·e^(−B1·τ),
/// Σ |A2|·e^(−B2·τ)]` over the glugs started by then, both scaled down together where their sum
/// would pass the ceiling, so their sum is the felt envelope ([`super::clips::envelope_at`]).
pub struct ComponentEnvelopes<'a> {
    envelope: EnvelopeSum<'a>,
}

impl<'a> ComponentEnvelopes<'a> {
    /// The envelopes of `source`'s glugs.
    pub fn new(source: &ClipSource<'a>) -> Self {
        Self {
            envelope: EnvelopeSum::new(source),
        }
    }

    /// `[low, high]`: the f1 and the f2 component's envelope at `t` (s).
    ///
    /// Their sum is the felt envelope as driven (an actuator's compensation included); it is
    /// shared between them as the model balances them, without the compensation (MODEL.md §19):
    /// the motors are the platform's, not the profiled actuator.
    pub fn at(&self, t: f64) -> [f64; 2] {
        let sums = self.envelope.ringing_at(t);
        let [low, high] = sums.components;
        let limit = self.envelope.limit();
        // Without a compensation the balance is the components' own (to the bit).
        if sums.components == sums.model_components {
            let scale = if low + high > limit {
                limit / (low + high)
            } else {
                1.0
            };
            return [low * scale, high * scale];
        }
        let total = (low + high).min(limit);
        let [model_low, model_high] = sums.model_components;
        let model_total = model_low + model_high;
        if model_total > 0.0 {
            [
                total * model_low / model_total,
                total * model_high / model_total,
            ]
        } else {
            [0.0; 2]
        }
    }

    /// The mean of `[low, high]` over `from_s..to_s`.
    pub fn mean(&self, from_s: f64, to_s: f64) -> [f64; 2] {
        let width = (to_s - from_s) / MEAN_POINTS as f64;
        let mut sum = [0.0; 2];
        for point in 0..MEAN_POINTS {
            let [low, high] = self.at(from_s + (point as f64 + 0.5) * width);
            sum[0] += low;
            sum[1] += high;
        }
        sum.map(|component| component / MEAN_POINTS as f64)
    }

    /// The felt envelope (both components) at `t`.
    pub fn felt_at(&self, t: f64) -> f64 {
        let [low, high] = self.at(t);
        low + high
    }
}

/// One entry of an Android waveform: the motor held at `amplitude` for `duration_ms`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Step {
    /// Where it starts (ms from the start of the clip).
    pub start_ms: u64,
    /// How long it lasts (ms, at least 1).
    pub duration_ms: u64,
    /// 1..=255 while the envelope is above [`ENVELOPE_FLOOR`], 0 below it.
    pub amplitude: u8,
    /// Whether an audible glug starts here (its onset rounded to the millisecond).
    pub onset: bool,
}

/// The felt envelope of a clip as Android waveform entries: a new entry at every audible glug's
/// onset (rounded to the whole millisecond Android's durations count in), then every
/// [`ANDROID_STEP_MS`] until the next onset; each entry holds the envelope's mean over it,
/// `round(255 · mean)` but at least 1 while the mean is above [`ENVELOPE_FLOOR`] (an amplitude
/// of 0 stops some motors with a glitch), 0 below it. Silent entries in a row are merged.
pub fn android_steps(source: &ClipSource) -> Vec<Step> {
    let envelopes = ComponentEnvelopes::new(source);
    let end_ms = ((clip_end_s(source) * 1000.0).ceil() as u64).max(1);
    let mut onsets_ms: Vec<u64> = clip_onsets(source)
        .into_iter()
        .map(|i| (source.glugs[i].onset_s * 1000.0).round() as u64)
        .filter(|&ms| ms < end_ms)
        .collect();
    onsets_ms.dedup();

    let mut starts: Vec<(u64, bool)> = Vec::new();
    let anchors = std::iter::once((0, false)).chain(onsets_ms.iter().map(|&ms| (ms, true)));
    let mut anchors = anchors.peekable();
    while let Some((anchor_ms, onset)) = anchors.next() {
        let next_ms = anchors.peek().map_or(end_ms, |&(ms, _)| ms);
        if next_ms == anchor_ms {
            continue;
        }
        starts.push((anchor_ms, onset));
        let mut start_ms = anchor_ms + ANDROID_STEP_MS;
        while start_ms < next_ms {
            starts.push((start_ms, false));
            start_ms += ANDROID_STEP_MS;
        }
    }

    let mut steps: Vec<Step> = Vec::with_capacity(starts.len());
    for (index, &(start_ms, onset)) in starts.iter().enumerate() {
        let stop_ms = starts.get(index + 1).map_or(end_ms, |&(ms, _)| ms);
        let [low, high] = envelopes.mean(start_ms as f64 / 1000.0, stop_ms as f64 / 1000.0);
        let amplitude = android_amplitude(low + high);
        match steps.last_mut() {
            Some(last) if !onset && amplitude == 0 && last.amplitude == 0 => {
                last.duration_ms += stop_ms - start_ms;
            }
            _ => steps.push(Step {
                start_ms,
                duration_ms: stop_ms - start_ms,
                amplitude,
                onset,
            }),
        }
    }
    steps
}

/// An envelope level (0..1 of full scale) on Android's amplitude scale.
fn android_amplitude(level: f64) -> u8 {
    if level.is_nan() || level < ENVELOPE_FLOOR {
        0
    } else {
        (level * ANDROID_FULL_AMPLITUDE as f64)
            .round()
            .clamp(1.0, ANDROID_FULL_AMPLITUDE as f64) as u8
    }
}

/// One frame of a dual-rumble effect: from `t_ms` to the next frame, the low-frequency
/// (strong) motor at `low` and the high-frequency (weak) motor at `high`, both 0..1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RumbleFrame {
    /// Start of the frame (ms).
    pub t_ms: f64,
    /// The f1 component's mean envelope over the frame.
    pub low: f64,
    /// The f2 component's mean envelope over the frame.
    pub high: f64,
}

/// The clip as dual-rumble frames at `rate_hz`: the low motor follows the f1 component's
/// envelope (A1 = c·a), the high motor the f2 component's (A2 = (1 − c)·a), each the mean over
/// its frame, so the viscosity moves weight between the motors as it does between f1 and f2.
pub fn rumble_frames(source: &ClipSource, rate_hz: f64) -> Vec<RumbleFrame> {
    let envelopes = ComponentEnvelopes::new(source);
    let period_s = 1.0 / rate_hz;
    let frames = ((clip_end_s(source) * rate_hz).ceil() as u64).max(1);
    (0..frames)
        .map(|k| {
            let start_s = k as f64 * period_s;
            let [low, high] = envelopes.mean(start_s, start_s + period_s);
            RumbleFrame {
                t_ms: start_s * 1000.0,
                low: low.clamp(0.0, 1.0),
                high: high.clamp(0.0, 1.0),
            }
        })
        .collect()
}
