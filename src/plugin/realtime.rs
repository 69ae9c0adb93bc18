//! The plugin's real-time side without plugin-framework types: parameter values, MIDI and
//! transport in; engine output and the editor's feed out. Allocation-free after `new()`.

use crate::device::live::{LiveControls, LiveReader};
use crate::device::midi::{CcDecoder, MidiMap, Overrides};
use crate::engine::{ControlValues, Controls, Engine, ModelConfig};
use crate::plugin::feed::{Feed, ScopeWriter};
use crate::plugin::params::GlugParams;
use crate::plugin::transport::TransportWatch;

/// The longest span rendered at once, so that the editor sees (nearly) every unit start; the
/// engine's output does not depend on how time is cut.
const FEED_SPAN: usize = 128;

/// The parameters' values for one `process()` call.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    /// Tilt, viscosity, fill level and pour time as the parameters set them (before MIDI).
    pub values: ControlValues,
    /// Output gain (dB).
    pub gain_db: f64,
    /// The model's constants.
    pub config: ModelConfig,
    /// The tilt device's MIDI mapping.
    pub midi: MidiMap,
}

impl Settings {
    /// The parameters' current values.
    pub fn from_params(params: &GlugParams) -> Self {
        Self {
            values: params.control_values(),
            gain_db: params.gain_db(),
            config: params.model_config(),
            midi: params.midi_map(),
        }
    }
}

/// A MIDI message the plugin acts on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MidiInput {
    /// A note-on: refill the bottle (MODEL.md §8).
    Refill,
    /// A control change, `value` 0–127, `channel` 0–15.
    Cc {
        /// MIDI channel, 0–15.
        channel: u8,
        /// Controller number, 0–127.
        cc: u8,
        /// Controller value, 0–127.
        value: u8,
    },
}

/// The engine as the plugin runs it, with MIDI overrides, transport resets and the editor's
/// feed around it.
pub struct RealtimeEngine {
    engine: Engine,
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
}

impl RealtimeEngine {
    /// Allocates: call from `initialize()`.
    pub fn new(sample_rate: f64, config: ModelConfig) -> Self {
        Self {
            engine: Engine::new(sample_rate, config),
            config,
            decoder: CcDecoder::default(),
            overrides: Overrides::default(),
            live: LiveReader::default(),
            transport: TransportWatch::default(),
            scope: ScopeWriter::new(sample_rate),
            units_seen: 0,
            rendered: 0,
        }
    }

    /// Sample rate the engine runs at (Hz).
    pub fn sample_rate(&self) -> f64 {
        self.engine.sample_rate()
    }

    /// The engine inside.
    pub fn engine(&self) -> &Engine {
        &self.engine
    }

    /// The host's reset: the bottle's, and the transport is watched afresh.
    pub fn reset(&mut self, config: ModelConfig) {
        self.reset_bottle(config);
        self.transport.reset();
    }

    /// Call once per `process()` before rendering; resets when the transport starts or jumps.
    pub fn observe_transport(&mut self, playing: bool, position: Option<i64>, config: ModelConfig) {
        if self.transport.observe(playing, position) {
            self.reset_bottle(config);
        }
    }

    /// MODEL.md §8 reset; MIDI overrides are dropped too, so a bounce starts from the parameters.
    fn reset_bottle(&mut self, config: ModelConfig) {
        self.apply_config(config);
        self.engine.reset();
        self.decoder.reset();
        self.overrides.clear();
        self.units_seen = 0;
    }

    /// Call once per `process()` after rendering `samples` samples.
    pub fn finish_block(&mut self, samples: usize) {
        self.transport.advance(samples);
    }

    /// Acts on one MIDI message: a note-on refills, a mapped CC overrides its control.
    pub fn handle(&mut self, input: MidiInput, map: &MidiMap) {
        match input {
            MidiInput::Refill => self.engine.refill(),
            MidiInput::Cc { channel, cc, value } => {
                if let Some((target, value)) = self.decoder.feed(map, channel, cc, value) {
                    self.overrides.set(target, value);
                }
            }
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

    /// Renders `out.len()` samples under `settings` (constant over the span).
    pub fn process(&mut self, settings: &Settings, out: &mut [f32], feed: &Feed) {
        self.apply_config(settings.config);
        let params = settings.values;
        let [tilt_deg, viscosity, fill_percent] =
            self.overrides
                .apply([params.tilt_deg, params.viscosity, params.fill_percent]);
        let values = ControlValues {
            tilt_deg,
            viscosity,
            fill_percent,
            pour_time_s: params.pour_time_s,
        };
        let controls = Controls::constant(values, settings.gain_db);
        let sample_rate = self.engine.sample_rate();
        for span in out.chunks_mut(FEED_SPAN) {
            self.engine.process(&controls, span);
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
        feed.now_s
            .store(self.rendered as f64 / sample_rate, Relaxed);
        feed.units_started.store(self.units_seen, Relaxed);
    }
}
