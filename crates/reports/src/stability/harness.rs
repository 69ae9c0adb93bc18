//! The one way a case renders: a [`Setup`] and the inputs, on a synthesis path, into a [`Run`]
//! (what was rendered and what the engine said about it); and the inputs the groups share.

use std::ops::Range;

use super::Scale;
use crate::timing::{self, RenderSpec, TimedRender};
use sake_glug_engine::config::OUTPUT_RAMP_S;
use sake_glug_engine::ControlValues;
use sake_glug_engine::{ControlSource, DrainMode, Engine, ModelConfig, Synthesis};

/// Span over which energy is summed unless a case sets its own: whole cycles of 80 Hz and 300 Hz.
pub(super) const ENERGY_SPAN_S: f64 = 0.1;

/// The inputs of a case as a function of the sample index.
pub(super) type Inputs = Box<dyn Fn(u64) -> ControlValues>;

/// Follow mode held full at 135°: continuous pouring at 12 glugs/s (the normal case).
pub(super) fn steady(_sample: u64) -> ControlValues {
    ControlValues {
        tilt_deg: 135.0,
        gain_db: -6.0,
        ..ControlValues::default()
    }
}

/// Pours as [`steady`] for `pour_s`, then stands the bottle upright: nothing starts after.
pub(super) fn pour_then_stop(sample_rate: f64, pour_s: f64) -> Inputs {
    pour_then_stop_at(sample_rate, pour_s, -6.0)
}

/// [`pour_then_stop`] at output gain `gain_db`.
pub(super) fn pour_then_stop_at(sample_rate: f64, pour_s: f64, gain_db: f64) -> Inputs {
    Box::new(move |sample| {
        let pouring = (sample as f64) < pour_s * sample_rate;
        ControlValues {
            tilt_deg: if pouring { 135.0 } else { 0.0 },
            gain_db,
            ..ControlValues::default()
        }
    })
}

/// The default constants in follow mode: the bottle stays full.
pub(super) fn follow() -> ModelConfig {
    ModelConfig {
        drain: DrainMode::Follow,
        ..ModelConfig::default()
    }
}

/// The normal case every time ratio refers to: [`steady`] pouring at `sample_rate`.
pub(super) fn normal<S: Synthesis>(sample_rate: f64, seconds: f64, scale: Scale) -> Run {
    run::<S>(
        &Setup::new(sample_rate, follow(), seconds).repeats(scale.repeats()),
        &steady,
    )
}

/// Everything about a render but its inputs and its synthesis path.
#[derive(Debug, Clone)]
pub(super) struct Setup {
    /// As asked for: the engine brings it into range.
    sample_rate: f64,
    config: ModelConfig,
    seconds: f64,
    /// Renders this often and keeps the fastest, so a busy machine does not fail a time check.
    repeats: usize,
    /// Span over which energies are summed (s).
    energy_span_s: f64,
    /// The samples kept, in [`Run::kept`].
    keep: Range<u64>,
    /// Constants the engine switches to halfway, through `set_config`.
    switch_to: Option<ModelConfig>,
}

impl Setup {
    /// `seconds` under `config` at `sample_rate`, once, with energies over
    /// [`ENERGY_SPAN_S`] spans.
    pub(super) fn new(sample_rate: f64, config: ModelConfig, seconds: f64) -> Self {
        Self {
            sample_rate,
            config,
            seconds,
            repeats: 1,
            energy_span_s: ENERGY_SPAN_S,
            keep: 0..0,
            switch_to: None,
        }
    }

    pub(super) fn repeats(self, repeats: usize) -> Self {
        Self { repeats, ..self }
    }

    pub(super) fn energy_span_s(self, energy_span_s: f64) -> Self {
        Self {
            energy_span_s,
            ..self
        }
    }

    pub(super) fn keep(self, keep: Range<u64>) -> Self {
        Self { keep, ..self }
    }

    /// Switches to `config` halfway (the energies are then not summed).
    pub(super) fn switching_to(self, config: ModelConfig) -> Self {
        Self {
            switch_to: Some(config),
            ..self
        }
    }
}

/// A render and what the engine said about it.
pub(super) struct Run {
    pub render: TimedRender,
    /// The engine's sample rate (Hz), brought into range.
    pub sample_rate: f64,
    /// Samples rendered.
    pub len: u64,
    /// Samples per energy span (0: none summed).
    pub energy_span: u64,
    /// The ceiling at the end (after a switch, the new constants').
    pub ceiling: f64,
    pub units_started: u64,
    pub units_skipped: u64,
    pub given_up: u64,
}

impl Run {
    pub(super) fn time_per_sample(&self) -> f64 {
        self.render.engine_time.as_secs_f64() / self.len as f64
    }

    pub(super) fn times_real_time(&self) -> f64 {
        self.len as f64 / self.sample_rate / self.render.engine_time.as_secs_f64()
    }
}

/// Renders `inputs` as `setup` says on synthesis path `S`, from a new engine each repeat,
/// keeping the fastest.
pub(super) fn run<S: Synthesis>(setup: &Setup, inputs: &impl ControlSource) -> Run {
    let mut best: Option<Run> = None;
    for _ in 0..setup.repeats.max(1) {
        let this = run_once::<S>(setup, inputs);
        if best
            .as_ref()
            .is_none_or(|b| this.render.engine_time < b.render.engine_time)
        {
            best = Some(this);
        }
    }
    best.expect("at least one repeat")
}

fn run_once<S: Synthesis>(setup: &Setup, inputs: &impl ControlSource) -> Run {
    let mut engine = Engine::<S>::with_synthesis(setup.sample_rate, setup.config);
    let fs = engine.sample_rate();
    let len = (setup.seconds * fs).round() as u64;
    let spec = RenderSpec {
        sample_rate: fs,
        config: setup.config,
        len,
        keep: std::slice::from_ref(&setup.keep),
        energy_span: (setup.energy_span_s * fs).round() as u64,
    };
    let render = match setup.switch_to {
        None => timing::timed_render_on(&mut engine, &spec, inputs),
        Some(config) => render_switching(&mut engine, config, &spec, inputs),
    };
    Run {
        render,
        sample_rate: fs,
        len,
        energy_span: spec.energy_span,
        ceiling: engine.config().ceiling,
        units_started: engine.stats().units_started,
        units_skipped: engine.stats().units_skipped,
        given_up: engine.components_given_up(),
    }
}

/// Renders the first half of `spec`, switches `engine` to `config` with `set_config`, and renders
/// the rest: one render whose peak is infinite if a part went over its own ceiling.
fn render_switching<S: Synthesis>(
    engine: &mut Engine<S>,
    config: ModelConfig,
    spec: &RenderSpec,
    inputs: &impl ControlSource,
) -> TimedRender {
    // The parts' energies and kept samples would not join up; no check asks for them.
    let part = |len| RenderSpec {
        len,
        keep: &[],
        energy_span: 0,
        ..*spec
    };
    let half = spec.len / 2;
    let old_ceiling = engine.config().ceiling as f32;
    let before = timing::timed_render_on(engine, &part(half), inputs);
    engine.set_config(config);
    // The ceiling moves to the new one along its ramp (MODEL.md §6): meanwhile the output
    // answers to the higher of the two, then to the new one alone.
    let ramp = ((engine.sample_rate() * OUTPUT_RAMP_S).round() as u64).min(spec.len - half);
    let ramping = timing::timed_render_on(engine, &part(ramp), inputs);
    let mut after = timing::timed_render_on(engine, &part(spec.len - half - ramp), inputs);
    // Each part answers to its own ceiling; a part over its own fails the case.
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
    after
}
