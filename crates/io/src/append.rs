//! Files appended to row by row instead of written all or nothing (the study's trial log, which
//! must keep every answer as it comes): opened for appending only (`O_APPEND`: every write lands
//! at the end, whoever else writes), without waiting, and a regular file only.

use std::fs::{File, OpenOptions};
use std::io;
use std::path::Path;

use crate::pending::made_folder_of;
use crate::read::kind_of;

/// The regular file at `path`, open to read and to append: created (its folder too, as every
/// written file's, [`made_folder_of`]), and refused if it exists, when `new`; else an existing
/// one. A FIFO, a device or a folder is refused at once, since the
/// opened file is checked, and opening does not wait (`O_NONBLOCK`: a FIFO opened to write waits
/// for a reader without it); the error then says what it is (`InvalidInput`).
pub fn open_to_append(path: &Path, new: bool) -> io::Result<File> {
    let mut options = OpenOptions::new();
    options.read(true).append(true).create_new(new);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    if new {
        made_folder_of(path)?;
    }
    let file = options.open(path)?;
    let file_type = file.metadata()?.file_type();
    if !file_type.is_file() {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("it is {}, not a regular file", kind_of(file_type)),
        ));
    }
    Ok(file)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::{Read, Seek, SeekFrom, Write};

    #[test]
    fn rows_land_at_the_end_and_only_regular_files_open() {
        let folder = tempfile::tempdir().unwrap();
        let log = folder.path().join("log.csv");
        open_to_append(&log, true)
            .unwrap()
            .write_all(b"a\n")
            .unwrap();
        assert!(open_to_append(&log, true).is_err(), "a new log exists");
        let mut file = open_to_append(&log, false).unwrap();
        let mut text = String::new();
        file.read_to_string(&mut text).unwrap();
        // Appended after a seek to the start all the same.
        file.seek(SeekFrom::Start(0)).unwrap();
        file.write_all(b"b\n").unwrap();
        assert_eq!(std::fs::read_to_string(&log).unwrap(), "a\nb\n");
        #[cfg(unix)]
        {
            let fifo = folder.path().join("pipe");
            let name = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
            assert_eq!(unsafe { libc::mkfifo(name.as_ptr(), 0o600) }, 0);
            for path in [fifo.as_path(), Path::new("/dev/null")] {
                let error = open_to_append(path, false).unwrap_err();
                assert!(error.to_string().contains("not a regular file"), "{error}");
            }
            // A folder cannot be opened to write at all.
            assert!(open_to_append(folder.path(), false).is_err());
        }
    }
}
