//! How Sake Glug reads and writes files.
//!
//! - [`text`]: outside text (a scene's field, a file name) made safe to echo in a message;
//! - [`pending`]: every file written all or nothing, in a temporary file beside its target
//!   ([`temp`]) renamed over it once complete.

pub mod pending;
pub mod temp;
pub mod text;

pub use pending::{remove_own_temps, remove_stale_temps, PendingFile, WriteError};
