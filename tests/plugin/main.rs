//! The plugin through nice-plug's real traits: parameters, MIDI, OSC, state, transport resets,
//! every sample rate, and real-time safety.

#[path = "../support/mod.rs"]
mod support;

mod clap_host;
mod fuzz;
mod host;

mod actuator;
mod automation;
mod clap_state;
mod descriptors;
mod layouts;

mod midi;
mod model;
mod nyquist;
mod osc;
mod osc_decoder;
mod osc_fuzz;
mod params;
mod realtime;
mod reset;
mod state;
mod take;
mod vstpreset;
