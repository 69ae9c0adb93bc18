//! The engine: the glug model of MODEL.md as plain Rust, shared by the plugin, the offline
//! renderer, the reports, the tests and the benches. No plugin, GUI or file-format type in here.
//!
//! Data flows one way: [`Controls`] (from a scene, a take or a host) → [`Pour`] (bottle, onsets,
//! randomness: [`pour`]) → a [`Synthesis`] path ([`synthesis`]) → the caller's output buffer.
//! [`Engine`] ties them together block by block.

pub mod actuator;
mod amplitude;
pub mod config;
mod controls;
pub mod curves;
mod glide;
mod headspace;
mod output;
pub mod pour;
mod presets;
mod quantity;
pub mod synthesis;

pub use actuator::{ActuatorResponse, Equalise, ResponseError};
pub use amplitude::{SilentBelow, PAPERS_SILENT_BELOW_ML};
pub use config::{Constant, ConstantSpec, Curve, DrainMode, ModelConfig};
pub use controls::{
    sample_time_s, Control, ControlSource, ControlSpec, ControlValues, Controls, DeviceInput, Lane,
    LinearSegment, PerControl,
};
pub use glide::Glide;
pub use headspace::Headspace;
use output::OutputStage;
use pour::MAX_ONSETS_PER_SAMPLE;
pub use pour::{Outflow, Pour, PourStats, UnitOnset};
pub use presets::{Preset, PresetValue, ADDED_RULES, PRESETS};
pub use quantity::{Knob, Quantity, Range, ValueError};
pub use synthesis::{AnchoredF32, RecursiveF32, RecursiveF64, Synthesis, GRID};

/// How the engine voiced a unit as it started: what a table of units or a clip needs to know
/// beyond its [`UnitOnset`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Voicing {
    /// The output gain G (linear, on its ramp: MODEL.md §6) at the unit's first sounding sample.
    pub output_gain: f64,
    /// Whether any of its components sounds: false for a unit given up by the start budget or
    /// the component cap (§11), or whose components are all omitted (§6: a(V_i) = 0 below the
    /// amplitude law's zero, a frequency of 0 or at/above Nyquist, −240 dB or weaker).
    pub audible: bool,
}

/// Renders the model into caller-provided buffers; allocation-free after construction.
///
/// The output of a given sample depends only on the controls up to it, never on how the caller
/// cuts time into blocks. `S` is the synthesis path; the default is the real-time f32 path.
pub struct Engine<S: Synthesis = AnchoredF32> {
    sample_rate: f64,
    pour: Pour,
    synthesis: S,
    /// Samples since the last reset: the grid periods and onset times are counted from it.
    sample: u64,
    /// The pour's last step changed nothing and would change nothing again under these controls.
    resting_under: Option<ControlValues>,
    /// Gain, ceiling and limiter (MODEL.md §6).
    output: OutputStage,
    last_unit: Option<UnitOnset>,
    /// The sample after the last one during which liquid flowed or a component sounded.
    active_until: u64,
    /// What the last sample rendered poured.
    last_outflow: Outflow,
    /// The sample after the block being rendered.
    block_end: u64,
    /// Units that started in the last sample of the last block, with their voicing: they are
    /// first heard in the next block, whose gain is only known when it comes, and are reported
    /// at its start (so that what a unit is heard at never depends on where a block ends).
    deferred: [Option<(UnitOnset, Voicing)>; MAX_ONSETS_PER_SAMPLE as usize],
    /// The actuator the output drives, if a profile is given: each unit's components are
    /// compensated for it as the unit starts (MODEL.md §18).
    actuator: Option<ActuatorResponse>,
    /// The pour's inputs of the last span that held them constant.
    held_pour: HeldPour,
}

/// The inputs that drove the pour over the last span that held them constant: as given, and
/// brought into range. A span under the very same constants (the usual one: a host's next block,
/// nothing changed) takes them as they are, without reading and bringing each into range again.
#[derive(Debug, Clone, Copy, Default)]
struct HeldPour(Option<(ControlValues, ControlValues)>);

impl HeldPour {
    /// The pour's inputs over the first `len` samples of `controls` if they hold the very same
    /// values over them (as constants, or samples that do not change: a ramp's end inside the
    /// block), as given and brought into range.
    #[inline]
    fn inputs(
        &mut self,
        controls: &Controls,
        len: usize,
    ) -> Option<(ControlValues, ControlValues)> {
        if let Some(held) = self.0 {
            let same = |control: Control| match controls[control] {
                // Bit for bit: NaN is held as NaN, and −0 is not 0.
                Lane::Constant(value) => value.to_bits() == held.0[control].to_bits(),
                Lane::Samples(_) => false,
            };
            if Control::pour().all(same) {
                return Some(held);
            }
        }
        let values = controls
            .pour_is_constant_over(len)
            .then(|| controls.values_at(0))?;
        let held = (values, values.sanitized());
        self.0 = Some(held);
        Some(held)
    }
}

impl Engine {
    /// An engine on the default, real-time synthesis path.
    pub fn new(sample_rate: f64, config: ModelConfig) -> Self {
        Self::with_synthesis(sample_rate, config)
    }
}

impl<S: Synthesis> Engine<S> {
    /// An engine on synthesis path `S`.
    pub fn with_synthesis(sample_rate: f64, config: ModelConfig) -> Self {
        let sample_rate = config::SAMPLE_RATE_HZ.sanitize(sample_rate);
        let mut engine = Self {
            sample_rate,
            pour: Pour::new(sample_rate, config),
            synthesis: S::new(sample_rate),
            sample: 0,
            resting_under: None,
            output: OutputStage::new(sample_rate),
            last_unit: None,
            active_until: 0,
            last_outflow: Outflow::NONE,
            block_end: 0,
            deferred: [None; MAX_ONSETS_PER_SAMPLE as usize],
            actuator: None,
            held_pour: HeldPour::default(),
        };
        engine.reset();
        engine
    }

    /// The sample rate in use (Hz), after sanitising the one asked for.
    pub fn sample_rate(&self) -> f64 {
        self.sample_rate
    }

    /// The constants in force.
    pub fn config(&self) -> &ModelConfig {
        self.pour.config()
    }

    /// New constants apply to units that start from now on; a new seed at the next reset.
    pub fn set_config(&mut self, config: ModelConfig) {
        self.pour.set_config(config);
        self.resting_under = None;
    }

    /// Compensates the units that start from now on for `actuator` (`None`: plays the model's
    /// drive as it is), and holds the output within its largest drive (MODEL.md §18).
    /// Allocation-free: a host may call it between blocks.
    pub fn set_actuator(&mut self, actuator: Option<ActuatorResponse>) {
        self.actuator = actuator;
    }

    /// The actuator the units are compensated for, if any.
    pub fn actuator(&self) -> Option<&ActuatorResponse> {
        self.actuator.as_ref()
    }

    /// The ceiling in force (linear): the model's, and at most the actuator's largest drive.
    fn ceiling(&self) -> f64 {
        let ceiling = self.pour.config().ceiling;
        match &self.actuator {
            Some(actuator) => ceiling.min(actuator.max_amplitude()),
            None => ceiling,
        }
    }

    /// MODEL.md §8 reset: refill, silence every unit, re-seed.
    pub fn reset(&mut self) {
        self.pour.reset();
        self.synthesis.clear();
        self.sample = 0;
        self.resting_under = None;
        self.last_unit = None;
        self.active_until = 0;
        self.last_outflow = Outflow {
            volume_before_ml: self.pour.volume_ml(),
            ..Outflow::NONE
        };
        self.deferred = [None; MAX_ONSETS_PER_SAMPLE as usize];
        self.output.reset();
    }

    /// MODEL.md §8 refill: sounding units ring on, the generator goes on.
    pub fn refill(&mut self) {
        self.pour.refill();
        self.resting_under = None;
    }

    /// The residual volume V (ml).
    pub fn volume_ml(&self) -> f64 {
        self.pour.volume_ml()
    }

    /// What the last sample rendered poured: V at its start, its outflow, whether the mouth was
    /// submerged (MODEL.md §3, §4). A sample of a block in which the pour rested is the same as
    /// the step it rested after (no outflow, the same V).
    pub fn last_outflow(&self) -> Outflow {
        self.last_outflow
    }

    /// Units started and skipped since the reset.
    pub fn stats(&self) -> PourStats {
        self.pour.stats()
    }

    /// The unit that started last, if any since the reset.
    pub fn last_unit(&self) -> Option<&UnitOnset> {
        self.last_unit.as_ref()
    }

    /// Components currently sounding.
    pub fn sounding_components(&self) -> usize {
        self.synthesis.len()
    }

    /// Components given up because more were sounding than the engine synthesises at once.
    pub fn components_given_up(&self) -> u64 {
        self.synthesis.given_up()
    }

    /// The most components that sounded at once since the last call (at any sample, not only at
    /// the end of a block); the count then starts again from those sounding now.
    pub fn take_peak_sounding(&mut self) -> usize {
        self.synthesis.take_peak_len()
    }

    /// Samples since the last reset that the output stage's limiter changed: a signal over the
    /// ceiling (clamped to it) or not finite (NaN to 0, ±∞ to ±ceiling). The output cannot show
    /// what the limiter hid; this count can.
    pub fn limiter_events(&self) -> u64 {
        self.output.limiter.events
    }

    /// Samples since the last reset that were NaN or infinite before the limiter: the synthesis
    /// itself failed there, even though the output stayed finite.
    pub fn non_finite_before_limiter(&self) -> u64 {
        self.output.limiter.non_finite
    }

    /// The output ceiling at the last sample rendered (linear): the scene's or the parameter's,
    /// or on its ramp to a new one (MODEL.md §6).
    pub fn ceiling_now(&self) -> f64 {
        self.output.ceiling_now()
    }

    /// The output gain at the last sample rendered (linear), on its ramp as
    /// [`Engine::ceiling_now`].
    pub fn gain_now(&self) -> f64 {
        self.output.gain_now()
    }

    /// Samples rendered since the last reset.
    pub fn position(&self) -> u64 {
        self.sample
    }

    /// The sample after the last one during which liquid flowed or a component sounded: where a
    /// render that runs "until pouring stops and every unit has decayed" ends.
    pub fn active_until(&self) -> u64 {
        self.active_until
    }

    /// Under the controls of the last block, which were constant, no liquid flows.
    pub fn is_resting(&self) -> bool {
        self.resting_under.is_some()
    }

    /// Nothing sounds and, under constant controls, nothing would start: the rest is silence.
    pub fn is_settled(&self) -> bool {
        self.synthesis.is_empty() && self.resting_under.is_some()
    }

    /// Renders `out.len()` samples; `controls` give the inputs from the block's first sample.
    pub fn process(&mut self, controls: &Controls, out: &mut [f32]) {
        self.process_observed(controls, out, &mut |_, _| {});
    }

    /// [`Engine::process`], telling `on_unit` of every unit that starts, in order, with how it
    /// was voiced (the output gain at its first sample, whether it sounds): what the clip and
    /// table writers need to know of the glugs. Watching changes no sample. A unit that starts
    /// in a block's last sample is told of at the start of the next block, whose gain it is
    /// first heard at; after the last block, [`Engine::report_deferred_units`] tells of it.
    pub fn process_observed(
        &mut self,
        controls: &Controls,
        out: &mut [f32],
        on_unit: &mut impl FnMut(&UnitOnset, Voicing),
    ) {
        if out.is_empty() {
            return;
        }
        // The slots fill in order: an empty first one (the usual block) means none waits, and
        // the slots are not read.
        if self.deferred[0].is_some() {
            self.report_units_deferred_to(controls, on_unit);
        }
        self.block_end = self.sample + out.len() as u64;
        if self.synthesis.is_empty() && self.rests_under(controls) {
            // Settled under the same controls: the block is silence, so it costs a fill and not
            // a walk over its grid periods. An empty bank only needs the last period start.
            out.fill(0.0);
            self.output
                .pass_silence(&controls.gain_db, self.ceiling(), out.len());
            let end = self.sample + out.len() as u64;
            let last_period = end / GRID as u64 * GRID as u64;
            if last_period > self.sample {
                self.synthesis.advance(last_period);
            }
            self.sample = end;
            return;
        }
        let mut done = 0;
        // Constant lanes need no slicing for each period.
        let constant = controls.is_constant();
        while done < out.len() {
            let period_end = (self.sample / GRID as u64 + 1) * GRID as u64;
            let span = (out.len() - done).min((period_end - self.sample) as usize);
            let sliced;
            let span_controls = if constant {
                controls
            } else {
                sliced = controls.offset(done);
                &sliced
            };
            self.process_span(span_controls, &mut out[done..done + span], on_unit);
            done += span;
        }
    }

    /// Tells `on_unit` of the units that started in the last sample of the last block, at the
    /// gain of this block's first sample.
    fn report_units_deferred_to(
        &mut self,
        controls: &Controls,
        on_unit: &mut impl FnMut(&UnitOnset, Voicing),
    ) {
        for deferred in &mut self.deferred {
            if let Some((onset, voicing)) = deferred.take() {
                let output_gain = self.output.gain_ahead(&controls.gain_db, 0);
                on_unit(
                    &onset,
                    Voicing {
                        output_gain,
                        ..voicing
                    },
                );
            }
        }
    }

    /// Tells `on_unit` of the units that started in the last sample rendered, heard at the gain
    /// as it would hold on (there is no next block to say otherwise): called after the last
    /// block of a render.
    pub fn report_deferred_units(&mut self, on_unit: &mut impl FnMut(&UnitOnset, Voicing)) {
        for (onset, voicing) in self.deferred.iter_mut().filter_map(Option::take) {
            on_unit(&onset, voicing);
        }
    }

    /// Renders a span that lies within one grid period.
    fn process_span(
        &mut self,
        controls: &Controls,
        out: &mut [f32],
        on_unit: &mut impl FnMut(&UnitOnset, Voicing),
    ) {
        self.step_pour(controls, out.len(), on_unit);
        let ceiling = self.ceiling();
        if self.synthesis.is_empty() {
            out.fill(0.0);
            self.output
                .pass_silence(&controls.gain_db, ceiling, out.len());
            self.advance_position(out.len());
            return;
        }
        self.synthesis.synthesize(self.sample, out);
        self.active_until = self.sample + out.len() as u64;
        self.output.apply(&controls.gain_db, ceiling, out);
        self.advance_position(out.len());
    }

    fn step_pour(
        &mut self,
        controls: &Controls,
        len: usize,
        on_unit: &mut impl FnMut(&UnitOnset, Voicing),
    ) {
        if self.rests_under(controls) {
            return;
        }
        let constant = self.held_pour.inputs(controls, len);
        // Most spans of a pour lie inside a plain run, where no unit starts: those take no
        // callback (and build none).
        let plain = constant.and_then(|(_, sanitized)| {
            self.pour.advance_plain(self.sample, len as u64, &sanitized)
        });
        let advanced = match plain {
            Some(advanced) => advanced,
            None => self.advance_pour(controls, constant, len, on_unit),
        };
        if let Some(until) = advanced.flowed_until {
            self.active_until = until;
        }
        let last_step = (len > 0).then_some(advanced.last);
        if let Some(step) = last_step {
            self.last_outflow = step;
        }
        self.resting_under = match last_step {
            Some(step) if step.amount_ml == 0.0 && !step.refilled => constant.map(|(raw, _)| raw),
            _ => None,
        };
    }

    /// The pour over a span in which units may start, under `constant` inputs (as given, and
    /// brought into range) if they hold over the span: each unit is started in the synthesis and
    /// told of.
    fn advance_pour(
        &mut self,
        controls: &Controls,
        constant: Option<(ControlValues, ControlValues)>,
        len: usize,
        on_unit: &mut impl FnMut(&UnitOnset, Voicing),
    ) -> pour::Advanced {
        let Self {
            pour,
            synthesis,
            last_unit,
            output,
            sample: span_start,
            block_end,
            deferred,
            actuator,
            ..
        } = self;
        let (span_start, block_end) = (*span_start, *block_end);
        let mut start_unit = |onset: &UnitOnset| {
            // The unit's gains for the actuator, once, at its start (MODEL.md §18).
            let compensated;
            let onset = match actuator {
                Some(actuator) => {
                    compensated = UnitOnset {
                        actuator_gain: actuator.gains(onset.shape.frequency_hz),
                        ..*onset
                    };
                    &compensated
                }
                None => onset,
            };
            let audible = synthesis.start_unit(onset);
            *last_unit = Some(*onset);
            // Heard from the sample after the one it starts in (MODEL.md §6: t_i ≤ t_n).
            let first_heard = (onset.sample + 1 - span_start) as usize;
            // The gain as it would hold on past the block: final unless another block follows.
            let voicing = Voicing {
                output_gain: output.gain_ahead(&controls.gain_db, first_heard),
                audible,
            };
            if onset.sample + 1 < block_end {
                on_unit(onset, voicing);
            } else if let Some(free) = deferred.iter_mut().find(|slot| slot.is_none()) {
                *free = Some((*onset, voicing));
            }
        };
        match constant {
            // Under constant controls the pour takes the span at once (plain samples in closed
            // form, the same numbers as one step per sample).
            Some((_, sanitized)) => {
                pour.advance(span_start, len as u64, &sanitized, &mut start_unit)
            }
            // Otherwise the levels of the span are worked out at once, and the rest stepped
            // sample by sample (the same numbers as `Pour::step`).
            None => pour.advance_varying(span_start, controls, len, &mut start_unit),
        }
    }

    /// Whether the pour rests under `controls`, the same constant ones as its last step: then
    /// stepping it would change nothing.
    fn rests_under(&self, controls: &Controls) -> bool {
        // While the bottle pours (the usual span) the pour rests under nothing: that is checked
        // first.
        self.resting_under.is_some_and(|resting| {
            controls.pour_is_constant() && resting.same_pour_as(&controls.values_at(0))
        })
    }

    fn advance_position(&mut self, len: usize) {
        self.sample += len as u64;
        if self.sample.is_multiple_of(GRID as u64) {
            self.synthesis.advance(self.sample);
        }
    }
}
