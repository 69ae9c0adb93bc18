//! The dry run's folder: every trial's stimuli (two, or three in the triangle and ABX; the
//! practice trials' too) as mono 32-bit float WAV files, with the trial list, written all or
//! nothing (a temporary folder beside the target, renamed onto it).
//!
//! What it writes is known before it starts, and refused with the figure if the disk has not the
//! room; a session has at most [`MAX_TRIALS`](crate::MAX_TRIALS) trials, so a dry run at most
//! three times as many files and the list. A temporary folder that a killed dry run left is removed by
//! the next one to the same folder (it is named after its process, as every temporary file).

use std::fs::File;
use std::path::{Path, PathBuf};

use super::session::{Place, Presented, Presenter, Silent, StudySession};
use super::trials::Trial;
use super::StudyError;
use sake_glug_io::text::{csv_cell, printable};
use sake_glug_io::{remove_stale_temps, temp_dir_beside};
use sake_glug_render::human_bytes;

/// The trial list's name inside the folder.
pub const TRIAL_LIST: &str = "trials.csv";

/// The most a mono float WAV file's header takes (RIFF, `fmt ` with its extension, `fact`,
/// `data`): a stimulus's file is this and 4 bytes a sample.
const WAV_HEADER_BYTES: u64 = 100;

/// Whether the folder `dir` can take a dry run: it does not exist or is empty, and names a
/// folder. Checked before anything is rendered (issue 40), and again as the files are written.
pub fn check_dry_run_folder(dir: &Path) -> Result<(), StudyError> {
    let folder_error = |message: String| StudyError::DryRunFolder {
        path: dir.to_owned(),
        message,
    };
    if dir.exists() {
        let empty = std::fs::read_dir(dir)
            .map_err(|error| folder_error(error.to_string()))?
            .next()
            .is_none();
        if !empty {
            return Err(folder_error(
                "it is not an empty folder; name a new one".into(),
            ));
        }
    }
    if dir.file_name().is_none() {
        return Err(folder_error("it names no folder".into()));
    }
    Ok(())
}

/// The files of a dry run's folder: each trial's stimuli in the order played
/// (`trial-007-1-model.wav`, …; a practice trial's `practice-001-1-model.wav`, …), and the trial
/// list, which lists the study's trials.
#[derive(Debug, Clone, PartialEq)]
pub struct DryRunFiles {
    /// The folder.
    pub folder: PathBuf,
    /// Each practice trial's files, in the order played.
    pub practice: Vec<Vec<String>>,
    /// Each of the study's trials' files.
    pub trials: Vec<Vec<String>>,
}

impl DryRunFiles {
    /// The names `session`'s dry run into `folder` writes (and a resumed one wrote).
    pub fn planned(session: &StudySession, folder: &Path) -> Self {
        let names = |kind: &str, trials: &[Trial]| -> Vec<Vec<String>> {
            trials
                .iter()
                .enumerate()
                .map(|(index, trial)| {
                    trial
                        .played()
                        .zip(1..)
                        .map(|(stimulus, place)| {
                            format!(
                                "{kind}-{:03}-{place}-{}.wav",
                                index + 1,
                                file_safe(&session.spec.stimuli[stimulus].name)
                            )
                        })
                        .collect()
                })
                .collect()
        };
        Self {
            folder: folder.to_owned(),
            practice: names("practice", &session.practice()),
            trials: names("trial", session.trials),
        }
    }

    /// The files of the trial at `place`.
    pub fn of_place(&self, place: Place) -> &[String] {
        let trials = match place.practice {
            true => &self.practice,
            false => &self.trials,
        };
        &trials[place.number - 1]
    }

    /// How many files the folder holds: every trial's and the trial list.
    pub fn count(&self) -> usize {
        self.practice
            .iter()
            .chain(&self.trials)
            .map(Vec::len)
            .sum::<usize>()
            + 1
    }
}

/// Writes `session`'s files into the folder `dir`, which must not exist or be empty. Each
/// stimulus is written once and every trial's file is a hard link to it (a copy where the
/// file system has none), so a long session takes the room of its stimuli alone.
pub fn write_dry_run(
    dir: &Path,
    session: &StudySession,
    sample_rate: u32,
) -> Result<DryRunFiles, StudyError> {
    check_dry_run_folder(dir)?;
    let folder_error = |message: String| StudyError::DryRunFolder {
        path: dir.to_owned(),
        message,
    };
    let parent = match dir.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    let io = |path: &Path| {
        let path = path.to_owned();
        move |source| StudyError::Io { path, source }
    };
    let spec = session.spec;
    let files = DryRunFiles::planned(session, dir);
    let list = trial_list(session, &files)?;
    let practice = session.practice();
    // Every trial played, practice first, with its files.
    let played: Vec<(&Trial, &Vec<String>)> = practice
        .iter()
        .zip(&files.practice)
        .chain(session.trials.iter().zip(&files.trials))
        .collect();
    let stimulus_bytes: Vec<u64> = session
        .rendered
        .iter()
        .map(|rendered| WAV_HEADER_BYTES + 4 * rendered.samples.len() as u64)
        .collect();
    let room = |needed: u64, how: &str| match free_bytes(parent) {
        Some(free) if needed > free => Err(folder_error(format!(
            "{how} it needs {}, and its disk has {} free",
            human_bytes(needed),
            human_bytes(free)
        ))),
        _ => Ok(()),
    };
    room(
        stimulus_bytes.iter().sum::<u64>() + list.len() as u64,
        "its stimuli and trial list:",
    )?;
    remove_stale_temps(dir);
    let temp = temp_dir_beside(dir).map_err(|error| folder_error(error.to_string()))?;
    let mut stimulus_files = Vec::new();
    for (index, (stimulus, rendered)) in spec.stimuli.iter().zip(session.rendered).enumerate() {
        let path = temp.path().join(format!(
            ".stimulus-{index}-{}.wav",
            file_safe(&stimulus.name)
        ));
        let wav_spec = hound::WavSpec {
            channels: 1,
            sample_rate,
            bits_per_sample: 32,
            sample_format: hound::SampleFormat::Float,
        };
        let wav_error = |error: hound::Error| StudyError::Io {
            path: path.clone(),
            source: std::io::Error::other(error),
        };
        let mut writer = hound::WavWriter::create(&path, wav_spec).map_err(wav_error)?;
        for &sample in &rendered.samples {
            writer.write_sample(sample).map_err(wav_error)?;
        }
        writer.finalize().map_err(wav_error)?;
        File::open(&path)
            .and_then(|file| file.sync_all())
            .map_err(io(&path))?;
        stimulus_files.push(path);
    }
    let mut copies_checked = false;
    for &(trial, names) in &played {
        for (stimulus, name) in trial.played().zip(names) {
            let path = temp.path().join(name);
            let source = &stimulus_files[stimulus];
            if std::fs::hard_link(source, &path).is_err() {
                if !copies_checked {
                    // No links here: every trial's file is a copy.
                    let copies = played
                        .iter()
                        .map(|(trial, _)| {
                            trial
                                .played()
                                .map(|stimulus| stimulus_bytes[stimulus])
                                .sum::<u64>()
                        })
                        .sum::<u64>();
                    room(
                        copies,
                        "this file system has no hard links, so every trial's files are copies:",
                    )?;
                    copies_checked = true;
                }
                std::fs::copy(source, &path).map_err(io(&path))?;
            }
        }
    }
    for file in &stimulus_files {
        std::fs::remove_file(file).map_err(io(file))?;
    }
    let list_path = temp.path().join(TRIAL_LIST);
    std::fs::write(&list_path, list)
        .and_then(|()| File::open(&list_path)?.sync_all())
        .map_err(io(&list_path))?;
    // The names in the folder are durable before it is renamed into place.
    File::open(temp.path())
        .and_then(|folder| folder.sync_all())
        .map_err(io(temp.path()))?;
    // rename(2) replaces an empty folder; a folder that gained files since is refused by it.
    std::fs::rename(temp.path(), dir).map_err(|error| folder_error(error.to_string()))?;
    // Renamed: nothing left for the guard to remove.
    let _ = temp.keep();
    Ok(files)
}

/// The trial list's bytes: a row per trial of the study, its stimuli and their `files`.
fn trial_list(session: &StudySession, files: &DryRunFiles) -> Result<Vec<u8>, StudyError> {
    let spec = session.spec;
    let mut list = csv::Writer::from_writer(Vec::new());
    let list_error = |error: csv::Error| StudyError::Io {
        path: files.folder.join(TRIAL_LIST),
        source: error.into(),
    };
    list.write_record([
        "trial",
        "first",
        "second",
        "first_file",
        "second_file",
        "first_gain_db",
        "second_gain_db",
        "third",
        "third_file",
        "third_gain_db",
    ])
    .map_err(list_error)?;
    for (index, (trial, names)) in session.trials.iter().zip(&files.trials).enumerate() {
        // The names are the spec's: a spreadsheet shows them as text, never runs them.
        let name = |stimulus: usize| csv_cell(&spec.stimuli[stimulus].name).into_owned();
        let gain = |stimulus: usize| session.rendered[stimulus].gain_db.to_string();
        list.write_record([
            (index + 1).to_string(),
            name(trial.first),
            name(trial.second),
            names[0].clone(),
            names[1].clone(),
            gain(trial.first),
            gain(trial.second),
            trial.third.map(name).unwrap_or_default(),
            names.get(2).cloned().unwrap_or_default(),
            trial.third.map(gain).unwrap_or_default(),
        ])
        .map_err(list_error)?;
    }
    Ok(list.into_inner().expect("a Vec never fails"))
}

/// The bytes an ordinary user may still write on the file system of `folder`; `None` where the
/// system does not say.
fn free_bytes(folder: &Path) -> Option<u64> {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let name = std::ffi::CString::new(folder.as_os_str().as_bytes()).ok()?;
        let mut stats = std::mem::MaybeUninit::<libc::statvfs>::uninit();
        // SAFETY: `name` is a NUL-terminated path and `stats` is written by a successful call.
        if unsafe { libc::statvfs(name.as_ptr(), stats.as_mut_ptr()) } != 0 {
            return None;
        }
        let stats = unsafe { stats.assume_init() };
        #[allow(
            clippy::unnecessary_cast,
            reason = "the fields are narrower than u64 on some systems"
        )]
        Some((stats.f_bavail as u64).saturating_mul(stats.f_frsize as u64))
    }
    #[cfg(not(unix))]
    {
        let _ = folder;
        None
    }
}

/// A stimulus name as a file name: what is not a letter, digit, `-`, `_`, `=` or `.` becomes
/// `_`, cut to 64 characters (a name is at most 255 bytes, and the spec's names may be longer).
fn file_safe(name: &str) -> String {
    const MAX_CHARS: usize = 64;
    name.chars()
        .take(MAX_CHARS)
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_=.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// A dry run: plays nothing, and cues each trial with the files of its folder to play by hand.
#[derive(Debug)]
pub struct DryRun<'a>(pub &'a DryRunFiles);

impl Presenter for DryRun<'_> {
    fn present(&mut self, trial: Trial) -> Result<Presented, StudyError> {
        Silent.present(trial)
    }

    fn cue(&self, place: Place) -> String {
        format!(
            "play {} (in {})…",
            self.0.of_place(place).join(", then "),
            printable(&self.0.folder.to_string_lossy())
        )
    }
}
