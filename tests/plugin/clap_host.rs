//! A minimal CLAP host: creates the plugin through the crate's exported `clap_entry`, as a DAW
//! does after loading the `.clap` file, and drives it only through the C ABI: the state
//! extension (save to bytes, load from bytes), the params extension (a host's automation) and
//! `process()`. What it saves and loads is nice-plug's real state path, not a copy between
//! instances.
#![allow(dead_code)]

use std::ffi::{c_char, c_void, CStr};
use std::ptr;

use clap_sys::audio_buffer::clap_audio_buffer;
use clap_sys::events::{
    clap_event_header, clap_event_midi, clap_event_param_value, clap_input_events,
    clap_output_events, CLAP_CORE_EVENT_SPACE_ID, CLAP_EVENT_MIDI, CLAP_EVENT_PARAM_VALUE,
};
use clap_sys::ext::audio_ports_config::{
    clap_audio_ports_config, clap_plugin_audio_ports_config, CLAP_EXT_AUDIO_PORTS_CONFIG,
};
use clap_sys::ext::params::{clap_param_info, clap_plugin_params, CLAP_EXT_PARAMS};
use clap_sys::ext::state::{clap_plugin_state, CLAP_EXT_STATE};
use clap_sys::factory::plugin_factory::{clap_plugin_factory, CLAP_PLUGIN_FACTORY_ID};
use clap_sys::host::clap_host;
use clap_sys::plugin::clap_plugin;
use clap_sys::process::clap_process;
use clap_sys::stream::{clap_istream, clap_ostream};
use clap_sys::version::CLAP_VERSION;

/// One plugin instance created by the host; destroyed on drop.
pub struct ClapInstance {
    plugin: *const clap_plugin,
    /// The plugin keeps a pointer to this for its whole life.
    _host: Box<clap_host>,
    activated: bool,
    /// Channels of the main output in the selected audio ports configuration.
    channels: u32,
}

unsafe extern "C" fn no_extension(_host: *const clap_host, _id: *const c_char) -> *const c_void {
    ptr::null()
}

unsafe extern "C" fn ignore(_host: *const clap_host) {}

impl Default for ClapInstance {
    fn default() -> Self {
        Self::new()
    }
}

impl ClapInstance {
    /// Creates and initialises the crate's one plugin through its entry point and factory.
    pub fn new() -> Self {
        let host = Box::new(clap_host {
            clap_version: CLAP_VERSION,
            host_data: ptr::null_mut(),
            name: c"sake-glug tests".as_ptr(),
            vendor: c"sake-glug".as_ptr(),
            url: c"".as_ptr(),
            version: c"0".as_ptr(),
            get_extension: Some(no_extension),
            request_restart: Some(ignore),
            request_process: Some(ignore),
            request_callback: Some(ignore),
        });
        let entry = &sake_glug_plugin::clap_entry;
        unsafe {
            assert!((entry.init.unwrap())(c"".as_ptr()));
            let factory = (entry.get_factory.unwrap())(CLAP_PLUGIN_FACTORY_ID.as_ptr())
                as *const clap_plugin_factory;
            assert!(!factory.is_null());
            let descriptor = ((*factory).get_plugin_descriptor.unwrap())(factory, 0);
            let plugin = ((*factory).create_plugin.unwrap())(factory, &*host, (*descriptor).id);
            assert!(!plugin.is_null());
            assert!(((*plugin).init.unwrap())(plugin));
            Self {
                plugin,
                _host: host,
                activated: false,
                channels: 2,
            }
        }
    }

    fn extension<T>(&self, id: &CStr) -> &T {
        unsafe {
            let extension = ((*self.plugin).get_extension.unwrap())(self.plugin, id.as_ptr());
            assert!(!extension.is_null(), "no extension {id:?}");
            &*(extension as *const T)
        }
    }

    /// The state as the host saves it into a project: the bytes the plugin writes to the stream.
    pub fn save(&self) -> Vec<u8> {
        unsafe extern "C" fn write(
            stream: *const clap_ostream,
            buffer: *const c_void,
            size: u64,
        ) -> i64 {
            let bytes = unsafe { &mut *((*stream).ctx as *mut Vec<u8>) };
            let chunk = unsafe { std::slice::from_raw_parts(buffer as *const u8, size as usize) };
            bytes.extend_from_slice(chunk);
            size as i64
        }
        let mut bytes = Vec::new();
        let stream = clap_ostream {
            ctx: &mut bytes as *mut Vec<u8> as *mut c_void,
            write: Some(write),
        };
        let state: &clap_plugin_state = self.extension(CLAP_EXT_STATE);
        assert!(unsafe { (state.save.unwrap())(self.plugin, &stream) });
        bytes
    }

    /// Loads `bytes` as a host loads a saved project; whether the plugin accepted them.
    pub fn load(&self, bytes: &[u8]) -> bool {
        struct Reader<'a> {
            bytes: &'a [u8],
            position: usize,
        }
        unsafe extern "C" fn read(
            stream: *const clap_istream,
            buffer: *mut c_void,
            size: u64,
        ) -> i64 {
            let reader = unsafe { &mut *((*stream).ctx as *mut Reader) };
            let left = &reader.bytes[reader.position..];
            let count = left.len().min(size as usize);
            unsafe { ptr::copy_nonoverlapping(left.as_ptr(), buffer as *mut u8, count) };
            reader.position += count;
            count as i64
        }
        let mut reader = Reader { bytes, position: 0 };
        let stream = clap_istream {
            ctx: &mut reader as *mut Reader as *mut c_void,
            read: Some(read),
        };
        let state: &clap_plugin_state = self.extension(CLAP_EXT_STATE);
        unsafe { (state.load.unwrap())(self.plugin, &stream) }
    }

    /// Sets the parameter named `name` (as a host lists it) from `text`, as a host's automation
    /// does: the text is turned into the parameter's CLAP value and sent in a flush.
    pub fn set_text(&self, name: &str, text: &str) {
        let change = self.change(0, name, text);
        let event = change.event(0);
        let events = EventList(vec![&event.header]);
        let params: &clap_plugin_params = self.extension(CLAP_EXT_PARAMS);
        unsafe { (params.flush.unwrap())(self.plugin, &events.input(), &no_output()) };
    }

    /// A change of the parameter named `name` to `text` at sample `at` of a render, as a host's
    /// automation lane sends it.
    pub fn change(&self, at: u64, name: &str, text: &str) -> ParamChange {
        let params: &clap_plugin_params = self.extension(CLAP_EXT_PARAMS);
        let param_id = self.param_id(params, name);
        let text = std::ffi::CString::new(text).unwrap();
        let mut value = 0.0;
        assert!(
            unsafe {
                (params.text_to_value.unwrap())(self.plugin, param_id, text.as_ptr(), &mut value)
            },
            "{name} does not parse {text:?}"
        );
        ParamChange {
            at,
            param_id,
            value,
        }
    }

    fn param_id(&self, params: &clap_plugin_params, name: &str) -> u32 {
        let count = unsafe { (params.count.unwrap())(self.plugin) };
        for index in 0..count {
            let mut info: clap_param_info = unsafe { std::mem::zeroed() };
            assert!(unsafe { (params.get_info.unwrap())(self.plugin, index, &mut info) });
            let info_name = unsafe { CStr::from_ptr(info.name.as_ptr()) };
            if info_name.to_str() == Ok(name) {
                return info.id;
            }
        }
        panic!("no parameter named {name}");
    }

    /// The text the plugin shows for the parameter named `name` at its current value, as a
    /// host's parameter list shows it (the plugin's own value-to-text, with its unit).
    pub fn shown(&self, name: &str) -> String {
        let params: &clap_plugin_params = self.extension(CLAP_EXT_PARAMS);
        let id = self.param_id(params, name);
        let mut value = f64::NAN;
        assert!(unsafe { (params.get_value.unwrap())(self.plugin, id, &mut value) });
        let mut text = [0 as c_char; 256];
        assert!(unsafe {
            (params.value_to_text.unwrap())(
                self.plugin,
                id,
                value,
                text.as_mut_ptr(),
                text.len() as u32,
            )
        });
        unsafe { CStr::from_ptr(text.as_ptr()) }
            .to_string_lossy()
            .into_owned()
    }

    /// Every parameter's CLAP info, in the plugin's order.
    fn parameters(&self) -> Vec<clap_param_info> {
        let params: &clap_plugin_params = self.extension(CLAP_EXT_PARAMS);
        let count = unsafe { (params.count.unwrap())(self.plugin) };
        (0..count)
            .map(|index| {
                let mut info: clap_param_info = unsafe { std::mem::zeroed() };
                assert!(unsafe { (params.get_info.unwrap())(self.plugin, index, &mut info) });
                info
            })
            .collect()
    }

    /// Every parameter as (name, CLAP flags).
    pub fn parameter_infos(&self) -> Vec<(String, u32)> {
        self.parameters()
            .into_iter()
            .map(|info| {
                let name = unsafe { CStr::from_ptr(info.name.as_ptr()) };
                (name.to_string_lossy().into_owned(), info.flags)
            })
            .collect()
    }

    /// Every parameter as (name, CLAP value, declared min, declared max).
    pub fn parameter_values(&self) -> Vec<(std::ffi::CString, f64, f64, f64)> {
        let params: &clap_plugin_params = self.extension(CLAP_EXT_PARAMS);
        self.parameters()
            .into_iter()
            .map(|info| {
                let mut value = f64::NAN;
                assert!(unsafe { (params.get_value.unwrap())(self.plugin, info.id, &mut value) });
                let name = unsafe { CStr::from_ptr(info.name.as_ptr()) }.to_owned();
                (name, value, info.min_value, info.max_value)
            })
            .collect()
    }

    /// The plugin's audio ports configurations as (name, main output channels), in order.
    pub fn audio_ports_configs(&self) -> Vec<(String, u32)> {
        let configs: &clap_plugin_audio_ports_config = self.extension(CLAP_EXT_AUDIO_PORTS_CONFIG);
        let count = unsafe { (configs.count.unwrap())(self.plugin) };
        (0..count)
            .map(|index| {
                let mut config: clap_audio_ports_config = unsafe { std::mem::zeroed() };
                assert!(unsafe { (configs.get.unwrap())(self.plugin, index, &mut config) });
                let name = unsafe { CStr::from_ptr(config.name.as_ptr()) };
                assert!(!config.has_main_input, "a generator takes no audio in");
                (
                    name.to_string_lossy().into_owned(),
                    config.main_output_channel_count,
                )
            })
            .collect()
    }

    /// Selects the first audio ports configuration whose main output has `channels` channels,
    /// as a host does before activating; whether the plugin took it.
    pub fn select_output_channels(&mut self, channels: u32) -> bool {
        assert!(
            !self.activated,
            "a host selects a configuration before activating"
        );
        let Some(index) = self
            .audio_ports_configs()
            .iter()
            .position(|(_, count)| *count == channels)
        else {
            return false;
        };
        let configs: &clap_plugin_audio_ports_config = self.extension(CLAP_EXT_AUDIO_PORTS_CONFIG);
        let mut config: clap_audio_ports_config = unsafe { std::mem::zeroed() };
        assert!(unsafe { (configs.get.unwrap())(self.plugin, index as u32, &mut config) });
        let selected = unsafe { (configs.select.unwrap())(self.plugin, config.id) };
        if selected {
            self.channels = channels;
        }
        selected
    }

    /// Activates at `sample_rate` and starts processing.
    pub fn activate(&mut self, sample_rate: f64) {
        unsafe {
            assert!(((*self.plugin).activate.unwrap())(
                self.plugin,
                sample_rate,
                1,
                8192
            ));
            assert!(((*self.plugin).start_processing.unwrap())(self.plugin));
        }
        self.activated = true;
    }

    /// Renders `total` samples of the output in blocks of `block`, with no events and no
    /// transport; returns the first channel (every channel carries the same signal).
    pub fn render(&mut self, total: usize, block: usize) -> Vec<f32> {
        self.render_automated(total, block, &[])
    }

    /// [`ClapInstance::render`] with parameter `changes` (in order of time) sent as events in the
    /// blocks they fall in, at their offsets there.
    pub fn render_automated(
        &mut self,
        total: usize,
        block: usize,
        changes: &[ParamChange],
    ) -> Vec<f32> {
        self.render_events(total, block, changes, &[])
    }

    /// [`ClapInstance::render`] with MIDI control changes (in order of time) sent as CLAP MIDI
    /// events, as a host passes a controller's messages on.
    pub fn render_midi(&mut self, total: usize, block: usize, ccs: &[MidiCc]) -> Vec<f32> {
        self.render_events(total, block, &[], ccs)
    }

    fn render_events(
        &mut self,
        total: usize,
        block: usize,
        changes: &[ParamChange],
        ccs: &[MidiCc],
    ) -> Vec<f32> {
        assert!(self.activated);
        let mut out = Vec::with_capacity(total);
        let mut buffers = vec![vec![0.0f32; block]; self.channels as usize];
        let mut steady_time = 0;
        while out.len() < total {
            let len = block.min(total - out.len());
            let mut channels: Vec<*mut f32> = buffers
                .iter_mut()
                .map(|buffer| buffer.as_mut_ptr())
                .collect();
            let mut output = clap_audio_buffer {
                data32: channels.as_mut_ptr(),
                data64: ptr::null_mut(),
                channel_count: self.channels,
                latency: 0,
                constant_mask: 0,
            };
            let block_start = steady_time as u64;
            let in_block: Vec<clap_event_param_value> = changes
                .iter()
                .filter(|change| (block_start..block_start + len as u64).contains(&change.at))
                .map(|change| change.event((change.at - block_start) as u32))
                .collect();
            let midi_in_block: Vec<clap_event_midi> = ccs
                .iter()
                .filter(|cc| (block_start..block_start + len as u64).contains(&cc.at))
                .map(|cc| cc.event((cc.at - block_start) as u32))
                .collect();
            // One list in order of time, as CLAP asks.
            let mut headers: Vec<&clap_event_header> = in_block
                .iter()
                .map(|event| &event.header)
                .chain(midi_in_block.iter().map(|event| &event.header))
                .collect();
            headers.sort_by_key(|header| header.time);
            let events = EventList(headers);
            let input = events.input();
            let output_events = no_output();
            let process = clap_process {
                steady_time,
                frames_count: len as u32,
                transport: ptr::null(),
                audio_inputs: ptr::null(),
                audio_outputs: &mut output,
                audio_inputs_count: 0,
                audio_outputs_count: 1,
                in_events: &input,
                out_events: &output_events,
            };
            unsafe { ((*self.plugin).process.unwrap())(self.plugin, &process) };
            for channel in &buffers[1..] {
                assert_eq!(
                    channel[..len],
                    buffers[0][..len],
                    "every channel carries the same signal"
                );
            }
            out.extend_from_slice(&buffers[0][..len]);
            steady_time += len as i64;
        }
        out
    }
}

impl Drop for ClapInstance {
    fn drop(&mut self) {
        unsafe {
            if self.activated {
                ((*self.plugin).stop_processing.unwrap())(self.plugin);
                ((*self.plugin).deactivate.unwrap())(self.plugin);
            }
            ((*self.plugin).destroy.unwrap())(self.plugin);
        }
    }
}

/// The header of a core CLAP event of type `Event` at sample `time` of a call.
fn core_event_header<Event>(time: u32, type_: u16) -> clap_event_header {
    clap_event_header {
        size: std::mem::size_of::<Event>() as u32,
        time,
        space_id: CLAP_CORE_EVENT_SPACE_ID,
        type_,
        flags: 0,
    }
}

/// A parameter's new CLAP value from a sample of a render on.
#[derive(Debug, Clone, Copy)]
pub struct ParamChange {
    /// The sample it takes effect at, counted from the render's start.
    pub at: u64,
    param_id: u32,
    value: f64,
}

impl ParamChange {
    fn event(&self, time: u32) -> clap_event_param_value {
        clap_event_param_value {
            header: core_event_header::<clap_event_param_value>(time, CLAP_EVENT_PARAM_VALUE),
            param_id: self.param_id,
            cookie: ptr::null_mut(),
            note_id: -1,
            port_index: -1,
            channel: -1,
            key: -1,
            value: self.value,
        }
    }
}

/// A MIDI control change at a sample of a render.
#[derive(Debug, Clone, Copy)]
pub struct MidiCc {
    /// The sample it comes at, counted from the render's start.
    pub at: u64,
    /// 0–15.
    pub channel: u8,
    pub cc: u8,
    /// 0–127.
    pub value: u8,
}

impl MidiCc {
    fn event(&self, time: u32) -> clap_event_midi {
        clap_event_midi {
            header: core_event_header::<clap_event_midi>(time, CLAP_EVENT_MIDI),
            port_index: 0,
            data: [0xB0 | (self.channel & 0x0F), self.cc, self.value],
        }
    }
}

/// Input events for one call.
struct EventList<'a>(Vec<&'a clap_event_header>);

impl EventList<'_> {
    fn input(&self) -> clap_input_events {
        unsafe extern "C" fn size(list: *const clap_input_events) -> u32 {
            let events = unsafe { &*((*list).ctx as *const EventList) };
            events.0.len() as u32
        }
        unsafe extern "C" fn get(
            list: *const clap_input_events,
            index: u32,
        ) -> *const clap_event_header {
            let events = unsafe { &*((*list).ctx as *const EventList) };
            events.0[index as usize]
        }
        clap_input_events {
            ctx: self as *const Self as *mut c_void,
            size: Some(size),
            get: Some(get),
        }
    }
}

fn no_output() -> clap_output_events {
    unsafe extern "C" fn try_push(
        _list: *const clap_output_events,
        _event: *const clap_event_header,
    ) -> bool {
        true
    }
    clap_output_events {
        ctx: ptr::null_mut(),
        try_push: Some(try_push),
    }
}
