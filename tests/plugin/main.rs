//! The plugin through nice-plug's real traits: parameters, MIDI, state, transport resets, every
//! sample rate, and real-time safety.

#[path = "../support/mod.rs"]
mod support;

mod clap_host;
mod fuzz;
mod host;

mod midi;
mod nyquist;
mod params;
mod realtime;
mod reset;
mod state;
