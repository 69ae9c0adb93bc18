//! What a tilt device sends, decoded for the engine. Plain Rust with no plugin type, so that the
//! plugin, the standalone app and the offline renderer decode a device the same way:
//!
//! - [`midi`]: the CC mapping of the bottle-shaped controller and the one MIDI decoder;
//! - [`midi_take`]: a recorded take as a Standard MIDI File, each message at its sample (feature
//!   `takes`, like the next);
//! - [`csv_lane`]: a logged take as CSV, a column or an accelerometer's gravity vector;
//! - [`axis`]: which sensor axis runs from the bottle's base to its mouth, and the tilt of a
//!   gravity reading;
//! - [`osc`]: OSC from phones and other sensors, arriving on a socket thread ([`OscListener`])
//!   and reaching the audio thread through [`LiveControls`], read without locks or allocation.

pub mod axis;
#[cfg(feature = "takes")]
pub mod csv_lane;
pub mod live;
pub mod midi;
#[cfg(feature = "takes")]
pub mod midi_take;
#[cfg(feature = "osc")]
pub mod osc;
#[cfg(feature = "osc")]
pub mod osc_listener;

/// The sensor axis along the bottle, and the tilt from a gravity reading.
pub use axis::{tilt_from_gravity, Axis, AxisParseError};
/// The latest live (OSC) values, shared lock-free with the audio thread.
pub use live::{LiveChanges, LiveControls, LiveReader};
#[cfg(feature = "osc")]
/// The OSC decoder: Sake Glug's addresses and the phone apps' gravity vectors.
pub use osc::{decode_osc, OscControl, OscError, Pointing, GRAVITY_SOURCES};
#[cfg(feature = "osc")]
/// The OSC socket thread and its counters.
pub use osc_listener::{OscListener, OscStats};
