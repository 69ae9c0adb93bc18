//! The handle behind the C interface, in safe Rust: the engine, the controls as a scene's lanes
//! would give them, and the queue that control calls from any thread wait in.

use std::cell::UnsafeCell;
use std::sync::atomic::{AtomicBool, Ordering};

use crossbeam_queue::ArrayQueue;
use sake_glug_engine::config::SAMPLE_RATE_HZ;
use sake_glug_engine::{
    sample_time_s, ActuatorResponse, Control, ControlValues, Controls, Engine, Lane, LinearSegment,
    ModelConfig, PerControl, Preset, UnitOnset, Voicing,
};
use sake_glug_model_file::{ModelFile, MAX_MODEL_BYTES};

use crate::types::{
    SakeGlugState, SakeGlugStatus, SakeGlugUnit, SAKE_GLUG_MAX_QUEUED_CONTROLS, SAKE_GLUG_MAX_UNITS,
};

/// Samples rendered per engine call: the most a ramp's lane fills at once. The engine gives the
/// same samples however time is cut, so this changes no sample.
const SPAN: usize = 256;

/// A control call, queued until the next process call takes it at its first sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Command {
    /// The control takes the value from the first sample on (a step).
    Set(Control, f64),
    /// The control goes from its value at the first sample to the target over that many samples,
    /// then holds it.
    Ramp(Control, f64, u64),
    /// MODEL.md §8 refill.
    Refill,
    /// MODEL.md §8 reset; every control holds the value it had reached.
    Reset,
    /// The actuator profile waiting in its slot (MODEL.md §18) takes effect.
    Actuator,
}

/// A control on its way to a target: the two-point lane of a scene from `(p0/fs, from)` to
/// `(p1/fs, target)` (MODEL.md §10), read at each sample's time exactly as the renderer reads it.
#[derive(Debug, Clone, Copy)]
struct Ramp {
    line: LinearSegment,
    /// p1: from this sample on the control holds the target.
    end_sample: u64,
}

impl Ramp {
    /// The lane's value at `sample`, which is at or after the ramp's start: on the line before the
    /// end point's time, the end point's value from then on.
    #[inline]
    fn value_at(&self, sample: u64, sample_rate: f64) -> f64 {
        let time_s = sample_time_s(sample, sample_rate);
        if time_s >= self.line.end.0 {
            self.line.end.1
        } else {
            self.line.value_at(time_s)
        }
    }
}

/// `sample_rate` if the engine takes it: in range and a whole number.
fn checked_sample_rate(sample_rate: f64) -> Result<f64, CreateError> {
    let sample_rate = SAMPLE_RATE_HZ
        .check("sample_rate", sample_rate)
        .map_err(|error| error.to_string())?;
    if sample_rate.fract() != 0.0 {
        return Err(format!(
            "`sample_rate` = {sample_rate} is not a whole number: a sample rate counts whole \
             samples per second"
        ));
    }
    Ok(sample_rate)
}

/// What only the audio thread touches.
struct Audio {
    engine: Engine,
    /// Each control's value, or the target of its ramp.
    held: ControlValues,
    /// `held` as the engine takes it while no ramp is under way: rebuilt when a control call
    /// changes it, not at every process call.
    held_lanes: Controls<'static>,
    ramps: PerControl<Option<Ramp>>,
    /// Whether any of `ramps` is under way: kept as the ramps change, so that the usual call
    /// checks one flag rather than each control's ramp.
    ramping: bool,
    /// The engine's last block was rendered under `held_lanes` as they are: the next may tell
    /// it that nothing changed ([`Engine::process_unchanged`]).
    held_unchanged: bool,
    /// θ of `held`, brought into range: the tilt of a call without a ramp, worked out when a
    /// control call changes it, not at every call.
    held_tilt_deg: f64,
    /// Storage for the ramps' lanes of one span.
    lanes: PerControl<Box<[f64]>>,
    /// One span of mono samples, for the interleaved call.
    mono: Box<[f32]>,
    /// The units heard first in the last process call, the first `kept` of them.
    units: Box<[SakeGlugUnit]>,
    kept: usize,
    lost: u32,
    /// θ of the last sample rendered, brought into range.
    last_tilt_deg: f64,
}

/// One live glug: the C interface's opaque handle.
pub struct SakeGlug {
    commands: ArrayQueue<Command>,
    /// The latest actuator profile set and not yet taken (`None`: no profile): one slot, so
    /// that the queue's calls stay small; a later call replaces a profile not yet taken.
    actuator: ArrayQueue<Option<ActuatorResponse>>,
    failed: AtomicBool,
    #[cfg(feature = "fault-injection")]
    fault: AtomicBool,
    audio: UnsafeCell<Audio>,
}

// The control calls share `commands` (a lock-free queue) and `failed` (an atomic) from any thread;
// `audio` is used by one thread at a time, the audio thread, as the header requires of callers.
unsafe impl Sync for SakeGlug {}

/// Why a handle could not be made: a message for `sake_glug_last_error`.
pub type CreateError = String;

impl SakeGlug {
    /// A handle at `sample_rate` (Hz, a whole number in the engine's range) playing the model of
    /// `model_text` (a model file's text, MODEL.md §12.1) or the paper's bottle, seeded with
    /// `seed`. Every control starts at the model's value or the engine's default.
    pub fn new(sample_rate: f64, model_text: Option<&str>, seed: u64) -> Result<Self, CreateError> {
        let sample_rate = checked_sample_rate(sample_rate)?;
        let model = match model_text {
            None => None,
            Some(text) if text.len() as u64 > MAX_MODEL_BYTES => {
                return Err(format!(
                    "model text: {} bytes, over the limit of {MAX_MODEL_BYTES} bytes",
                    text.len()
                ))
            }
            Some(text) => Some(
                ModelFile::parse("model", text).map_err(|error| format!("model text: {error}"))?,
            ),
        };
        let config = model
            .as_ref()
            .map(|model| *model.config())
            .unwrap_or_default();
        let held = ControlValues::from_fn(|control| {
            model
                .as_ref()
                .and_then(|model| model.controls()[control])
                .unwrap_or(control.range().default)
        });
        Ok(Self::with(sample_rate, config, held, seed))
    }

    /// A handle playing the shipped preset `id` (presets/<id>.toml, written from the engine's
    /// table of presets): its bottle, glug and liquid, every other control at its default.
    pub fn preset(sample_rate: f64, id: &str, seed: u64) -> Result<Self, CreateError> {
        let sample_rate = checked_sample_rate(sample_rate)?;
        let preset = Preset::find(id).ok_or_else(|| {
            format!(
                "no preset `{}`: the presets are {} (`sake-glug presets` describes them)",
                id.escape_debug(),
                Preset::ids()
            )
        })?;
        Ok(Self::with(
            sample_rate,
            preset.config(ModelConfig::default()),
            preset.controls(ControlValues::default()),
            seed,
        ))
    }

    /// A handle at a checked sample rate under `config` (its seed replaced by `seed`), every
    /// control held at `held`.
    fn with(sample_rate: f64, mut config: ModelConfig, held: ControlValues, seed: u64) -> Self {
        config.seed = seed;
        Self {
            commands: ArrayQueue::new(SAKE_GLUG_MAX_QUEUED_CONTROLS),
            actuator: ArrayQueue::new(1),
            failed: AtomicBool::new(false),
            #[cfg(feature = "fault-injection")]
            fault: AtomicBool::new(false),
            audio: UnsafeCell::new(Audio {
                engine: Engine::new(sample_rate, config),
                held,
                held_lanes: Controls::constant(held),
                ramps: PerControl::splat(None),
                ramping: false,
                held_unchanged: false,
                held_tilt_deg: Control::Tilt.range().sanitize(held.tilt_deg),
                lanes: PerControl::from_fn(|_| vec![0.0; SPAN].into_boxed_slice()),
                mono: vec![0.0; SPAN].into_boxed_slice(),
                units: vec![SakeGlugUnit::default(); SAKE_GLUG_MAX_UNITS].into_boxed_slice(),
                kept: 0,
                lost: 0,
                last_tilt_deg: Control::Tilt.range().sanitize(held.tilt_deg),
            }),
        }
    }

    /// Queues a control call for the next process call; any thread. Checks nothing but room.
    pub fn queue(&self, command: Command) -> Result<(), SakeGlugStatus> {
        if self.has_failed() {
            return Err(SakeGlugStatus::Failed);
        }
        self.commands
            .push(command)
            .map_err(|_| SakeGlugStatus::QueueFull)
    }

    /// Compensates the units that start from the next process call on for `actuator` (`None`:
    /// none), as `sake-glug render --actuator` does; any thread.
    pub fn set_actuator(&self, actuator: Option<ActuatorResponse>) -> Result<(), SakeGlugStatus> {
        if self.has_failed() {
            return Err(SakeGlugStatus::Failed);
        }
        self.actuator.force_push(actuator);
        self.queue(Command::Actuator)
    }

    /// Whether an earlier call failed (the handle renders silence from then on).
    pub fn has_failed(&self) -> bool {
        self.failed.load(Ordering::Relaxed)
    }

    /// Marks the handle failed after a panic.
    pub fn fail(&self) {
        self.failed.store(true, Ordering::Relaxed);
    }

    /// Makes the next process call panic (the test of the boundary's catch).
    #[cfg(feature = "fault-injection")]
    pub fn inject_fault(&self) {
        self.fault.store(true, Ordering::Relaxed);
    }

    /// The audio thread's side.
    ///
    /// # Safety
    /// No other reference to it may live: only the audio thread calls this, one call at a time.
    #[allow(clippy::mut_from_ref)]
    unsafe fn audio(&self) -> &mut Audio {
        unsafe { &mut *self.audio.get() }
    }

    /// Renders `out.len()` mono samples after taking the queued control calls.
    ///
    /// # Safety
    /// The audio thread's call (see [`SakeGlug::audio`]).
    pub unsafe fn process(&self, out: &mut [f32]) {
        self.check_fault();
        let audio = unsafe { self.audio() };
        audio.start_call(&self.commands, &self.actuator);
        let first = audio.engine.position();
        // A call of at most a span (a game's or a host's small block) is one span, without the
        // loop's set-up.
        if out.len() <= SPAN {
            if !out.is_empty() {
                audio.render_span(out, first);
            }
            return;
        }
        for span in out.chunks_mut(SPAN) {
            audio.render_span(span, first);
        }
    }

    /// Renders `out.len() / channels` frames, the mono signal in each of `channels` interleaved
    /// channels.
    ///
    /// # Safety
    /// The audio thread's call (see [`SakeGlug::audio`]).
    pub unsafe fn process_interleaved(&self, out: &mut [f32], channels: usize) {
        self.check_fault();
        let audio = unsafe { self.audio() };
        audio.start_call(&self.commands, &self.actuator);
        let first = audio.engine.position();
        for frames in out.chunks_mut(SPAN * channels) {
            let len = frames.len() / channels;
            let mut mono = std::mem::take(&mut audio.mono);
            audio.render_span(&mut mono[..len], first);
            for (frame, &sample) in frames.chunks_exact_mut(channels).zip(mono.iter()) {
                frame.fill(sample);
            }
            audio.mono = mono;
        }
    }

    /// The bottle after the last process call.
    ///
    /// # Safety
    /// The audio thread's call (see [`SakeGlug::audio`]).
    pub unsafe fn state(&self) -> SakeGlugState {
        unsafe { self.audio() }.state()
    }

    /// The units heard first in the last process call.
    ///
    /// # Safety
    /// The audio thread's call (see [`SakeGlug::audio`]).
    pub unsafe fn units(&self) -> &[SakeGlugUnit] {
        let audio = unsafe { self.audio() };
        &audio.units[..audio.kept]
    }

    fn check_fault(&self) {
        #[cfg(feature = "fault-injection")]
        if self.fault.swap(false, Ordering::Relaxed) {
            panic!("a fault injected by the test");
        }
    }
}

impl Audio {
    /// Takes every queued control call, in order, at the first sample of the call.
    fn start_call(
        &mut self,
        commands: &ArrayQueue<Command>,
        actuator: &ArrayQueue<Option<ActuatorResponse>>,
    ) {
        // An empty queue (the usual call) is two loads, where a pop that finds nothing is more.
        if !commands.is_empty() {
            self.take_commands(commands, actuator);
        }
        self.kept = 0;
        self.lost = 0;
    }

    /// The queued control calls, in order: out of line, so that the usual call, which finds the
    /// queue empty, carries no more than the check.
    #[cold]
    fn take_commands(
        &mut self,
        commands: &ArrayQueue<Command>,
        actuator: &ArrayQueue<Option<ActuatorResponse>>,
    ) {
        while let Some(command) = commands.pop() {
            if command == Command::Actuator {
                // Every profile set by now is in the slot: a later marker finds it empty.
                if let Some(response) = actuator.pop() {
                    self.engine.set_actuator(response);
                }
                continue;
            }
            self.apply(command);
        }
        self.held_lanes = Controls::constant(self.held);
        self.held_unchanged = false;
        self.held_tilt_deg = Control::Tilt.range().sanitize(self.held.tilt_deg);
        self.ramping = self.ramps.iter().any(|(_, ramp)| ramp.is_some());
    }

    fn apply(&mut self, command: Command) {
        let position = self.engine.position();
        let sample_rate = self.engine.sample_rate();
        match command {
            Command::Set(control, value) => {
                self.ramps[control] = None;
                self.held[control] = value;
            }
            Command::Ramp(control, target, samples) => {
                let from = self.value_at(control, position);
                let end_sample = position.saturating_add(samples);
                // A ramp to the value it starts from is that value held, as the renderer reads a
                // flat segment.
                self.ramps[control] = (samples > 0 && from != target).then(|| Ramp {
                    line: LinearSegment {
                        start: (sample_time_s(position, sample_rate), from),
                        end: (sample_time_s(end_sample, sample_rate), target),
                    },
                    end_sample,
                });
                self.held[control] = target;
            }
            Command::Refill => self.engine.refill(),
            Command::Actuator => {}
            Command::Reset => {
                for &control in Control::ALL {
                    self.held[control] = self.value_at(control, position);
                    self.ramps[control] = None;
                }
                self.engine.reset();
            }
        }
    }

    /// The control's value at `sample` (at or after the engine's position).
    fn value_at(&self, control: Control, sample: u64) -> f64 {
        match self.ramps[control] {
            Some(ramp) if sample < ramp.end_sample => {
                ramp.value_at(sample, self.engine.sample_rate())
            }
            _ => self.held[control],
        }
    }

    /// Renders one span of at most [`SPAN`] samples, keeping the units first heard in it.
    fn render_span(&mut self, out: &mut [f32], call_start: u64) {
        let position = self.engine.position();
        let sample_rate = self.engine.sample_rate();
        let Audio {
            engine,
            held,
            held_lanes,
            ramps,
            ramping,
            held_unchanged,
            held_tilt_deg,
            lanes,
            units,
            kept,
            lost,
            last_tilt_deg,
            ..
        } = self;
        // No ramp under way (the usual call): every control is its held value.
        let ramped = *ramping;
        let ramp_lanes: Controls;
        let controls = if !ramped {
            &*held_lanes
        } else {
            ramp_lanes = lanes.each_mut().into_map(|control, lane| {
                match &mut ramps[control] {
                    Some(ramp) if position < ramp.end_sample => {
                        let lane = &mut lane[..out.len()];
                        for (index, value) in lane.iter_mut().enumerate() {
                            *value = ramp.value_at(position + index as u64, sample_rate);
                        }
                        Lane::Samples(lane)
                    }
                    // A ramp that has ended holds its target, as a lane past its last point.
                    ramp => {
                        *ramp = None;
                        Lane::Constant(held[control])
                    }
                }
            });
            // The ramps that ended here hold their targets from the next call on.
            *ramping = ramps.iter().any(|(_, ramp)| ramp.is_some());
            &ramp_lanes
        };
        let mut keep = |onset: &UnitOnset, voicing| match units.get_mut(*kept) {
            Some(unit) => {
                *unit = unit_of(onset, voicing, call_start);
                *kept += 1;
            }
            None => *lost = lost.saturating_add(1),
        };
        if !ramped && *held_unchanged {
            engine.process_unchanged(controls, out, &mut keep);
        } else {
            engine.process_observed(controls, out, &mut keep);
        }
        // Only a block under `held_lanes` leaves the engine's last controls the held ones.
        *held_unchanged = !ramped;
        if out.is_empty() {
            return;
        }
        *last_tilt_deg = if ramped {
            Control::Tilt
                .range()
                .sanitize(controls.tilt_deg.at(out.len() - 1))
        } else {
            *held_tilt_deg
        };
    }

    fn state(&self) -> SakeGlugState {
        let engine = &self.engine;
        let position = engine.position();
        let outflow = engine.last_outflow();
        let ramping = Control::ALL
            .iter()
            .any(|&control| self.ramps[control].is_some_and(|ramp| position < ramp.end_sample));
        SakeGlugState {
            position,
            active_until: engine.active_until(),
            volume_ml: engine.volume_ml(),
            outflow_ml_per_s: outflow.amount_ml * engine.sample_rate(),
            tilt_deg: self.last_tilt_deg,
            output_gain: engine.gain_now(),
            submerged: outflow.submerged.into(),
            settled: (engine.is_settled() && !ramping).into(),
            units: self.kept as u32,
            units_lost: self.lost,
        }
    }
}

/// A unit as the C interface reports it, first heard at its sample n + 1 of a call that started
/// at sample `call_start`.
fn unit_of(onset: &UnitOnset, voicing: Voicing, call_start: u64) -> SakeGlugUnit {
    SakeGlugUnit {
        frame: (onset.sample + 1 - call_start) as u32,
        audible: voicing.audible.into(),
        sample: onset.sample,
        fraction: onset.fraction,
        tilt_deg: onset.tilt_deg,
        volume_ml: onset.volume_ml,
        pocket_ml: onset.pocket_ml,
        amplitude: voicing.output_gain * onset.amplitude,
        viscosity_c: onset.viscosity,
        f1_hz: onset.shape.frequency_hz[0],
        f2_hz: onset.shape.frequency_hz[1],
        b1_per_s: onset.shape.decay_per_s[0],
        b2_per_s: onset.shape.decay_per_s[1],
    }
}
