//! What a tilt device sends, decoded for the engine: the MIDI CC mapping of the bottle-shaped
//! controller, and OSC from phones and other sensors. Plain Rust with no plugin type, so that the
//! plugin, the standalone app and the offline renderer decode a device the same way.
//!
//! OSC arrives on a socket thread ([`OscListener`]) and reaches the audio thread through
//! [`LiveControls`], which the audio thread reads without locks or allocation.

pub mod axis;
pub mod live;
pub mod midi;
pub mod osc;
pub mod osc_listener;

/// The sensor axis along the bottle, and the tilt from a gravity reading.
pub use axis::{tilt_from_gravity, Axis, AxisParseError};
/// The latest live (OSC) values, shared lock-free with the audio thread.
pub use live::{LiveChanges, LiveControls, LiveReader};
/// The OSC decoder: Sake Glug's addresses and the phone apps' gravity vectors.
pub use osc::{decode_osc, OscControl, OscError, Pointing, GRAVITY_SOURCES};
/// The OSC socket thread and its counters.
pub use osc_listener::{OscListener, OscStats};
