//! Drives an [`Engine`] on any synthesis path from a control function of time, block by block,
//! keeping only chosen windows of the output and timing the engine alone. Shared by the accuracy
//! and stability reports so that both measure the same thing the same way.

use std::ops::Range;
use std::time::{Duration, Instant};

use sake_glug_engine::{
    Control, ControlSource, Controls, Engine, Lane, ModelConfig, PerControl, Synthesis,
};

/// Samples per `process` call: a typical host block.
pub const BLOCK: usize = 4096;

/// What one render kept and cost.
pub struct TimedRender {
    /// The samples inside the requested windows, window after window.
    pub kept: Vec<f32>,
    /// Time spent inside `Engine::process` only (building the control lanes is not counted).
    pub engine_time: Duration,
    /// Largest |y| over the whole render.
    pub peak: f32,
    /// Whether every sample of the whole render was finite.
    pub all_finite: bool,
    /// Sum of y² over consecutive spans of `energy_span` samples (empty if not asked for).
    pub energies: Vec<f64>,
    /// Engine time spent up to the end of each energy span (the block that ends it).
    pub span_times: Vec<Duration>,
    /// The most components that sounded at once, at any sample.
    pub max_sounding: usize,
    /// Samples the engine's output limiter changed (over the ceiling or not finite).
    pub limiter_events: u64,
    /// Samples that were NaN or infinite before the limiter.
    pub non_finite_before_limiter: u64,
    /// The limiter's events up to the end of each energy span (cumulative, exact: blocks are cut
    /// at span ends), so a check can tell where the output is the unlimited signal.
    pub span_limiter_events: Vec<u64>,
    /// The sample after the one in which the last unit started (0 if none did).
    pub last_onset_by: u64,
}

impl TimedRender {
    /// A render that has produced nothing yet, with room for `kept` samples.
    pub fn nothing_yet(kept: usize) -> Self {
        Self {
            kept: Vec::with_capacity(kept),
            engine_time: Duration::ZERO,
            peak: 0.0,
            all_finite: true,
            energies: Vec::new(),
            span_times: Vec::new(),
            max_sounding: 0,
            limiter_events: 0,
            non_finite_before_limiter: 0,
            span_limiter_events: Vec::new(),
            last_onset_by: 0,
        }
    }
}

/// Options of [`timed_render`] besides the controls.
pub struct RenderSpec<'a> {
    /// Sample rate (Hz).
    pub sample_rate: f64,
    /// The model's constants.
    pub config: ModelConfig,
    /// Samples to render.
    pub len: u64,
    /// Windows (ascending, disjoint) whose samples are kept.
    pub keep: &'a [Range<u64>],
    /// Span over which energies are summed; 0 for none.
    pub energy_span: u64,
}

/// Renders `spec.len` samples of `controls` on synthesis path `S` from a reset.
pub fn timed_render<S: Synthesis>(spec: &RenderSpec, controls: &impl ControlSource) -> TimedRender {
    let mut engine = Engine::<S>::with_synthesis(spec.sample_rate, spec.config);
    timed_render_on(&mut engine, spec, controls)
}

/// As [`timed_render`], on an engine the caller built (and may inspect afterwards).
pub fn timed_render_on<S: Synthesis>(
    engine: &mut Engine<S>,
    spec: &RenderSpec,
    controls: &impl ControlSource,
) -> TimedRender {
    let mut lanes: PerControl<Vec<f64>> = PerControl::from_fn(|_| Vec::with_capacity(BLOCK));
    let mut out = vec![0.0f32; BLOCK];
    let kept_len: u64 = spec
        .keep
        .iter()
        .map(|w| w.end.min(spec.len) - w.start.min(spec.len))
        .sum();
    let mut result = TimedRender::nothing_yet(kept_len as usize);
    // Counts since the engine's reset; a caller's engine may have rendered before.
    let (limiter_before, non_finite_before) =
        (engine.limiter_events(), engine.non_finite_before_limiter());
    engine.take_peak_sounding();
    let mut energy = 0.0;
    let mut start = 0u64;
    while start < spec.len {
        let mut len = (spec.len - start).min(BLOCK as u64) as usize;
        if spec.energy_span > 0 {
            // A block ends at the next span end, so the limiter's count is known per span. Any
            // cut gives the same samples.
            let to_span_end = spec.energy_span - start % spec.energy_span;
            len = len.min(to_span_end as usize);
        }
        for &control in Control::ALL {
            lanes[control].clear();
        }
        for sample in start..start + len as u64 {
            let values = controls.at(sample);
            for &control in Control::ALL {
                lanes[control].push(values[control]);
            }
        }
        let block: Controls = PerControl::from_fn(|control| lane(&lanes[control]));
        let out = &mut out[..len];
        let began = Instant::now();
        engine.process(&block, out);
        result.engine_time += began.elapsed();
        result.max_sounding = result.max_sounding.max(engine.take_peak_sounding());
        result.limiter_events = engine.limiter_events() - limiter_before;
        result.non_finite_before_limiter = engine.non_finite_before_limiter() - non_finite_before;
        result.last_onset_by = engine.last_unit().map_or(0, |unit| unit.sample + 1);

        for (offset, &y) in out.iter().enumerate() {
            let sample = start + offset as u64;
            result.all_finite &= y.is_finite();
            result.peak = result.peak.max(y.abs());
            if spec.energy_span > 0 {
                energy += y as f64 * y as f64;
                if (sample + 1).is_multiple_of(spec.energy_span) {
                    result.energies.push(energy);
                    result.span_times.push(result.engine_time);
                    result.span_limiter_events.push(result.limiter_events);
                    energy = 0.0;
                }
            }
        }
        for window in spec.keep {
            let from = window.start.max(start);
            let to = window.end.min(start + len as u64);
            if from < to {
                result
                    .kept
                    .extend_from_slice(&out[(from - start) as usize..(to - start) as usize]);
            }
        }
        start += len as u64;
    }
    result
}

/// A lane that is constant when its values are, so the engine can take its idle path.
fn lane(values: &[f64]) -> Lane<'_> {
    match values.first() {
        Some(&first) if values.iter().all(|v| v.to_bits() == first.to_bits()) => {
            Lane::Constant(first)
        }
        _ => Lane::Samples(values),
    }
}
