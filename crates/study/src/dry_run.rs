//! The dry run's folder: every trial's two stimuli as mono 32-bit float WAV files, with the
//! trial list, written all or nothing (a temporary folder beside the target, renamed onto it).

use std::path::{Path, PathBuf};

use super::session::StudySession;
use super::StudyError;

/// The trial list's name inside the folder.
pub const TRIAL_LIST: &str = "trials.csv";

/// Writes `session`'s files into the folder `dir`, which must not exist or be empty. Each
/// stimulus is written once and every trial's file is a hard link to it (a copy where the
/// file system has none), so a long session takes the room of its stimuli alone.
pub fn write_dry_run(
    dir: &Path,
    session: &StudySession,
    sample_rate: u32,
) -> Result<Vec<PathBuf>, StudyError> {
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
    let parent = match dir.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    let name = dir
        .file_name()
        .ok_or_else(|| folder_error("it names no folder".into()))?;
    let temp = sake_glug_io::temp::temp_file_builder()
        .prefix(&format!(".{}.sake-glug-", name.to_string_lossy()))
        .suffix(".tmp")
        .tempdir_in(parent)
        .map_err(|error| folder_error(error.to_string()))?;
    let io = |path: &Path| {
        let path = path.to_owned();
        move |source| StudyError::Io { path, source }
    };
    let spec = session.spec;
    let mut stimulus_files = Vec::new();
    for (stimulus, rendered) in spec.stimuli.iter().zip(session.rendered) {
        let path = temp
            .path()
            .join(format!(".stimulus-{}.wav", file_safe(&stimulus.name)));
        let spec = hound::WavSpec {
            channels: 1,
            sample_rate,
            bits_per_sample: 32,
            sample_format: hound::SampleFormat::Float,
        };
        let wav_error = |error: hound::Error| StudyError::Io {
            path: path.clone(),
            source: std::io::Error::other(error),
        };
        let mut writer = hound::WavWriter::create(&path, spec).map_err(wav_error)?;
        for &sample in &rendered.samples {
            writer.write_sample(sample).map_err(wav_error)?;
        }
        writer.finalize().map_err(wav_error)?;
        stimulus_files.push(path);
    }
    let mut list = csv::Writer::from_writer(Vec::new());
    let list_error = |error: csv::Error| StudyError::Io {
        path: dir.join(TRIAL_LIST),
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
    ])
    .map_err(list_error)?;
    let mut written = Vec::new();
    for (index, trial) in session.trials.iter().enumerate() {
        let mut files = Vec::new();
        for (place, stimulus) in [(1, trial.first), (2, trial.second)] {
            let file = format!(
                "trial-{:03}-{place}-{}.wav",
                index + 1,
                file_safe(&spec.stimuli[stimulus].name)
            );
            let path = temp.path().join(&file);
            std::fs::hard_link(&stimulus_files[stimulus], &path)
                .or_else(|_| std::fs::copy(&stimulus_files[stimulus], &path).map(drop))
                .map_err(io(&path))?;
            written.push(dir.join(&file));
            files.push(file);
        }
        list.write_record([
            (index + 1).to_string(),
            spec.stimuli[trial.first].name.clone(),
            spec.stimuli[trial.second].name.clone(),
            files[0].clone(),
            files[1].clone(),
            session.rendered[trial.first].gain_db.to_string(),
            session.rendered[trial.second].gain_db.to_string(),
        ])
        .map_err(list_error)?;
    }
    for file in &stimulus_files {
        std::fs::remove_file(file).map_err(io(file))?;
    }
    let list_path = temp.path().join(TRIAL_LIST);
    std::fs::write(&list_path, list.into_inner().expect("a Vec never fails"))
        .map_err(io(&list_path))?;
    written.push(dir.join(TRIAL_LIST));
    // rename(2) replaces an empty folder; a folder that gained files since is refused by it.
    std::fs::rename(temp.path(), dir).map_err(|error| folder_error(error.to_string()))?;
    // Renamed: nothing left for the guard to remove.
    let _ = temp.keep();
    Ok(written)
}

/// A stimulus name as a file name: what is not a letter, digit, `-`, `_`, `=` or `.` becomes
/// `_`.
fn file_safe(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "-_=.".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect()
}
