//! Sinks: one per kind of file a render writes, all fed by the same single pass.
//!
//! A `Sink` hears the render as it runs (its samples block by block, each unit as it starts,
//! the bottle at the samples it asks for) and, once the render has ended, completes its file in
//! a temporary file beside the target (a `PendingFile`); [`super::render_to_files`] replaces
//! the targets only once every sink has finished. What a sink needs to keep it keeps itself: a
//! WAV or CSV streams its samples to disk and keeps no units, the tables stream their rows; the
//! clips keep the glugs.
//!
//! Every format is declared whole by its own file here, as a `FORMAT` ([`OutputFormat`]): its
//! name, its extension and whether that picks it, its sink, how the fidelity report reads it
//! back, what carries c in it, and its platform's limits (as constants beside it). Adding one is
//! that file and an entry in [`OutputFormat::ALL`]; nothing else knows a format by name.

mod ahap;
mod android;
mod android_ogg;
mod clip;
mod csv;
mod dualsense;
mod haps;
mod haptic;
mod plot;
pub(crate) mod read_back;
mod rumble;
mod state;
mod units;
mod wav;

use std::path::{Path, PathBuf};

use super::clips::HapticBand;
use super::loudness::{HapticPeak, LevelError, LevelTarget};
use super::memory::human_bytes;
use super::render::{BottleReport, RenderError, RenderSummary};
use super::scene::Scene;
use super::tables::{StateRate, StateRateError};
use clip::ClipSink;
use read_back::ReadBack;
use sake_glug_engine::{UnitOnset, Voicing};
pub(crate) use sake_glug_io::{remove_own_temps, remove_stale_temps, PendingFile};

pub use ahap::{ahap_json, CORE_HAPTICS_MAX_EVENT_S};
pub use android::{android_waveform_json, android_xml};
pub use android_ogg::{ANDROID_HAPTIC_TAG, ANDROID_OGG_CHANNELS};
pub use csv::{write_csv_samples, TIMED_SAMPLE_COLUMNS};
pub use dualsense::{AudioChannels, DUALSENSE_CHANNELS, DUALSENSE_RATE_HZ};
pub use haps::{haps_json, HAPS_VERSION};
pub use haptic::haptic_json;
#[cfg(feature = "plot")]
pub use plot::{draw_pour_plot, PlotData, Waveform};
pub use rumble::{rumble_json, DEFAULT_RUMBLE_RATE_HZ, RUMBLE_RATE_RANGE_HZ};
#[cfg(feature = "plot")]
pub use sake_glug_plot::PlotError;
pub use wav::{Clipped, SampleFormat, WavError};

/// One file of a render, written from the render's single pass. Every method but
/// [`Sink::finish`] has a default that ignores what it hears.
pub(crate) trait Sink {
    /// The next samples of the output: every sample of the render passes here once, in order.
    fn samples(&mut self, _block: &[f32]) -> Result<(), OutputError> {
        Ok(())
    }
    /// A unit started (at `(onset.sample + onset.fraction) / fs`), voiced as `voicing` says (its
    /// output gain, linear, on its ramp: MODEL.md §6, and whether it sounds).
    fn unit_started(&mut self, _onset: &UnitOnset, _voicing: Voicing) {}
    /// The next position after `position` (samples rendered) at which this sink wants a
    /// [`Sink::bottle`] report, or `None` for none. The render then ends a block there (which
    /// changes no sample), and reports after every block: as often as the most demanding sink
    /// asked.
    fn next_bottle_report(&self, _position: u64) -> Option<u64> {
        None
    }
    /// The bottle after a block.
    fn bottle(&mut self, _report: &BottleReport) {}
    /// `--haptic-peak` (MODEL.md §19): the gain of the haptic channel of a file that carries
    /// one ([`read_back::HapticChannel`]) over the samples [`Sink::samples`] hears, told before
    /// the first of them; its audio channels keep the samples as they are.
    fn haptic_gain(&mut self, _gain: f64) {}
    /// Once the samples have all been heard: whether the file clips ([`Clipped`]), for the
    /// render to warn.
    fn clipped(&self) -> Option<Clipped> {
        None
    }
    /// The most memory (bytes) the sink may keep, as far as it can tell before the render: a
    /// render whose sinks may need more than the machine has is refused before it starts.
    fn memory_bytes(&self) -> u64 {
        0
    }
    /// The render has ended (`summary`): completes the file in its temporary file, which
    /// replaces the target only once every sink of the render has finished.
    fn finish(self: Box<Self>, summary: &RenderSummary) -> Result<PendingFile, OutputError>;
}

/// What a sink is opened with: the file it writes and the render it is written from.
#[derive(Clone, Copy)]
pub(crate) struct SinkContext<'a> {
    /// The file asked for.
    pub path: &'a Path,
    /// The scene being rendered.
    pub scene: &'a Scene,
    /// Its name, for the clips' metadata.
    pub scene_name: &'a str,
    /// How the files are written.
    pub options: &'a OutputOptions,
    /// How its format is read back (a clip's drive is measured so).
    pub read_back: Option<ReadBack>,
}

/// Opens the sink of one format, refusing up front what it knows it cannot write.
type OpenSink = for<'a> fn(SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError>;

/// A kind of file a render writes, as its own file declares it (its `FORMAT`).
#[derive(Clone, Copy)]
pub struct OutputFormat {
    /// Its name in `--formats` and `-o NAME:PATH`.
    name: &'static str,
    /// The extension of its files, without the dot.
    extension: &'static str,
    /// Picked by its extension: false for a format that shares its extension with another (a
    /// table in `.csv`, a 4-channel `.wav`), which is picked only by its name.
    by_extension: bool,
    /// Whether this build writes it: false for one behind a feature the build lacks, whose
    /// `open` refuses it by name.
    built: bool,
    /// How its sink is opened.
    open: OpenSink,
    /// How the fidelity report reads it back; `None` for a file not played (the plot, the
    /// tables), which it does not measure.
    read_back: Option<ReadBack>,
    /// What carries the viscosity c in it, in the fidelity table's words ("—" if not played).
    carries_c: &'static str,
}

impl OutputFormat {
    /// `.wav`: the mono output, for an actuator driven from an audio interface.
    pub const WAV: Self = wav::FORMAT;
    /// `.haptic`: a Meta Haptics Studio 1.0 clip.
    pub const HAPTIC: Self = haptic::FORMAT;
    /// `.ahap`: an Apple Core Haptics pattern.
    pub const AHAP: Self = ahap::FORMAT;
    /// `.csv`: one sample per line, no header (Syntacts' format).
    pub const CSV: Self = csv::FORMAT;
    /// `.png`: the pour plot (feature `plot`; a build without it refuses a plot by name).
    pub const PLOT: Self = plot::FORMAT;
    /// `units` (`.csv`): one row per glug unit (MODEL.md §14).
    pub const UNITS: Self = units::FORMAT;
    /// `state` (`.csv`): the bottle at the state rate (MODEL.md §14).
    pub const STATE: Self = state::FORMAT;
    /// `.xml`: Android's vibration XML (`VibrationXmlParser`).
    pub const ANDROID_XML: Self = android::XML_FORMAT;
    /// `android-waveform` (`.json`): the arrays of Android's `VibrationEffect.createWaveform`.
    pub const ANDROID_WAVEFORM: Self = android::WAVEFORM_FORMAT;
    /// `rumble` (`.json`): frames of a dual-rumble gamepad's two motors.
    pub const RUMBLE: Self = rumble::FORMAT;
    /// `.haps`: an Interhaptics / Razer Haptic Composer file (version 5).
    pub const HAPS: Self = haps::FORMAT;
    /// `dualsense` (`.wav`): 4 channels at 48 kHz (another rate resampled), the DualSense's audio
    /// and actuators.
    pub const DUALSENSE: Self = dualsense::FORMAT;
    /// `.ogg`: Android's haptic-coupled Ogg Vorbis (feature `ogg`; a build without it refuses
    /// one by name).
    pub const ANDROID_OGG: Self = android_ogg::FORMAT;

    /// Every format, in the order a file's extension is looked up and the fidelity report
    /// lists them.
    pub const ALL: &'static [Self] = &[
        Self::WAV,
        Self::HAPTIC,
        Self::AHAP,
        Self::CSV,
        Self::PLOT,
        Self::UNITS,
        Self::STATE,
        // The platforms (issue 19).
        Self::ANDROID_XML,
        Self::ANDROID_WAVEFORM,
        Self::RUMBLE,
        Self::HAPS,
        Self::DUALSENSE,
        Self::ANDROID_OGG,
    ];

    /// Its name, as `--formats` and `-o NAME:PATH` take it.
    pub fn name(self) -> &'static str {
        self.name
    }

    /// The extension (without the dot) its files get.
    pub fn extension(self) -> &'static str {
        self.extension
    }

    /// Whether this build writes it (a format behind a feature the build lacks does not).
    pub fn is_built(self) -> bool {
        self.built
    }

    /// What carries the viscosity c in its file, in the fidelity table's words.
    pub fn carries_c(self) -> &'static str {
        self.carries_c
    }

    /// The gain `--haptic-peak` gives this format's clip of `source` (1 for a format that is
    /// no clip, or without the option): the same its sink finds.
    pub(crate) fn clip_drive_gain(
        self,
        path: &Path,
        source: &crate::clips::ClipSource,
        options: &OutputOptions,
    ) -> Result<clip::DriveGain, OutputError> {
        match (options.haptic_peak, self.read_back) {
            (Some(peak), Some(ReadBack::Clip(read, document))) => {
                clip::DriveGain::of(document, read, path, source, options, peak)
            }
            _ => Ok(clip::DriveGain(1.0)),
        }
    }

    /// How the fidelity report reads it back, if it is played.
    pub(crate) fn read_back(self) -> Option<ReadBack> {
        self.read_back
    }

    /// The name of its file for a scene called `stem` in `--out-dir`: `stem.ext`, or
    /// `stem.name.ext` for a format its extension does not pick (so `.csv` samples and a
    /// `.units.csv` table of the same scene sit side by side).
    pub fn file_name(self, stem: &str) -> String {
        if self.by_extension {
            format!("{stem}.{}", self.extension)
        } else {
            format!("{stem}.{}.{}", self.name, self.extension)
        }
    }

    /// The format of a name (any case).
    pub fn of_name(name: &str) -> Option<Self> {
        Self::ALL
            .iter()
            .copied()
            .find(|format| format.name.eq_ignore_ascii_case(name))
    }

    /// The format an extension (without the dot, any case) picks.
    fn of_extension(extension: &str) -> Option<Self> {
        Self::ALL
            .iter()
            .copied()
            .find(|format| format.by_extension && format.extension.eq_ignore_ascii_case(extension))
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

    /// Every format's name, as a list a message can end with: "wav, haptic, … or png".
    pub fn names() -> String {
        one_of(Self::ALL.iter().map(|format| format.name.to_owned()))
    }

    /// Every extension that picks a format, as a list a message can end with: ".wav, .haptic,
    /// … or .png".
    pub fn extensions() -> String {
        one_of(
            Self::ALL
                .iter()
                .filter(|format| format.by_extension)
                .map(|format| format!(".{}", format.extension)),
        )
    }

    /// The sink that writes `context.path` in this format.
    pub(crate) fn open<'a>(
        self,
        context: SinkContext<'a>,
    ) -> Result<Box<dyn Sink + 'a>, OutputError> {
        (self.open)(context)
    }
}

/// A file a render writes, and its format.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Output {
    /// The format it is written in.
    pub format: OutputFormat,
    /// The file.
    pub path: PathBuf,
}

impl Output {
    /// The output a file names by its extension.
    pub fn of_path(path: impl Into<PathBuf>) -> Result<Self, OutputError> {
        let path = path.into();
        Ok(Self {
            format: OutputFormat::of_path(&path)?,
            path,
        })
    }

    /// `-o`'s argument: `NAME:PATH` (a format by name, e.g. `units:glugs.csv`), or a path whose
    /// extension picks the format. A prefix before `:` that names no format is part of the path.
    pub fn parse(argument: &str) -> Result<Self, OutputError> {
        match argument
            .split_once(':')
            .and_then(|(name, path)| Some((OutputFormat::of_name(name)?, path)))
        {
            Some((_, "")) => Err(OutputError::NoPath {
                argument: argument.to_owned(),
            }),
            Some((format, path)) => Ok(Self {
                format,
                path: PathBuf::from(path),
            }),
            None => Self::of_path(argument),
        }
    }
}

/// Formats are told apart by name (each has its own).
impl PartialEq for OutputFormat {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name
    }
}

impl Eq for OutputFormat {}

impl std::fmt::Debug for OutputFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "OutputFormat({})", self.name)
    }
}

/// "a, b or c".
fn one_of(items: impl Iterator<Item = String>) -> String {
    let items: Vec<String> = items.collect();
    match items.split_last() {
        Some((last, [])) => last.clone(),
        Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        None => String::new(),
    }
}

/// How the files of a render are written.
#[derive(Debug, Clone, Copy, Default)]
pub struct OutputOptions {
    /// Sample format of WAV files.
    pub sample_format: SampleFormat,
    /// The actuator band the `.haptic` frequencies map to.
    pub haptic_band: HapticBand,
    /// A `.csv` of samples gets a header and a time column (Syntacts' form has neither).
    pub csv_time: bool,
    /// Rows per second of a `state` table.
    pub state_rate: StateRate,
    /// How the platform formats (rumble, DualSense, Android) are written.
    pub platforms: PlatformOptions,
    /// `--loudness` and `--true-peak`: the level of the waveform files (MODEL.md §19).
    pub level: LevelTarget,
    /// `--haptic-peak`: the drive the strongest moment of every haptic clip reaches; `None`
    /// keeps the model's own level (the output gain included).
    pub haptic_peak: Option<HapticPeak>,
    /// Measures the waveform's loudness even with no level asked (for a report).
    pub measure_loudness: bool,
}

/// How the platform formats are written.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlatformOptions {
    /// Frames a second of a `rumble` file ([`RUMBLE_RATE_RANGE_HZ`]).
    pub rumble_rate_hz: f64,
    /// What the audio channels of a `dualsense` or `android-ogg` file hold.
    pub audio_channels: AudioChannels,
}

impl Default for PlatformOptions {
    fn default() -> Self {
        Self {
            rumble_rate_hz: DEFAULT_RUMBLE_RATE_HZ,
            audio_channels: AudioChannels::default(),
        }
    }
}

/// Why the files of a render could not be written.
#[derive(Debug, thiserror::Error)]
pub enum OutputError {
    /// An output's extension names no format the renderer writes.
    #[error(
        "{}: unknown output format; the extension must be {}, or name the format as NAME:PATH \
         ({})",
        path.display(),
        OutputFormat::extensions(),
        OutputFormat::names()
    )]
    UnknownFormat {
        /// The output asked for.
        path: PathBuf,
    },
    /// `-o NAME:` without a file.
    #[error("-o {argument}: a file is missing after the format's name")]
    NoPath {
        /// The argument as given.
        argument: String,
    },
    /// The render itself failed.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The render cannot be brought to the loudness asked.
    #[error(transparent)]
    Level(#[from] LevelError),
    /// The files asked for may need more memory than the machine has: refused before the
    /// render starts.
    #[error(
        "the files asked for may need {} of memory ({}), more than the {} available; give the \
         scene a shorter duration_s, or leave out the files that keep every glug (.haptic, \
         .ahap, .png): a .wav or .csv keeps none",
        human_bytes(*needed),
        files
            .iter()
            .map(|(path, bytes)| format!("{} {}", path.display(), human_bytes(*bytes)))
            .collect::<Vec<_>>()
            .join(", "),
        human_bytes(*available)
    )]
    TooBig {
        /// Bytes all the files may need together.
        needed: u64,
        /// Bytes the machine has available.
        available: u64,
        /// Each file that keeps something, with the bytes it may need.
        files: Vec<(PathBuf, u64)>,
    },
    /// A WAV file could not be written.
    #[error(transparent)]
    Wav(#[from] WavError),
    /// A `state` table's rate does not fit the render.
    #[error(transparent)]
    StateRate(#[from] StateRateError),
    /// A rumble rate the platforms do not take.
    #[error(
        "{}: a rumble file of {rate_hz} frames a second; give a rate from {} to {} Hz",
        path.display(),
        RUMBLE_RATE_RANGE_HZ.start(),
        RUMBLE_RATE_RANGE_HZ.end()
    )]
    RumbleRate {
        /// The file asked for.
        path: PathBuf,
        /// The rate asked for (Hz).
        rate_hz: f64,
    },
    /// The Ogg Vorbis encoder refused, or this build has none.
    #[error("cannot write {}: {message}", path.display())]
    Ogg {
        /// The file asked for.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// The render is longer than a file of this format can hold.
    #[error(
        "{}: a {format} file holds at most {max_s:.0} s; give the scene a shorter duration_s",
        path.display()
    )]
    TooLongFor {
        /// The file asked for.
        path: PathBuf,
        /// The format's name.
        format: &'static str,
        /// The longest render it can hold (s).
        max_s: f64,
    },
    /// A file just written could not be read back (`--fidelity`).
    #[error(transparent)]
    ReadBack(#[from] sake_glug_io::read::ReadError),
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
    Plot(#[from] PlotError),
    /// A plot was asked for from a build without the `plot` feature.
    #[cfg(not(feature = "plot"))]
    #[error("{}: this build draws no plots (feature `plot`)", path.display())]
    NoPlot {
        /// The plot asked for.
        path: PathBuf,
    },
}

impl From<sake_glug_io::WriteError> for OutputError {
    fn from(error: sake_glug_io::WriteError) -> Self {
        Self::Io {
            path: error.path,
            source: error.source,
        }
    }
}

impl OutputError {
    /// The file system refused `path`.
    pub(crate) fn io(path: &Path) -> impl FnOnce(std::io::Error) -> Self + '_ {
        move |source| Self::Io {
            path: path.to_owned(),
            source,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each format's declaration stands on its own: its name finds it, an extension that picks
    /// it picks nothing else, and it says what carries c exactly when it is played.
    #[test]
    fn every_format_declares_itself_whole() {
        for &format in OutputFormat::ALL {
            assert_eq!(OutputFormat::of_name(format.name()), Some(format));
            if format.by_extension {
                assert_eq!(OutputFormat::of_extension(format.extension), Some(format));
            }
            assert_eq!(
                format.read_back().is_some(),
                format.carries_c() != "—",
                "{format:?}"
            );
        }
    }
}
