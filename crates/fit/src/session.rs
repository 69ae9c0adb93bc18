//! A fit session (MODEL.md §13): the bottle's capacity and its recordings, each a WAV file at one
//! tilt, with its start volume or a weight log, and the liquid it holds.

use sake_glug_io::keys;
use sake_glug_io::read::{self, InputKind};
use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::error::FitError;
use sake_glug_engine::curves::REFERENCE_TILT_DEG;
use sake_glug_engine::{Constant, Control};

/// The liquid of a recording that names none.
pub const DEFAULT_LIQUID: &str = "liquid";

/// A validated session, its paths resolved against the session file's folder.
#[derive(Debug, Clone, PartialEq)]
pub struct FitSession {
    /// The session file (for messages), or the first clip of a fit of clips.
    pub path: PathBuf,
    /// Whether it is a fit of clips named on the command line (no session file).
    pub from_clips: bool,
    /// The bottle's capacity C (ml).
    pub capacity_ml: f64,
    /// Every recording, in the file's order.
    pub recordings: Vec<RecordingSpec>,
}

/// One `[[recording]]`.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordingSpec {
    /// Its place in messages: `recording[0]` (a clip: its file).
    pub key: String,
    /// Its audio's place in messages: `recording[0].audio` (a clip: its file).
    pub audio_key: String,
    /// The WAV file.
    pub audio: PathBuf,
    /// The tilt the bottle was held at (degrees).
    pub tilt_deg: f64,
    /// The volume at the first sample (ml), if given.
    pub start_ml: Option<f64>,
    /// The scale's log, if given.
    pub weight: Option<WeightSpec>,
    /// The liquid's name ([`DEFAULT_LIQUID`] if none given).
    pub liquid: String,
}

/// Where a recording's weight log is and how to read it.
#[derive(Debug, Clone, PartialEq)]
pub struct WeightSpec {
    /// The CSV file.
    pub csv: PathBuf,
    /// The column of times (s).
    pub time: String,
    /// The column of weights (g).
    pub column: String,
    /// g per ml of the liquid.
    pub density_g_per_ml: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SessionFile {
    capacity_ml: Option<f64>,
    #[serde(default)]
    recording: Vec<RecordingFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RecordingFile {
    audio: PathBuf,
    tilt_deg: f64,
    start_ml: Option<f64>,
    weight: Option<WeightFile>,
    liquid: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct WeightFile {
    csv: PathBuf,
    #[serde(default = "time_column")]
    time: String,
    column: String,
    #[serde(default = "water_density")]
    density_g_per_ml: f64,
}

fn time_column() -> String {
    sake_glug_device::csv_lane::TIME_COLUMN.to_owned()
}

fn water_density() -> f64 {
    1.0
}

impl FitSession {
    /// Reads and validates the session at `path`.
    pub fn load(path: &Path) -> Result<Self, FitError> {
        let text = read::read_text(path, InputKind::FIT_SESSION).map_err(FitError::SessionRead)?;
        Self::parse(&text, path)
    }

    /// Validates the session `text` of the file at `path` (its folder resolves the paths).
    pub fn parse(text: &str, path: &Path) -> Result<Self, FitError> {
        let file: SessionFile = toml::from_str(text).map_err(|error| FitError::SessionSyntax {
            path: path.to_owned(),
            message: keys::syntax_message(&error, text),
        })?;
        let value_error = |key: String, value: f64, why| FitError::SessionValue {
            path: path.to_owned(),
            key,
            value,
            why,
        };
        let capacity = Constant::Capacity.quantity();
        let capacity_ml = file.capacity_ml.unwrap_or(capacity.range.default);
        if !capacity.range.contains(capacity_ml) {
            return Err(value_error(
                "capacity_ml".into(),
                capacity_ml,
                "outside the capacity's range (see `sake-glug parameters`)",
            ));
        }
        if file.recording.is_empty() {
            return Err(FitError::NoRecording {
                path: path.to_owned(),
            });
        }
        let folder = path.parent().unwrap_or(Path::new(""));
        let tilt = Control::Tilt.range();
        let mut recordings = Vec::with_capacity(file.recording.len());
        for (index, recording) in file.recording.into_iter().enumerate() {
            let key = format!("recording[{index}]");
            if !tilt.contains(recording.tilt_deg) {
                return Err(value_error(
                    format!("{key}.tilt_deg"),
                    recording.tilt_deg,
                    "a tilt lies within 0 to 180 degrees",
                ));
            }
            if let Some(start_ml) = recording.start_ml {
                if !(0.0..=capacity_ml).contains(&start_ml) {
                    return Err(value_error(
                        format!("{key}.start_ml"),
                        start_ml,
                        "a start volume lies within 0 and capacity_ml",
                    ));
                }
            }
            let weight = match recording.weight {
                None => None,
                Some(weight) => {
                    let density = weight.density_g_per_ml;
                    if !(density.is_finite() && density > 0.0) {
                        return Err(value_error(
                            format!("{key}.weight.density_g_per_ml"),
                            density,
                            "a density is a positive number of g per ml",
                        ));
                    }
                    Some(WeightSpec {
                        csv: folder.join(weight.csv),
                        time: weight.time,
                        column: weight.column,
                        density_g_per_ml: density,
                    })
                }
            };
            if recording.start_ml.is_none() && weight.is_none() {
                return Err(FitError::NoVolume { key });
            }
            let liquid = recording.liquid.unwrap_or_else(|| DEFAULT_LIQUID.into());
            if !is_file_name(&liquid) {
                return Err(FitError::SessionSyntax {
                    path: path.to_owned(),
                    message: format!(
                        "`{key}.liquid` = \"{}\" ({} characters): a liquid names its model \
                         file, so it is 1 to {MAX_LIQUID_CHARS} characters, each a letter, a \
                         digit, `-` or `_`",
                        sake_glug_io::text::quoted(&liquid),
                        liquid.chars().count()
                    ),
                });
            }
            recordings.push(RecordingSpec {
                audio_key: format!("{key}.audio"),
                key,
                audio: folder.join(recording.audio),
                tilt_deg: recording.tilt_deg,
                start_ml: recording.start_ml,
                weight,
                liquid,
            });
        }
        Ok(FitSession {
            path: path.to_owned(),
            from_clips: false,
            capacity_ml,
            recordings,
        })
    }

    /// What a fit reads, as the command line and Python name it: one session file (a `.toml`
    /// path), or WAV clips of one bottle ([`Self::of_clips`], with the clips' `capacity_ml` and
    /// `tilt_deg`, which a session file gives itself).
    pub fn from_inputs(
        inputs: &[PathBuf],
        capacity_ml: Option<f64>,
        tilt_deg: Option<f64>,
    ) -> Result<Self, FitError> {
        let sessions = inputs.iter().filter(|path| is_session_file(path)).count();
        match (sessions, inputs) {
            (_, []) => Err(FitError::Inputs(
                "no recording: name a session file or WAV clips",
            )),
            (0, clips) => Self::of_clips(clips, capacity_ml, tilt_deg),
            (1, [session]) if capacity_ml.is_none() && tilt_deg.is_none() => Self::load(session),
            (1, [_]) => Err(FitError::Inputs(
                "the capacity and the tilt are given for clips; a session file gives its own \
                 (capacity_ml, and each recording's tilt_deg)",
            )),
            _ => Err(FitError::Inputs(
                "give one session file, or WAV clips without one",
            )),
        }
    }

    /// A session of clips without a session file: a bottle of `capacity_ml` (default: the
    /// model's) held at `tilt_deg` (default 135°), full at each clip's first sample, one liquid.
    pub fn of_clips(
        clips: &[PathBuf],
        capacity_ml: Option<f64>,
        tilt_deg: Option<f64>,
    ) -> Result<Self, FitError> {
        let first = clips.first().ok_or(FitError::Inputs(
            "no recording: name a session file or WAV clips",
        ))?;
        let capacity = Constant::Capacity.quantity();
        let capacity_ml = capacity_ml.unwrap_or(capacity.range.default);
        if !capacity.range.contains(capacity_ml) {
            return Err(FitError::ClipOption {
                key: "capacity_ml",
                value: capacity_ml,
                why: "outside the capacity's range (see `sake-glug parameters`)",
            });
        }
        let tilt_deg = tilt_deg.unwrap_or(REFERENCE_TILT_DEG);
        if !Control::Tilt.range().contains(tilt_deg) {
            return Err(FitError::ClipOption {
                key: "tilt_deg",
                value: tilt_deg,
                why: "a tilt lies within 0 to 180 degrees",
            });
        }
        let recordings = clips
            .iter()
            .map(|clip| {
                let shown = sake_glug_io::text::printable(&clip.to_string_lossy()).into_owned();
                RecordingSpec {
                    key: shown.clone(),
                    audio_key: shown,
                    audio: clip.clone(),
                    tilt_deg,
                    start_ml: Some(capacity_ml),
                    weight: None,
                    liquid: DEFAULT_LIQUID.to_owned(),
                }
            })
            .collect();
        Ok(FitSession {
            path: first.clone(),
            from_clips: true,
            capacity_ml,
            recordings,
        })
    }

    /// The liquids, each once, in the order first named.
    pub fn liquids(&self) -> Vec<&str> {
        let mut liquids: Vec<&str> = Vec::new();
        for recording in &self.recordings {
            if !liquids.contains(&recording.liquid.as_str()) {
                liquids.push(&recording.liquid);
            }
        }
        liquids
    }
}

/// Whether `path` names a session file rather than a recording: its extension is `.toml`.
fn is_session_file(path: &Path) -> bool {
    path.extension()
        .is_some_and(|extension| extension.eq_ignore_ascii_case("toml"))
}

/// The longest liquid name: it names a file `<name>.toml`, whose name must fit every system.
const MAX_LIQUID_CHARS: usize = 64;

/// Whether `name` can name a file `<name>.toml` in any folder, on any system.
fn is_file_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= MAX_LIQUID_CHARS
        && name
            .chars()
            .all(|ch| ch.is_ascii_alphanumeric() || ch == '-' || ch == '_')
}
