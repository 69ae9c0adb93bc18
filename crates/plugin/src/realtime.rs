//! The plugin's real-time side without plugin-framework types: parameter values, MIDI and
//! transport in; engine output and the editor's feed out. Allocation-free after `new()`.

use crate::feed::{Feed, ScopeWriter, Visible};
use crate::layering::{layered_config, layered_controls};
use crate::loaded_model::ModelLayer;
use crate::params::GlugParams;
use crate::transport::TransportWatch;
use sake_glug_device::live::{LiveControls, LiveReader};
use sake_glug_device::midi::{CcDecoder, DeviceAction, MidiInput, MidiMap, Overrides};
use sake_glug_engine::{
    ActuatorResponse, Control, ControlValues, Controls, Engine, ModelConfig, PerControl,
};

/// The longest span rendered at once, so that the editor sees (nearly) every unit start; the
/// engine's output does not depend on how time is cut.
const FEED_SPAN: usize = 128;

/// How long units that ring across a transport reset take to fade out (s): short enough that
/// the new bounce is clean after it, long enough that the fade makes no click.
pub const FADE_S: f64 = 0.005;

/// The parameters' values for one `process()` call.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Every control as the parameters set it (before MIDI and OSC).
    pub values: ControlValues,
    /// The model's constants.
    pub config: ModelConfig,
    /// The tilt device's MIDI mapping.
    pub midi: MidiMap,
    /// The actuator the units are compensated for (MODEL.md §18), if one is chosen.
    pub actuator: Option<ActuatorResponse>,
}

impl Settings {
    /// The parameters' current values.
    pub fn from_params(params: &GlugParams) -> Self {
        Self::with_model(params, None)
    }

    /// The parameters' current values over a loaded model's (MODEL.md §12.1): a parameter that
    /// shows the model's value plays it in full; the model gives what has no parameter.
    pub fn with_model(params: &GlugParams, model: Option<&ModelLayer>) -> Self {
        let (values, config) = match model {
            None => (params.control_values(), params.model_config()),
            Some(layer) => (
                layered_controls(params, layer),
                layered_config(params, layer),
            ),
        };
        Self {
            values,
            config,
            midi: params.midi_map(),
            actuator: None,
        }
    }
}

/// The engine as the plugin runs it, with MIDI overrides, transport resets and the editor's
/// feed around it.
pub struct RealtimeEngine {
    engine: Engine,
    /// The units that were sounding when the transport reset the bottle, fading out over
    /// [`FADE_S`] instead of being cut (a click); the new pour starts in `engine` meanwhile.
    tail: Engine,
    /// Samples of the fade still to go; 0 while the tail is silent.
    fade_left: usize,
    fade_len: usize,
    /// The tail's samples of one span, allocated once.
    tail_span: Box<[f32]>,
    config: ModelConfig,
    decoder: CcDecoder,
    overrides: Overrides,
    /// What has been taken from the live (OSC) input.
    live: LiveReader,
    transport: TransportWatch,
    scope: ScopeWriter,
    units_seen: u64,
    /// Samples rendered since construction (the feed's clock; not reset with the bottle).
    rendered: u64,
    /// What the editor was last shown, so that it is redrawn only when that changes.
    shown: Visible,
}

impl RealtimeEngine {
    /// Allocates: call from `activate()`.
    pub fn new(sample_rate: f64, config: ModelConfig) -> Self {
        let engine = Engine::new(sample_rate, config);
        let fade_len = ((engine.sample_rate() * FADE_S).round() as usize).max(1);
        Self {
            tail: Engine::new(sample_rate, config),
            fade_left: 0,
            fade_len,
            tail_span: vec![0.0; FEED_SPAN].into_boxed_slice(),
            engine,
            config,
            decoder: CcDecoder::default(),
            overrides: Overrides::default(),
            live: LiveReader::default(),
            transport: TransportWatch::default(),
            scope: ScopeWriter::new(sample_rate),
            units_seen: 0,
            rendered: 0,
            shown: Visible::default(),
        }
    }

    /// Sample rate the engine runs at (Hz).
    pub fn sample_rate(&self) -> f64 {
        self.engine.sample_rate()
    }

    /// What the editor was shown after the last block.
    pub fn visible(&self) -> Visible {
        self.shown
    }

    /// The engine inside.
    pub fn engine(&self) -> &Engine {
        &self.engine
    }

    /// The host's reset: everything silent at once (nothing plays after it), the device's
    /// values forgotten, and the transport watched afresh.
    pub fn reset(&mut self, config: ModelConfig) {
        self.tail.reset();
        self.fade_left = 0;
        self.reset_bottle(config);
        self.decoder.reset();
        self.overrides.clear();
        self.transport.reset();
    }

    /// Call once per `process()` before rendering; resets when the transport starts or jumps.
    /// Units that were sounding fade out over [`FADE_S`] while the new pour starts, and the
    /// device keeps its last values: a bottle held tilted stays tilted.
    pub fn observe_transport(&mut self, playing: bool, position: Option<i64>, config: ModelConfig) {
        if self.transport.observe(playing, position) {
            if self.engine.sounding_components() > 0 {
                // The old pour becomes the tail (a swap: nothing is allocated).
                std::mem::swap(&mut self.engine, &mut self.tail);
                self.fade_left = self.fade_len;
            }
            self.reset_bottle(config);
        }
    }

    /// MODEL.md §8 reset of the bottle that plays.
    fn reset_bottle(&mut self, config: ModelConfig) {
        // After a swap `engine` may hold older constants than `self.config`: set them anyway.
        self.config = config;
        self.engine.set_config(config);
        self.engine.reset();
        self.units_seen = 0;
    }

    /// Call once per `process()` after rendering `samples` samples.
    pub fn finish_block(&mut self, samples: usize) {
        self.transport.advance(samples);
    }

    /// Acts on one MIDI message: a note-on refills, a mapped CC overrides its control.
    pub fn handle(&mut self, input: MidiInput, map: &MidiMap) {
        match self.decoder.decode(map, input) {
            Some(DeviceAction::Refill) => self.engine.refill(),
            Some(DeviceAction::Set(target, value)) => self.overrides.set(target, value),
            None => {}
        }
    }

    /// Takes what a live input (OSC) set since the last call, as MIDI is taken: a new value
    /// overrides its control, a refill refills. Atomic loads only: real-time safe.
    pub fn apply_live(&mut self, live: &LiveControls) {
        let changes = self.live.poll(live);
        for (target, value) in changes.set_values() {
            self.overrides.set(target, value);
        }
        if changes.refill {
            self.engine.refill();
        }
    }

    fn apply_config(&mut self, config: ModelConfig) {
        if config != self.config {
            self.config = config;
            self.engine.set_config(config);
        }
    }

    /// Adds the tail, fading linearly to silence, and keeps the sum within the ceiling.
    fn add_fading_tail(&mut self, controls: &Controls, span: &mut [f32]) {
        let tail = &mut self.tail_span[..span.len()];
        self.tail.process(controls, tail);
        // The ceiling of the pour that plays, where its ramp has got to (MODEL.md §6).
        let ceiling = self.engine.ceiling_now() as f32;
        for (y, ringing) in span.iter_mut().zip(tail.iter()) {
            let gain = self.fade_left as f32 / self.fade_len as f32;
            *y = (*y + ringing * gain).clamp(-ceiling, ceiling);
            self.fade_left = self.fade_left.saturating_sub(1);
        }
        if self.fade_left == 0 {
            self.tail.reset();
        }
    }

    /// Renders `out.len()` samples under `settings` (constant over the span).
    pub fn process(&mut self, settings: &Settings, out: &mut [f32], feed: &Feed) {
        self.apply_config(settings.config);
        // Also after a transport reset swapped in the tail, which may hold an older one.
        if self.engine.actuator() != settings.actuator.as_ref() {
            self.engine.set_actuator(settings.actuator);
        }
        let values = self.overrides.apply(settings.values);
        let tilt_deg = values.tilt_deg;
        let controls = Controls::constant(values);
        let sample_rate = self.engine.sample_rate();
        // The tail stands upright: it only rings out, nothing new starts in it.
        let tail_controls = Controls::constant(ControlValues {
            tilt_deg: 0.0,
            ..values
        });
        for span in out.chunks_mut(FEED_SPAN) {
            self.engine.process(&controls, span);
            if self.fade_left > 0 {
                self.add_fading_tail(&tail_controls, span);
            }
            let started = self.engine.stats().units_started;
            if started != self.units_seen {
                self.units_seen = started;
                if let Some(unit) = self.engine.last_unit() {
                    // The onset on the feed's clock: the span's end, minus how long ago it was.
                    let since_reset_at_end = self.engine.position() as f64;
                    let onset_since_reset = unit.sample as f64 + unit.fraction;
                    let span_end = (self.rendered + span.len() as u64) as f64;
                    let onset_s =
                        (span_end - (since_reset_at_end - onset_since_reset)) / sample_rate;
                    feed.push_unit(onset_s, unit);
                }
            }
            self.rendered += span.len() as u64;
            self.scope.write(feed, span);
        }
        use std::sync::atomic::Ordering::Relaxed;
        feed.volume_ml
            .store(self.engine.volume_ml() as f32, Relaxed);
        feed.capacity_ml
            .store(self.engine.config().capacity_ml as f32, Relaxed);
        feed.tilt_deg.store(tilt_deg as f32, Relaxed);
        for &control in Control::ALL {
            feed.played[control].store(values[control] as f32, Relaxed);
        }
        feed.now_s
            .store(self.rendered as f64 / sample_rate, Relaxed);
        feed.units_started.store(self.units_seen, Relaxed);
        let shown = Visible {
            units: self.units_seen,
            volume_ml: self.engine.volume_ml() as f32,
            tilt_deg: tilt_deg as f32,
            played: PerControl::from_fn(|control| values[control] as f32),
            sounding: self.engine.sounding_components() > 0 || self.fade_left > 0,
        };
        feed.publish(shown, self.shown);
        self.shown = shown;
    }
}
