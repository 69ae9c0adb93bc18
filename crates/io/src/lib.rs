//! How Sake Glug reads and writes files: one way each.
//!
//! - [`read`]: every input file, read through one bounded reader (a regular file only, within
//!   the limit of its kind, which [`read::InputKind`] declares);
//! - [`append`]: the one file appended to instead (the study's trial log), opened as safely;
//! - [`pending`]: every output file, written all or nothing: in a temporary file beside its
//!   target ([`temp`]), renamed over it once complete;
//! - [`keys`]: the dotted keys of the product's TOML files (feature `toml`);
//! - [`text`]: outside text (a file's field, a file name) made safe to echo in a message.

pub mod append;
#[cfg(feature = "toml")]
pub mod keys;
pub mod pending;
pub mod read;
pub mod temp;
pub mod text;

pub use pending::{remove_own_temps, remove_stale_temps, temp_dir_beside, PendingFile, WriteError};
pub use read::{InputKind, ReadError, ReadFailure};
