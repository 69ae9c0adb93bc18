//! Actuator profiles (MODEL.md §18): what a device does to each frequency, as a TOML file.
//!
//! [`ActuatorProfile`] reads and checks one (through `sake_glug_io::read`, every refusal naming
//! its key) into the engine's plain [`ActuatorResponse`]; [`SHIPPED`] are the profiles of
//! `actuators/`, embedded, found by name; [`ProfileText`] writes one; [`measure`] measures a
//! device (on JACK with feature `audio`: [`JackRig`]).
//!
//! The profile is its own crate, not part of the engine (which reads no file) nor of the model
//! files (a model is a bottle and a liquid; a profile is the device that plays them, chosen
//! apart from it): the renderer, the plugin and the C library each link it, and it links only
//! the engine, the file layer and toml.

#[cfg(feature = "audio")]
mod jack_rig;
pub mod measure;
mod profile;
mod shipped;

#[cfg(feature = "audio")]
pub use jack_rig::JackRig;
pub use profile::{ActuatorProfile, ProfileError, ProfileText};
pub use sake_glug_engine::{ActuatorResponse, Equalise};
pub use shipped::{shipped_names, SHIPPED};

/// The most a profile's text may hold (bytes): a file's limit, and the C library's for a text.
pub const MAX_PROFILE_BYTES: u64 = sake_glug_io::read::InputKind::ACTUATOR.max_bytes;
