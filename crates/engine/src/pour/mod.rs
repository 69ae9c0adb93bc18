//! The pour: bottle, onsets and random draws together turn controls into a stream of unit onsets
//! (MODEL.md §3, §4, §7, §8). Every synthesis path, fast or reference, is driven by this.

mod bottle;
mod exact;
mod onsets;
mod randomness;
mod span;

pub use bottle::Outflow;
pub use onsets::MAX_ONSETS_PER_SAMPLE;
pub use randomness::UnitShape;

use crate::config::ModelConfig;
use crate::controls::{Control, ControlValues, Controls, Lane, PerControl};
use crate::quantity::Range;
use bottle::{fill_ml, Bottle, SpanLevels, SPAN};
use exact::Direction;
use onsets::OnsetDetector;
use randomness::UnitDraws;
use span::{PlainRun, PourState};

/// The inputs of up to a grid period of samples, brought into range (the output gain's row
/// unused: it does not drive the pour).
type SpanInputs = PerControl<[f64; SPAN]>;

/// The first `len` ≤ [`SPAN`] samples of the controls that drive the pour, each as
/// [`ControlValues::sanitized`] would give it.
fn read_span(inputs: &mut SpanInputs, controls: &Controls, len: usize) {
    for control in Control::pour() {
        read_lane(
            &controls[control],
            &mut inputs[control][..len],
            control.range(),
        );
    }
}

/// The first `values.len()` samples of `lane`, brought into `range`.
#[inline]
fn read_lane(lane: &Lane, values: &mut [f64], range: Range) {
    match *lane {
        Lane::Constant(value) => values.fill(range.sanitize(value)),
        Lane::Samples(samples) if samples.len() >= values.len() => {
            for (value, &sample) in values.iter_mut().zip(samples) {
                *value = range.sanitize(sample);
            }
        }
        Lane::Samples(_) => {
            for (index, value) in values.iter_mut().enumerate() {
                *value = range.sanitize(lane.at(index));
            }
        }
    }
}

/// After n plans in a row found no plain sample ahead, 2^n − 1 samples (at most 2^6 − 1) are
/// stepped one by one before the next plan: a state that the closed form cannot take (a tie in
/// the rounding) then costs a plan only now and then.
const MAX_PLAN_BACKOFF_LOG2: u32 = 6;

/// One wave unit as it starts (the inputs of §5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitOnset {
    /// n: the sample during which the unit starts.
    pub sample: u64,
    /// x: the onset is at (n + x) / fs.
    pub fraction: f64,
    /// V_i.
    pub volume_ml: f64,
    /// θ_n: the tilt of the onset's sample, brought into range (°).
    pub tilt_deg: f64,
    /// b_i: the pocket volume whose filling started the unit (ml, §4, §7).
    pub pocket_ml: f64,
    /// Asum_i = a(V_i)·exp(σ_A·z_i) (§5, §12), before the output gain.
    pub amplitude: f64,
    /// c_i, clamped to [0, 1].
    pub viscosity: f64,
    /// f1_i, f2_i, B1_i, B2_i and the amplitude's factor as drawn for this unit (§7, §12).
    pub shape: UnitShape,
    /// Each component's gain from the actuator compensation (§18), `[1, 1]` without a profile:
    /// the engine sets it as the unit starts.
    pub actuator_gain: [f64; 2],
}

impl UnitOnset {
    /// A1 = c·a, A2 = (1 − c)·a (paper eq. 2), each times its actuator gain (§18; × 1 changes
    /// no bit without a profile).
    pub fn component_amplitudes(&self) -> [f64; 2] {
        [
            self.viscosity * self.amplitude * self.actuator_gain[0],
            (1.0 - self.viscosity) * self.amplitude * self.actuator_gain[1],
        ]
    }
}

/// Counts kept for reports and tests.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PourStats {
    /// Units whose onset came since the last reset, the skipped ones included.
    pub units_started: u64,
    /// Units not synthesised because more started within one sample than the engine starts.
    pub units_skipped: u64,
}

/// What [`Pour::advance`] did over its samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Advanced {
    /// The last sample's outflow.
    pub last: Outflow,
    /// The sample after the last one during which liquid flowed, if any did.
    pub flowed_until: Option<u64>,
}

impl Advanced {
    /// Before the first sample of a span: nothing flowed yet from `volume_ml`.
    fn nothing_yet(volume_ml: f64) -> Self {
        Self {
            last: Outflow {
                volume_before_ml: volume_ml,
                amount_ml: 0.0,
                submerged: false,
                refilled: false,
            },
            flowed_until: None,
        }
    }
}

/// The pour: bottle, onset accumulator and random draws, turning the controls, sample by
/// sample, into unit onsets.
pub struct Pour {
    config: ModelConfig,
    bottle: Bottle,
    onsets: OnsetDetector,
    draws: UnitDraws,
    stats: PourStats,
    /// The plain samples ahead under the controls of the last step, once planned.
    plain: Option<PlainRun>,
    /// Per-sample steps to take before planning again, after a plan found none.
    plan_backoff: u32,
    /// Plans in a row that found no plain sample.
    plans_failed: u32,
    /// The next step must check for changes: the constants changed since the last one.
    config_changed: bool,
}

impl Pour {
    /// A pour at `sample_rate` (Hz) under `config` (brought into range); the bottle fills to the
    /// fill level at the first step.
    pub fn new(sample_rate: f64, config: ModelConfig) -> Self {
        let config = config.sanitized();
        Self {
            config,
            bottle: Bottle::new(sample_rate),
            onsets: OnsetDetector::default(),
            draws: UnitDraws::new(config.seed),
            stats: PourStats::default(),
            plain: None,
            plan_backoff: 0,
            plans_failed: 0,
            config_changed: true,
        }
    }

    /// The constants in use, brought into range.
    pub fn config(&self) -> &ModelConfig {
        &self.config
    }

    /// New constants take effect from the next sample; a new seed at the next reset.
    pub fn set_config(&mut self, config: ModelConfig) {
        self.config = config.sanitized();
        self.config_changed = true;
        self.plain = None;
        // The bottle's levels are of the old curves, perhaps.
        self.bottle.forget_levels();
    }

    /// MODEL.md §8 reset: refill, re-seed, clear the counts.
    pub fn reset(&mut self) {
        self.bottle.refill();
        self.onsets.clear();
        self.draws.reseed(self.config.seed);
        self.stats = PourStats::default();
        self.plain = None;
    }

    /// MODEL.md §8 refill: the generator goes on.
    pub fn refill(&mut self) {
        self.bottle.refill();
        self.plain = None;
    }

    /// Residual volume V after the last step (ml).
    pub fn volume_ml(&self) -> f64 {
        self.bottle.volume_ml()
    }

    /// The counts since the last reset.
    pub fn stats(&self) -> PourStats {
        self.stats
    }

    /// Advances one sample and calls `emit` for each unit starting in it.
    #[inline]
    pub fn step(
        &mut self,
        sample: u64,
        controls: ControlValues,
        emit: impl FnMut(&UnitOnset),
    ) -> Outflow {
        self.step_sanitized(sample, &controls.sanitized(), emit)
    }

    /// [`Pour::step`] for controls already brought into range, so that a caller stepping many
    /// samples under the same controls sanitises them once.
    #[inline]
    pub fn step_sanitized(
        &mut self,
        sample: u64,
        controls: &ControlValues,
        emit: impl FnMut(&UnitOnset),
    ) -> Outflow {
        self.plain = None;
        self.config_changed = false;
        let outflow = self.bottle.step(controls, &self.config);
        if outflow.refilled {
            self.onsets.clear();
        }
        self.count_onsets(sample, controls.tilt_deg, controls.viscosity, outflow, emit)
    }

    /// `count` samples from `first_sample` under the same `controls` (already brought into
    /// range), with the same onsets, outflows and volumes as `count` calls of
    /// [`Pour::step_sanitized`]: plain samples are taken in closed form (see [`span`]), the
    /// others one by one.
    pub fn advance(
        &mut self,
        first_sample: u64,
        count: u64,
        controls: &ControlValues,
        mut emit: impl FnMut(&UnitOnset),
    ) -> Advanced {
        let mut advanced = Advanced::nothing_yet(self.bottle.volume_ml());
        let mut done = 0;
        if count > 0
            && (self.config_changed
                || !self
                    .bottle
                    .is_steady_under(controls, self.config.capacity_ml))
        {
            advanced.last = self.step_sanitized(first_sample, controls, &mut emit);
            done = 1;
            if advanced.last.amount_ml > 0.0 {
                advanced.flowed_until = Some(first_sample + 1);
            }
        }
        while done < count {
            let sample = first_sample + done;
            if self.plain.is_none() && self.plan_backoff == 0 {
                self.plain = PlainRun::plan(&self.state());
                if self.plain.is_some() {
                    self.plans_failed = 0;
                } else {
                    // Mostly the very next sample alone is special (an onset, a binade edge);
                    // a state that keeps failing is planned for ever more rarely.
                    self.plan_backoff = (1 << self.plans_failed.min(MAX_PLAN_BACKOFF_LOG2)) - 1;
                    self.plans_failed += 1;
                }
            }
            match &mut self.plain {
                Some(run) => {
                    let taken = run.samples_left.min(count - done);
                    run.samples_left -= taken;
                    let run = *run;
                    if run.samples_left == 0 {
                        self.plain = None;
                    }
                    advanced.last = self.take_plain(&run, taken);
                    if run.outflow.amount_ml > 0.0 {
                        advanced.flowed_until = Some(sample + taken);
                    }
                    done += taken;
                }
                None => {
                    self.plan_backoff = self.plan_backoff.saturating_sub(1);
                    advanced.last = self.step_steady(sample, controls, &mut emit);
                    if advanced.last.amount_ml > 0.0 {
                        advanced.flowed_until = Some(sample + 1);
                    }
                    done += 1;
                }
            }
        }
        advanced
    }

    /// Samples left in the plain run under way (0 if none): how far ahead
    /// [`Pour::advance_plain`] may take the pour at once, if the controls it was planned for
    /// still hold.
    #[inline]
    pub fn plain_samples_left(&self) -> u64 {
        self.plain.map_or(0, |run| run.samples_left)
    }

    /// [`Pour::advance`] of a span that lies wholly inside the plain run under way, under the
    /// controls it was planned for (the usual span while a bottle pours): no unit starts in it,
    /// so it takes no callback, and V and g move in closed form. `None` where [`Pour::advance`]
    /// has more to do: the run ends within the span, or none is planned, or the controls or
    /// constants changed since the last step.
    #[inline]
    pub fn advance_plain(
        &mut self,
        first_sample: u64,
        count: u64,
        controls: &ControlValues,
    ) -> Option<Advanced> {
        // As `advance` would find it: no step of its own first, and the run covering the span.
        if self.config_changed
            || !self
                .bottle
                .is_steady_under(controls, self.config.capacity_ml)
        {
            return None;
        }
        self.advance_plain_unchanged(first_sample, count)
    }

    /// [`Pour::advance_plain`] where the caller knows that neither the controls nor the constants
    /// changed, and no refill was asked for, since the last step, which was taken under the
    /// controls the run was planned for (the engine's blocks under the very controls of a
    /// constant block before them): only whether the run covers the span is left to check.
    #[inline]
    pub fn advance_plain_unchanged(&mut self, first_sample: u64, count: u64) -> Option<Advanced> {
        let run = self.plain.as_mut()?;
        if count == 0 || run.samples_left < count {
            return None;
        }
        run.samples_left -= count;
        let run = *run;
        if run.samples_left == 0 {
            self.plain = None;
        }
        Some(Advanced {
            last: self.take_plain(&run, count),
            flowed_until: (run.outflow.amount_ml > 0.0).then_some(first_sample + count),
        })
    }

    /// `count` samples from `first_sample` whose controls may change from sample to sample: the
    /// same onsets, outflows and volumes as `count` calls of [`Pour::step`] with
    /// `controls.values_at(i)`. The inputs are brought into range and the levels of every sample
    /// worked out first, a span at a time in loops that vectorise; only the refills, the volume,
    /// the accumulator and the onsets are then stepped one sample at a time.
    pub fn advance_varying(
        &mut self,
        first_sample: u64,
        controls: &Controls,
        count: usize,
        mut emit: impl FnMut(&UnitOnset),
    ) -> Advanced {
        self.plain = None;
        let mut advanced = Advanced::nothing_yet(self.bottle.volume_ml());
        let mut inputs = SpanInputs::splat([0.0; SPAN]);
        let mut levels = SpanLevels::default();
        let mut start = 0;
        while start < count {
            let len = (count - start).min(SPAN);
            let controls = controls.offset(start);
            read_span(&mut inputs, &controls, len);
            self.bottle.levels_of_span(
                &inputs.tilt_deg[..len],
                &inputs.pour_time_s[..len],
                &self.config,
                &mut levels,
            );
            self.config_changed = false;
            let fills = &inputs.fill_percent[..len];
            let first = first_sample + start as u64;
            if self.bottle.refills_none_of(fills, self.config.drain) {
                self.step_span_without_refill(
                    first,
                    &inputs,
                    &levels,
                    len,
                    &mut advanced,
                    &mut emit,
                );
            } else {
                for (index, &fill) in fills.iter().enumerate() {
                    let sample = first + index as u64;
                    let outflow = self.bottle.step_with(fill, &levels.at(index), &self.config);
                    if outflow.refilled {
                        self.onsets.clear();
                    }
                    let outflow = self.count_onsets(
                        sample,
                        inputs.tilt_deg[index],
                        inputs.viscosity[index],
                        outflow,
                        &mut emit,
                    );
                    if outflow.amount_ml > 0.0 {
                        advanced.flowed_until = Some(sample + 1);
                    }
                    advanced.last = outflow;
                }
            }
            start += len;
        }
        advanced
    }

    /// The samples of a span that refills nothing, each drained as [`Bottle::step_with`] drains
    /// it and counted with the arithmetic of the onset detector, but V and g kept in registers: a
    /// sample that starts a unit goes through the detector itself, from the state before it.
    fn step_span_without_refill(
        &mut self,
        first_sample: u64,
        inputs: &SpanInputs,
        levels: &SpanLevels,
        len: usize,
        advanced: &mut Advanced,
        emit: &mut impl FnMut(&UnitOnset),
    ) {
        let drain = self.config.drain;
        let capacity_ml = self.config.capacity_ml;
        let mut volume = self.bottle.volume_ml();
        let mut accumulated = self.onsets.accumulated_ml();
        let mut pocket = self.draws.next_pocket_ml(&self.config);
        for index in 0..len {
            let fill = || fill_ml(inputs.fill_percent[index], capacity_ml);
            let (outflow, volume_after) = levels.at(index).drain(volume, fill, false, drain);
            volume = volume_after;
            let sample = first_sample + index as u64;
            if outflow.amount_ml > 0.0 {
                advanced.flowed_until = Some(sample + 1);
                if outflow.submerged {
                    let sum = accumulated + outflow.amount_ml;
                    if sum >= pocket {
                        self.onsets.set_accumulated_ml(accumulated);
                        self.count_onsets(
                            sample,
                            inputs.tilt_deg[index],
                            inputs.viscosity[index],
                            outflow,
                            &mut *emit,
                        );
                        accumulated = self.onsets.accumulated_ml();
                        pocket = self.draws.next_pocket_ml(&self.config);
                    } else {
                        accumulated = sum;
                    }
                }
            }
            advanced.last = outflow;
        }
        self.onsets.set_accumulated_ml(accumulated);
        self.bottle.end_span(volume, inputs.fill_percent[len - 1]);
    }

    fn state(&self) -> PourState<'_> {
        PourState {
            volume_ml: self.bottle.volume_ml(),
            accumulated_ml: self.onsets.accumulated_ml(),
            levels: self.bottle.current_levels(),
            drain: self.config.drain,
            pocket_ml: self.draws.next_pocket_ml(&self.config),
        }
    }

    /// `count` plain samples of `run`; returns the last one's outflow: the run's, from the V
    /// before that sample.
    fn take_plain(&mut self, run: &PlainRun, count: u64) -> Outflow {
        let volume = self.bottle.volume_ml();
        let step = run.volume_step;
        let volume_before_ml = if step > 0.0 {
            self.bottle
                .set_volume_ml(exact::after(volume, step, count, Direction::Down));
            exact::after(volume, step, count - 1, Direction::Down)
        } else {
            volume
        };
        if run.accumulated_step > 0.0 {
            let accumulated = self.onsets.accumulated_ml();
            self.onsets.set_accumulated_ml(exact::after(
                accumulated,
                run.accumulated_step,
                count,
                Direction::Up,
            ));
        }
        Outflow {
            volume_before_ml,
            ..run.outflow
        }
    }

    /// [`Pour::step_sanitized`] under the same `controls` (brought into range) as the previous
    /// step and with no refill asked for since: the bottle skips its checks for changes.
    #[inline]
    pub fn step_steady(
        &mut self,
        sample: u64,
        controls: &ControlValues,
        emit: impl FnMut(&UnitOnset),
    ) -> Outflow {
        self.plain = None;
        let outflow = self.bottle.step_steady(self.config.drain);
        self.count_onsets(sample, controls.tilt_deg, controls.viscosity, outflow, emit)
    }

    /// Counts the onsets of one sample whose tilt and viscosity (brought into range) the units
    /// take.
    #[inline]
    fn count_onsets(
        &mut self,
        sample: u64,
        tilt_deg: f64,
        viscosity: f64,
        outflow: Outflow,
        mut emit: impl FnMut(&UnitOnset),
    ) -> Outflow {
        let (capacity_ml, silent_below) = (self.config.capacity_ml, self.config.silent_below);
        let mut started = 0;
        let skipped = self.onsets.feed(
            &outflow,
            &self.config,
            &mut self.draws,
            |crossing, shape: UnitShape| {
                started += 1;
                emit(&UnitOnset {
                    sample,
                    fraction: crossing.fraction,
                    volume_ml: crossing.volume_ml,
                    tilt_deg,
                    pocket_ml: crossing.pocket_ml,
                    amplitude: silent_below.amplitude(crossing.volume_ml, capacity_ml)
                        * shape.amplitude_factor,
                    viscosity,
                    shape,
                    actuator_gain: [1.0, 1.0],
                });
            },
        );
        self.stats.units_started += started + skipped;
        self.stats.units_skipped += skipped;
        outflow
    }
}
