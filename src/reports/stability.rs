//! Stability on stiff and extreme cases: the cases, what each checks, and the measurements, shared
//! by `sake-glug stability` (long renders) and `tests/reports/stability.rs` (short ones).
//!
//! Every case renders through the engine's public API and checks some of:
//! - **finite**: no NaN or infinity in any sample, before the output limiter as well as after;
//! - **ceiling**: |y| never exceeds the (sanitised) ceiling, or the higher of the old and the new
//!   one while it ramps to a new one (MODEL.md §6), and how often the limiter acted;
//! - **energy**: once no unit starts any more, the energy of consecutive spans never grows, judged
//!   only where the limiter did not act (so the output is the signal before the limiter);
//! - **time**: engine run time per sample within a factor of a normal case measured in the same
//!   run (catches denormal slow-downs and runaway work); a ratio, never an absolute time;
//! - case-specific properties (voices capped, nothing computed above Nyquist, no drift...).

use super::accuracy;
use super::timing::{self, RenderSpec, TimedRender};
use crate::engine::config::{self, ControlValues, OUTPUT_RAMP_S};
use crate::engine::synthesis::reference;
use crate::engine::synthesis::MAX_PARTIALS;
use crate::engine::ControlSource;
use crate::engine::{DrainMode, Engine, ModelConfig, VoiceBank};

/// How long the cases render.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Seconds to minutes, for the test suite (dev profile).
    Test,
    /// Up to 24 hours, for the report (release build).
    Report,
}

impl Scale {
    /// Length of the sweeps' renders, seconds.
    fn sweep_s(self) -> f64 {
        match self {
            Scale::Test => 3.0,
            Scale::Report => 30.0,
        }
    }

    /// Length of the long renders, seconds.
    fn long_s(self) -> f64 {
        match self {
            Scale::Test => 600.0,
            Scale::Report => 24.0 * 3600.0,
        }
    }

    /// Repetitions of a timed render; the fastest counts, so a busy machine does not fail a case.
    fn repeats(self) -> usize {
        match self {
            Scale::Test => 3,
            Scale::Report => 2,
        }
    }
}

/// Run time per sample may be at most this many times a normal case's.
pub const MAX_TIME_RATIO: f64 = 5.0;
/// Consecutive spans' energy may grow by at most this fraction (beats between components of one
/// unit move energy between spans a little; growth means instability).
const ENERGY_TOLERANCE: f64 = 0.01;
/// Span over which energy is summed: whole cycles of 80 Hz and 300 Hz.
const ENERGY_SPAN_S: f64 = 0.1;
/// The output gain of the decay sweep: twelve never-decaying units in phase at 300 Hz sum to
/// 4 before the gain, and must stay under the ceiling so that their energy can be judged.
const DECAY_SWEEP_GAIN_DB: f64 = -20.0;

/// The stability catalogue: every group of cases, each describing what it renders and what its
/// time check compares with. `sake-glug stability --catalogue` prints it as the case table of
/// `docs/stability.md`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StabilityCase {
    /// Decay rates from 0 to 10⁹ s⁻¹.
    DecaySweep,
    /// Frequencies from 0 to far above Nyquist.
    FrequencySweep,
    /// Sample rates from 1 kHz to 768 kHz, and out-of-range ones.
    SampleRateSweep,
    /// Hundreds of units due per sample.
    Flood,
    /// Tilt jumping 0° ↔ 180° every sample.
    TiltFlip,
    /// NaN, infinities and absurd values for every input.
    HostileInputs,
    /// Hours of rendering.
    LongRender,
}

impl StabilityCase {
    /// Every group, in the report's order.
    pub const ALL: [StabilityCase; 7] = [
        StabilityCase::DecaySweep,
        StabilityCase::FrequencySweep,
        StabilityCase::SampleRateSweep,
        StabilityCase::Flood,
        StabilityCase::TiltFlip,
        StabilityCase::HostileInputs,
        StabilityCase::LongRender,
    ];

    /// The group's short name, as the tables show it.
    pub fn name(self) -> &'static str {
        match self {
            StabilityCase::DecaySweep => "decay",
            StabilityCase::FrequencySweep => "frequency",
            StabilityCase::SampleRateSweep => "sample rate",
            StabilityCase::Flood => "flood",
            StabilityCase::TiltFlip => "tilt flip",
            StabilityCase::HostileInputs => "hostile input",
            StabilityCase::LongRender => "long render",
        }
    }

    /// What the group renders.
    pub fn description(self) -> &'static str {
        match self {
            StabilityCase::DecaySweep => {
                "B1 = B2 ∈ {0, 10⁻⁶, 1, 45, 10³, 10⁵, 10⁷, 10⁹} s⁻¹; 1 s of steady pouring then \
                 upright, at −20 dB (twelve undecaying units in phase stay under the ceiling)"
            }
            StabilityCase::FrequencySweep => {
                "f1 = f2 ∈ {0, 1, 80, 0.4999·fs, fs/2, fs, 400 kHz, 10⁹} Hz; the same pour"
            }
            StabilityCase::SampleRateSweep => {
                "fs ∈ {1, 8, 44.1, 96, 192, 384, 768} kHz and out-of-range {0, −48 kHz, NaN, ∞, \
                 10¹²} (sanitised to the nearest bound, NaN to 48 kHz); the same pour"
            }
            StabilityCase::Flood => {
                "pour time 10 ms, pocket 0.001 ml (≈ 600 units due per sample): once in simulate \
                 mode (the bottle empties in 10 ms), once in follow mode (the flood lasts the \
                 whole render)"
            }
            StabilityCase::TiltFlip => "tilt 0° ↔ 180° every sample, simulate and follow modes",
            StabilityCase::HostileInputs => {
                "NaN, +∞, −∞, −10³⁰⁰, 10³⁰⁰, −1 and 0 for each of the five controls (every \
                 other sample, so they arrive mid-pour) and each constant of `ModelConfig` (at \
                 construction, and again through `set_config` halfway through a pour) and the \
                 sample rate"
            }
            StabilityCase::LongRender => {
                "continuous pouring; one unit with B = 0 ringing for the whole render"
            }
        }
    }

    /// What the group's time check compares with.
    pub fn time_reference(self) -> &'static str {
        match self {
            StabilityCase::DecaySweep => "the same pour with B = 0 (most work, no small values)",
            StabilityCase::FrequencySweep => "continuous pouring (follow mode, 135°)",
            StabilityCase::TiltFlip => {
                "continuous pouring with the tilt moving at every sample (follow mode, a slow \
                 sweep from 100° to 170°): under constant controls the pour takes a period at \
                 once, under a moving tilt sample by sample, like the flip"
            }
            StabilityCase::SampleRateSweep => "continuous pouring at 48 kHz, per sample",
            StabilityCase::Flood => {
                "a busy ordinary pour whose bank is also full (0.02 ml pockets, 3000 units/s)"
            }
            StabilityCase::HostileInputs => "—",
            StabilityCase::LongRender => {
                "the render's own early minutes: a late minute may cost at most the time ratio \
                 times an early one (medians of the first and last thirds)"
            }
        }
    }

    /// Runs every case of the group at `scale`.
    pub fn run(self, scale: Scale) -> Vec<Outcome> {
        match self {
            StabilityCase::DecaySweep => decay_sweep(scale),
            StabilityCase::FrequencySweep => frequency_sweep(scale),
            StabilityCase::SampleRateSweep => sample_rate_sweep(scale),
            StabilityCase::Flood => flood(scale),
            StabilityCase::TiltFlip => tilt_flip(scale),
            StabilityCase::HostileInputs => hostile_inputs(scale),
            StabilityCase::LongRender => long_render(scale),
        }
    }
}

impl std::fmt::Display for StabilityCase {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A property a stability case checks; each describes itself for the report.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Property {
    /// No NaN or infinity.
    Finite,
    /// Never above the ceiling.
    Ceiling,
    /// Energy does not grow once nothing starts.
    Energy,
    /// Cost per sample bounded by a normal case's.
    Time,
    /// Components at 0 Hz or at and above Nyquist never sound.
    NotComputed,
    /// The same number of units at every sample rate.
    SameGlugs,
    /// The bank never holds more than its cap.
    VoicesCapped,
    /// Units do start.
    Glugs,
    /// A never-decaying unit stays on the reference.
    NoDrift,
}

impl Property {
    /// Every property, in the order of the checks table.
    pub const ALL: [Property; 9] = [
        Property::Finite,
        Property::Ceiling,
        Property::Energy,
        Property::Time,
        Property::NotComputed,
        Property::SameGlugs,
        Property::VoicesCapped,
        Property::Glugs,
        Property::NoDrift,
    ];

    /// The property's short name, as the tables show it.
    pub fn name(self) -> &'static str {
        match self {
            Property::Finite => "finite",
            Property::Ceiling => "ceiling",
            Property::Energy => "energy",
            Property::Time => "time",
            Property::NotComputed => "not computed",
            Property::SameGlugs => "same glugs",
            Property::VoicesCapped => "voices capped",
            Property::Glugs => "glugs",
            Property::NoDrift => "no drift",
        }
    }

    /// What the property asserts.
    pub fn description(self) -> String {
        match self {
            Property::Finite => "no NaN or infinity in any sample: in the output, and before \
                                 the output limiter (the engine counts the samples that were not \
                                 finite before it turned them into 0 or the ceiling)"
                .into(),
            Property::Ceiling => "|y| never exceeds the sanitised ceiling (compared in f32, as \
                                  the engine clamps), or the higher of the old and the new one \
                                  during the 10 ms ramp to a new one; the measurement says on \
                                  how many samples the limiter acted"
                .into(),
            Property::Energy => format!(
                "once no unit starts any more, the energy of consecutive {ENERGY_SPAN_S} s spans \
                 never grows by more than {} % (a never-decaying unit keeps its energy; a \
                 decaying one loses it); judged where the limiter did not act, where the output \
                 is the signal before the limiter: a judged span in which the limiter acted \
                 fails the check",
                ENERGY_TOLERANCE * 100.0
            ),
            Property::Time => format!(
                "engine run time per sample at most {MAX_TIME_RATIO}× that of a normal case \
                 measured in the same run (fastest of {} runs in the report, of {} in the \
                 tests): catches denormal slow-downs and runaway work. Never an absolute time",
                Scale::Report.repeats(),
                Scale::Test.repeats()
            ),
            Property::NotComputed => "components with f = 0 or f ≥ fs/2 never sound: no \
                                      component in the bank, output exactly 0"
                .into(),
            Property::SameGlugs => "the number of units at any sample rate equals the number \
                                    at 48 kHz (±1): onsets are sub-sample exact"
                .into(),
            Property::VoicesCapped => format!(
                "at most {MAX_PARTIALS} components sound, and the units beyond the caps are \
                 counted as skipped"
            ),
            Property::Glugs => "units start at all under the case's inputs".into(),
            Property::NoDrift => "the last second of the long render of a never-decaying unit \
                                  is within −100 dB of the f64 reference"
                .into(),
        }
    }
}

impl std::fmt::Display for Property {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The catalogue as Markdown: the checks table and the case table of `docs/stability.md`.
pub fn catalogue() -> String {
    let mut text = String::from("| check | what it asserts |\n|---|---|\n");
    for property in Property::ALL {
        text += &format!(
            "| {} | {} |\n",
            property,
            property.description().replace('|', "\\|")
        );
    }
    text += "\n| group | cases | normal case for the time check |\n|---|---|---|\n";
    for case in StabilityCase::ALL {
        text += &format!(
            "| {} | {} | {} |\n",
            case,
            case.description(),
            case.time_reference()
        );
    }
    text
}

/// One property checked by a case.
#[derive(Debug, Clone)]
pub struct Check {
    /// The property checked.
    pub what: Property,
    /// Whether the property held.
    pub passed: bool,
    /// The measurement behind the verdict.
    pub detail: String,
}

/// The result of one case.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The catalogue entry this case belongs to.
    pub group: StabilityCase,
    /// The case's name within its group.
    pub name: String,
    /// The properties checked.
    pub checks: Vec<Check>,
    /// Measurements worth reporting that are not checks.
    pub notes: String,
}

impl Outcome {
    /// Whether every check passed.
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| c.passed)
    }

    /// One line: every check with its verdict and measurement, then the notes.
    pub fn summary(&self) -> String {
        let checks: Vec<String> = self
            .checks
            .iter()
            .map(|c| {
                let mark = if c.passed { "ok" } else { "FAILED" };
                format!("{} {mark} ({})", c.what, c.detail)
            })
            .collect();
        format!("{}; {}", checks.join(", "), self.notes)
    }
}

/// The inputs of a case as a function of the sample index.
type Inputs = Box<dyn Fn(u64) -> (ControlValues, f64)>;

/// Follow mode held full at 135°: continuous pouring at 12 glugs/s (the normal case).
fn steady(_sample: u64) -> (ControlValues, f64) {
    (
        ControlValues {
            tilt_deg: 135.0,
            ..ControlValues::default()
        },
        -6.0,
    )
}

/// Pours as [`steady`] for `pour_s`, then stands the bottle upright: nothing starts after.
fn pour_then_stop(sample_rate: f64, pour_s: f64) -> Inputs {
    pour_then_stop_at(sample_rate, pour_s, -6.0)
}

/// [`pour_then_stop`] at output gain `gain_db`.
fn pour_then_stop_at(sample_rate: f64, pour_s: f64, gain_db: f64) -> Inputs {
    Box::new(move |sample| {
        let pouring = (sample as f64) < pour_s * sample_rate;
        (
            ControlValues {
                tilt_deg: if pouring { 135.0 } else { 0.0 },
                ..ControlValues::default()
            },
            gain_db,
        )
    })
}

fn follow() -> ModelConfig {
    ModelConfig {
        drain: DrainMode::Follow,
        ..ModelConfig::default()
    }
}

/// A render and what the engine said about it.
struct Run {
    render: TimedRender,
    len: u64,
    ceiling: f64,
    units_started: u64,
    units_skipped: u64,
    given_up: u64,
}

#[cfg(feature = "fault-injection")]
thread_local! {
    /// Whether the engines this thread's cases build get a NaN in their first component.
    static NAN_IN_A_COMPONENT: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Runs `cases` with a NaN injected into the first component of every engine they build: the
/// suite must then fail (the tests show it does). Only with the `fault-injection` feature.
#[cfg(feature = "fault-injection")]
pub fn with_nan_in_a_component<R>(cases: impl FnOnce() -> R) -> R {
    NAN_IN_A_COMPONENT.with(|inject| inject.set(true));
    let result = cases();
    NAN_IN_A_COMPONENT.with(|inject| inject.set(false));
    result
}

/// An engine on the default path, with the fault of [`with_nan_in_a_component`] when asked.
fn new_engine(sample_rate: f64, config: ModelConfig) -> Engine<VoiceBank> {
    #[allow(unused_mut)]
    let mut engine = Engine::<VoiceBank>::with_synthesis(sample_rate, config);
    #[cfg(feature = "fault-injection")]
    if NAN_IN_A_COMPONENT.with(|inject| inject.get()) {
        engine.inject_nan_into_next_component();
    }
    engine
}

impl Run {
    /// What `engine` did in `render`, a render of `len` samples.
    fn of(render: TimedRender, len: u64, engine: &Engine<VoiceBank>) -> Self {
        Self {
            render,
            len,
            ceiling: engine.config().ceiling,
            units_started: engine.stats().units_started,
            units_skipped: engine.stats().units_skipped,
            given_up: engine.components_given_up(),
        }
    }

    fn time_per_sample(&self) -> f64 {
        self.render.engine_time.as_secs_f64() / self.len as f64
    }

    fn times_real_time(&self, sample_rate: f64) -> f64 {
        self.len as f64 / sample_rate / self.render.engine_time.as_secs_f64()
    }
}

/// Renders `seconds` of `inputs` on the default path, `repeats` times, keeping the fastest.
fn run(
    sample_rate: f64,
    config: ModelConfig,
    seconds: f64,
    inputs: &impl ControlSource,
    repeats: usize,
) -> Run {
    let mut best: Option<Run> = None;
    for _ in 0..repeats.max(1) {
        let mut engine = new_engine(sample_rate, config);
        let fs = engine.sample_rate();
        let len = (seconds * fs).round() as u64;
        let spec = RenderSpec {
            sample_rate: fs,
            config,
            len,
            keep: &[],
            energy_span: (ENERGY_SPAN_S * fs).round() as u64,
        };
        let render = timing::timed_render_on(&mut engine, &spec, inputs);
        let this = Run::of(render, len, &engine);
        if best
            .as_ref()
            .is_none_or(|b| this.render.engine_time < b.render.engine_time)
        {
            best = Some(this);
        }
    }
    best.expect("at least one repeat")
}

fn check(what: Property, passed: bool, detail: String) -> Check {
    Check {
        what,
        passed,
        detail,
    }
}

fn finite(run: &Run) -> Check {
    let hidden = run.render.non_finite_before_limiter;
    check(
        Property::Finite,
        run.render.all_finite && hidden == 0,
        if hidden == 0 {
            "every sample, before the limiter too".into()
        } else {
            format!("{hidden} samples NaN or infinite before the limiter")
        },
    )
}

fn ceiling(run: &Run) -> Check {
    check(
        Property::Ceiling,
        // In f32, as the engine clamps: 0.001 rounds up in f32.
        run.render.all_finite && run.render.peak <= run.ceiling as f32,
        format!(
            "peak {:.3} ≤ {}, limiter acted on {} samples",
            run.render.peak, run.ceiling, run.render.limiter_events
        ),
    )
}

/// Energy of consecutive spans after the last onset never grows beyond the tolerance, and the
/// limiter did not act in those spans (there the output is the signal before the limiter).
fn energy_not_growing(run: &Run, span: u64) -> Check {
    let first = (run.render.last_onset_by / span + 1) as usize;
    let energies = run.render.energies.get(first..).unwrap_or(&[]);
    let limited = limiter_events_in_spans(&run.render, first);
    let worst = energies
        .windows(2)
        .map(|pair| {
            if pair[0] > 0.0 {
                pair[1] / pair[0]
            } else if pair[1] > 0.0 {
                f64::INFINITY
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max);
    check(
        Property::Energy,
        worst <= 1.0 + ENERGY_TOLERANCE && energies.len() >= 2 && limited == 0,
        format!(
            "largest span-to-span ratio {worst:.4} over {} spans, limiter acted on {limited} \
             samples in them",
            energies.len()
        ),
    )
}

/// Samples the limiter changed in the energy spans from `first` on.
fn limiter_events_in_spans(render: &TimedRender, first: usize) -> u64 {
    let counts = &render.span_limiter_events;
    match counts.last() {
        Some(&last) if first < counts.len() => {
            last - if first == 0 { 0 } else { counts[first - 1] }
        }
        _ => 0,
    }
}

fn time_ratio(run: &Run, normal: &Run) -> Check {
    let ratio = run.time_per_sample() / normal.time_per_sample();
    check(
        Property::Time,
        ratio <= MAX_TIME_RATIO,
        format!("{ratio:.2}× the normal case per sample"),
    )
}

fn outcome(
    group: StabilityCase,
    name: String,
    checks: Vec<Check>,
    run: &Run,
    sample_rate: f64,
) -> Outcome {
    Outcome {
        group,
        name,
        checks,
        notes: format!(
            "{:.0}× real time, {} units ({} skipped), {} components given up, at most {} sounding, \
             limiter acted on {} samples",
            run.times_real_time(sample_rate),
            run.units_started,
            run.units_skipped,
            run.given_up,
            run.render.max_sounding,
            run.render.limiter_events
        ),
    }
}

/// The normal case every time ratio refers to: [`steady`] pouring at `sample_rate`.
fn normal(sample_rate: f64, seconds: f64, scale: Scale) -> Run {
    run(sample_rate, follow(), seconds, &steady, scale.repeats())
}

/// Decay rates from 0 to 10⁹ s⁻¹: a second of pouring, then the units ring out. Times are
/// compared with B = 0, the same pour with the most work (every component rings to the end) and
/// no small values, so a slower decay case means time lost to denormals or wasted work.
fn decay_sweep(scale: Scale) -> Vec<Outcome> {
    let fs = 48_000.0;
    let seconds = scale.sweep_s();
    let span = (ENERGY_SPAN_S * fs) as u64;
    // Deterministic: equal frequencies, so ringing units add without beats.
    let config = |decay: f64| ModelConfig {
        decay_per_s: [decay; 2],
        ..follow().deterministic()
    };
    let inputs = pour_then_stop_at(fs, 1.0, DECAY_SWEEP_GAIN_DB);
    let normal = run(fs, config(0.0), seconds, &inputs, scale.repeats());
    [0.0, 1e-6, 1.0, 45.0, 1e3, 1e5, 1e7, 1e9]
        .into_iter()
        .map(|decay| {
            let run = run(fs, config(decay), seconds, &inputs, scale.repeats());
            let checks = vec![
                finite(&run),
                ceiling(&run),
                energy_not_growing(&run, span),
                time_ratio(&run, &normal),
            ];
            outcome(
                StabilityCase::DecaySweep,
                format!("B1 = B2 = {decay:e} /s"),
                checks,
                &run,
                fs,
            )
        })
        .collect()
}

/// Frequencies from 0 to above Nyquist: nothing is computed for 0 or at/above fs/2.
fn frequency_sweep(scale: Scale) -> Vec<Outcome> {
    let fs = 48_000.0;
    let seconds = scale.sweep_s();
    let normal = normal(fs, seconds, scale);
    let span = (ENERGY_SPAN_S * fs) as u64;
    [
        0.0,
        1.0,
        80.0,
        0.4999 * fs,
        0.5 * fs,
        fs,
        config::F1_HZ.max,
        1e9,
    ]
    .into_iter()
    .map(|frequency| {
        let config = ModelConfig {
            frequency_hz: [frequency; 2],
            ..follow().deterministic()
        };
        let run = run(
            fs,
            config,
            seconds,
            &pour_then_stop(fs, 1.0),
            scale.repeats(),
        );
        let mut checks = vec![finite(&run), ceiling(&run)];
        if frequency > 0.0 && frequency < 0.5 * fs {
            checks.push(energy_not_growing(&run, span));
        } else {
            checks.push(check(
                Property::NotComputed,
                run.render.max_sounding == 0 && run.render.peak == 0.0,
                format!(
                    "at most {} components sounded, peak {}",
                    run.render.max_sounding, run.render.peak
                ),
            ));
        }
        checks.push(time_ratio(&run, &normal));
        outcome(
            StabilityCase::FrequencySweep,
            format!("f1 = f2 = {frequency} Hz"),
            checks,
            &run,
            fs,
        )
    })
    .collect()
}

/// Sample rates from 1 kHz to 768 kHz, and out-of-range ones (sanitised to the nearest bound or
/// the default): the same glugs at every rate, per-sample cost like 48 kHz's.
fn sample_rate_sweep(scale: Scale) -> Vec<Outcome> {
    let seconds = scale.sweep_s();
    let normal = normal(48_000.0, seconds, scale);
    let at_48k = run(
        48_000.0,
        follow(),
        seconds,
        &pour_then_stop(48_000.0, 1.0),
        1,
    )
    .units_started;
    [
        1_000.0,
        8_000.0,
        44_100.0,
        96_000.0,
        192_000.0,
        384_000.0,
        768_000.0,
        0.0,
        -48_000.0,
        f64::NAN,
        f64::INFINITY,
        1e12,
    ]
    .into_iter()
    .map(|requested| {
        let fs = config::SAMPLE_RATE_HZ.sanitize(requested);
        let inputs = pour_then_stop(fs, 1.0);
        let run = run(requested, follow(), seconds, &inputs, scale.repeats());
        let span = (ENERGY_SPAN_S * fs).round() as u64;
        let checks = vec![
            finite(&run),
            ceiling(&run),
            energy_not_growing(&run, span),
            check(
                Property::SameGlugs,
                run.units_started.abs_diff(at_48k) <= 1,
                format!("{} units, {} at 48 kHz", run.units_started, at_48k),
            ),
            time_ratio(&run, &normal),
        ];
        outcome(
            StabilityCase::SampleRateSweep,
            format!("fs = {requested} Hz (runs at {fs} Hz)"),
            checks,
            &run,
            fs,
        )
    })
    .collect()
}

/// Pour time down to 10 ms and pockets down to 0.001 ml: hundreds of units due per sample.
/// The pour voices at most 8 per sample and counts the rest as skipped, the start budget admits
/// a burst of 8 units and then 6000 units per second, and the bank holds at most 256
/// components (MODEL.md §11); the run time is compared with a busy but ordinary pour whose bank
/// is also full (0.02 ml pockets).
fn flood(scale: Scale) -> Vec<Outcome> {
    let fs = 48_000.0;
    let seconds = scale.sweep_s();
    let busy_config = ModelConfig {
        pocket_ml: 0.02,
        ..follow()
    };
    let busy = run(fs, busy_config, seconds, &steady, scale.repeats());
    let span = (ENERGY_SPAN_S * fs) as u64;
    let fastest = |_: u64| {
        (
            ControlValues {
                tilt_deg: 135.0,
                pour_time_s: config::POUR_TIME_S.min,
                ..ControlValues::default()
            },
            -6.0,
        )
    };
    let mut outcomes = Vec::new();
    for (name, drain) in [
        (
            "flood, bottle empties in 10 ms (simulate)",
            DrainMode::Simulate,
        ),
        ("flood for the whole render (follow)", DrainMode::Follow),
    ] {
        let config = ModelConfig {
            pocket_ml: config::POCKET_ML.min,
            drain,
            ..ModelConfig::default()
        };
        let run = run(fs, config, seconds, &fastest, scale.repeats());
        let mut checks = vec![
            finite(&run),
            ceiling(&run),
            check(
                Property::VoicesCapped,
                run.render.max_sounding <= MAX_PARTIALS && run.units_skipped > 0,
                format!(
                    "at most {} sounding (cap {MAX_PARTIALS}), {} of {} units skipped",
                    run.render.max_sounding, run.units_skipped, run.units_started
                ),
            ),
            time_ratio(&run, &busy),
        ];
        if drain == DrainMode::Simulate {
            checks.push(energy_not_growing(&run, span));
        }
        outcomes.push(outcome(
            StabilityCase::Flood,
            name.to_string(),
            checks,
            &run,
            fs,
        ));
    }
    outcomes
}

/// Tilt jumping 0° ↔ 180° every sample, in both drain modes.
fn tilt_flip(scale: Scale) -> Vec<Outcome> {
    let fs = 48_000.0;
    let seconds = scale.sweep_s();
    let sweep_samples = seconds * fs;
    let sweep = move |sample: u64| {
        (
            ControlValues {
                tilt_deg: 100.0 + 70.0 * (sample as f64 / sweep_samples),
                ..ControlValues::default()
            },
            -6.0,
        )
    };
    let normal = run(fs, follow(), seconds, &sweep, scale.repeats());
    let flip = |sample: u64| {
        (
            ControlValues {
                tilt_deg: if sample.is_multiple_of(2) { 0.0 } else { 180.0 },
                ..ControlValues::default()
            },
            -6.0,
        )
    };
    [("simulate", ModelConfig::default()), ("follow", follow())]
        .into_iter()
        .map(|(mode, config)| {
            let run = run(fs, config, seconds, &flip, scale.repeats());
            let checks = vec![
                finite(&run),
                ceiling(&run),
                check(
                    Property::Glugs,
                    run.units_started > 0,
                    format!("{} units started", run.units_started),
                ),
                time_ratio(&run, &normal),
            ];
            outcome(
                StabilityCase::TiltFlip,
                format!("0° ↔ 180° every sample ({mode})"),
                checks,
                &run,
                fs,
            )
        })
        .collect()
}

/// Values no input should ever carry.
const HOSTILE: [f64; 7] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    -1e300,
    1e300,
    -1.0,
    0.0,
];

/// NaN, ±∞, negative and huge values for every control and every constant, each alone, through
/// the engine's API: output finite and under the sanitised ceiling.
fn hostile_inputs(scale: Scale) -> Vec<Outcome> {
    let fs = 48_000.0;
    let seconds = match scale {
        Scale::Test => 0.5,
        Scale::Report => 5.0,
    };
    type SetControl = fn(&mut ControlValues, &mut f64, f64);
    let controls: [(&str, SetControl); 5] = [
        ("tilt", |c, _, v| c.tilt_deg = v),
        ("viscosity", |c, _, v| c.viscosity = v),
        ("fill", |c, _, v| c.fill_percent = v),
        ("pour time", |c, _, v| c.pour_time_s = v),
        ("gain", |_, g, v| *g = v),
    ];
    type SetConfig = fn(&mut ModelConfig, f64);
    let constants: [(&str, SetConfig); 11] = [
        ("capacity", |c, v| c.capacity_ml = v),
        ("pocket", |c, v| c.pocket_ml = v),
        ("f1", |c, v| c.frequency_hz[0] = v),
        ("f2", |c, v| c.frequency_hz[1] = v),
        ("B1", |c, v| c.decay_per_s[0] = v),
        ("B2", |c, v| c.decay_per_s[1] = v),
        ("timing jitter", |c, v| c.timing_jitter = v),
        ("frequency jitter", |c, v| c.freq_jitter = v),
        ("decay sigma", |c, v| c.decay_sigma = v),
        ("ceiling", |c, v| c.ceiling = v),
        ("sample rate", |_, _| {}),
    ];
    let mut outcomes = Vec::new();
    let mut judge = |name: String, runs: Vec<Run>| {
        let hidden: u64 = runs
            .iter()
            .map(|r| r.render.non_finite_before_limiter)
            .sum();
        let all_finite = runs.iter().all(|r| r.render.all_finite) && hidden == 0;
        let within = runs
            .iter()
            .all(|r| r.render.all_finite && r.render.peak <= r.ceiling as f32);
        let peak = runs.iter().map(|r| r.render.peak).fold(0.0f32, f32::max);
        let limited: u64 = runs.iter().map(|r| r.render.limiter_events).sum();
        outcomes.push(Outcome {
            group: StabilityCase::HostileInputs,
            name,
            checks: vec![
                check(
                    Property::Finite,
                    all_finite,
                    format!(
                        "{} renders, {hidden} samples not finite before the limiter",
                        runs.len()
                    ),
                ),
                check(
                    Property::Ceiling,
                    within,
                    format!("largest peak {peak:.3}, limiter acted on {limited} samples"),
                ),
            ],
            notes: "values: NaN, +∞, −∞, −1e300, 1e300, −1, 0 (constants: at construction and \
                    again through set_config mid-pour)"
                .into(),
        });
    };
    for (name, set) in controls {
        let runs = HOSTILE
            .iter()
            .map(|&value| {
                // The bad value every other sample, so it also arrives mid-pour.
                let inputs = move |sample: u64| {
                    let (mut values, mut gain) = steady(sample);
                    if sample % 2 == 1 {
                        set(&mut values, &mut gain, value);
                    }
                    (values, gain)
                };
                run(fs, follow(), seconds, &inputs, 1)
            })
            .collect();
        judge(format!("control: {name}"), runs);
    }
    for (name, set) in constants {
        let runs = HOSTILE
            .iter()
            .map(|&value| {
                let mut config = follow();
                set(&mut config, value);
                let sample_rate = if name == "sample rate" { value } else { fs };
                run(sample_rate, config, seconds, &steady, 1)
            })
            .chain(HOSTILE.iter().map(|&value| {
                // The same value arriving mid-pour through `set_config`.
                let mut config = follow();
                set(&mut config, value);
                switch_config(fs, config, seconds, &steady)
            }))
            .collect();
        judge(format!("constant: {name}"), runs);
    }
    outcomes
}

/// Renders `seconds` under the normal constants, switching to `config` with `set_config` halfway.
fn switch_config(
    sample_rate: f64,
    config: ModelConfig,
    seconds: f64,
    inputs: &impl ControlSource,
) -> Run {
    let mut engine = new_engine(sample_rate, follow());
    let half = (seconds * sample_rate / 2.0).round() as u64;
    let spec = RenderSpec {
        sample_rate,
        config: follow(),
        len: half,
        keep: &[],
        energy_span: 0,
    };
    let before = timing::timed_render_on(&mut engine, &spec, inputs);
    engine.set_config(config);
    // The ceiling moves to the new one along its ramp (MODEL.md §6): meanwhile the output
    // answers to the higher of the two, then to the new one alone.
    let ramp = (engine.sample_rate() * OUTPUT_RAMP_S).round() as u64;
    let ramping = timing::timed_render_on(
        &mut engine,
        &RenderSpec {
            len: ramp.min(half),
            ..spec
        },
        inputs,
    );
    let mut after = timing::timed_render_on(
        &mut engine,
        &RenderSpec {
            len: half - ramp.min(half),
            ..spec
        },
        inputs,
    );
    // Each part answers to its own ceiling; a part over its own fails the case.
    let old_ceiling = follow().ceiling as f32;
    let ramp_ceiling = old_ceiling.max(engine.config().ceiling as f32);
    if before.peak > old_ceiling || ramping.peak > ramp_ceiling {
        after.peak = f32::INFINITY;
    }
    for part in [&before, &ramping] {
        after.all_finite &= part.all_finite;
        after.engine_time += part.engine_time;
        after.limiter_events += part.limiter_events;
        after.non_finite_before_limiter += part.non_finite_before_limiter;
        after.max_sounding = after.max_sounding.max(part.max_sounding);
    }
    Run {
        render: after,
        len: 2 * half,
        ceiling: engine.config().ceiling,
        units_started: engine.stats().units_started,
        units_skipped: engine.stats().units_skipped,
        given_up: engine.components_given_up(),
    }
}

/// Hours of rendering: continuous pouring stays stationary, a never-decaying unit neither grows
/// nor fades nor drifts from the reference, and the cost per second does not grow with length.
fn long_render(scale: Scale) -> Vec<Outcome> {
    let fs = 48_000.0;
    let seconds = scale.long_s();
    let span_s = 60.0;
    let mut outcomes = Vec::new();
    let stationary = |run: &Run, what: Property| {
        let energies = &run.render.energies;
        // The first minute holds the onset transients of the ring scene; compare from the second.
        let (first, last) = (energies[1], energies[energies.len() - 1]);
        let ratio = last / first;
        let limited = limiter_events_in_spans(&run.render, 1);
        check(
            what,
            (1.0 - ENERGY_TOLERANCE..=1.0 + ENERGY_TOLERANCE).contains(&ratio) && limited == 0,
            format!(
                "last minute's energy / second minute's = {ratio:.6}, limiter acted on \
                 {limited} samples after the first minute"
            ),
        )
    };
    let cost_flat = |run: &Run| {
        let times = &run.render.span_times;
        let minute = |k: usize| {
            times[k].as_secs_f64()
                - if k == 0 {
                    0.0
                } else {
                    times[k - 1].as_secs_f64()
                }
        };
        // Medians of the first and of the last third (the first minute aside: start-up), so one
        // busy moment of the machine does not count.
        let median = |range: std::ops::Range<usize>| {
            let mut v: Vec<f64> = range.map(minute).collect();
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        let n = times.len();
        let third = (n - 1) / 3;
        let ratio = median(n - third..n) / median(1..1 + third);
        check(
            Property::Time,
            ratio <= MAX_TIME_RATIO,
            format!("a late minute costs {ratio:.2}× an early one"),
        )
    };
    let spec_span = (span_s * fs) as u64;

    let steady_config = follow().deterministic();
    let run_steady = long_run(fs, steady_config, seconds, &steady, spec_span);
    let checks = vec![
        finite(&run_steady),
        ceiling(&run_steady),
        stationary(&run_steady, Property::Energy),
        cost_flat(&run_steady),
    ];
    outcomes.push(outcome(
        StabilityCase::LongRender,
        format!("continuous pouring for {}", accuracy::length_label(seconds)),
        checks,
        &run_steady,
        fs,
    ));

    let ring = accuracy::cases()
        .into_iter()
        .find(|s| s.name == "ring")
        .expect("the accuracy set has the ring scene");
    let controls = ring.controls(fs);
    let run_ring = long_run(fs, ring.config, seconds, &controls, spec_span);
    let len = (seconds * fs) as u64;
    let window = len - fs as u64..len;
    let exact = reference::evaluate(fs, ring.config, &controls, window.clone()).samples;
    let spec = RenderSpec {
        sample_rate: fs,
        config: ring.config,
        len,
        keep: std::slice::from_ref(&window),
        energy_span: 0,
    };
    let last_second = timing::timed_render::<VoiceBank>(&spec, &controls).kept;
    let (max_db, _) = accuracy::error_db(&last_second, &exact);
    let checks = vec![
        finite(&run_ring),
        ceiling(&run_ring),
        stationary(&run_ring, Property::Energy),
        check(
            Property::NoDrift,
            max_db < -100.0,
            format!("last second vs reference: {max_db:.1} dB"),
        ),
    ];
    outcomes.push(outcome(
        StabilityCase::LongRender,
        format!(
            "a unit with B = 0 ringing for {}",
            accuracy::length_label(seconds)
        ),
        checks,
        &run_ring,
        fs,
    ));
    outcomes
}

fn long_run(
    sample_rate: f64,
    config: ModelConfig,
    seconds: f64,
    inputs: &impl ControlSource,
    energy_span: u64,
) -> Run {
    let mut engine = new_engine(sample_rate, config);
    let len = (seconds * sample_rate).round() as u64;
    let spec = RenderSpec {
        sample_rate,
        config,
        len,
        keep: &[],
        energy_span,
    };
    let render = timing::timed_render_on(&mut engine, &spec, inputs);
    Run::of(render, len, &engine)
}

/// Every group of cases, in the report's order.
pub fn run_all(scale: Scale, mut progress: impl FnMut(&Outcome)) -> Vec<Outcome> {
    let mut all = Vec::new();
    for case in StabilityCase::ALL {
        for outcome in case.run(scale) {
            progress(&outcome);
            all.push(outcome);
        }
    }
    all
}

/// The outcomes as a Markdown table.
pub fn report(outcomes: &[Outcome]) -> String {
    let mut text =
        String::from("| group | case | result | checks | measured |\n|---|---|---|---|---|\n");
    for o in outcomes {
        let checks: Vec<String> = o
            .checks
            .iter()
            .map(|c| {
                format!(
                    "{}{}: {}",
                    if c.passed { "" } else { "**FAILED** " },
                    c.what,
                    c.detail
                )
            })
            .collect();
        text += &format!(
            "| {} | {} | {} | {} | {} |\n",
            o.group,
            o.name,
            if o.passed() { "pass" } else { "**FAIL**" },
            checks.join("; "),
            o.notes
        );
    }
    let failed = outcomes.iter().filter(|o| !o.passed()).count();
    text += &format!("\n{} cases, {} failed.\n", outcomes.len(), failed);
    text
}
