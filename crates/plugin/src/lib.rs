//! The plugin shell: the CLAP and VST3 plugin around the real-time glue in [`realtime`]. It holds
//! the parameters, hands MIDI and the transport to [`RealtimeEngine`] and keeps no DSP of its own.

mod actuator_setting;
mod feed;
mod layering;
mod loaded_model;
mod midi_learn;
mod osc_input;
mod params;
pub mod presets;
mod realtime;
pub mod standalone;
mod transport;

#[cfg(feature = "editor")]
mod editor;

pub use actuator_setting::{Actuator, ActuatorSetting, ACTUATOR_FELT_KEY, ACTUATOR_KEY};
pub use feed::{Feed, UnitView, Visible, SCOPE_COLUMNS, SCOPE_COLUMN_S, UNIT_SLOTS};
pub use layering::model_values;
pub use loaded_model::{LoadedModel, ModelLayer, MODEL_KEY, MODEL_NAME_KEY};
pub use midi_learn::{Learnt, MidiLearn};
pub use osc_input::{OscInput, OscSettings, OscStatus, DEFAULT_AXIS, DEFAULT_OSC_INTERFACE};
pub use params::{
    exact, float_param, format, migrate_state, parse_number, GlugParams, ModelParams, STATE_VERSION,
};
pub use realtime::{RealtimeEngine, Settings, FADE_S};
pub use transport::TransportWatch;

use std::num::NonZeroU32;
use std::sync::Arc;

use nice_plug::prelude::*;

use sake_glug_actuator::ActuatorResponse;
use sake_glug_device::midi::{MidiInput, MidiMap};

/// The plugin shell: parameters and lifecycle around [`RealtimeEngine`], which does the work.
///
/// `RAW_MIDI` says whether the format passes the device's CCs as raw MIDI. CLAP does, with no
/// cost. VST3 has no raw CCs: nice-plug would register 16 × 130 hidden MIDI-mapping parameters
/// for them (2,097 in all, 51 s to load in pedalboard, an assertion per parameter in Carla), so
/// the VST3 export takes note-ons only and the device reaches Tilt by the host's MIDI learn
/// (docs/guide/tilt-device.md).
pub struct SakeGlugPlugin<const RAW_MIDI: bool> {
    params: Arc<GlugParams>,
    feed: Arc<Feed>,
    /// OSC from phones and sensors: the socket thread and the values it leaves for `process()`.
    osc: Arc<OscInput>,
    /// Built in `activate()`, where allocating is allowed.
    renderer: Option<RealtimeEngine>,
    /// The audio thread's copy of the loaded model (MODEL.md §12.1), taken from
    /// [`GlugParams::loaded_model`] at the start of each block.
    model: Option<ModelLayer>,
    /// The audio thread's copy of the actuator's response (MODEL.md §18), taken from
    /// [`GlugParams::actuator`] at the start of each block.
    actuator: Option<ActuatorResponse>,
}

/// The CLAP plugin, with raw MIDI from the device.
pub type SakeGlug = SakeGlugPlugin<true>;
/// The VST3 plugin: the same parameters, state and sound, note-ons as its only MIDI.
pub type SakeGlugVst3 = SakeGlugPlugin<false>;

impl<const RAW_MIDI: bool> Default for SakeGlugPlugin<RAW_MIDI> {
    fn default() -> Self {
        let params = GlugParams::default();
        if let Some(model) = standalone::options().and_then(|options| options.model.as_ref()) {
            layering::load_unshared(model, &params);
        }
        if let Some(actuator) = standalone::options().and_then(|options| options.actuator.clone()) {
            params.actuator.set(Some(actuator));
        }
        if let Some(setting) = standalone::options().and_then(|options| options.learn) {
            params.learn.arm(setting);
        }
        let params = Arc::new(params);
        standalone::share_params(&params);
        Self {
            params,
            feed: Arc::new(Feed::default()),
            osc: Arc::new(OscInput::default()),
            renderer: None,
            model: None,
            actuator: None,
        }
    }
}

impl<const RAW_MIDI: bool> SakeGlugPlugin<RAW_MIDI> {
    /// The parameters, as the host and the editor see them.
    pub fn glug_params(&self) -> &Arc<GlugParams> {
        &self.params
    }

    /// What the audio thread reports to the editor.
    pub fn feed(&self) -> &Arc<Feed> {
        &self.feed
    }

    /// The OSC input (its status and counters).
    pub fn osc(&self) -> &Arc<OscInput> {
        &self.osc
    }

    /// The renderer, once the plugin has been initialised.
    pub fn renderer(&self) -> Option<&RealtimeEngine> {
        self.renderer.as_ref()
    }

    /// The parameters' values over the loaded model, with the actuator, after taking the
    /// newest model and actuator chosen (lock-free: also on the audio thread).
    fn settings(&mut self) -> Settings {
        if let Some(model) = self.params.loaded_model.take_change() {
            self.model = model;
        }
        if let Some(actuator) = self.params.actuator.take_change() {
            self.actuator = actuator;
        }
        Settings {
            actuator: self.actuator,
            ..Settings::with_model(&self.params, self.model.as_ref())
        }
    }
}

/// The MIDI message a host event carries, if the synth acts on it. A note-on on a wildcard
/// channel (CLAP's "every channel") counts as one on the channel the map listens to.
fn midi_input<S>(event: &NoteEvent<S>, map: &MidiMap) -> Option<MidiInput> {
    match *event {
        NoteEvent::NoteOn {
            channel, velocity, ..
        } if velocity > 0.0 => Some(MidiInput::NoteOn {
            channel: channel.number().or(map.channel).unwrap_or(0),
        }),
        NoteEvent::MidiCC {
            channel, cc, value, ..
        } => Some(MidiInput::Cc {
            channel,
            cc,
            value: (value.clamp(0.0, 1.0) * 127.0).round() as u8,
        }),
        _ => None,
    }
}

impl<const RAW_MIDI: bool> Plugin for SakeGlugPlugin<RAW_MIDI> {
    const NAME: &'static str = "Sake Glug";
    const VENDOR: &'static str = "Sake Glug";
    // The project has no public homepage or contact: blank, which a host shows as nothing
    // (CLAP lets an optional field be blank, VST3's factory fields are fixed arrays left
    // empty), rather than a placeholder it would show to users.
    const URL: &'static str = "";
    const EMAIL: &'static str = "";
    const VERSION: &'static str = env!("CARGO_PKG_VERSION");

    // A generator: no audio input; the same signal on every output channel.
    const AUDIO_IO_LAYOUTS: &'static [AudioIOLayout] = &[
        AudioIOLayout {
            main_input_channels: None,
            main_output_channels: NonZeroU32::new(2),
            ..AudioIOLayout::const_default()
        },
        AudioIOLayout {
            main_input_channels: None,
            main_output_channels: NonZeroU32::new(1),
            ..AudioIOLayout::const_default()
        },
    ];

    // CCs from the tilt device need the full MIDI config where the format passes raw MIDI.
    const MIDI_INPUT: MidiConfig = if RAW_MIDI {
        MidiConfig::MidiCCs
    } else {
        MidiConfig::Basic
    };
    const SAMPLE_ACCURATE_AUTOMATION: bool = true;

    #[cfg(feature = "editor")]
    type Editor = nice_plug_egui::EguiEditor<editor::GlugEditor>;
    #[cfg(not(feature = "editor"))]
    type Editor = ();
    type SysExMessage = ();
    type BackgroundTask = ();

    /// An old layout brought up to date, then every value into range (a newer layout's too).
    fn filter_state(state: &mut PluginState) {
        migrate_state(state);
        params::validate_state(state);
    }

    fn params(&self) -> Arc<dyn Params> {
        self.params.clone()
    }

    #[cfg(feature = "editor")]
    fn editor(&mut self, _async_executor: AsyncExecutor<Self>) -> Option<Self::Editor> {
        if !standalone::editor_wanted() {
            return None;
        }
        editor::create(self.params.clone(), self.feed.clone(), self.osc.clone())
    }

    fn activate(
        &mut self,
        _audio_io_layout: &AudioIOLayout,
        buffer_config: &BufferConfig,
        _context: &mut impl ActivateContext<Self>,
    ) -> bool {
        // Not the audio thread: the socket may be bound here. A port a loaded state asks for
        // waits for the user's consent.
        self.osc.follow(&self.params.osc);
        let sample_rate = buffer_config.sample_rate as f64;
        let reusable = self
            .renderer
            .as_ref()
            .is_some_and(|renderer| renderer.sample_rate() == sample_rate);
        let config = self.settings().config;
        if !reusable {
            self.renderer = Some(RealtimeEngine::new(sample_rate, config));
        }
        true
    }

    fn reset(&mut self) {
        let config = self.settings().config;
        if let Some(renderer) = &mut self.renderer {
            renderer.reset(config);
        }
    }

    fn process(
        &mut self,
        buffer: &mut Buffer,
        _aux: &mut AuxiliaryBuffers,
        context: &mut impl ProcessContext<Self>,
    ) -> ProcessStatus {
        let len = buffer.samples();
        let channels = buffer.as_slice();
        let mut settings = self.settings();
        let Some(renderer) = &mut self.renderer else {
            channels.iter_mut().for_each(|channel| channel.fill(0.0));
            return ProcessStatus::Normal;
        };
        let transport = context.transport();
        renderer.observe_transport(transport.playing, transport.pos_samples(), settings.config);
        renderer.apply_live(self.osc.live());
        standalone::mark_processing();

        let Some((first, others)) = channels.split_first_mut() else {
            return ProcessStatus::KeepAlive;
        };
        // Events split the block so that a note-on or CC acts on its own sample.
        let mut next_event = context.next_event();
        let mut position = 0;
        loop {
            while let Some(event) = next_event {
                if event.timing() as usize > position && position < len {
                    break;
                }
                if let NoteEvent::MidiCC { channel, cc, .. } = event {
                    // MIDI learn: the armed row takes this CC, which then acts as mapped.
                    if self
                        .params
                        .learn
                        .take(&mut settings.midi, channel, cc)
                        .is_some()
                    {
                        self.params.set_midi_map(settings.midi);
                        #[cfg(feature = "editor")]
                        self.feed.repaint.request_repaint();
                    }
                }
                if let Some(input) = midi_input(&event, &settings.midi) {
                    renderer.handle(input, &settings.midi);
                }
                next_event = context.next_event();
            }
            if position >= len {
                break;
            }
            let end = next_event.map_or(len, |event| {
                (event.timing() as usize).clamp(position + 1, len)
            });
            renderer.process(&settings, &mut first[position..end], &self.feed);
            position = end;
        }
        for channel in others {
            channel.copy_from_slice(first);
        }
        renderer.finish_block(len);
        ProcessStatus::KeepAlive
    }
}

impl ClapPlugin for SakeGlug {
    const CLAP_ID: &'static str = "org.sake-glug.sake-glug";
    const CLAP_DESCRIPTION: Option<&'static str> =
        Some("The glug vibration of sake poured from a bottle, driven by its tilt");
    const CLAP_MANUAL_URL: Option<&'static str> = None;
    const CLAP_SUPPORT_URL: Option<&'static str> = None;
    const CLAP_FEATURES: &'static [ClapFeature] = &[
        ClapFeature::Instrument,
        ClapFeature::Synthesizer,
        ClapFeature::Mono,
        ClapFeature::Stereo,
    ];

    fn remote_controls(&self, context: &mut impl RemoteControlsContext) {
        let params = &self.params;
        context.add_section("Pour", |section| {
            section.add_page("Pour", |page| {
                for &control in sake_glug_engine::Control::ALL {
                    page.add_param(&params.controls[control]);
                }
            });
        });
    }
}

impl Vst3Plugin for SakeGlugVst3 {
    const VST3_CLASS_ID: [u8; 16] = *b"SakeGlugPluginV1";
    const VST3_SUBCATEGORIES: &'static [Vst3SubCategory] = &[
        Vst3SubCategory::Instrument,
        Vst3SubCategory::Synth,
        Vst3SubCategory::Generator,
    ];
}

nice_export_clap!(SakeGlug);
nice_export_vst3!(SakeGlugVst3);
