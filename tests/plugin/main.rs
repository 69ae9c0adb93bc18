//! The plugin through nice-plug's real traits: parameters, MIDI, state, transport resets, every
//! sample rate, and real-time safety.

mod host;

mod clap_state;

mod midi;
mod nyquist;
mod params;
mod realtime;
mod reset;
mod state;
mod take;
