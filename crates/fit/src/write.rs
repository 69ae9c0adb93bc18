//! The fit's files, written all or none (as a render's are, through
//! [`PendingFile`](sake_glug_io::PendingFile)).

use std::io::Write;
use std::path::{Path, PathBuf};

use super::error::FitError;
use super::session_fit::SessionFit;
use sake_glug_io::PendingFile;

/// The files a fit writes.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct FitOutputs {
    /// The model of a session of one liquid.
    pub model: Option<PathBuf>,
    /// The folder of `<liquid>.toml`, one per liquid.
    pub out_dir: Option<PathBuf>,
    /// The markdown report.
    pub report: Option<PathBuf>,
    /// The PNG plot.
    pub plot: Option<PathBuf>,
    /// The units table (CSV).
    pub units: Option<PathBuf>,
    /// The comparison picture (PNG): the recording beside the model's render.
    pub compare: Option<PathBuf>,
}

/// Writes every file `outputs` asks for from `fit`; returns each file and its size. A session of
/// several liquids needs `out_dir`; one of one liquid takes either.
pub fn write_fit(fit: &SessionFit, outputs: &FitOutputs) -> Result<Vec<(PathBuf, u64)>, FitError> {
    let mut texts: Vec<(PathBuf, String)> = Vec::new();
    match (&outputs.model, &outputs.out_dir) {
        (Some(_), Some(_)) => {
            return Err(FitError::Outputs(
                "give either -o MODEL.toml or --out-dir DIR, not both".into(),
            ))
        }
        (Some(path), None) => match fit.liquids.as_slice() {
            [liquid] => texts.push((path.clone(), liquid.model_toml.clone())),
            liquids => {
                return Err(FitError::Outputs(format!(
                    "the session has {} liquids ({}): write one model each with --out-dir DIR",
                    liquids.len(),
                    liquids
                        .iter()
                        .map(|l| l.liquid.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                )))
            }
        },
        (None, Some(folder)) => {
            for liquid in &fit.liquids {
                texts.push((
                    folder.join(format!("{}.toml", liquid.liquid)),
                    liquid.model_toml.clone(),
                ));
            }
        }
        (None, None) => {}
    }
    if let Some(path) = &outputs.report {
        texts.push((path.clone(), super::report_markdown(fit)));
    }
    if let Some(path) = &outputs.units {
        texts.push((path.clone(), super::units_csv(fit)));
    }
    let mut files = Vec::new();
    for (path, text) in texts {
        let file = pending(&path, "")?;
        let written = file.writer().and_then(|mut writer| {
            writer.write_all(text.as_bytes())?;
            writer.flush()
        });
        written.map_err(|error| write_error(&path, error))?;
        files.push(file);
    }
    #[cfg(feature = "plot")]
    if let Some(path) = &outputs.plot {
        let file = pending(path, ".png")?;
        super::draw_fit_plot(fit, &file)?;
        files.push(file);
    }
    #[cfg(feature = "plot")]
    if let Some(path) = &outputs.compare {
        let file = pending(path, ".png")?;
        super::draw_compare_plot(fit, &file)?;
        files.push(file);
    }
    #[cfg(not(feature = "plot"))]
    if outputs.plot.is_some() || outputs.compare.is_some() {
        return Err(FitError::Outputs(
            "this build draws no plots (feature `plot`)".into(),
        ));
    }
    PendingFile::commit_all(files).map_err(|error| FitError::Write {
        path: PathBuf::from("the fit's files"),
        message: error.to_string(),
    })
}

fn pending(path: &Path, suffix: &str) -> Result<PendingFile, FitError> {
    if let Some(folder) = path.parent().filter(|f| !f.as_os_str().is_empty()) {
        std::fs::create_dir_all(folder).map_err(|error| write_error(path, error))?;
    }
    PendingFile::beside(path, suffix).map_err(|error| write_error(path, error))
}

fn write_error(path: &Path, error: std::io::Error) -> FitError {
    FitError::Write {
        path: path.to_owned(),
        message: error.to_string(),
    }
}
