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
pub use output::peak;
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
    /// The last block was taken whole under constant controls ([`Engine::process_constant`])
    /// and nothing but rendering has touched the engine since: the pour's inputs and the
    /// output's targets it took are in force, for [`Engine::process_unchanged`].
    constant_block_taken: bool,
    /// The largest |y| of the last block's output, where the output stage knew it from its own
    /// pass (see [`Engine::block_peak`]).
    block_peak: Option<f32>,
}

/// The inputs that drove the pour over the last span that held them constant: as given, and
/// brought into range. A span under the very same constants (the usual one: a host's next block,
/// nothing changed) takes them as they are, without reading and bringing each into range again.
/// They are read in place, not handed out: a copy of both sets each block cost more than the
/// comparison.
#[derive(Debug, Clone, Copy)]
struct HeldPour {
    /// Whether `raw` and `sanitized` hold a span's inputs yet.
    held: bool,
    raw: ControlValues,
    sanitized: ControlValues,
}

impl Default for HeldPour {
    fn default() -> Self {
        Self {
            held: false,
            raw: ControlValues::splat(0.0),
            sanitized: ControlValues::splat(0.0),
        }
    }
}

impl HeldPour {
    /// Whether the pour's inputs hold the very same values over the first `len` samples of
    /// `controls` (as constants, or samples that do not change: a ramp's end inside the block);
    /// if so, `raw` and `sanitized` are them, as given and brought into range.
    #[inline]
    fn take(&mut self, controls: &Controls, len: usize) -> bool {
        let same = |control: Control| match controls[control] {
            // Bit for bit: NaN is held as NaN, and −0 is not 0.
            Lane::Constant(value) => value.to_bits() == self.raw[control].to_bits(),
            Lane::Samples(_) => false,
        };
        (self.held && Control::pour().all(same)) || self.take_new(controls, len)
    }

    /// [`HeldPour::take`] of inputs that are not those held: out of line, as the usual span
    /// finds the same ones.
    #[inline(never)]
    fn take_new(&mut self, controls: &Controls, len: usize) -> bool {
        if !controls.pour_is_constant_over(len) {
            return false;
        }
        self.raw = controls.values_at(0);
        self.sanitized = self.raw.sanitized();
        self.held = true;
        true
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
            constant_block_taken: false,
            block_peak: None,
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
        self.constant_block_taken = false;
    }

    /// Compensates the units that start from now on for `actuator` (`None`: plays the model's
    /// drive as it is), and holds the output within its largest drive (MODEL.md §18).
    /// Allocation-free: a host may call it between blocks.
    pub fn set_actuator(&mut self, actuator: Option<ActuatorResponse>) {
        self.actuator = actuator;
        self.constant_block_taken = false;
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
        self.constant_block_taken = false;
    }

    /// MODEL.md §8 refill: sounding units ring on, the generator goes on.
    pub fn refill(&mut self) {
        self.pour.refill();
        self.resting_under = None;
        self.constant_block_taken = false;
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

    /// The largest |y| of the last block's output, where the engine knows it without reading
    /// the block again: a block under constant controls at a settled gain and ceiling, whose
    /// output stage is one pass over the whole block, or a settled block of silence. `None`
    /// where it does not (then the caller reads the samples).
    pub fn block_peak(&self) -> Option<f32> {
        self.block_peak
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
        self.constant_block_taken = false;
        self.block_peak = None;
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
            self.block_peak = Some(0.0);
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
        if controls.is_constant() {
            self.process_constant(controls, out, on_unit);
            return;
        }
        let mut done = 0;
        while done < out.len() {
            let span = self.span_at(out.len() - done);
            let sliced = controls.offset(done);
            self.process_span(&sliced, &mut out[done..done + span], on_unit);
            done += span;
        }
    }

    /// The samples from the position on that lie in its grid period, at most `left`.
    #[inline]
    fn span_at(&self, left: usize) -> usize {
        let period_end = (self.sample / GRID as u64 + 1) * GRID as u64;
        left.min((period_end - self.sample) as usize)
    }

    /// A block under constant controls (every lane a constant: a render's held scene, the C
    /// library's calls without a ramp). What is the same for every span is done once for the
    /// block: the pour's inputs and the output's targets taken, the ceiling worked out; a plain
    /// run of the pour that covers several spans is taken at once, then only the synthesis goes
    /// span by span; and at a settled gain and ceiling the output stage takes the whole block
    /// in one pass. The same samples, units and state as span by span: V and g move in closed
    /// form, exact for any cut of a run; the output stage works sample by sample; and no unit
    /// starts inside a plain run, so the synthesis of a span never waits on the pour of a later
    /// one.
    fn process_constant(
        &mut self,
        controls: &Controls,
        out: &mut [f32],
        on_unit: &mut impl FnMut(&UnitOnset, Voicing),
    ) {
        let constant = self.held_pour.take(controls, out.len());
        let ceiling = self.ceiling();
        let settled = self
            .output
            .begin_constant_block(controls.gain_db.at(0), ceiling);
        // The pour has been stepped up to this sample, which may be ahead of the synthesis.
        let mut poured_to = self.sample;
        let mut done = 0;
        while done < out.len() {
            let span = self.span_at(out.len() - done);
            if poured_to == self.sample {
                poured_to +=
                    self.pour_ahead(controls, constant, out.len() - done, span, on_unit) as u64;
            }
            let out = &mut out[done..done + span];
            if self.synthesis.is_empty() {
                out.fill(0.0);
                if !settled {
                    self.output.pass_silence(&controls.gain_db, ceiling, span);
                }
            } else {
                self.synthesis.synthesize(self.sample, out);
                // The pour may have flowed further ahead already.
                self.active_until = self.active_until.max(self.sample + span as u64);
                if !settled {
                    self.output.apply(&controls.gain_db, ceiling, out);
                }
            }
            self.advance_position(span);
            done += span;
        }
        if settled {
            self.block_peak = Some(self.output.apply_settled(out));
        }
        self.constant_block_taken = true;
    }

    /// [`Engine::process_observed`] of a block under the very controls of the last block, every
    /// lane a constant, the caller knowing that none changed (the C library rebuilds its
    /// controls only when a control call comes). A block within one grid period, inside the
    /// pour's plain run, at a settled gain and ceiling (nearly every small block of the C
    /// library) skips what [`Engine::process_constant`] would find the same: the controls'
    /// comparison, the output's targets taken again, the walk over spans. The same samples,
    /// units and state: it takes the pour's closed form and the synthesis as that would, and the
    /// output stage's one pass.
    pub fn process_unchanged(
        &mut self,
        controls: &Controls,
        out: &mut [f32],
        on_unit: &mut impl FnMut(&UnitOnset, Voicing),
    ) {
        self.block_peak = None;
        if !(self.constant_block_taken && self.take_steady_span(out)) {
            self.process_observed(controls, out, on_unit);
        }
    }

    /// [`Engine::process_unchanged`]'s block, if it is one that needs nothing but the plain
    /// run, the synthesis and the settled output stage; false, having changed nothing, if not.
    #[inline]
    fn take_steady_span(&mut self, out: &mut [f32]) -> bool {
        let len = out.len();
        let offset = (self.sample % GRID as u64) as usize;
        if len == 0
            || offset + len > GRID
            || self.deferred[0].is_some()
            || self.resting_under.is_some()
            || !self.output.is_settled()
        {
            return false;
        }
        // The controls, the constants and the bottle are those of the constant block before
        // (`constant_block_taken`: anything else that touches the engine clears it).
        let Some(advanced) = self.pour.advance_plain_unchanged(self.sample, len as u64) else {
            return false;
        };
        self.poured(advanced, true);
        if self.synthesis.is_empty() {
            out.fill(0.0);
        } else {
            // A block shorter than a period takes its part of the period's sum through the
            // output stage, worked out once for the period.
            let from_period = len < GRID
                && match self.synthesis.period_sum(self.sample) {
                    Some((sum, number)) => self.output.apply_settled_from(sum, number, offset, out),
                    None => false,
                };
            if !from_period {
                self.synthesis.synthesize(self.sample, out);
                self.output.apply_settled(out);
            }
            self.active_until = self.active_until.max(self.sample + len as u64);
        }
        self.advance_position(len);
        true
    }

    /// Steps the pour from the position, under the block's `constant` inputs, over at
    /// least the `span` that starts there; returns how many samples it was stepped, at most
    /// `block_left`. A plain run that covers the span is taken as far as it goes within the
    /// block, cut at the end of a grid period (the pour is then ahead of the synthesis only by
    /// whole spans); otherwise the span alone, as [`Engine::step_pour`] takes it.
    fn pour_ahead(
        &mut self,
        controls: &Controls,
        constant: bool,
        block_left: usize,
        span: usize,
        on_unit: &mut impl FnMut(&UnitOnset, Voicing),
    ) -> usize {
        if self.rests_under(controls) {
            // Nothing changes the pour's rest within a block of constant controls.
            return block_left;
        }
        let reach = self.pour.plain_samples_left().min(block_left as u64) as usize;
        if constant && reach >= span {
            let ahead = if reach == block_left {
                reach
            } else {
                reach - ((self.sample + reach as u64) % GRID as u64) as usize
            };
            let sanitized = &self.held_pour.sanitized;
            if let Some(advanced) = self
                .pour
                .advance_plain(self.sample, ahead as u64, sanitized)
            {
                self.poured(advanced, true);
                return ahead;
            }
        }
        self.step_pour_under(controls, constant, span, on_unit);
        span
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
        let constant = self.held_pour.take(controls, len);
        self.step_pour_under(controls, constant, len, on_unit);
    }

    /// [`Engine::step_pour`] of a span, under the held inputs if `constant` (they hold over
    /// it), when the pour does not rest.
    fn step_pour_under(
        &mut self,
        controls: &Controls,
        constant: bool,
        len: usize,
        on_unit: &mut impl FnMut(&UnitOnset, Voicing),
    ) {
        if len == 0 {
            // As a step over no sample leaves it: no last step to rest after.
            self.resting_under = None;
            return;
        }
        // Most spans of a pour lie inside a plain run, where no unit starts: those take no
        // callback (and build none).
        let plain = if constant {
            let sanitized = &self.held_pour.sanitized;
            self.pour.advance_plain(self.sample, len as u64, sanitized)
        } else {
            None
        };
        let advanced = match plain {
            Some(advanced) => advanced,
            None => self.advance_pour(controls, constant, len, on_unit),
        };
        self.poured(advanced, constant);
    }

    /// What a step of the pour over at least one sample leaves for the engine: until when
    /// liquid flowed, the last sample's outflow, and whether the pour now rests under the held
    /// inputs (if they were `constant` over the step).
    #[inline]
    fn poured(&mut self, advanced: pour::Advanced, constant: bool) {
        if let Some(until) = advanced.flowed_until {
            self.active_until = until;
        }
        let step = advanced.last;
        self.last_outflow = step;
        // Branches, not one select: the usual step flows, and then only the tag is written
        // (a select built the whole Option, the held inputs copied, at every step).
        if constant && step.amount_ml == 0.0 && !step.refilled {
            self.resting_under = Some(self.held_pour.raw);
        } else if self.resting_under.is_some() {
            self.resting_under = None;
        }
    }

    /// The pour over a span in which units may start, under the held inputs if `constant`
    /// (they hold over the span): each unit is started in the synthesis and told of.
    fn advance_pour(
        &mut self,
        controls: &Controls,
        constant: bool,
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
            held_pour,
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
        if constant {
            // Under constant controls the pour takes the span at once (plain samples in closed
            // form, the same numbers as one step per sample).
            pour.advance(
                span_start,
                len as u64,
                &held_pour.sanitized,
                &mut start_unit,
            )
        } else {
            // Otherwise the levels of the span are worked out at once, and the rest stepped
            // sample by sample (the same numbers as `Pour::step`).
            pour.advance_varying(span_start, controls, len, &mut start_unit)
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
