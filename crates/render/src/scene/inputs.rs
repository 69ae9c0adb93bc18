//! The files a scene reads besides itself, as its summary lists them.

use std::path::{Path, PathBuf};

/// A file a scene read besides itself: a CSV lane or its MIDI take.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputFile {
    /// The scene key that names it (`midi_take` for the take).
    pub key: &'static str,
    /// The file, as read: the scene's folder joined with the path the scene gives.
    pub path: PathBuf,
    /// Whether the file lies outside the scene's folder (an absolute path, `..`, or a link out
    /// of it), for the summary to say so. `false` for a take given to
    /// [`Scene::with_midi_take`], which the user named.
    pub outside_folder: bool,
}

impl InputFile {
    /// `path`, read by the scene in `folder` for `key`.
    pub(super) fn new(key: &'static str, path: PathBuf, folder: &Path) -> Self {
        // Canonical paths, so that a link counts where it leads; "" is the current folder.
        let folder = if folder.as_os_str().is_empty() {
            Path::new(".")
        } else {
            folder
        };
        let inside = match (path.canonicalize(), folder.canonicalize()) {
            (Ok(file), Ok(folder)) => file.starts_with(folder),
            _ => false,
        };
        Self {
            key,
            path,
            outside_folder: !inside,
        }
    }
}
