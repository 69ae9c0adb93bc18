//! Every file the product reads, read one way: a regular file only (a FIFO, a device, a socket or
//! a folder is refused as soon as it is opened, and opening never waits), within the size limit
//! of its kind, and, for text, UTF-8. The kinds and their limits are the table [`InputKind::ALL`]:
//! a new input is one entry there.
//!
//! What is checked is the opened file, not the path: a path checked and then opened can be
//! replaced in between. A FIFO opened for reading without `O_NONBLOCK` waits for a writer; opened
//! with it, it is refused at once (`O_NONBLOCK` changes nothing for a regular file).

use std::fs::{File, FileType};
use std::io::{self, Read};
use std::path::{Path, PathBuf};

use crate::text::printable;

/// A kind of file the product reads: what a message calls it and the most bytes read of it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct InputKind {
    /// What a message calls it ("scene file", "recording").
    pub name: &'static str,
    /// The largest file of this kind read (bytes): larger ones are refused before they are
    /// read, and one that yields more than its size said (/proc, a file that grows) is refused
    /// once past it.
    pub max_bytes: u64,
}

const MIB: u64 = 1 << 20;

impl InputKind {
    /// A scene (16 MiB): its automation points are written out in TOML, which the parser holds
    /// several times over while it reads them; a longer recording belongs in a CSV lane.
    pub const SCENE: Self = Self::new("scene file", 16 * MIB);
    /// A model file (1 MiB): a bottle and a liquid, a few hundred bytes as `sake-glug fit`
    /// writes them.
    pub const MODEL: Self = Self::new("model file", MIB);
    /// A Standard MIDI File of a take (16 MiB): four million messages of about four bytes, over
    /// an hour of a control change every millisecond, far more than a tilt device sends.
    pub const MIDI_TAKE: Self = Self::new("MIDI take", 16 * MIB);
    /// A CSV log of a take (256 MiB): an hour of readings at 1 kHz with a time and three gravity
    /// columns (about 70 bytes a row) fits, and the text, held whole while it is read, stays a
    /// small part of a computer's memory.
    pub const CSV_LANE: Self = Self::new("CSV lane", 256 * MIB);
    /// A fit session (1 MiB): a list of recordings.
    pub const FIT_SESSION: Self = Self::new("session file", MIB);
    /// A recording to fit (4 GiB, the most a RIFF WAV file can hold).
    pub const RECORDING: Self = Self::new("recording", 4096 * MIB);
    /// A scale's weight log beside a recording (256 MiB, as a CSV lane).
    pub const WEIGHT_LOG: Self = Self::new("weight log", 256 * MIB);
    /// A study's spec (1 MiB).
    pub const STUDY_SPEC: Self = Self::new("study spec", MIB);
    /// A study's trial log (64 MiB: a row is under 200 bytes, a study a few thousand rows).
    pub const STUDY_LOG: Self = Self::new("study log", 64 * MIB);
    /// An actuator profile (64 KiB): a name, a few dozen [Hz, dB] points and their spread, with
    /// the comments that cite them.
    pub const ACTUATOR: Self = Self::new("actuator profile", 64 * 1024);
    /// A set's manifest of takes (16 MiB): a row of a few hundred bytes per take, at most
    /// 9,999 takes.
    pub const VARIATIONS: Self = Self::new("variations manifest", 16 * MIB);
    /// A file a render has just written, read back to measure what it holds (`--fidelity`) (4
    /// GiB, the most a RIFF WAV file can hold).
    pub const WRITTEN: Self = Self::new("file read back", 4096 * MIB);

    /// Every kind of input, for a test that tries each.
    pub const ALL: [Self; 12] = [
        Self::SCENE,
        Self::MODEL,
        Self::MIDI_TAKE,
        Self::CSV_LANE,
        Self::FIT_SESSION,
        Self::RECORDING,
        Self::WEIGHT_LOG,
        Self::STUDY_SPEC,
        Self::STUDY_LOG,
        Self::ACTUATOR,
        Self::VARIATIONS,
        Self::WRITTEN,
    ];

    const fn new(name: &'static str, max_bytes: u64) -> Self {
        Self { name, max_bytes }
    }
}

/// Why a file was not read (the file itself is named by whoever holds this).
#[derive(Debug, thiserror::Error)]
pub enum ReadFailure {
    /// Opening or reading it failed.
    #[error("{0}")]
    Io(#[from] io::Error),
    /// A FIFO, a device, a folder: reading it could block, never end or mean nothing.
    #[error("it is {0}, not a regular file")]
    NotAFile(&'static str),
    /// Larger than the limit, by its size on disk.
    #[error("it is {size} bytes, over the limit of {limit} bytes ({} MiB)", limit >> 20)]
    TooLarge {
        /// Its size (bytes).
        size: u64,
        /// The limit (bytes).
        limit: u64,
    },
    /// More bytes than the limit came out of it, whatever its size said.
    #[error("it holds more than the limit of {limit} bytes ({} MiB)", limit >> 20)]
    OverLimit {
        /// The limit (bytes).
        limit: u64,
    },
    /// Text that is not UTF-8.
    #[error("line {line} is not UTF-8 text")]
    NotText {
        /// The line, from 1.
        line: u64,
    },
}

/// A file that was not read: its kind, the file, and why.
#[derive(Debug, thiserror::Error)]
#[error("cannot read {} {}: {failure}", kind.name, printable(&path.to_string_lossy()))]
pub struct ReadError {
    /// What kind of input it was.
    pub kind: InputKind,
    /// The file.
    pub path: PathBuf,
    /// Why it was not read.
    pub failure: ReadFailure,
}

/// An input file, open, that yields at most its kind's limit: reading past it fails with
/// [`ReadFailure::OverLimit`] (as an `io::Error` whose inner error is that failure).
#[derive(Debug)]
pub struct InputReader {
    file: io::Take<File>,
    size: u64,
    limit: u64,
}

impl InputReader {
    /// Its size on disk when opened (bytes).
    pub fn size(&self) -> u64 {
        self.size
    }
}

impl Read for InputReader {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let read = self.file.read(buf)?;
        if read == 0 && !buf.is_empty() && self.file.limit() == 0 {
            // The one byte past the limit that `take` allows came out: the file holds more.
            return Err(io::Error::other(ReadFailure::OverLimit {
                limit: self.limit,
            }));
        }
        Ok(read)
    }
}

/// Opens the input file at `path` of `kind`: a regular file within its limit, else refused.
pub fn open(path: &Path, kind: InputKind) -> Result<InputReader, ReadError> {
    open_within(path, kind.max_bytes).map_err(|failure| ReadError {
        kind,
        path: path.to_owned(),
        failure,
    })
}

/// Every byte of the input file at `path` of `kind`.
pub fn read_bytes(path: &Path, kind: InputKind) -> Result<Vec<u8>, ReadError> {
    bytes_within(path, kind.max_bytes).map_err(|failure| ReadError {
        kind,
        path: path.to_owned(),
        failure,
    })
}

/// The text of the input file at `path` of `kind` (UTF-8).
pub fn read_text(path: &Path, kind: InputKind) -> Result<String, ReadError> {
    bytes_within(path, kind.max_bytes)
        .and_then(utf8_text)
        .map_err(|failure| ReadError {
            kind,
            path: path.to_owned(),
            failure,
        })
}

/// Every byte of the regular file at `path`, refused if it holds more than `limit` bytes.
pub fn bytes_within(path: &Path, limit: u64) -> Result<Vec<u8>, ReadFailure> {
    let file = open_within(path, limit)?;
    let mut bytes = Vec::with_capacity(file.size.min(limit) as usize);
    read_to_end(file, &mut bytes)?;
    Ok(bytes)
}

/// The text of the regular file at `path` (UTF-8), refused if over `limit` bytes.
pub fn text_within(path: &Path, limit: u64) -> Result<String, ReadFailure> {
    bytes_within(path, limit).and_then(utf8_text)
}

/// Reads `file` to its end, the limit's failure given back as itself.
fn read_to_end(mut file: InputReader, bytes: &mut Vec<u8>) -> Result<(), ReadFailure> {
    file.read_to_end(bytes).map_err(|error| {
        match error
            .get_ref()
            .and_then(|inner| inner.downcast_ref::<ReadFailure>())
        {
            Some(&ReadFailure::OverLimit { limit }) => ReadFailure::OverLimit { limit },
            _ => ReadFailure::Io(error),
        }
    })?;
    Ok(())
}

/// The regular file at `path`, opened without waiting, refused if over `limit` bytes.
pub fn open_within(path: &Path, limit: u64) -> Result<InputReader, ReadFailure> {
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    let metadata = file.metadata()?;
    if !metadata.is_file() {
        return Err(ReadFailure::NotAFile(kind_of(metadata.file_type())));
    }
    let size = metadata.len();
    if size > limit {
        return Err(ReadFailure::TooLarge { size, limit });
    }
    Ok(InputReader {
        // One byte past the limit tells a file that holds more from one that holds exactly it.
        file: file.take(limit + 1),
        size,
        limit,
    })
}

/// `bytes` as text, or the line (from 1) where they stop being UTF-8.
pub fn utf8_text(bytes: Vec<u8>) -> Result<String, ReadFailure> {
    String::from_utf8(bytes).map_err(|error| {
        let bytes = &error.as_bytes()[..error.utf8_error().valid_up_to()];
        let line = 1 + bytes.iter().filter(|&&byte| byte == b'\n').count() as u64;
        ReadFailure::NotText { line }
    })
}

/// What a file that is not a regular file is, for a message.
pub(crate) fn kind_of(file_type: FileType) -> &'static str {
    if file_type.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if file_type.is_char_device() || file_type.is_block_device() {
            return "a device";
        }
        if file_type.is_socket() {
            return "a socket";
        }
    }
    "a special file"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_input_file_is_read_up_to_its_limit() {
        let folder = tempfile::tempdir().unwrap();
        let path = folder.path().join("take.csv");
        std::fs::write(&path, "0123456789").unwrap();
        assert_eq!(bytes_within(&path, 10).unwrap(), b"0123456789");
        assert!(matches!(
            bytes_within(&path, 9),
            Err(ReadFailure::TooLarge { size: 10, limit: 9 })
        ));
    }

    #[cfg(target_os = "linux")]
    #[test]
    fn the_limit_holds_while_reading_a_file_larger_than_its_size_says() {
        // Files of /proc say they hold 0 bytes.
        let status = Path::new("/proc/self/status");
        assert_eq!(std::fs::metadata(status).unwrap().len(), 0);
        assert!(matches!(
            bytes_within(status, 16),
            Err(ReadFailure::OverLimit { limit: 16 })
        ));
    }

    #[cfg(unix)]
    #[test]
    fn a_fifo_and_a_device_are_refused_at_once() {
        let folder = tempfile::tempdir().unwrap();
        let fifo = folder.path().join("pipe");
        let name = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o600) }, 0);
        for kind in InputKind::ALL {
            let error = read_bytes(&fifo, kind).unwrap_err();
            assert!(
                matches!(error.failure, ReadFailure::NotAFile("a FIFO (named pipe)")),
                "{error}"
            );
            assert!(error
                .to_string()
                .starts_with(&format!("cannot read {} ", kind.name)));
            let error = read_bytes(Path::new("/dev/zero"), kind).unwrap_err();
            assert!(
                matches!(error.failure, ReadFailure::NotAFile("a device")),
                "{error}"
            );
        }
        assert!(matches!(
            text_within(folder.path(), 16),
            Err(ReadFailure::NotAFile("a folder"))
        ));
    }

    #[test]
    fn text_that_is_not_utf8_names_its_line() {
        assert!(matches!(
            utf8_text(b"a\nb\n\xff".to_vec()),
            Err(ReadFailure::NotText { line: 3 })
        ));
    }
}
