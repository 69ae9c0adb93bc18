//! What every haptic clip is written from: the glugs of a render and their felt envelope.
//!
//! The clip formats ([`super::sinks`]: Meta's `.haptic`, Apple's `.ahap`, the pour plot's
//! envelope) describe what is *felt*, not the waveform: an amplitude envelope that jumps at every
//! glug onset and decays like the glug, a felt frequency, and one transient per audible glug. The
//! shared logic (envelope, breakpoints, frequency mapping) lives here so the formats agree on
//! every number. Its exp and ln are libm's, pure Rust, not the platform's C maths library
//! (glibc's and MinGW-w64's differ in the last bit), so a clip written on Windows is the Linux
//! one byte for byte (tests/host/test_windows.py).

use std::fmt;
use std::str::FromStr;

use sake_glug_engine::UnitOnset;

/// One glug of the render: two decaying sinusoids starting at `onset_s`,
/// `y(τ) = A1·e^(−B1·τ)·sin(2π·f1·τ) + A2·e^(−B2·τ)·sin(2π·f2·τ)` for `τ = t − onset_s ≥ 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Glug {
    /// Onset time in seconds from the start of the render (sub-sample exact).
    pub onset_s: f64,
    /// `[A1, A2]` = `[c·a, (1 − c)·a]`, already multiplied by the output gain at the onset.
    pub amplitudes: [f64; 2],
    /// `[f1, f2]` in Hz: the low (≈ 80 Hz) and the high (≈ 300 Hz) component.
    pub frequency_hz: [f64; 2],
    /// `[B1, B2]`: the decay rates of the components in 1/s.
    pub decay_per_s: [f64; 2],
    /// Viscosity `c` in 0..1 (water 0.33); the share of the low component.
    pub viscosity: f64,
    /// The actuator's compensation gains already in `amplitudes` (`[1, 1]` without a profile,
    /// MODEL.md §18). The felt frequency is weighted without them (§19): a platform plays a
    /// clip's frequency or sharpness on its own actuator, which would compensate it again.
    pub actuator_gain: [f64; 2],
}

impl Glug {
    /// A unit of a render at `sample_rate` (Hz) as the clips see it: its onset in seconds and
    /// its components at the output gain it starts to be heard at.
    pub fn of_unit(unit: &UnitOnset, output_gain: f64, sample_rate: u32) -> Self {
        let [a1, a2] = unit.component_amplitudes();
        Self {
            onset_s: (unit.sample as f64 + unit.fraction) / sample_rate as f64,
            amplitudes: [a1 * output_gain, a2 * output_gain],
            frequency_hz: unit.shape.frequency_hz,
            decay_per_s: unit.shape.decay_per_s,
            viscosity: unit.viscosity,
            actuator_gain: unit.actuator_gain,
        }
    }
}

/// What a clip is written from: the glugs of one render and where they came from.
#[derive(Debug, Clone, Copy)]
pub struct ClipSource<'a> {
    /// Length of the render in seconds; the clip ends here.
    pub duration_s: f64,
    /// The glugs of the render, in any order.
    pub glugs: &'a [Glug],
    /// The output limiter's ceiling (≤ 1.0, or scaled with the glugs by `--haptic-peak`): the
    /// felt envelope never exceeds it.
    pub ceiling: f64,
    /// Name of the scene that was rendered, recorded in the clip's metadata.
    pub scene_name: &'a str,
    /// Random seed of the render, recorded in the clip's metadata.
    pub seed: u64,
}

/// The band of real frequencies (Hz) that the normalised 0..1 frequency of a `.haptic` clip
/// and the sharpness of an `.ahap` pattern span: `f = low + x·(high − low)`, as in Meta's
/// actuator configuration files.
///
/// The default, 80..300 Hz, is the span of the model's own components (f1 ≈ 80 Hz,
/// f2 ≈ 300 Hz). A glug's felt frequency is a weighted mean of f1 and f2, so every viscosity
/// lands inside the band without clamping and the whole 0..1 range carries the viscosity;
/// with the default component frequencies the normalised value is exactly `1 − c`. A generic
/// voice coil's 20..250 Hz would squeeze all viscosities into 0.26..0.90 and clamp thin
/// liquids (c < 0.23) to 1. The player's actuator file maps 0..1 onto its own band anyway,
/// so the band here only decides how the contrast is spread, not what the motor plays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HapticBand {
    /// Frequency in Hz that normalised 0 stands for.
    pub low_hz: f64,
    /// Frequency in Hz that normalised 1 stands for.
    pub high_hz: f64,
}

impl Default for HapticBand {
    fn default() -> Self {
        Self {
            low_hz: 80.0,
            high_hz: 300.0,
        }
    }
}

impl HapticBand {
    /// The position of `hz` in the band, clamped to 0..1 (0 = `low_hz`, 1 = `high_hz`).
    pub fn normalise(&self, hz: f64) -> f64 {
        let position = (hz - self.low_hz) / (self.high_hz - self.low_hz);
        // NaN (from a NaN frequency) would otherwise escape the clamp into the file.
        if position.is_nan() {
            0.5
        } else {
            position.clamp(0.0, 1.0)
        }
    }
}

impl fmt::Display for HapticBand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}..{}", self.low_hz, self.high_hz)
    }
}

/// Why a text is not a haptic band `LOW..HIGH` (in Hz).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BandParseError {
    /// The text is not two numbers separated by `..`.
    #[error("haptic band {text:?} is not two numbers in Hz written as LOW..HIGH (e.g. 80..300)")]
    NotTwoNumbers {
        /// The text that was given.
        text: String,
    },
    /// One of the edges is infinite or NaN.
    #[error("haptic band {text:?} has an edge that is not a finite number")]
    NotFinite {
        /// The text that was given.
        text: String,
    },
    /// One of the edges is below 0 Hz.
    #[error("haptic band {text:?} has a negative frequency")]
    Negative {
        /// The text that was given.
        text: String,
    },
    /// The low edge is not below the high edge.
    #[error(
        "haptic band {text:?}: the low edge {low_hz} Hz must be below the high edge {high_hz} Hz"
    )]
    LowNotBelowHigh {
        /// The text that was given.
        text: String,
        /// The parsed low edge in Hz.
        low_hz: f64,
        /// The parsed high edge in Hz.
        high_hz: f64,
    },
}

impl FromStr for HapticBand {
    type Err = BandParseError;

    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let not_two_numbers = || BandParseError::NotTwoNumbers {
            text: text.to_owned(),
        };
        let (low, high) = text.trim().split_once("..").ok_or_else(not_two_numbers)?;
        let low_hz: f64 = low.trim().parse().map_err(|_| not_two_numbers())?;
        let high_hz: f64 = high.trim().parse().map_err(|_| not_two_numbers())?;
        if !low_hz.is_finite() || !high_hz.is_finite() {
            return Err(BandParseError::NotFinite {
                text: text.to_owned(),
            });
        }
        if low_hz < 0.0 || high_hz < 0.0 {
            return Err(BandParseError::Negative {
                text: text.to_owned(),
            });
        }
        if low_hz >= high_hz {
            return Err(BandParseError::LowNotBelowHigh {
                text: text.to_owned(),
                low_hz,
                high_hz,
            });
        }
        Ok(Self { low_hz, high_hz })
    }
}

/// Whether a glug can be felt at all (its amplitude `a` is above 0). Inaudible glugs get no
/// transient in the clips.
pub fn is_audible(glug: &Glug) -> bool {
    glug.amplitudes[0].abs() + glug.amplitudes[1].abs() > 0.0
}

/// The felt envelope of one glug `τ` seconds after its onset: `|A1|·e^(−B1·τ) + |A2|·e^(−B2·τ)`,
/// an upper bound of the glug's `|y|`.
fn unit_envelope(glug: &Glug, tau: f64) -> f64 {
    (0..2)
        .map(|k| glug.amplitudes[k].abs() * libm::exp(-glug.decay_per_s[k] * tau))
        .sum()
}

/// The felt envelope at time `t`: `min(ceiling, Σ over glugs started by t of
/// A1·e^(−B1·τ) + A2·e^(−B2·τ))`. It bounds `|y|` from above, jumps at every onset and decays
/// like the glugs.
pub fn envelope_at(glugs: &[Glug], ceiling: f64, t: f64) -> f64 {
    let sum: f64 = glugs
        .iter()
        .filter(|glug| glug.onset_s <= t)
        .map(|glug| unit_envelope(glug, t - glug.onset_s))
        .sum();
    sum.min(ceiling)
}

/// A glug's felt frequency in Hz: the amplitude-weighted mean `(A1·f1 + A2·f2)/(A1 + A2)`, so
/// a more viscous glug (more of the low component) feels lower, the amplitudes taken without
/// an actuator's compensation (MODEL.md §19). An inaudible glug has no weights; its viscosity
/// `c·f1 + (1 − c)·f2` stands in.
pub fn felt_frequency_hz(glug: &Glug) -> f64 {
    let [a1, a2] = model_amplitudes(glug);
    let [f1, f2] = glug.frequency_hz;
    if a1 + a2 > 0.0 {
        (a1 * f1 + a2 * f2) / (a1 + a2)
    } else {
        glug.viscosity * f1 + (1.0 - glug.viscosity) * f2
    }
}

/// `|A1|, |A2|` without the actuator's compensation: the model's balance of the components.
fn model_amplitudes(glug: &Glug) -> [f64; 2] {
    let [a1, a2] = glug.amplitudes.map(f64::abs);
    let [g1, g2] = glug.actuator_gain;
    let uncompensated = |a: f64, g: f64| if g > 0.0 { a / g } else { a };
    [uncompensated(a1, g1), uncompensated(a2, g2)]
}

/// A glug's own peak on the envelope's 0..1 scale: `min(ceiling, |A1| + |A2|)`, clamped to 0..1.
pub fn glug_peak(glug: &Glug, ceiling: f64) -> f64 {
    (glug.amplitudes[0].abs() + glug.amplitudes[1].abs())
        .min(ceiling)
        .clamp(0.0, FULL_SCALE)
}

/// The strength of a glug's transient (AHAP `HapticIntensity`, `.haptic` emphasis amplitude):
/// `√(glug_peak)`. Core Haptics' intensity is perceptual: its output amplitude grows roughly
/// with the square of the intensity, and Meta's converter likewise writes the square root of
/// the amplitude, so the square root keeps the felt strength proportional to the sound's.
pub fn transient_intensity(glug: &Glug, ceiling: f64) -> f64 {
    glug_peak(glug, ceiling).sqrt()
}

/// How far before an onset the "just before" breakpoint sits: short enough that the jump
/// looks vertical, long enough that the time is not duplicated (the spec allows duplicates
/// but discourages them).
pub const ONSET_LEAD_S: f64 = 0.0005;

/// Full drive: the largest amplitude, intensity or magnitude of every clip format (a `.haptic`
/// amplitude, an `.ahap` intensity, a `.haps` keyframe, a rumble motor, Android's 255).
pub const FULL_SCALE: f64 = 1.0;

/// The envelope level (−60 dB of full scale) below which a decay is no longer sampled.
pub const ENVELOPE_FLOOR: f64 = 1e-3;

/// Between two decay breakpoints the glug falls by this factor (about 8 dB). For the default
/// decay (40–45 /s) that is a step of 20–23 ms, so with glugs 80 ms apart a clip has about
/// 60 breakpoints per second, the density Meta Haptics Studio writes. The envelope is convex
/// between onsets, so the straight lines a player draws between breakpoints stay above it and
/// remain an upper bound of the waveform.
const DECAY_STEP_FALL: f64 = 2.5;

/// Limits of the decay step, for glugs that decay unusually fast or not at all.
const MIN_DECAY_STEP_S: f64 = 0.002;
const MAX_DECAY_STEP_S: f64 = 0.1;

/// The shortest clip written, so that a clip of no length still has a start and an end.
const MIN_CLIP_S: f64 = 0.001;

/// One breakpoint of the felt envelope.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Breakpoint {
    /// Time in seconds from the start of the clip.
    pub time_s: f64,
    /// `envelope_at(time_s)`, clamped to 0..1.
    pub amplitude: f64,
    /// The felt frequency (Hz) of everything ringing here: every started component's frequency
    /// weighted by its decayed amplitude; `None` while nothing rings.
    pub felt_frequency_hz: Option<f64>,
    /// The index (into `ClipSource::glugs`) of the audible glug whose onset this is, if any.
    pub onset_of: Option<usize>,
}

/// The end time of a clip: its duration, but never less than 1 ms, so that even an empty clip
/// has a start and an end.
pub fn clip_end_s(source: &ClipSource) -> f64 {
    if source.duration_s.is_finite() {
        source.duration_s.max(MIN_CLIP_S)
    } else {
        MIN_CLIP_S
    }
}

/// The indices of the audible glugs that start inside the clip (`0 ≤ onset ≤ end`), sorted by
/// onset. Glugs outside the clip cannot be written into it.
pub fn clip_onsets(source: &ClipSource) -> Vec<usize> {
    let end_s = clip_end_s(source);
    sorted_audible(source.glugs)
        .into_iter()
        .filter(|&i| (0.0..=end_s).contains(&source.glugs[i].onset_s))
        .collect()
}

/// The glugs of a clip as every file and the summary name them: "59 units, 42 audible" (every
/// unit the render started, and those with a above 0 that start inside the clip).
pub fn glug_count(source: &ClipSource) -> String {
    format!(
        "{} units, {} audible",
        source.glugs.len(),
        clip_onsets(source).len()
    )
}

/// The indices of all audible glugs, sorted by onset. A glug that started before the clip
/// still rings into it, so the envelope sums these, not only the clip's onsets.
fn sorted_audible(glugs: &[Glug]) -> Vec<usize> {
    let mut indices: Vec<usize> = (0..glugs.len())
        .filter(|&i| is_audible(&glugs[i]))
        .collect();
    indices.sort_by(|&a, &b| glugs[a].onset_s.total_cmp(&glugs[b].onset_s));
    indices
}

/// Sums the envelope quickly over sorted glugs, skipping the ones that have long decayed, so
/// that a render of minutes with thousands of glugs stays linear in time. The clips' felt
/// envelope and the platform formats' two components ([`super::steps`]) are both read from it.
pub(crate) struct EnvelopeSum<'a> {
    glugs: &'a [Glug],
    /// Indices of the audible glugs, sorted by onset.
    sorted: Vec<usize>,
    ceiling: f64,
    largest_amplitude: f64,
    slowest_decay_per_s: f64,
}

/// What rings at one time, summed over the glugs started by then (unclamped).
pub(crate) struct RingingSums {
    /// Σ |A1|·e^(−B1·τ) and Σ |A2|·e^(−B2·τ).
    pub components: [f64; 2],
    /// Both together, summed glug by glug (the felt envelope before the ceiling).
    pub total: f64,
    /// Σ of each component's amplitude × its frequency, the amplitudes without an actuator's
    /// compensation ([`felt_frequency_hz`]).
    pub weighted_hz: f64,
    /// Σ of those amplitudes: `weighted_hz / model_total` is the felt frequency.
    pub model_total: f64,
    /// Those amplitudes component by component: the model's balance of the two.
    pub model_components: [f64; 2],
}

impl<'a> EnvelopeSum<'a> {
    /// The envelope of `source`'s audible glugs.
    pub(crate) fn new(source: &ClipSource<'a>) -> Self {
        let glugs = source.glugs;
        let sorted = sorted_audible(glugs);
        let largest_amplitude = sorted
            .iter()
            .map(|&i| glugs[i].amplitudes[0].abs() + glugs[i].amplitudes[1].abs())
            .fold(0.0, f64::max);
        let slowest_decay_per_s = sorted
            .iter()
            .flat_map(|&i| glugs[i].decay_per_s)
            .fold(f64::INFINITY, f64::min);
        Self {
            glugs,
            sorted,
            ceiling: source.ceiling,
            largest_amplitude,
            slowest_decay_per_s,
        }
    }

    /// The sums of what rings at `t`, over the audible glugs.
    pub(crate) fn ringing_at(&self, t: f64) -> RingingSums {
        let started = self.sorted.partition_point(|&i| self.glugs[i].onset_s <= t);
        let mut sums = RingingSums {
            components: [0.0; 2],
            total: 0.0,
            weighted_hz: 0.0,
            model_total: 0.0,
            model_components: [0.0; 2],
        };
        // Newest first: once even the largest glug would have decayed to nothing, every older
        // one has too (their contributions are below 1e-15 each).
        for &i in self.sorted[..started].iter().rev() {
            let glug = &self.glugs[i];
            let tau = t - glug.onset_s;
            if self.largest_amplitude * libm::exp(-self.slowest_decay_per_s * tau) < 1e-15 {
                break;
            }
            for k in 0..2 {
                let amplitude = glug.amplitudes[k].abs() * libm::exp(-glug.decay_per_s[k] * tau);
                sums.components[k] += amplitude;
                sums.total += amplitude;
                let gain = glug.actuator_gain[k];
                let model = if gain > 0.0 {
                    amplitude / gain
                } else {
                    amplitude
                };
                sums.weighted_hz += model * glug.frequency_hz[k];
                sums.model_total += model;
                sums.model_components[k] += model;
            }
        }
        sums
    }

    /// `envelope_at(t)` clamped to 0..1, and the felt frequency of what rings at `t` (see
    /// [`Breakpoint::felt_frequency_hz`]), over the audible glugs.
    fn at(&self, t: f64) -> (f64, Option<f64>) {
        let RingingSums {
            total,
            weighted_hz,
            model_total,
            ..
        } = self.ringing_at(t);
        let frequency_hz = (model_total > 0.0).then(|| weighted_hz / model_total);
        // A breakpoint is written as it is: never above full scale, the limit of every clip
        // format. `--haptic-peak` scales the ceiling with the glugs by a gain whose rounding can
        // leave their product a hair above 1 (MODEL.md §19), so the clamp comes after it. (The
        // step formats average the envelope unclamped, and clamp each step.)
        (total.min(self.limit()).min(FULL_SCALE), frequency_hz)
    }

    /// The largest value the envelope takes: the ceiling (at most 1, full scale, unless
    /// `--haptic-peak` scaled it with the glugs: the format then writes no value above its
    /// drive, its own strongest one being the drive asked for).
    pub(crate) fn limit(&self) -> f64 {
        self.ceiling.max(0.0)
    }

    /// The last time in `from_s..to_s` at which the decaying envelope is still at its limit,
    /// found by bisection to well below a nanosecond.
    fn last_time_at_limit(&self, from_s: f64, to_s: f64) -> f64 {
        let (mut at_limit_s, mut below_s) = (from_s, to_s);
        for _ in 0..48 {
            let middle_s = 0.5 * (at_limit_s + below_s);
            if self.at(middle_s).0 >= self.limit() {
                at_limit_s = middle_s;
            } else {
                below_s = middle_s;
            }
        }
        at_limit_s
    }
}

/// The breakpoints of the felt envelope of a clip, in time order: the clip's start; at every
/// audible onset a point [`ONSET_LEAD_S`] before it (the decayed value) and one at it (the
/// jumped value, marked with the glug); points along each decay, 20–23 ms apart by default
/// (each a fall of about 8 dB), until the next onset or until the envelope falls below
/// [`ENVELOPE_FLOOR`]; where a decay leaves the ceiling, the last point still on it; and the
/// clip's end. Every amplitude is `envelope_at` of its time, and the straight lines between
/// the points never fall below the envelope, so they still bound the waveform.
pub fn envelope_breakpoints(source: &ClipSource) -> Vec<Breakpoint> {
    let end_s = clip_end_s(source);
    let onsets = clip_onsets(source);
    let envelope = EnvelopeSum::new(source);
    let mut points: Vec<Breakpoint> = Vec::new();
    let push = |points: &mut Vec<Breakpoint>, time_s: f64, onset_of: Option<usize>| {
        let (amplitude, felt_frequency_hz) = envelope.at(time_s);
        let limit = envelope.limit();
        if let Some(&previous) = points.last() {
            // Leaving the ceiling: mark where, or the straight line from the last limited
            // point would cut below the envelope's knee.
            if previous.amplitude >= limit && amplitude < limit {
                let knee_s = envelope.last_time_at_limit(previous.time_s, time_s);
                if knee_s > previous.time_s {
                    let (knee_amplitude, knee_frequency_hz) = envelope.at(knee_s);
                    points.push(Breakpoint {
                        time_s: knee_s,
                        amplitude: knee_amplitude,
                        felt_frequency_hz: knee_frequency_hz,
                        onset_of: None,
                    });
                }
            }
        }
        points.push(Breakpoint {
            time_s,
            amplitude,
            felt_frequency_hz,
            onset_of,
        });
    };

    let first_onset_at_start = onsets
        .first()
        .is_some_and(|&i| source.glugs[i].onset_s <= 0.0);
    if !first_onset_at_start {
        push(&mut points, 0.0, None);
    }
    for (position, &index) in onsets.iter().enumerate() {
        let glug = &source.glugs[index];
        let onset_s = glug.onset_s;
        let before_s = onset_s - ONSET_LEAD_S;
        if points.last().is_some_and(|last| before_s > last.time_s) {
            push(&mut points, before_s, None);
        }
        push(&mut points, onset_s, Some(index));

        // Decay points stop short of the next onset's "before" point so they never crowd it.
        let next_onset_s = onsets
            .get(position + 1)
            .map_or(f64::INFINITY, |&next| source.glugs[next].onset_s);
        let decay_stop_s = (next_onset_s - ONSET_LEAD_S - MIN_DECAY_STEP_S).min(end_s);
        let slowest = glug.decay_per_s[0].min(glug.decay_per_s[1]);
        let step_s = if slowest > 0.0 {
            (libm::log(DECAY_STEP_FALL) / slowest).clamp(MIN_DECAY_STEP_S, MAX_DECAY_STEP_S)
        } else {
            MAX_DECAY_STEP_S
        };
        let mut steps = 1.0;
        loop {
            let time_s = onset_s + steps * step_s;
            if time_s >= decay_stop_s {
                break;
            }
            push(&mut points, time_s, None);
            if points.last().is_some_and(|p| p.amplitude < ENVELOPE_FLOOR) {
                break;
            }
            steps += 1.0;
        }
    }
    if points.last().is_none_or(|last| last.time_s < end_s) {
        push(&mut points, end_s, None);
    }
    points
}
