//! How close a model sounds to a recording (MODEL.md §13): the model rendered as the recording
//! was made ([`AsRecorded`]), the correlation of the two spectra over 50–1000 Hz (Welch's power
//! spectrum, each bin averaged in power with its neighbours within ±25 Hz, in dB, the model's
//! read at the recording's bins), and what a listener would recognise ([`super::listen`]): the
//! rate, the pitch's fall over the glugs, the balance of the two modes and the log-spectral
//! distance. The same for the paper's default bottle, so that a fit shows whether it came closer
//! than the default.

use sake_glug_engine::Control;
use sake_glug_io::keys;
use sake_glug_render::{render_scene_to_vec, Scene};

use super::listen::Heard;
use super::recording::RecordingFit;
use super::spectrum::Spectrum;
use super::units::Modes;

/// The band compared (Hz): the glug's components lie in it.
pub const COMPARED_BAND_HZ: (f64, f64) = (50.0, 1000.0);
/// Each bin is averaged with its neighbours within this distance (Hz).
const SMOOTHING_HZ: f64 = 25.0;
/// The log-spectral distance's band (Hz): wide enough for a bubble's bright mode.
pub const DISTANCE_BAND_HZ: (f64, f64) = (50.0, 4000.0);
/// The longest render compared (s): the recording's first seconds, as its fit keeps them.
pub const RENDER_S: f64 = super::recording::EXCERPT_S;
/// The default bottle: a scene of nothing but the tilt of a model file.
const DEFAULT_BOTTLE: &str = "tilt_deg = 135.0\n";

/// Where the energy is split without two modes (Hz): above a glug's low modes, below a bubble's
/// bright ring.
pub const ONE_MODE_SPLIT_HZ: f64 = 700.0;

/// One recording against its liquid's model and the default bottle.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// The recording's name.
    pub recording: String,
    /// How the model and the default bottle were rendered ([`AsRecorded::describe`]).
    pub rendered: String,
    /// Correlation of the smoothed dB spectra, recording against the fitted model.
    pub fitted: f64,
    /// …and against the default bottle.
    pub default: f64,
    /// The log-spectral distance from the recording (dB): the fitted model's, the default's.
    pub distance: [f64; 2],
    /// Where the modes' energy is split (Hz).
    pub split_hz: f64,
    /// What a listener hears: in the recording, the fitted model, the default bottle.
    pub heard: [Heard; 3],
}

impl Comparison {
    /// The glugs the recording's pitch fall is read over: the recording's glugs heard.
    pub fn glugs(&self) -> usize {
        self.heard[0].onsets_s.len()
    }
}

/// The smoothed dB spectrum of `spectrum` at each of its bins within the compared band.
pub fn smoothed_db(spectrum: &Spectrum) -> Vec<(f64, f64)> {
    smoothed_db_in(spectrum, COMPARED_BAND_HZ)
}

/// The smoothed dB spectrum of `spectrum` at each of its bins within `band` (Hz): each bin
/// averaged in power with its neighbours within [`SMOOTHING_HZ`].
fn smoothed_db_in(spectrum: &Spectrum, (low, high): (f64, f64)) -> Vec<(f64, f64)> {
    let reach = (SMOOTHING_HZ / spectrum.bin_hz).round() as usize;
    let last = spectrum.power.len().saturating_sub(1);
    (0..spectrum.power.len())
        .filter(|&bin| (low..=high).contains(&spectrum.hz(bin)))
        .map(|bin| {
            let around = &spectrum.power[bin.saturating_sub(reach)..=(bin + reach).min(last)];
            let mean = around.iter().sum::<f64>() / around.len() as f64;
            (spectrum.hz(bin), 10.0 * mean.max(1e-30).log10())
        })
        .collect()
}

/// The smoothed dB spectra of `ours` and `theirs` within `band` as pairs at `ours`'s bins (the
/// second read there, linearly between its own); None where either has too few bins.
fn paired_db(ours: &Spectrum, theirs: &Spectrum, band: (f64, f64)) -> Option<Vec<(f64, f64)>> {
    let ours = smoothed_db_in(ours, band);
    let theirs = smoothed_db_in(theirs, band);
    if ours.len() < 3 || theirs.len() < 2 {
        return None;
    }
    let at = |hz: f64| {
        let after = theirs
            .partition_point(|p| p.0 < hz)
            .clamp(1, theirs.len() - 1);
        let ((f0, v0), (f1, v1)) = (theirs[after - 1], theirs[after]);
        v0 + (v1 - v0) * ((hz - f0) / (f1 - f0)).clamp(0.0, 1.0)
    };
    Some(ours.iter().map(|&(hz, db)| (db, at(hz))).collect())
}

/// The correlation of the smoothed dB spectra of `recording` and `model` over the band (the
/// model's read at the recording's bins, linearly between its own).
pub fn spectral_correlation(recording: &Spectrum, model: &Spectrum) -> f64 {
    paired_db(recording, model, COMPARED_BAND_HZ).map_or(f64::NAN, |pairs| pearson(&pairs))
}

/// The log-spectral distance of two spectra (dB): the RMS difference of their smoothed dB
/// spectra over [`DISTANCE_BAND_HZ`] (its top at most 45 % of `sample_rate`), each less its mean
/// there (so that level is not counted), the second read at the first's bins.
pub fn log_spectral_distance(ours: &Spectrum, theirs: &Spectrum, sample_rate: f64) -> f64 {
    let band = (
        DISTANCE_BAND_HZ.0,
        DISTANCE_BAND_HZ.1.min(0.45 * sample_rate),
    );
    let Some(pairs) = paired_db(ours, theirs, band) else {
        return f64::NAN;
    };
    let n = pairs.len() as f64;
    let mean_a = pairs.iter().map(|p| p.0).sum::<f64>() / n;
    let mean_b = pairs.iter().map(|p| p.1).sum::<f64>() / n;
    (pairs
        .iter()
        .map(|(x, y)| ((x - mean_a) - (y - mean_b)).powi(2))
        .sum::<f64>()
        / n)
        .sqrt()
}

/// Pearson's correlation of the pairs.
fn pearson(pairs: &[(f64, f64)]) -> f64 {
    let n = pairs.len() as f64;
    let (mean_x, mean_y) = (
        pairs.iter().map(|p| p.0).sum::<f64>() / n,
        pairs.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let (mut xy, mut xx, mut yy) = (0.0, 0.0, 0.0);
    for &(x, y) in pairs {
        xy += (x - mean_x) * (y - mean_y);
        xx += (x - mean_x).powi(2);
        yy += (y - mean_y).powi(2);
    }
    xy / (xx * yy).sqrt()
}

/// How a recording was made, so that a model is rendered as it was poured: the same tilt, the
/// same volume at the first sample, for as long (at most [`RENDER_S`]: the plots and the measures
/// read the recording's first seconds), at the same rate, the bottle draining as the model says.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AsRecorded {
    /// The tilt held (°).
    pub tilt_deg: f64,
    /// The bottle's volume at the first sample, as a share of its capacity.
    pub fill: f64,
    /// The length rendered (s).
    pub duration_s: f64,
    /// The recording's rate (Hz).
    pub sample_rate: u32,
}

impl AsRecorded {
    /// How `recording` was made, in a bottle of `capacity_ml`: its session's tilt and start
    /// volume (its `start_ml`, else its weight log's first volume, else full, as a clip is).
    pub fn of(recording: &RecordingFit, capacity_ml: f64) -> Self {
        let start_ml = recording
            .spec
            .start_ml
            .or_else(|| recording.weight.as_ref().map(|log| log.volume_at(0.0)))
            .filter(|ml| ml.is_finite())
            .unwrap_or(capacity_ml);
        Self {
            tilt_deg: recording.spec.tilt_deg,
            fill: (start_ml / capacity_ml).clamp(0.0, 1.0),
            duration_s: recording.duration_s.clamp(0.05, RENDER_S),
            sample_rate: recording.sample_rate,
        }
    }

    /// What was rendered, in words (the picture and the JSON say it).
    pub fn describe(&self) -> String {
        format!(
            "rendered as recorded: held at {}°, from {:.0} % full, for {:.2} s at {} Hz",
            self.tilt_deg,
            100.0 * self.fill,
            self.duration_s,
            self.sample_rate
        )
    }
}

/// The samples of the model file `model_toml` (a scene) rendered as the recording was made
/// ([`AsRecorded`]); the renderer's message if it refuses.
pub fn render_model(model_toml: &str, made: &AsRecorded) -> Result<Vec<f32>, String> {
    let table: toml::Table =
        toml::from_str(model_toml).map_err(|error| keys::syntax_message(&error, model_toml))?;
    render_table(table, made)
}

/// The model file `table` (parsed) rendered as the recording was made: its rate, length, tilt and
/// fill set to the recording's.
pub(crate) fn render_table(mut table: toml::Table, made: &AsRecorded) -> Result<Vec<f32>, String> {
    let mut set = |key: &str, value: toml::Value| keys::insert(&mut table, key, value);
    set("sample_rate", toml::Value::Integer(made.sample_rate.into()));
    set("duration_s", toml::Value::Float(made.duration_s));
    set(
        Control::Tilt.quantity().scene_key,
        toml::Value::Float(made.tilt_deg),
    );
    set(
        Control::Fill.quantity().scene_key,
        toml::Value::Float(100.0 * made.fill),
    );
    let text = toml::to_string(&table).map_err(|error| error.to_string())?;
    let scene = Scene::parse(&text).map_err(|error| error.to_string())?;
    render_scene_to_vec(&scene)
        .map(|(samples, _)| samples)
        .map_err(|error| error.to_string())
}

/// The default bottle rendered as [`render_model`] renders a model.
pub fn render_default(made: &AsRecorded) -> Result<Vec<f32>, String> {
    render_model(DEFAULT_BOTTLE, made)
}

/// Where the energy of the bottle's two modes is split for [`Heard::high_share`]: between the
/// liquid's modes where it has two, else at [`ONE_MODE_SPLIT_HZ`].
pub fn split_hz(modes: Modes) -> f64 {
    match modes {
        Modes::Split(boundary_hz) => boundary_hz,
        Modes::ByOrder | Modes::One => ONE_MODE_SPLIT_HZ,
    }
}
