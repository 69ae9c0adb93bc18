//! What a tilt device sends, decoded for the engine. Plain Rust with no plugin type, so that the
//! plugin and the offline renderer decode a take the same way:
//!
//! - [`midi`]: the CC mapping of the bottle-shaped controller and the one MIDI decoder;
//! - [`midi_take`]: a recorded take as a Standard MIDI File, each message at its sample;
//! - [`csv_lane`]: a logged take as CSV, a column or an accelerometer's gravity vector;
//! - [`axis`]: which sensor axis runs from the bottle's base to its mouth, and the tilt of a
//!   gravity reading.

pub mod axis;
pub mod csv_lane;
pub mod midi;
pub mod midi_take;
