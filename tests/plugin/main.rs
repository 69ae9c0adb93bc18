//! The plugin through nice-plug's real traits: parameters, MIDI, state, transport resets, every
//! sample rate, and real-time safety.

mod clap_host;
mod host;

mod midi;
mod nyquist;
mod params;
mod realtime;
mod reset;
mod state;
