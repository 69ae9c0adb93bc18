//! What a tilt device sends, decoded for the engine: the MIDI CC mapping of the bottle-shaped
//! controller. Plain Rust with no plugin type, so that the plugin and the offline renderer decode
//! a take the same way.

pub mod midi;
