//! Every unit of a recording (MODEL.md §5, §13): where each starts, and its resonances.
//!
//! Each detected unit is first fitted with the paper's eq. 1 as it stands ([`eq1`]: two
//! components from phase 0 at a common onset). A real glug is not always that: one mode may
//! dominate, a component may start at another phase, the pitch may glide. So a unit eq. 1 does
//! not describe, or describes with its stronger component away from the unit's own spectral
//! peak, is fitted again ([`phased`]) with one or two components started at the peaks of its own
//! spectrum, each with a phase of its own, then gliding, then in the first part of its span
//! only (where a gliding pitch has not moved far). A unit kept steady is fitted again gliding,
//! and keeps the glide where it explains much more. A unit is kept if its
//! fit explains at least half of the samples fitted and its stronger component lies at its own
//! spectral peak; otherwise it is rejected with the reason. Units are fitted in time order, each
//! kept unit subtracted from the recording before the next is fitted, so that a unit starting
//! while the last one rings is fitted alone.

mod eq1;
mod modes;
mod phased;
mod second_mode;
mod window;

use std::f64::consts::TAU;

use sake_glug_engine::{Constant, Range};

use super::listen::glug_onsets;
use super::onsets::detect_onsets;
use super::spectrum::{own_peaks, pooled_peak_above, HeldLines, Spectrum};
use super::stats;
pub use modes::{local_split, Modes};
use window::{Span, Window};

/// The fitted span starts this long before the detected onset (s): the silence before a unit
/// pins its onset.
const BEFORE_ONSET_S: f64 = 0.004;
/// …and ends this long before the next detected onset (s), which may lie late by as much.
const BEFORE_NEXT_S: f64 = 0.004;
/// The longest span (s): the components are 50 dB down by then at 40 /s.
const LONGEST_WINDOW_S: f64 = 0.15;
/// The shortest span (s) a unit is fitted in: a period of 125 Hz, several of a bubble's.
const SHORTEST_WINDOW_S: f64 = 0.008;
/// Samples per period of the highest component the pencil keeps (it decimates to this).
const PENCIL_SAMPLES_PER_PERIOD: f64 = 8.0;
/// Samples per period of the highest component the least-squares fit keeps: it fits every k-th
/// sample of its window, k as large as keeps this many. Eq. 1 has seven numbers; a 25 kHz window
/// holds 83 samples a period of 300 Hz, and the fit's cost falls with k while its noise grows
/// only as √k (MODEL.md §13).
const FIT_SAMPLES_PER_PERIOD: f64 = 16.0;
/// A unit is kept only if its fit explains at least this share of the samples fitted.
pub const MIN_EXPLAINED: f64 = 0.5;
/// The highest decay rate of a resonance (1/s): a faster one is a click.
pub(crate) const MAX_DECAY_PER_S: f64 = 5_000.0;
/// The lowest frequency of a resonance (Hz): below it lie drift and handling noise.
pub(crate) const LOWEST_HZ: f64 = 20.0;
/// The stronger component lies at the unit's own spectral peak (the strongest peak of the samples
/// fitted) when within this share of the peak's frequency, or within one bin of a spectrum as
/// long as those samples (1/their length), if wider.
pub const AT_PEAK_SHARE: f64 = 0.1;
/// A fitted unit is subtracted until it has decayed by this factor (−80 dB).
const SUBTRACT_UNTIL: f64 = 1e-4;
/// A glide's time constant may be at most this many times its ring's 1/B: by the time the ring
/// has fallen by e² (17 dB) the pitch is at least 1/e of the way to its own frequency, which is
/// then heard; a slower glide's end is a guess (MODEL.md §13).
const GLIDE_REACHED: f64 = 2.0;
/// A glide is kept where it leaves at most this share of what a steady fit left of a unit (or of
/// a short mode's first samples).
pub(super) const GLIDE_LEAVES: f64 = 0.75;
/// A glide refit may ring its unit's stronger mode at most this many times as long as the steady
/// fit did: fitted steady, a sweep decays up to about twice as fast as it rings (MODEL.md §13), so
/// a glide ringing longer still has traded its sweep for a ring the window cannot check, and
/// subtracted, that ring would lie in every later unit's residual for a second.
const GLIDE_RINGS_LONGER: f64 = 2.0;
/// A gliding unit is fitted again in the first this share of its span…
const GLIDE_SHARE: f64 = 0.4;
/// …but never fewer than this many periods of its lowest start.
const GLIDE_PERIODS: f64 = 4.0;

/// The model's ranges of a glide's ρ and τ_g (ms), which every mode shares (MODEL.md §12): a
/// component is fitted before it is put in a mode.
pub(super) fn glide_ranges() -> (Range, Range) {
    (
        Constant::F1GlideRatio.range(),
        Constant::F1GlideTime.range(),
    )
}

/// One resonance of a unit: A·e^(−Bτ)·sin(2π·cycles(τ) + φ), τ the time since the unit's onset,
/// cycles(τ) = fτ for a steady component (φ = 0 in the paper's eq. 1) and, for one that glides
/// from ρ·f into f (MODEL.md §5.2), fτ + (ρ − 1)·f·τ_g·(1 − e^(−τ/τ_g)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Component {
    /// f, its own frequency: the one a glide approaches (Hz).
    pub frequency_hz: f64,
    /// Its glide into f, if it glides.
    pub glide: Option<UnitGlide>,
    /// The frequency it is heard at (Hz): f, or for a glide its frequency at the centre of its
    /// energy in the span fitted. Which mode it rings, and whether it is at the span's spectral
    /// peak, take this one.
    pub heard_hz: f64,
    /// B (1/s).
    pub decay_per_s: f64,
    /// A (the recording's units), ≥ 0.
    pub amplitude: f64,
    /// φ (radians): 0 in the paper's eq. 1.
    pub phase: f64,
    /// The height of its peak in the spectrum of the span fitted (its samples alone, under the
    /// Hann window, at the frequency it is heard at, from the samples the fit read): which tells a
    /// unit's stronger component.
    pub in_span: f64,
}

/// A component's glide as MODEL.md §5.2 has it: from ρ·f, approaching f exponentially.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitGlide {
    /// ρ, the start frequency over f.
    pub ratio: f64,
    /// τ_g, the approach's time constant (s).
    pub time_s: f64,
}

impl UnitGlide {
    /// The cycles the glide adds to fτ by τ, for a component of own frequency `hz`.
    pub fn cycles(&self, hz: f64, tau: f64) -> f64 {
        (self.ratio - 1.0) * hz * self.time_s * (1.0 - (-tau / self.time_s).exp())
    }

    /// Its frequency over f at τ.
    pub fn factor(&self, tau: f64) -> f64 {
        1.0 + (self.ratio - 1.0) * (-tau / self.time_s).exp()
    }
}

impl Component {
    /// The cycles its phase has turned through τ seconds after the onset (φ aside).
    pub fn cycles(&self, tau: f64) -> f64 {
        self.frequency_hz * tau + self.glide.map_or(0.0, |g| g.cycles(self.frequency_hz, tau))
    }

    /// Its value τ seconds after the onset.
    pub fn value(&self, tau: f64) -> f64 {
        self.amplitude
            * (-self.decay_per_s * tau).exp()
            * (TAU * self.cycles(tau) + self.phase).sin()
    }

    /// The frequency its mode records in its unit: its own f, or the one it is heard at where its
    /// glide is slower than its ring (its own f is then a guess).
    fn recorded_hz(&self) -> f64 {
        if self.unheard_glide().is_some() {
            self.heard_hz
        } else {
            self.frequency_hz
        }
    }

    /// Why its glide is not heard, if it glides more slowly than it rings ([`GLIDE_REACHED`]).
    fn unheard_glide(&self) -> Option<Rejection> {
        let glide = self.glide?;
        (glide.time_s * self.decay_per_s > GLIDE_REACHED).then(|| Rejection::GlideUnheard {
            glide_ms: 1e3 * glide.time_s,
            ring_ms: 1e3 / self.decay_per_s,
        })
    }

    /// Why it is no resonance of a recording at `fs`, if it is not one.
    fn check(&self, fs: f64) -> Result<(), Rejection> {
        let Component {
            heard_hz: hz,
            decay_per_s: decay,
            ..
        } = *self;
        let glide_finite = self
            .glide
            .is_none_or(|g| g.ratio.is_finite() && g.time_s.is_finite() && g.time_s > 0.0);
        let numbers = [hz, decay, self.amplitude, self.frequency_hz, self.phase];
        // A glide starts at ρ·f, which must lie in the model's range of ρ and be heard.
        let start_hz = self.glide.map_or(hz, |g| g.ratio * self.frequency_hz);
        let (ratios, times_ms) = glide_ranges();
        let out_of_range = self
            .glide
            .filter(|g| !(ratios.contains(g.ratio) && times_ms.contains(1e3 * g.time_s)));
        if !(numbers.iter().all(|v| v.is_finite()) && glide_finite) {
            Err(Rejection::NotFinite)
        } else if !(LOWEST_HZ..fs / 2.0).contains(&hz) {
            Err(Rejection::Frequency { hz })
        } else if let Some(glide) = out_of_range {
            Err(Rejection::GlideRange {
                ratio: glide.ratio,
                glide_ms: 1e3 * glide.time_s,
            })
        } else if !(LOWEST_HZ..fs / 2.0).contains(&start_hz)
            || !(LOWEST_HZ..fs / 2.0).contains(&self.frequency_hz)
        {
            Err(Rejection::Frequency { hz: start_hz })
        } else if decay <= 0.0 {
            Err(Rejection::NoDecay)
        } else if decay >= MAX_DECAY_PER_S {
            Err(Rejection::Click { decay })
        } else {
            Ok(())
        }
    }
}

/// Which fit gave a unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnitMethod {
    /// The paper's eq. 1 as it stands.
    Eq1,
    /// One or two components, each with its phase, from the unit's own spectral peaks.
    Phased,
    /// As [`UnitMethod::Phased`] with each component gliding into its own frequency (MODEL.md
    /// §5.2): a unit a steady fit left a sweep of, or one no steady fit described.
    Glide,
}

/// One unit, as fitted: its components, and eq. 1's view of it (the bottle's two modes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitFit {
    /// The onset t_i (s from the recording's first sample).
    pub onset_s: f64,
    /// Its components as fitted (one or two), the lower first.
    pub components: [Option<Component>; 2],
    /// A1, A2: its amplitude in the bottle's low and high mode (0 where it does not ring one).
    pub amplitude: [f64; 2],
    /// f1, f2 (Hz; NaN where it does not ring that mode): each component's own frequency, the
    /// one a glide approaches.
    pub frequency_hz: [f64; 2],
    /// Each mode's glide, where its component glides.
    pub glide: [Option<UnitGlide>; 2],
    /// B1, B2 (1/s; NaN where it does not ring that mode).
    pub decay_per_s: [f64; 2],
    /// Whether each mode's component was fitted gliding, its glide heard or not: a mode rising
    /// into its pitch, fitted steady, decays too fast (MODEL.md §13).
    pub swept: [bool; 2],
    /// The share of the samples fitted that the fit explains.
    pub r_squared: f64,
    /// The span fitted, `[first, end)`…
    pub window: (usize, usize),
    /// …of which every `stride`-th sample from `first` on was read (MODEL.md §13).
    pub stride: usize,
    /// Where eq. 1's Levenberg-Marquardt started, `[onset (s), A1, A2, f1, f2, B1, B2]` (the
    /// pencil's poles, the onset grid and its amplitudes): another solver started here is
    /// compared fairly (benches/render/fit.rs). NaN for a unit another fit gave.
    pub start: [f64; 7],
    /// Which fit gave it.
    pub method: UnitMethod,
}

impl UnitFit {
    fn new(fitted: Fitted, placed: Placed, start: Option<[f64; 7]>, method: UnitMethod) -> Self {
        let mut sorted = fitted.components.to_vec();
        // A component the amplitudes' fit held at 0 rings nothing, and its frequency is whatever
        // Levenberg-Marquardt left it at: it is no mode of the unit's.
        if sorted.iter().any(|c| c.amplitude > 0.0) {
            sorted.retain(|c| c.amplitude > 0.0);
        }
        sorted.sort_by(|a, b| a.heard_hz.total_cmp(&b.heard_hz));
        for component in &mut sorted {
            component.in_span = in_span(component, fitted.onset_s, placed);
        }
        let mut unit = Self {
            onset_s: fitted.onset_s,
            components: [sorted.first().copied(), sorted.get(1).copied()],
            amplitude: [0.0; 2],
            frequency_hz: [f64::NAN; 2],
            glide: [None; 2],
            decay_per_s: [f64::NAN; 2],
            swept: [false; 2],
            r_squared: fitted.explained,
            window: placed.window,
            stride: placed.stride,
            start: start.unwrap_or([f64::NAN; 7]),
            method,
        };
        unit.assign(&Modes::by_order());
        unit
    }

    /// The unit a phased fit gives, placed at `placed`.
    fn of_phased(fitted: &phased::PhasedFit, placed: Placed, method: UnitMethod) -> Self {
        Self::new(
            Fitted {
                onset_s: fitted.onset_s,
                components: &fitted.components,
                explained: fitted.explained,
            },
            placed,
            None,
            method,
        )
    }

    /// Its components, as fitted.
    pub fn fitted(&self) -> impl Iterator<Item = &Component> {
        self.components.iter().flatten()
    }

    /// Puts each component in the mode `modes` gives the frequency it is heard at (the stronger,
    /// where two fall in one).
    pub fn assign(&mut self, modes: &Modes) {
        self.assign_by(modes, |c| c.heard_hz);
    }

    /// Puts each component in the mode `split` gives the frequency it would record there
    /// ([`UnitFit::frequency_hz`]): a split taken between neighbours' recorded f1 and f2 compares
    /// like with like. A cavity gliding down into its f is heard well above it, so a full
    /// bottle's lone cavity, heard near the bubble, would be put in the bubble's mode.
    pub fn assign_by_neighbours(&mut self, split: &Modes) {
        self.assign_by(split, Component::recorded_hz);
    }

    /// Whether it rings one mode only.
    pub fn rings_one_mode(&self) -> bool {
        self.amplitude.iter().filter(|&&a| a > 0.0).count() == 1
    }

    fn assign_by(&mut self, modes: &Modes, pitch: impl Fn(&Component) -> f64) {
        let mut best: [Option<Component>; 2] = [None, None];
        let count = self.fitted().count();
        for (index, component) in self.fitted().enumerate() {
            let mode = modes.mode_of(pitch(component), index, count);
            if best[mode].is_none_or(|b| b.in_span < component.in_span) {
                best[mode] = Some(*component);
            }
        }
        for (mode, component) in best.into_iter().enumerate() {
            // A glide slower than its ring never reaches its own f: the mode is the pitch heard.
            let heard = component.filter(|c| c.unheard_glide().is_some());
            self.amplitude[mode] = component.map_or(0.0, |c| c.amplitude);
            self.frequency_hz[mode] = component.map_or(f64::NAN, |c| c.recorded_hz());
            self.glide[mode] = component.and_then(|c| c.glide).filter(|_| heard.is_none());
            self.decay_per_s[mode] = component.map_or(f64::NAN, |c| c.decay_per_s);
            self.swept[mode] = component.is_some_and(|c| c.glide.is_some());
        }
    }

    /// Asum = A1 + A2.
    pub fn amplitude_sum(&self) -> f64 {
        self.amplitude[0] + self.amplitude[1]
    }

    /// c = A1/(A1 + A2) (paper eq. 2).
    pub fn viscosity(&self) -> f64 {
        self.amplitude[0] / self.amplitude_sum()
    }

    /// Its stronger component: the one whose peak in the spectrum of the span fitted is taller.
    pub fn stronger(&self) -> Option<&Component> {
        self.fitted().max_by(|a, b| a.in_span.total_cmp(&b.in_span))
    }

    /// Its samples at `time_s`: every component fitted.
    pub fn value_at(&self, time_s: f64) -> f64 {
        let tau = time_s - self.onset_s;
        if tau < 0.0 {
            return 0.0;
        }
        self.fitted().map(|c| c.value(tau)).sum()
    }
}

/// A fit not kept: why, and the fit if one was made (boxed: a unit is large).
type Failed = Box<(Rejection, Option<UnitFit>)>;

/// A fit's result: its onset (s), components and the share of the samples it explains.
struct Fitted<'a> {
    onset_s: f64,
    components: &'a [Component],
    explained: f64,
}

/// Where a fit lies: its span `[first, end)` of the recording, read every `stride`-th sample, at
/// the rate `fs`.
#[derive(Debug, Clone, Copy)]
struct Placed {
    window: (usize, usize),
    stride: usize,
    fs: f64,
}

/// The height of `component`'s peak (from `onset_s`) in the span's spectrum: the power of its
/// samples alone, under the Hann window, at the frequency it is heard at. The taller of a unit's
/// components is the one whose peak its spectrum shows.
fn in_span(component: &Component, onset_s: f64, placed: Placed) -> f64 {
    let (first, end) = placed.window;
    let width = (end - first) as f64;
    let (mut re, mut im) = (0.0, 0.0);
    // Every stride-th sample, as the fit read them: enough samples a period of the components.
    for n in (first..end).step_by(placed.stride) {
        let tau = n as f64 / placed.fs - onset_s;
        if tau < 0.0 {
            continue;
        }
        let hann = 0.5 - 0.5 * (TAU * (n - first) as f64 / width).cos();
        let value = hann * component.value(tau);
        let (sine, cosine) = (TAU * component.heard_hz * tau).sin_cos();
        re += value * cosine;
        im -= value * sine;
    }
    re * re + im * im
}

/// Why a detected unit was not used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rejection {
    /// The next unit starts too soon after it.
    TooShort {
        /// The span there is (s).
        span_s: f64,
    },
    /// Its span's spectrum has no peak.
    NoResonance,
    /// A number of the fit is not finite.
    NotFinite,
    /// Eq. 1 needs a component of negative amplitude (it starts out of phase).
    OutOfPhase,
    /// A component outside 20 Hz … fs/2.
    Frequency {
        /// Its frequency (Hz).
        hz: f64,
    },
    /// A component that does not decay.
    NoDecay,
    /// A component whose glide lies outside the model's ranges of ρ and τ_g (a fit's free phase,
    /// not a sweep).
    GlideRange {
        /// ρ.
        ratio: f64,
        /// τ_g (ms).
        glide_ms: f64,
    },
    /// A component gliding so slowly that its ring dies before it reaches its own frequency:
    /// that frequency is not heard, so no fit can tell it.
    GlideUnheard {
        /// τ_g (ms).
        glide_ms: f64,
        /// 1/B (ms).
        ring_ms: f64,
    },
    /// A component decaying faster than a resonance does.
    Click {
        /// Its decay rate (1/s).
        decay: f64,
    },
    /// The fit explains too little of it.
    Unexplained {
        /// The share it explains.
        share: f64,
    },
    /// Its stronger component is not at its own spectral peak.
    OffPeak {
        /// The stronger component's frequency (Hz).
        component_hz: f64,
        /// The peak's (Hz).
        peak_hz: f64,
    },
    /// The onset moved too far from where it was detected.
    OnsetMoved {
        /// By how much (s).
        shift_s: f64,
    },
}

impl Rejection {
    /// The reason without its figures, so that like reasons count together.
    pub fn kind(&self) -> &'static str {
        match self {
            Rejection::TooShort { .. } => "the next unit starts too soon",
            Rejection::NoResonance => "no resonance",
            Rejection::NotFinite => "the fit did not converge",
            Rejection::OutOfPhase => "a negative amplitude",
            Rejection::Frequency { .. } => "a frequency out of range",
            Rejection::NoDecay => "no decay",
            Rejection::GlideRange { .. } => "a glide out of range",
            Rejection::Click { .. } => "a click",
            Rejection::GlideUnheard { .. } => "a glide slower than its ring",
            Rejection::Unexplained { .. } => "the fit explains too little",
            Rejection::OffPeak { .. } => "not at its spectral peak",
            Rejection::OnsetMoved { .. } => "the onset moved",
        }
    }
}

impl std::fmt::Display for Rejection {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Rejection::TooShort { span_s } => write!(
                f,
                "the next unit starts {:.1} ms after it (a fit needs {:.0} ms)",
                1e3 * span_s,
                1e3 * SHORTEST_WINDOW_S
            ),
            Rejection::NoResonance => write!(f, "its spectrum shows no resonance"),
            Rejection::NotFinite => write!(f, "the fit did not converge"),
            Rejection::OutOfPhase => write!(f, "eq. 1 fits it only with a negative amplitude"),
            Rejection::Frequency { hz } => write!(
                f,
                "a component at {hz:.1} Hz, outside {LOWEST_HZ} Hz … half the sample rate"
            ),
            Rejection::NoDecay => write!(f, "a component does not decay"),
            Rejection::GlideRange { ratio, glide_ms } => {
                let (ratios, times_ms) = glide_ranges();
                write!(
                    f,
                    "a component glides from ρ = {ratio:.2} over τ_g = {glide_ms:.1} ms, outside \
                     the model's {} … {} and {} … {} ms",
                    ratios.min, ratios.max, times_ms.min, times_ms.max
                )
            }
            Rejection::GlideUnheard { glide_ms, ring_ms } => write!(
                f,
                "a component glides with τ_g = {glide_ms:.1} ms but rings for 1/B = \
                 {ring_ms:.1} ms: its own frequency is never heard"
            ),
            Rejection::Click { decay } => write!(
                f,
                "a component decays at {decay:.0} /s: a click, not a resonance"
            ),
            Rejection::Unexplained { share } => write!(
                f,
                "the fit explains {:.0} % of it (a unit needs {:.0} %)",
                100.0 * share,
                100.0 * MIN_EXPLAINED
            ),
            Rejection::OffPeak {
                component_hz,
                peak_hz,
            } => write!(
                f,
                "its stronger component ({component_hz:.1} Hz) is not at its spectral peak \
                 ({peak_hz:.1} Hz)"
            ),
            Rejection::OnsetMoved { shift_s } => write!(
                f,
                "the fitted onset lies {:.1} ms from the detected one",
                1e3 * shift_s
            ),
        }
    }
}

/// A detected unit: its fit, and whether it was used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DetectedUnit {
    /// Where it was detected (s).
    pub onset_s: f64,
    /// The fit: the one used, or the best rejected one (if any fit was made).
    pub fit: Option<UnitFit>,
    /// Why it was not used (`None`: used).
    pub rejection: Option<Rejection>,
}

/// Every unit of one recording.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingUnits {
    /// The units kept, in time order.
    pub units: Vec<UnitFit>,
    /// Every unit detected, in time order, used or not.
    pub detected: Vec<DetectedUnit>,
    /// The spectrum's peaks that started eq. 1's frequencies (Hz; f1 < f2).
    pub start_hz: [f64; 2],
    /// Whether the spectrum showed only one peak (the other start was guessed).
    pub one_peak: bool,
    /// The recording's spectrum.
    pub spectrum: Spectrum,
    /// The share of the recording's energy the units kept explain, from 0 to 1.
    pub explained: f64,
}

impl RecordingUnits {
    /// The units detected but not used.
    pub fn rejected(&self) -> usize {
        self.detected
            .iter()
            .filter(|d| d.rejection.is_some())
            .count()
    }
}

/// Every how many samples the pencil and the least-squares fit read a span.
#[derive(Debug, Clone, Copy)]
struct Strides {
    pencil: usize,
    fit: usize,
}

impl Strides {
    /// The strides that keep enough samples a period of `highest_hz` (with a margin for a
    /// component found above its start).
    fn for_highest(highest_hz: f64, fs: f64) -> Self {
        let highest_hz = highest_hz * eq1::POLE_MATCH_RATIO;
        Self {
            pencil: ((fs / (PENCIL_SAMPLES_PER_PERIOD * highest_hz)) as usize).max(1),
            fit: ((fs / (FIT_SAMPLES_PER_PERIOD * highest_hz)) as usize).max(1),
        }
    }
}

/// A detected onset stands for a glug only within this of where the envelope shows one (s).
const GLUG_MATCH_S: f64 = 0.025;

/// The onsets (samples) that stand for a glug: for each glug the envelope shows (`glugs`), the
/// detected onset nearest it within [`GLUG_MATCH_S`]. The detector places an onset to the
/// sample but also rises where a glug's own modes beat or a second bubble joins it; the envelope
/// tells a glug from its parts, so no glug is split into several units.
fn one_per_glug(detected: &[usize], glugs: &[usize], fs: f64) -> Vec<usize> {
    let reach = (GLUG_MATCH_S * fs) as usize;
    let mut kept: Vec<usize> = glugs
        .iter()
        .filter_map(|&glug| {
            detected
                .iter()
                .copied()
                .filter(|&onset| onset.abs_diff(glug) <= reach)
                .min_by_key(|&onset| onset.abs_diff(glug))
        })
        .collect();
    kept.dedup();
    kept
}

/// Finds and fits every unit of `samples` (DC removed) at `sample_rate`.
pub fn fit_units(samples: &[f32], sample_rate: u32) -> RecordingUnits {
    let fs = sample_rate as f64;
    let spectrum = Spectrum::of(samples, fs);
    let held = Spectrum::held_lines(samples, fs);
    let peaks = spectrum.peaks(&held);
    // The paper's ratio of f2 to f1 guesses the other component when only one shows.
    const RATIO: f64 = 300.0 / 80.0;
    let (start_hz, one_peak) = match peaks.as_slice() {
        [low, high] => ([*low, *high], false),
        [only] if *only < 160.0 => ([*only, only * RATIO], true),
        [only] => ([only / RATIO, *only], true),
        _ => ([80.0, 300.0], true),
    };
    let onsets = one_per_glug(
        &detect_onsets(samples, fs, start_hz[0]),
        &glug_onsets(samples, fs),
        fs,
    );
    let strides = Strides::for_highest(start_hz[1], fs);
    let fit_with =
        |pooled_hz| InTurn::fit(samples, &onsets, fs, &held, start_hz, strides, pooled_hz);
    let mut in_turn = fit_with(None);
    // Where no unit's own early residue showed a short mode units enough agree on above the long
    // mode, the residues of every unit summed may (MODEL.md §13): a bubble mode 20–30 dB under a
    // cavity carrying most of the amplitude lies under each unit's noise but rings near one pitch
    // in all of them. It is sought above every unit's main mode, glide included: below lie the
    // misfits of a glide's start, which the sum gathers too, and which units may agree on as a
    // short mode.
    let highest_main_hz = in_turn.main_hz.iter().copied().fold(0.0, f64::max);
    let lowest_hz = highest_main_hz * modes::SEPARATE_MODES;
    if in_turn.agreed_hz.iter().all(|&hz| hz < lowest_hz)
        && in_turn.early_left.len() >= second_mode::MIN_AGREEING_UNITS
    {
        if let Some(pooled_hz) = pooled_peak_above(
            &in_turn.early_left,
            fs,
            lowest_hz,
            second_mode::SHORT_DECAY_GUESS_PER_S,
            &held,
        ) {
            let pooled = fit_with(Some(pooled_hz));
            // Kept where its units agree on the pitch the sum showed; where they agree on another
            // (pair fits drawn back to the short mode the first fitting found, under the sum's
            // search), the first fitting stands.
            let agreed_on_sum = !pooled.agreed_hz.is_empty()
                && (stats::median(&pooled.agreed_hz) / pooled_hz - 1.0).abs()
                    <= second_mode::AGREEING_PITCH;
            if agreed_on_sum {
                in_turn = pooled;
            }
        }
    }
    let InTurn {
        units,
        detected,
        residual,
        ..
    } = in_turn;
    let energy = |signal: &[f32]| signal.iter().map(|&y| f64::from(y).powi(2)).sum::<f64>();
    // Units whose fits, taken out, leave more than was there explain none of it, not less.
    let explained = (1.0 - energy(&residual) / energy(samples).max(1e-300)).max(0.0);
    RecordingUnits {
        units,
        detected,
        start_hz,
        one_peak,
        spectrum,
        explained,
    }
}

/// The units of a recording fitted in turn, each from what the units before it left.
struct InTurn {
    units: Vec<UnitFit>,
    detected: Vec<DetectedUnit>,
    residual: Vec<f32>,
    /// The pitches (Hz) of the short modes units enough agreed on (MODEL.md §13).
    agreed_hz: Vec<f64>,
    /// What each unit kept with nothing fitted above its stronger component left early…
    early_left: Vec<Vec<f64>>,
    /// …and the highest pitch of that component: where its glide starts, or where it is heard
    /// (Hz).
    main_hz: Vec<f64>,
}

impl InTurn {
    fn fit(
        samples: &[f32],
        onsets: &[usize],
        fs: f64,
        held: &HeldLines,
        start_hz: [f64; 2],
        strides: Strides,
        pooled_hz: Option<f64>,
    ) -> Self {
        let mut residual = samples.to_vec();
        // Per unit kept, where a short mode was found: its place in `detected`, and the unit
        // without and with it.
        let mut short_modes: Vec<Option<(usize, UnitFit, UnitFit)>> = Vec::new();
        let mut units = Vec::with_capacity(onsets.len());
        let mut detected = Vec::with_capacity(onsets.len());
        let (mut early_left, mut main_hz) = (Vec::new(), Vec::new());
        for (index, &onset) in onsets.iter().enumerate() {
            let first = onset.saturating_sub((BEFORE_ONSET_S * fs) as usize);
            let next = onsets.get(index + 1).copied().unwrap_or(samples.len());
            let end = next
                .saturating_sub((BEFORE_NEXT_S * fs) as usize)
                .min(onset + (LONGEST_WINDOW_S * fs) as usize)
                .min(samples.len());
            let onset_s = onset as f64 / fs;
            if end < first + ((SHORTEST_WINDOW_S + BEFORE_ONSET_S) * fs) as usize {
                detected.push(DetectedUnit {
                    onset_s,
                    fit: None,
                    rejection: Some(Rejection::TooShort {
                        span_s: end.saturating_sub(onset) as f64 / fs,
                    }),
                });
                continue;
            }
            let span = Span::of(&residual, (first, end), onset, fs, held);
            match fit_one_way(&span, start_hz, strides) {
                Ok(unit) => {
                    let early = second_mode::early_left(&span, &unit);
                    let with_short = early.as_ref().and_then(|early| {
                        second_mode::with_second_mode(&span, unit, early, pooled_hz)
                    });
                    if let (Some(early), Some(main)) = (early, unit.stronger()) {
                        early_left.push(early.samples);
                        // A glide's misfit lies between where it starts and its own f.
                        let start_hz = main.glide.map_or(main.heard_hz, |glide| {
                            main.heard_hz.max(main.frequency_hz * glide.ratio)
                        });
                        main_hz.push(start_hz);
                    }
                    short_modes.push(with_short.map(|both| (detected.len(), unit, both)));
                    let unit = with_short.unwrap_or(unit);
                    subtract(&mut residual, &unit, fs);
                    units.push(unit);
                    detected.push(DetectedUnit {
                        onset_s,
                        fit: Some(unit),
                        rejection: None,
                    });
                }
                Err(failure) => {
                    let (rejection, fit) = *failure;
                    detected.push(DetectedUnit {
                        onset_s,
                        fit,
                        rejection: Some(rejection),
                    });
                }
            }
        }
        // A short mode too few units agree on is left out of every unit (MODEL.md §13).
        let found: Vec<Option<f64>> = short_modes
            .iter()
            .map(|short| short.and_then(|(_, _, both)| both.components[1].map(|c| c.heard_hz)))
            .collect();
        let agreed = second_mode::agreed(&found, units.len());
        let agreed_hz: Vec<f64> = found
            .iter()
            .zip(&agreed)
            .filter_map(|(hz, &agrees)| hz.filter(|_| agrees))
            .collect();
        for ((unit, short), agreed) in units.iter_mut().zip(&short_modes).zip(agreed) {
            if let (Some((index, without, _)), false) = (short, agreed) {
                *unit = *without;
                detected[*index].fit = Some(*without);
            }
        }
        InTurn {
            units,
            detected,
            residual,
            agreed_hz,
            early_left,
            main_hz,
        }
    }
}

/// The stronger component of `unit` must lie at the strongest peak of the samples it was fitted
/// to, read as the fit read them (every stride-th: a spectrum up to 8 samples a period of 1.3
/// times the highest start); a peak beyond that folds elsewhere and fails the check, and the fits
/// from the unit's own peaks (found in every sample) then read at strides set by those peaks.
fn at_peak(span: &Span, unit: UnitFit) -> Result<UnitFit, Failed> {
    let read: Vec<f64> = span.samples[..unit.window.1 - span.first]
        .iter()
        .step_by(unit.stride)
        .copied()
        .collect();
    let rate = span.fs / unit.stride as f64;
    let peak_hz = own_peaks(&read, rate, &span.held)
        .first()
        .map_or(f64::NAN, |p| p.0);
    let component_hz = unit.stronger().map_or(f64::NAN, |c| c.heard_hz);
    // A gliding mode's energy is spread over the pitches it sweeps, so its peak may lie anywhere
    // between where it starts and its own frequency.
    let (low_hz, high_hz) = unit
        .stronger()
        .and_then(|c| c.glide.map(|g| (c.frequency_hz * g.ratio, c.frequency_hz)))
        .map_or((component_hz, component_hz), |(a, b)| (a.min(b), a.max(b)));
    let tolerance = (AT_PEAK_SHARE * peak_hz).max(rate / read.len() as f64);
    if peak_hz >= low_hz - tolerance && peak_hz <= high_hz + tolerance {
        Ok(unit)
    } else {
        Err(Box::new((
            Rejection::OffPeak {
                component_hz,
                peak_hz,
            },
            Some(unit),
        )))
    }
}

/// The unit `span` holds: eq. 1 if it describes it, else a phased fit from its own peaks, else
/// the same in the first part of the span; or why none does, with the best fit rejected. (A unit
/// kept with one component is then given the short second mode its fit left out, where there is
/// one; a unit rejected stays rejected: a second mode found in what a fit could not explain would
/// make a babble of bubbles look like a glug.)
fn fit_one_way(span: &Span, start_hz: [f64; 2], strides: Strides) -> Result<UnitFit, Failed> {
    let at_peak = |unit: UnitFit| at_peak(span, unit);
    let paper = eq1::fit(span, start_hz, strides)
        .map_err(|rejection| Box::new((rejection, None)))
        .and_then(at_peak);
    let Err(first_reason) = paper else {
        return paper.map(|unit| with_glide(span, unit));
    };
    let peaks = own_peaks(&span.samples, span.fs, &span.held);
    if peaks.is_empty() {
        return Err(Box::new((Rejection::NoResonance, None)));
    }
    let own_hz: Vec<f64> = peaks.iter().map(|p| p.0).collect();
    let highest = own_hz.iter().copied().fold(0.0, f64::max);
    let own_strides = Strides::for_highest(highest, span.fs);
    let poles = eq1::pencil_poles(span.after_onset(0.04), own_strides.pencil, span.fs);
    let starts: Vec<(f64, f64)> = own_hz
        .iter()
        .map(|&hz| eq1::nearest_pole(&poles, hz).unwrap_or((hz, eq1::DECAY_GUESS_PER_S)))
        .collect();
    let mut best = first_reason;
    let lowest = own_hz.iter().copied().fold(f64::INFINITY, f64::min);
    let glide_end = span.onset
        + ((GLIDE_SHARE * (span.end - span.onset) as f64)
            .max(GLIDE_PERIODS / lowest * span.fs)
            .max(SHORTEST_WINDOW_S * span.fs)) as usize;
    // Phases of their own, then a glide too, then a glide in the first part of the span only;
    // each with the unit's peaks, then with its strongest alone (one mode may dominate).
    let attempts = [
        (UnitMethod::Phased, span.end),
        (UnitMethod::Glide, span.end),
        (UnitMethod::Glide, glide_end.min(span.end)),
    ];
    let counts: &[usize] = if starts.len() > 1 { &[2, 1] } else { &[1] };
    for (&count, (method, end)) in counts
        .iter()
        .flat_map(|count| attempts.iter().map(move |attempt| (count, *attempt)))
    {
        let window = span.window_until(own_strides.fit, end);
        let attempt = phased::fit(
            &window,
            span.onset_s(),
            &starts[..count],
            &[method == UnitMethod::Glide; 2],
            0,
        )
        .map_err(|rejection| Box::new((rejection, None)))
        .map(|fitted| {
            UnitFit::of_phased(
                &fitted,
                Placed {
                    window: (span.first, end),
                    stride: own_strides.fit,
                    fs: span.fs,
                },
                method,
            )
        })
        .and_then(|unit| check(unit, span.fs))
        .and_then(at_peak);
        match attempt {
            Ok(unit) if method == UnitMethod::Phased => return Ok(with_glide(span, unit)),
            Ok(unit) => return Ok(unit),
            Err(reason) => best = better(best, reason),
        }
    }
    Err(best)
}

/// `unit`, fitted with steady components, fitted again with each gliding (MODEL.md §5.2) over the
/// same samples; the glide is kept where it leaves at most [`GLIDE_LEAVES`] of what the steady
/// fit left, and passes the same checks. A glide has two numbers more per component, so on a
/// steady unit it explains next to nothing more; on a gliding one a steady fit leaves the sweep.
/// Where every component gliding fails the checks, the stronger glides and the other is steady,
/// then the stronger glides alone: a weak component a steady fit spent on the sweep's residue
/// has no glide of its own to find, and one out of range must not cost the mode its glide.
pub(super) fn with_glide(span: &Span, unit: UnitFit) -> UnitFit {
    let starts: Vec<(f64, f64)> = unit.fitted().map(|c| (c.heard_hz, c.decay_per_s)).collect();
    let stronger = unit
        .fitted()
        .position(|c| Some(c) == unit.stronger())
        .unwrap_or(0);
    let mut attempts = vec![(starts.clone(), [true; 2])];
    if starts.len() > 1 {
        let mut stronger_only = [false; 2];
        stronger_only[stronger] = true;
        attempts.push((starts.clone(), stronger_only));
        attempts.push((vec![starts[stronger]], [true, false]));
    }
    let window = span.window_until(unit.stride, unit.window.1);
    for (starts, gliding) in attempts {
        let Ok(fitted) = phased::fit(
            &window,
            span.onset_s(),
            &starts,
            &gliding,
            phased::GLIDE_RESTARTS,
        ) else {
            continue;
        };
        let glided = UnitFit::of_phased(
            &fitted,
            Placed {
                window: unit.window,
                stride: unit.stride,
                fs: span.fs,
            },
            UnitMethod::Glide,
        );
        let ring = |unit: &UnitFit| unit.stronger().map_or(f64::NAN, |c| 1.0 / c.decay_per_s);
        // A steady component beside the glide stands for what is left of the sweep, below it; one
        // drawn up to a bright mode would ring it steady, and a mode rising into its pitch,
        // fitted steady, decays too fast: that mode is left to the short mode's pair, which fits
        // it gliding first.
        let steady_below = glided.components.iter().flatten().all(|c| {
            c.glide.is_some() || glided.stronger().is_none_or(|s| c.heard_hz < s.heard_hz)
        });
        match check_glide(glided, span.fs).and_then(|glided| at_peak(span, glided)) {
            Ok(glided)
                if 1.0 - glided.r_squared <= GLIDE_LEAVES * (1.0 - unit.r_squared)
                    && ring(&glided) <= GLIDE_RINGS_LONGER * ring(&unit)
                    && steady_below =>
            {
                return glided
            }
            _ => {}
        }
    }
    unit
}

/// A glide fitted to a unit a steady fit described, checked as [`check`] does and heard: its
/// stronger component reaches its own frequency while it rings (else the steady fit stands). A
/// weaker one may glide more slowly than it rings, as a short mode in a pair may; its mode is
/// then the pitch it is heard at (`UnitFit::assign`).
fn check_glide(unit: UnitFit, fs: f64) -> Result<UnitFit, Failed> {
    let unit = check(unit, fs)?;
    let unheard = unit.stronger().and_then(Component::unheard_glide);
    match unheard {
        Some(rejection) => Err(Box::new((rejection, Some(unit)))),
        None => Ok(unit),
    }
}

/// A phased fit checked: finite, resonant and explaining enough.
fn check(unit: UnitFit, fs: f64) -> Result<UnitFit, Failed> {
    for component in unit.fitted() {
        component.check(fs).map_err(|r| Box::new((r, Some(unit))))?;
    }
    if unit.r_squared < MIN_EXPLAINED {
        return Err(Box::new((
            Rejection::Unexplained {
                share: unit.r_squared,
            },
            Some(unit),
        )));
    }
    Ok(unit)
}

/// Of two rejections, the one whose fit explains more (a fit over none).
fn better(a: Failed, b: Failed) -> Failed {
    let share = |r: &Failed| r.1.map_or(f64::NEG_INFINITY, |u| u.r_squared);
    if share(&b) > share(&a) {
        b
    } else {
        a
    }
}

/// Subtracts `unit` from `signal` until it has decayed by [`SUBTRACT_UNTIL`].
fn subtract(signal: &mut [f32], unit: &UnitFit, fs: f64) {
    let slowest = unit
        .fitted()
        .map(|c| c.decay_per_s)
        .fold(f64::INFINITY, f64::min)
        .max(1.0);
    let first = ((unit.onset_s * fs).ceil().max(0.0) as usize).min(signal.len());
    let end = (first + (-SUBTRACT_UNTIL.ln() / slowest * fs) as usize).min(signal.len());
    // The unit's span at full rate, as a window of its own.
    let span = Window {
        data: vec![0.0; end - first],
        first,
        stride: 1,
        fs,
    };
    for component in unit.fitted() {
        if component.glide.is_some() {
            for (n, sample) in signal[first..end].iter_mut().enumerate() {
                let tau = (first + n) as f64 / fs - unit.onset_s;
                *sample -= component.value(tau) as f32;
            }
            continue;
        }
        let (sine, cosine) = (
            component.amplitude * component.phase.cos(),
            component.amplitude * component.phase.sin(),
        );
        span.rotate(
            unit.onset_s,
            component.frequency_hz,
            component.decay_per_s,
            |n, z, _| signal[first + n] -= (sine * z.im + cosine * z.re) as f32,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `glide_ranges` reads f1's ranges for every component: that holds only while f2's are the
    /// same.
    #[test]
    fn every_mode_shares_the_glide_ranges() {
        assert_eq!(
            glide_ranges(),
            (
                Constant::F2GlideRatio.range(),
                Constant::F2GlideTime.range()
            )
        );
    }
}
