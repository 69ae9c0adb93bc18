//! One render, many files: the WAV, the CSV of samples, the `.haptic` and `.ahap` clips and the
//! pour plot are all written from the same pass (the same units and samples), all or nothing.
//!
//! Every file goes to a temporary file beside its target first and replaces the target only
//! once every file of the render is complete, so a failed render leaves no partial file.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use tempfile::NamedTempFile;

use super::clips::{self, ClipSource, Glug, HapticBand};
use super::render::{render_scene, RenderError, RenderObserver, RenderSummary};
use super::scene::Scene;
use super::wav::{SampleFormat, WavError, WavFile};
use crate::engine::UnitOnset;
use crate::files::temp_file_builder;

/// A kind of file a render writes, chosen by the file's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OutputFormat {
    /// `.wav`: the mono output, for an actuator driven from an audio interface.
    Wav,
    /// `.haptic`: a Meta Haptics Studio 1.0 clip.
    Haptic,
    /// `.ahap`: an Apple Core Haptics pattern.
    Ahap,
    /// `.csv`: one sample per line, no header (Syntacts' format).
    Csv,
    /// `.png`: the pour plot (feature `plot`).
    Plot,
}

impl OutputFormat {
    /// Every format with its extension.
    pub const ALL: [(OutputFormat, &'static str); 5] = [
        (OutputFormat::Wav, "wav"),
        (OutputFormat::Haptic, "haptic"),
        (OutputFormat::Ahap, "ahap"),
        (OutputFormat::Csv, "csv"),
        (OutputFormat::Plot, "png"),
    ];

    /// The format of an extension (without the dot, any case).
    pub fn of_extension(extension: &str) -> Option<Self> {
        let extension = extension.to_ascii_lowercase();
        Self::ALL
            .iter()
            .find(|(_, known)| *known == extension)
            .map(|(format, _)| *format)
    }

    /// The format of a file, by its extension; an unknown or missing one is refused.
    pub fn of_path(path: &Path) -> Result<Self, OutputError> {
        path.extension()
            .and_then(|extension| extension.to_str())
            .and_then(Self::of_extension)
            .ok_or_else(|| OutputError::UnknownFormat {
                path: path.to_owned(),
            })
    }

    /// The extension files of this format get.
    pub fn extension(self) -> &'static str {
        Self::ALL
            .iter()
            .find(|(format, _)| *format == self)
            .map_or("", |(_, extension)| extension)
    }
}

/// Why the files of a render could not be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// An output's extension names no format the renderer writes.
    #[error(
        "{}: unknown output format; the extension must be .wav, .haptic, .ahap, .csv or .png",
        path.display()
    )]
    UnknownFormat {
        /// The output asked for.
        path: PathBuf,
    },
    /// The render itself failed.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// A WAV file could not be written.
    #[error(transparent)]
    Wav(#[from] WavError),
    /// Another file could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Io {
        /// The file asked for.
        path: PathBuf,
        /// What the file system said.
        source: std::io::Error,
    },
    /// The pour plot could not be drawn.
    #[cfg(feature = "plot")]
    #[error(transparent)]
    Plot(#[from] super::plot::PlotError),
    /// A plot was asked for from a build without the `plot` feature.
    #[cfg(not(feature = "plot"))]
    #[error("{}: this build draws no plots (feature `plot`)", path.display())]
    NoPlot {
        /// The plot asked for.
        path: PathBuf,
    },
}

/// How the files of a render are written.
#[derive(Debug, Clone, Copy, Default)]
pub struct OutputOptions {
    /// Sample format of WAV files.
    pub wav_format: SampleFormat,
    /// The actuator band the `.haptic` frequencies map to.
    pub haptic_band: HapticBand,
}

/// What a render wrote.
#[derive(Debug, Clone)]
pub struct RenderReport {
    /// The render itself.
    pub summary: RenderSummary,
    /// Audible glugs (those the clips mark).
    pub audible_glugs: usize,
    /// Amplitude breakpoints of the felt envelope written to the clips (0 when the render wrote
    /// no `.haptic`, `.ahap` or plot).
    pub envelope_breakpoints: usize,
    /// Each file written, with its size in bytes.
    pub files: Vec<(PathBuf, u64)>,
}

/// Renders `scene` once and writes every file of `outputs` from that pass. `scene_name` goes
/// into the clips' metadata; `progress` hears the samples rendered so far.
pub fn render_to_files(
    scene: &Scene,
    scene_name: &str,
    outputs: &[PathBuf],
    options: &OutputOptions,
    progress: impl FnMut(u64),
) -> Result<RenderReport, OutputError> {
    let formats = outputs
        .iter()
        .map(|path| OutputFormat::of_path(path))
        .collect::<Result<Vec<_>, _>>()?;
    let wants = |format| formats.contains(&format);
    // A render that is known to be too long for a WAV file is refused before it starts.
    if let Some(samples) = scene.duration_samples() {
        for (path, _) in outputs
            .iter()
            .zip(&formats)
            .filter(|(_, f)| **f == OutputFormat::Wav)
        {
            WavFile::check_length(path, samples, scene.sample_rate, options.wav_format)?;
        }
    }
    #[cfg(not(feature = "plot"))]
    if let Some((path, _)) = outputs
        .iter()
        .zip(&formats)
        .find(|(_, f)| **f == OutputFormat::Plot)
    {
        return Err(OutputError::NoPlot { path: path.clone() });
    }

    let mut wavs = Vec::new();
    let mut csvs = Vec::new();
    for (path, format) in outputs.iter().zip(&formats) {
        match format {
            OutputFormat::Wav => wavs.push(WavFile::create(
                path,
                scene.sample_rate,
                options.wav_format,
            )?),
            OutputFormat::Csv => csvs.push(CsvFile::create(path)?),
            _ => {}
        }
    }
    let keep_samples = wants(OutputFormat::Plot);
    let mut observer = Observer {
        progress,
        units: Vec::new(),
        bottle: Vec::new(),
        bottle_every: keep_samples.then(|| (scene.sample_rate as usize / 100).max(1)),
    };
    let mut samples = Vec::new();
    let summary = render_scene(
        scene,
        |block: &[f32]| {
            for wav in &mut wavs {
                wav.write(block)?;
            }
            for csv in &mut csvs {
                csv.write(block)?;
            }
            if keep_samples {
                samples.extend_from_slice(block);
            }
            Ok::<(), OutputError>(())
        },
        &mut observer,
    )?;

    let glugs: Vec<Glug> = observer
        .units
        .iter()
        .map(|(unit, gain)| glug(scene, unit, *gain))
        .collect();
    let source = ClipSource {
        duration_s: summary.duration_s(),
        glugs: &glugs,
        ceiling: scene.config.ceiling,
        scene_name,
        seed: scene.config.seed,
    };
    // The felt envelope is worked out only for the files that carry it (it costs about as much
    // as the render of a pour itself).
    let carries_envelope = formats.iter().any(|format| {
        matches!(
            format,
            OutputFormat::Haptic | OutputFormat::Ahap | OutputFormat::Plot
        )
    });
    let breakpoints = if carries_envelope {
        clips::envelope_breakpoints(&source)
    } else {
        Vec::new()
    };
    let mut finished: Vec<Finished> = Vec::new();
    for wav in wavs {
        finished.push(Finished::Wav(wav));
    }
    for csv in csvs {
        finished.push(Finished::Temp(csv.finish()?));
    }
    for (path, format) in outputs.iter().zip(&formats) {
        let text = match format {
            OutputFormat::Haptic => clips::haptic::haptic_json(&source, &options.haptic_band),
            OutputFormat::Ahap => clips::ahap::ahap_json(&source),
            _ => continue,
        };
        finished.push(Finished::Temp(write_temp(path, text.as_bytes())?));
    }
    #[cfg(feature = "plot")]
    for (path, _) in outputs
        .iter()
        .zip(&formats)
        .filter(|(_, f)| **f == OutputFormat::Plot)
    {
        let envelope: Vec<(f64, f64)> = breakpoints
            .iter()
            .map(|b| (b.time_s, b.amplitude))
            .collect();
        let onsets_s: Vec<f64> = clips::clip_onsets(&source)
            .into_iter()
            .map(|index| glugs[index].onset_s)
            .collect();
        let fs = scene.sample_rate as f64;
        let volume_ml: Vec<(f64, f64)> = std::iter::once((0.0, observer.first_volume(scene)))
            .chain(observer.bottle.iter().map(|&(n, v)| (n as f64 / fs, v)))
            .collect();
        let tilt_deg: Vec<(f64, f64)> = volume_ml
            .iter()
            .map(|&(t, _)| (t, scene.tilt_deg.value_at(t)))
            .collect();
        let data = super::plot::PlotData {
            sample_rate: fs,
            samples: &samples,
            envelope: &envelope,
            onsets_s: &onsets_s,
            volume_ml: &volume_ml,
            capacity_ml: scene.config.capacity_ml,
            tilt_deg: &tilt_deg,
        };
        let temp = new_temp(path, ".png")?;
        super::plot::draw_pour_plot(&data, temp.path())?;
        finished.push(Finished::Temp(PendingFile {
            path: path.clone(),
            temp,
        }));
    }

    // Every file is complete: only now do they replace their targets.
    let mut files = Vec::new();
    for file in finished {
        files.push(file.commit()?);
    }
    Ok(RenderReport {
        summary,
        audible_glugs: glugs.iter().filter(|g| clips::is_audible(g)).count(),
        envelope_breakpoints: breakpoints.len(),
        files,
    })
}

/// A unit as the clips see it: its onset in seconds and its components at the output gain it
/// starts to be heard at.
fn glug(scene: &Scene, unit: &UnitOnset, gain: f64) -> Glug {
    let onset_s = (unit.sample as f64 + unit.fraction) / scene.sample_rate as f64;
    let [a1, a2] = unit.component_amplitudes();
    Glug {
        onset_s,
        amplitudes: [a1 * gain, a2 * gain],
        frequency_hz: unit.shape.frequency_hz,
        decay_per_s: unit.shape.decay_per_s,
        viscosity: unit.viscosity,
    }
}

/// Collects what the clips and the plot need while the render runs.
struct Observer<P> {
    progress: P,
    /// Each unit with the output gain it is heard at.
    units: Vec<(UnitOnset, f64)>,
    /// `(position, V)` after every block, when the plot is drawn.
    bottle: Vec<(u64, f64)>,
    bottle_every: Option<usize>,
}

impl<P> Observer<P> {
    #[cfg(feature = "plot")]
    /// The volume at the start: the fill level, as a reset fills the bottle (MODEL.md §8).
    fn first_volume(&self, scene: &Scene) -> f64 {
        scene.config.capacity_ml * scene.fill_percent.value_at(0.0) / 100.0
    }
}

impl<P: FnMut(u64)> RenderObserver for Observer<P> {
    fn progress(&mut self, rendered: u64) {
        (self.progress)(rendered)
    }

    fn unit_started(&mut self, onset: &UnitOnset, output_gain: f64) {
        self.units.push((*onset, output_gain));
    }

    fn bottle_every(&self) -> Option<usize> {
        self.bottle_every
    }

    fn bottle(&mut self, position: u64, volume_ml: f64) {
        self.bottle.push((position, volume_ml));
    }
}

/// A complete file waiting to replace its target.
struct PendingFile {
    path: PathBuf,
    temp: NamedTempFile,
}

enum Finished {
    Wav(WavFile),
    Temp(PendingFile),
}

impl Finished {
    fn commit(self) -> Result<(PathBuf, u64), OutputError> {
        let path = match self {
            Finished::Wav(wav) => wav.commit()?,
            Finished::Temp(PendingFile { path, temp }) => {
                temp.persist(&path).map_err(|error| OutputError::Io {
                    path: path.clone(),
                    source: error.error,
                })?;
                path
            }
        };
        let bytes = std::fs::metadata(&path).map_or(0, |meta| meta.len());
        Ok((path, bytes))
    }
}

/// A CSV of samples being written to its temporary file.
struct CsvFile {
    path: PathBuf,
    temp: NamedTempFile,
    writer: BufWriter<std::fs::File>,
}

impl CsvFile {
    fn create(path: &Path) -> Result<Self, OutputError> {
        let temp = new_temp(path, ".csv")?;
        let file = temp.reopen().map_err(|source| io_error(path, source))?;
        Ok(Self {
            path: path.to_owned(),
            temp,
            writer: BufWriter::new(file),
        })
    }

    fn write(&mut self, samples: &[f32]) -> Result<(), OutputError> {
        clips::csv::write_csv_samples(samples, &mut self.writer)
            .map_err(|source| io_error(&self.path, source))
    }

    fn finish(mut self) -> Result<PendingFile, OutputError> {
        self.writer
            .flush()
            .map_err(|source| io_error(&self.path, source))?;
        Ok(PendingFile {
            path: self.path,
            temp: self.temp,
        })
    }
}

fn write_temp(path: &Path, bytes: &[u8]) -> Result<PendingFile, OutputError> {
    let mut temp = new_temp(path, "")?;
    temp.write_all(bytes)
        .and_then(|()| temp.flush())
        .map_err(|source| io_error(path, source))?;
    Ok(PendingFile {
        path: path.to_owned(),
        temp,
    })
}

/// A temporary file in the target's folder (so that the rename is atomic), with `suffix`
/// where a library infers the format from the name.
fn new_temp(path: &Path, suffix: &str) -> Result<NamedTempFile, OutputError> {
    let directory = match path.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    temp_file_builder()
        .suffix(suffix)
        .tempfile_in(directory)
        .map_err(|source| io_error(path, source))
}

fn io_error(path: &Path, source: std::io::Error) -> OutputError {
    OutputError::Io {
        path: path.to_owned(),
        source,
    }
}
