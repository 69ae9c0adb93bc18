//! A minimal host for the plugin tests: activates the plugin, sets parameters as a wrapper does,
//! and calls `process()` with a buffer and a mock `ProcessContext`.
#![allow(dead_code)]

use std::collections::{BTreeMap, VecDeque};

use nice_plug::prelude::*;
use sake_glug_plugin::SakeGlug;

pub struct MockActivate;

impl ActivateContext<SakeGlug> for MockActivate {
    fn plugin_api(&self) -> PluginApi {
        PluginApi::Clap
    }
    fn execute(&self, _task: ()) {}
    fn set_latency_samples(&self, _samples: u32) {}
    fn set_current_voice_capacity(&self, _capacity: u32) {}
}

pub struct MockProcess {
    pub transport: Transport,
    pub events: VecDeque<PluginNoteEvent<SakeGlug>>,
}

impl ProcessContext<SakeGlug> for MockProcess {
    fn plugin_api(&self) -> PluginApi {
        PluginApi::Clap
    }
    fn execute_background(&self, _task: ()) {}
    fn execute_gui(&self, _task: ()) {}
    fn transport(&self) -> &Transport {
        &self.transport
    }
    fn next_event(&mut self) -> Option<PluginNoteEvent<SakeGlug>> {
        self.events.pop_front()
    }
    fn try_send_event(
        &mut self,
        event: PluginNoteEvent<SakeGlug>,
    ) -> Result<
        (),
        (
            PluginNoteEvent<SakeGlug>,
            nice_plug::context::process::SendEventError,
        ),
    > {
        Err((
            event,
            nice_plug::context::process::SendEventError::NoOutputBuffer,
        ))
    }
    fn set_latency_samples(&self, _samples: u32) {}
    fn request_restart(&self) {}
    fn set_current_voice_capacity(&self, _capacity: u32) {}
}

/// What the host tells the plugin about its transport for one block.
#[derive(Debug, Clone, Copy, Default)]
pub struct Playhead {
    pub playing: bool,
    pub position: Option<i64>,
}

pub struct TestHost {
    pub plugin: SakeGlug,
    pub sample_rate: f32,
    pub channels: usize,
    /// Wraps every `process()` call, e.g. in `assert_no_alloc`.
    pub guard: fn(&mut dyn FnMut()),
}

fn unguarded(f: &mut dyn FnMut()) {
    f()
}

impl TestHost {
    pub fn new(sample_rate: f32, channels: usize) -> Self {
        Self::with_plugin(SakeGlug::default(), sample_rate, channels)
    }

    pub fn with_plugin(mut plugin: SakeGlug, sample_rate: f32, channels: usize) -> Self {
        let layout = SakeGlug::AUDIO_IO_LAYOUTS
            .iter()
            .find(|layout| layout.main_output_channels.map(|n| n.get() as usize) == Some(channels))
            .expect("the plugin offers this output layout");
        let config = BufferConfig {
            sample_rate,
            min_buffer_size: None,
            max_buffer_size: 8192,
            process_mode: ProcessMode::Realtime,
        };
        assert!(plugin.activate(layout, &config, &mut MockActivate));
        plugin.reset();
        Self {
            plugin,
            sample_rate,
            channels,
            guard: unguarded,
        }
    }

    fn param_ptr(&self, id: &str) -> ParamPtr {
        let params = self.plugin.glug_params().clone() as std::sync::Arc<dyn Params>;
        params
            .param_map()
            .into_iter()
            .find(|(param_id, _, _)| param_id == id)
            .map(|(_, ptr, _)| ptr)
            .unwrap_or_else(|| panic!("no parameter {id}"))
    }

    /// Sets a parameter from its text, as a host's generic UI would.
    pub fn set_text(&self, id: &str, text: &str) {
        let ptr = self.param_ptr(id);
        unsafe {
            let normalized = ptr
                .string_to_normalized_value(text)
                .unwrap_or_else(|| panic!("{id} does not parse {text:?}"));
            ptr._internal_set_normalized_value(normalized);
        }
    }

    pub fn set_normalized(&self, id: &str, normalized: f32) {
        unsafe {
            self.param_ptr(id)
                ._internal_set_normalized_value(normalized);
        }
    }

    /// Renders one block; returns every channel.
    pub fn process(
        &mut self,
        len: usize,
        events: Vec<PluginNoteEvent<SakeGlug>>,
        playhead: Playhead,
    ) -> Vec<Vec<f32>> {
        let mut storage = vec![vec![f32::NAN; len]; self.channels];
        let mut buffer = Buffer::default();
        unsafe {
            buffer.set_slices(len, |slices| {
                slices.clear();
                slices.extend(storage.iter_mut().map(|channel| channel.as_mut_slice()));
            });
        }
        let mut transport = Transport::new(self.sample_rate);
        transport.playing = playhead.playing;
        transport.pos_samples = playhead.position;
        let mut context = MockProcess {
            transport,
            events: events.into(),
        };
        let mut aux = AuxiliaryBuffers {
            inputs: &mut [],
            outputs: &mut [],
        };
        let plugin = &mut self.plugin;
        let mut status = None;
        (self.guard)(&mut || status = Some(plugin.process(&mut buffer, &mut aux, &mut context)));
        drop(buffer);
        assert!(matches!(status, Some(ProcessStatus::KeepAlive)));
        storage
    }

    /// Renders `total` samples in blocks of `block`, with no events and the transport stopped.
    pub fn render_mono(&mut self, total: usize, block: usize) -> Vec<f32> {
        let mut out = Vec::with_capacity(total);
        while out.len() < total {
            let len = block.min(total - out.len());
            let channels = self.process(len, Vec::new(), Playhead::default());
            out.extend_from_slice(&channels[0]);
        }
        out
    }

    /// The state a wrapper would save: every parameter's plain value and the persisted fields.
    pub fn state(&self) -> String {
        let params = self.plugin.glug_params().clone() as std::sync::Arc<dyn Params>;
        let values: BTreeMap<String, f32> = params
            .param_map()
            .into_iter()
            .map(|(id, ptr, _)| (id, unsafe { ptr.unmodulated_plain_value() }))
            .collect();
        format!("{values:?}\n{:?}", params.serialize_fields())
    }

    pub fn restore(&self, from: &TestHost) {
        let source = from.plugin.glug_params().clone() as std::sync::Arc<dyn Params>;
        let target = self.plugin.glug_params().clone() as std::sync::Arc<dyn Params>;
        let targets: BTreeMap<String, ParamPtr> = target
            .param_map()
            .into_iter()
            .map(|(id, ptr, _)| (id, ptr))
            .collect();
        for (id, ptr, _) in source.param_map() {
            unsafe {
                let plain = ptr.unmodulated_plain_value();
                let target = targets[&id];
                target._internal_set_normalized_value(target.preview_normalized(plain));
            }
        }
        target.deserialize_fields(&source.serialize_fields());
    }
}

pub fn note_on(timing: u32) -> PluginNoteEvent<SakeGlug> {
    NoteEvent::NoteOn {
        timing,
        voice_id: nice_plug::midi::VoiceID::Wildcard,
        channel: nice_plug::midi::Channel::Number(0),
        key: nice_plug::midi::Key::Number(60),
        velocity: 0.8,
    }
}

pub fn cc(timing: u32, channel: u8, cc: u8, value: u8) -> PluginNoteEvent<SakeGlug> {
    NoteEvent::MidiCC {
        timing,
        channel,
        cc,
        value: value as f32 / 127.0,
    }
}

pub fn peak(samples: &[f32]) -> f32 {
    samples.iter().fold(0.0, |peak, s| peak.max(s.abs()))
}
