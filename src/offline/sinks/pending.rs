//! Files written all or nothing: each in a temporary file beside its target, which it replaces
//! only once every file of the render is complete.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use tempfile::NamedTempFile;

use super::OutputError;
use crate::files::temp_file_builder;

/// A file being written in a temporary file beside its target, which it replaces on
/// [`PendingFile::commit`]; dropped uncommitted, it leaves nothing behind.
pub(crate) struct PendingFile {
    path: PathBuf,
    temp: NamedTempFile,
}

impl PendingFile {
    /// An empty temporary file in the target's folder (so that the rename is atomic), its name
    /// ending in `suffix` where a library infers the format from the name.
    pub(super) fn beside(path: &Path, suffix: &str) -> std::io::Result<Self> {
        let directory = match path.parent() {
            Some(parent) if !parent.as_os_str().is_empty() => parent,
            _ => Path::new("."),
        };
        let temp = temp_file_builder().suffix(suffix).tempfile_in(directory)?;
        Ok(Self {
            path: path.to_owned(),
            temp,
        })
    }

    /// The file asked for.
    pub(super) fn path(&self) -> &Path {
        &self.path
    }

    /// The temporary file, for a library that writes to a path (plotters).
    #[cfg(feature = "plot")]
    pub(super) fn temp_path(&self) -> &Path {
        self.temp.path()
    }

    /// A buffered writer at the start of the temporary file.
    pub(super) fn writer(&self) -> std::io::Result<BufWriter<File>> {
        Ok(BufWriter::new(self.temp.reopen()?))
    }

    /// Replaces the target with the complete file; returns the target and its size in bytes.
    pub(crate) fn commit(self) -> Result<(PathBuf, u64), OutputError> {
        let Self { path, temp } = self;
        temp.persist(&path).map_err(|error| OutputError::Io {
            path: path.clone(),
            source: error.error,
        })?;
        let bytes = std::fs::metadata(&path).map_or(0, |meta| meta.len());
        Ok((path, bytes))
    }
}
