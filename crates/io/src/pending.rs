//! Files written all or nothing: each in a temporary file beside its target, and the targets
//! replaced together once every file of the render is complete, or none of them.
//!
//! A temporary file is named after its target and this process (see [`temp_file_beside`]), so
//! that one left by a render killed outright (`kill -9`, a power cut) is recognised and removed
//! by the next render to the same target once its process is gone. Dropped uncommitted (an
//! error, an interruption), it is removed at once.

use std::fs::{self, File};
use std::io::{self, BufWriter};
use std::path::{Path, PathBuf};

use tempfile::NamedTempFile;

use crate::temp::temp_file_builder;

/// A file that could not be written, and why.
#[derive(Debug, thiserror::Error)]
#[error("cannot write {}: {source}", path.display())]
pub struct WriteError {
    /// The file asked for.
    pub path: PathBuf,
    /// What the file system said.
    pub source: io::Error,
}

impl WriteError {
    /// The file system refused `path`.
    pub fn at(path: &Path) -> impl FnOnce(io::Error) -> Self + '_ {
        move |source| Self {
            path: path.to_owned(),
            source,
        }
    }
}

/// A file being written in a temporary file beside its target, which it replaces when
/// committed with the others of its render ([`PendingFile::commit_all`]).
pub struct PendingFile {
    path: PathBuf,
    temp: NamedTempFile,
}

impl PendingFile {
    /// An empty temporary file in the target's folder (so that the rename is atomic), its name
    /// ending in `suffix` where a library infers the format from the name. A target that is a
    /// folder is refused here, before anything is rendered.
    pub fn beside(path: &Path, suffix: &str) -> io::Result<Self> {
        if is_folder(path) {
            return Err(folder_error());
        }
        Ok(Self {
            path: path.to_owned(),
            temp: temp_file_beside(path, suffix)?,
        })
    }

    /// The file asked for.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The temporary file, for a library that writes to a path (plotters).
    pub fn temp_path(&self) -> &Path {
        self.temp.path()
    }

    /// A buffered writer at the start of the temporary file.
    pub fn writer(&self) -> io::Result<BufWriter<File>> {
        Ok(BufWriter::new(self.temp.reopen()?))
    }

    /// Replaces every target with its complete file, all or nothing; returns each target and
    /// its size in bytes.
    ///
    /// Every file is synced first, and the folders are locked so that two renders' commits into
    /// them run one after the other (their sets never mix). Every target is checked before the
    /// first is replaced (a folder is refused), and each existing one keeps its permissions
    /// (and its owner, where the system lets the renderer set it: as root) and is kept aside
    /// (a hard link, else a rename) until all are replaced: if one replacement still fails,
    /// the ones done are undone, and no target has changed. Replacing gives a target a new
    /// inode: other hard links to it keep the old file.
    pub fn commit_all(files: Vec<Self>) -> Result<Vec<(PathBuf, u64)>, WriteError> {
        let mut sizes = Vec::with_capacity(files.len());
        for file in &files {
            let temp = file.temp.as_file();
            temp.sync_all()
                .and_then(|()| temp.metadata())
                .map(|meta| sizes.push((file.path.clone(), meta.len())))
                .map_err(WriteError::at(&file.path))?;
        }
        let folders = lock_folders(files.iter().map(|file| file.path.as_path()));
        let targets = files
            .iter()
            .map(|file| file.prepare().map_err(WriteError::at(&file.path)))
            .collect::<Result<Vec<_>, _>>()?;
        let mut tried = Vec::with_capacity(files.len());
        for (file, mut target) in files.into_iter().zip(targets) {
            let path = file.path.clone();
            let result = file.replace(&mut target);
            // The one that failed too: its target may be aside already.
            tried.push((path.clone(), target));
            if let Err(source) = result {
                for (path, target) in tried.into_iter().rev() {
                    target.restore(&path);
                }
                return Err(WriteError { path, source });
            }
        }
        // The renames themselves are durable once their folders are synced.
        for folder in &folders {
            let _ = folder.sync_all();
        }
        Ok(sizes)
    }

    /// Checks that the target can be replaced and gives the file the target's permissions and
    /// owner; keeps an existing target aside by a hard link where the file system has them.
    fn prepare(&self) -> io::Result<Target> {
        let existing = match fs::symlink_metadata(&self.path) {
            Ok(meta) => Some(meta),
            Err(error) if error.kind() == io::ErrorKind::NotFound => None,
            Err(error) => return Err(error),
        };
        if existing.as_ref().is_some_and(fs::Metadata::is_dir) {
            return Err(folder_error());
        }
        if let Some(meta) = existing.as_ref().filter(|meta| meta.is_file()) {
            keep_owner_and_mode(self.temp.path(), meta)?;
        }
        let backup = match existing {
            Some(_) => backup_of(&self.path, |target, backup| fs::hard_link(target, backup)).ok(),
            None => None,
        };
        Ok(Target {
            existed: existing.is_some(),
            backup,
            moved_aside: false,
            replaced: false,
        })
    }

    /// Renames the file over its target (moving an existing target aside first if it could not
    /// be linked).
    fn replace(self, target: &mut Target) -> io::Result<()> {
        if target.existed && target.backup.is_none() {
            target.backup = Some(backup_of(&self.path, |target, backup| {
                fs::rename(target, backup)
            })?);
            target.moved_aside = true;
        }
        self.temp.persist(&self.path).map_err(|error| error.error)?;
        target.replaced = true;
        Ok(())
    }
}

/// What a commit keeps of one target until every target is replaced.
struct Target {
    /// There was a file (or link) at the target.
    existed: bool,
    /// The previous target, under another name, removed when dropped.
    backup: Option<NamedTempFile<()>>,
    /// The backup was renamed from the target, not linked: the target is gone.
    moved_aside: bool,
    /// The new file is in place.
    replaced: bool,
}

impl Target {
    /// Puts back what was at `path` before the commit.
    fn restore(self, path: &Path) {
        match self.backup {
            // A rename onto another link of the same file would do nothing and leave both: a
            // link beside an untouched target is only removed, as dropping it does.
            Some(backup) if self.replaced || self.moved_aside => {
                let _ = backup.persist(path);
            }
            Some(_) => {}
            None if self.replaced => {
                let _ = fs::remove_file(path);
            }
            None => {}
        }
    }
}

/// A new empty temporary file beside `target`, named `.<target>.sake-glug-<pid>.<random>.tmp`
/// and then `suffix`: hidden, after its target, and with the process that writes it, so that
/// [`remove_stale_temps`] can tell one left by a process that is gone.
pub fn temp_file_beside(target: &Path, suffix: &str) -> io::Result<NamedTempFile> {
    let prefix = own_prefix(target);
    let suffix = format!(".tmp{suffix}");
    let mut builder: tempfile::Builder = temp_file_builder();
    builder
        .prefix(&prefix)
        .suffix(&suffix)
        .tempfile_in(made_folder_of(target)?)
        .map_err(without_temp_name)
}

/// A new empty temporary folder beside the folder `target`, named as [`temp_file_beside`] names a
/// file (so that [`remove_stale_temps`] removes one a killed process left), with the permissions
/// any new folder gets (0o777 less the umask), to be filled and renamed onto `target`.
pub fn temp_dir_beside(target: &Path) -> io::Result<tempfile::TempDir> {
    let prefix = own_prefix(target);
    let mut builder = tempfile::Builder::new();
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(fs::Permissions::from_mode(0o777));
    }
    builder
        .prefix(&prefix)
        .suffix(".tmp")
        .tempdir_in(made_folder_of(target)?)
        .map_err(without_temp_name)
}

/// The previous target kept under a name like its temporary file's (ending in `.old`), made by
/// `keep` (a hard link or a rename) at the path it is given.
fn backup_of(
    target: &Path,
    keep: impl Fn(&Path, &Path) -> io::Result<()>,
) -> io::Result<NamedTempFile<()>> {
    let prefix = own_prefix(target);
    let mut builder: tempfile::Builder = tempfile::Builder::new();
    builder
        .prefix(&prefix)
        .suffix(".old")
        .make_in(folder_of(target), |backup| keep(target, backup))
}

/// How the names of this process's files beside `target` begin.
fn own_prefix(target: &Path) -> String {
    format!("{}{}.", sibling_prefix(target), std::process::id())
}

/// `.<target's name>.sake-glug-`, the name cut short enough to leave room for the rest.
fn sibling_prefix(target: &Path) -> String {
    const MAX_NAME_BYTES: usize = 100;
    let name = target
        .file_name()
        .map_or("output".into(), |name| name.to_string_lossy());
    let mut end = name.len().min(MAX_NAME_BYTES);
    while !name.is_char_boundary(end) {
        end -= 1;
    }
    format!(".{}.sake-glug-", &name[..end])
}

/// Removes this process's temporary files beside `target`, for a process that is to end at once,
/// without dropping them (a second stop signal). Not the backup of a target that a commit keeps
/// (`.old`): a commit cut short may still need it, and the next render to the target removes it.
pub fn remove_own_temps(target: &Path) {
    let Ok(entries) = fs::read_dir(folder_of(target)) else {
        return;
    };
    let prefix = own_prefix(target);
    for entry in entries.flatten() {
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if name.starts_with(&prefix) && !name.ends_with(".old") {
            let _ = fs::remove_file(entry.path());
        }
    }
}

/// Removes the files (and the folders of [`temp_dir_beside`]) a process killed outright left
/// beside `target` (their process is gone); returns those it cannot tell about (where the system
/// does not say which processes run), for the caller to name.
pub fn remove_stale_temps(target: &Path) -> Vec<PathBuf> {
    let Ok(entries) = fs::read_dir(folder_of(target)) else {
        return Vec::new();
    };
    let prefix = sibling_prefix(target);
    let mut unknown = Vec::new();
    for entry in entries.flatten() {
        let name = entry.file_name();
        let pid = name
            .to_string_lossy()
            .strip_prefix(&prefix)
            .and_then(|rest| rest.split_once('.'))
            .and_then(|(pid, _)| pid.parse::<u32>().ok());
        let Some(pid) = pid.filter(|&pid| pid != std::process::id()) else {
            continue;
        };
        // Not followed: a link is nobody's temporary file.
        let Ok(kind) = entry.file_type() else {
            continue;
        };
        if !kind.is_file() && !kind.is_dir() {
            continue;
        }
        match process_alive(pid) {
            Some(false) if kind.is_dir() => {
                let _ = fs::remove_dir_all(entry.path());
            }
            Some(false) => {
                let _ = fs::remove_file(entry.path());
            }
            Some(true) => {}
            None => unknown.push(entry.path()),
        }
    }
    unknown
}

/// Whether process `pid` runs, where the system says (a `/proc` file system).
fn process_alive(pid: u32) -> Option<bool> {
    let proc = Path::new("/proc");
    proc.join("self")
        .exists()
        .then(|| proc.join(pid.to_string()).exists())
}

/// The folder a target is in.
fn folder_of(target: &Path) -> &Path {
    match target.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    }
}

/// The folder `target` is written in, made (with its parents) if it is missing: every command
/// that writes a file makes its folder, as `--out-dir` does. Refused, naming the folder.
pub fn made_folder_of(target: &Path) -> io::Result<&Path> {
    let folder = folder_of(target);
    fs::create_dir_all(folder).map_err(|error| {
        io::Error::new(
            error.kind(),
            format!("cannot make its folder {}: {error}", folder.display()),
        )
    })?;
    Ok(folder)
}

/// The file system's error without the name of the temporary file it was about, a hidden name
/// the user never asked for (the caller names the target). The `tempfile` crate appends it as
/// ` at path "…"` to the system's own words, and keeps no other way to them.
fn without_temp_name(error: io::Error) -> io::Error {
    let text = error.to_string();
    match text.rsplit_once(" at path ") {
        Some((cause, _)) => io::Error::new(error.kind(), cause.to_owned()),
        None => error,
    }
}

fn is_folder(path: &Path) -> bool {
    fs::symlink_metadata(path).is_ok_and(|meta| meta.is_dir())
}

fn folder_error() -> io::Error {
    io::Error::new(io::ErrorKind::IsADirectory, "it is a folder, not a file")
}

/// Gives `file` the permissions of the target `meta` is of, and its owner where the system
/// lets this process set it (only root may give a file away; an owner may still set the group).
fn keep_owner_and_mode(file: &Path, meta: &fs::Metadata) -> io::Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::{chown, MetadataExt};
        let ours = fs::metadata(file)?;
        if (ours.uid(), ours.gid()) != (meta.uid(), meta.gid())
            && chown(file, Some(meta.uid()), Some(meta.gid())).is_err()
        {
            let _ = chown(file, None, Some(meta.gid()));
        }
    }
    fs::set_permissions(file, meta.permissions())
}

/// Opens and locks (advisory, shared by every render) the folder of each target, each folder
/// once and in one order, so that two commits never wait on each other. A folder that cannot be
/// opened or locked is not locked: the lock orders commits, it is not needed to write.
fn lock_folders<'a>(targets: impl Iterator<Item = &'a Path>) -> Vec<File> {
    let mut folders: Vec<PathBuf> = targets
        .filter_map(|target| folder_of(target).canonicalize().ok())
        .collect();
    folders.sort();
    folders.dedup();
    folders
        .iter()
        .filter_map(|folder| File::open(folder).ok())
        .inspect(|folder| {
            let _ = folder.lock();
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn pending(path: &Path, text: &str) -> PendingFile {
        let file = PendingFile::beside(path, "").unwrap();
        let mut writer = file.writer().unwrap();
        writer.write_all(text.as_bytes()).unwrap();
        writer.flush().unwrap();
        file
    }

    fn names(folder: &Path) -> Vec<String> {
        let mut names: Vec<String> = fs::read_dir(folder)
            .unwrap()
            .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }

    /// The second rename fails (its temporary file was replaced behind the render's back): the
    /// first target, already replaced, is put back, the second is as it was, the third is not
    /// written, and nothing is left beside them.
    /// A target in a folder that is missing is written there, the folder made; one whose
    /// folder cannot be made, or that cannot take a file, is refused naming the folder, never
    /// the hidden temporary file (issue 49: `".pour_01.wav.sake-glug-8131….tmp"`).
    #[test]
    fn a_missing_folder_is_made_and_a_refusal_names_no_temporary_file() {
        let folder = tempfile::tempdir().unwrap();
        let target = folder.path().join("out/takes/pour.wav");
        PendingFile::commit_all(vec![pending(&target, "glug")]).unwrap();
        assert_eq!(fs::read_to_string(&target).unwrap(), "glug");

        let obstacle = folder.path().join("a-file");
        fs::write(&obstacle, "").unwrap();
        let error = PendingFile::beside(&obstacle.join("out/pour.wav"), "")
            .err()
            .unwrap()
            .to_string();
        assert!(
            error.contains(&format!(
                "cannot make its folder {}",
                obstacle.join("out").display()
            )),
            "{error}"
        );
        // A folder that takes no file (as root, only /proc refuses one).
        for target in [Path::new("/proc/pour.wav"), &obstacle.join("pour.wav")] {
            for error in [
                PendingFile::beside(target, "").err().map(|e| e.to_string()),
                temp_dir_beside(target).err().map(|e| e.to_string()),
            ] {
                let error = error.unwrap();
                // (Every temporary file's name holds `.sake-glug-`: `temp_file_beside`.)
                assert!(!error.contains(".sake-glug-"), "{error}");
            }
        }
    }

    #[test]
    fn a_failed_replacement_puts_back_the_ones_done() {
        let folder = tempfile::tempdir().unwrap();
        let [kept, failing, added] =
            ["keep.wav", "keep.csv", "new.haptic"].map(|name| folder.path().join(name));
        fs::write(&kept, "old").unwrap();
        fs::write(&failing, "old").unwrap();
        let files = vec![
            pending(&kept, "new"),
            pending(&failing, "new"),
            pending(&added, "new"),
        ];
        // A folder where the second file was: its rename is the one that fails.
        let obstacle = files[1].temp.path().to_owned();
        fs::remove_file(&obstacle).unwrap();
        fs::create_dir(&obstacle).unwrap();
        let error = PendingFile::commit_all(files).unwrap_err();
        fs::remove_dir(&obstacle).unwrap();
        assert!(error.to_string().contains("keep.csv"), "{error}");
        assert_eq!(fs::read_to_string(&kept).unwrap(), "old");
        assert_eq!(fs::read_to_string(&failing).unwrap(), "old");
        assert_eq!(names(folder.path()), ["keep.csv", "keep.wav"]);
    }

    #[test]
    fn a_replaced_target_keeps_its_mode_and_nothing_is_left_beside_it() {
        use std::os::unix::fs::PermissionsExt;
        let folder = tempfile::tempdir().unwrap();
        let target = folder.path().join("private.wav");
        fs::write(&target, "old").unwrap();
        fs::set_permissions(&target, fs::Permissions::from_mode(0o600)).unwrap();
        PendingFile::commit_all(vec![pending(&target, "new")]).unwrap();
        assert_eq!(fs::read_to_string(&target).unwrap(), "new");
        let mode = fs::metadata(&target).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o600, "mode {mode:o}");
        assert_eq!(names(folder.path()), ["private.wav"]);
    }

    #[test]
    fn only_the_temporary_files_of_processes_that_are_gone_are_removed() {
        let folder = tempfile::tempdir().unwrap();
        let target = folder.path().join("pour.wav");
        // No process has a pid this large (Linux's limit is 2^22).
        let dead = folder
            .path()
            .join(".pour.wav.sake-glug-4294967290.a1b2c3.tmp");
        let alive = folder.path().join(format!(
            ".pour.wav.sake-glug-{}.d4e5f6.tmp",
            std::process::id()
        ));
        let other = folder
            .path()
            .join(".other.wav.sake-glug-4294967290.a1b2c3.tmp");
        for file in [&dead, &alive, &other] {
            fs::write(file, "").unwrap();
        }
        assert!(remove_stale_temps(&target).is_empty());
        assert!(!dead.exists() && alive.exists() && other.exists());
    }

    #[test]
    fn a_temporary_folder_can_be_filled_and_a_dead_ones_is_removed() {
        use std::os::unix::fs::PermissionsExt;
        let folder = tempfile::tempdir().unwrap();
        let target = folder.path().join("dry");
        let temp = temp_dir_beside(&target).unwrap();
        let mode = fs::metadata(temp.path()).unwrap().permissions().mode();
        assert_eq!(mode & 0o100, 0o100, "searchable by its owner: {mode:o}");
        let dead = folder.path().join(".dry.sake-glug-4294967290.a1b2c3.tmp");
        fs::create_dir(&dead).unwrap();
        fs::write(dead.join("trial-001-1-a.wav"), "").unwrap();
        assert!(remove_stale_temps(&target).is_empty());
        assert!(!dead.exists() && temp.path().exists());
    }
}
