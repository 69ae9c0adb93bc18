//! How close a model sounds to a recording (MODEL.md §13): the model rendered at the recording's
//! rate, and the correlation of the two spectra over 50–1000 Hz (Welch's power spectrum, each
//! bin averaged in power with its neighbours within ±25 Hz, in dB, the model's read at the
//! recording's bins). The same for the paper's default bottle, so that a fit shows whether it
//! came closer than the default.

use sake_glug_io::keys;
use sake_glug_render::{render_scene_to_vec, Scene};

use super::session_fit::SessionFit;
use super::spectrum::Spectrum;

/// The band compared (Hz): the glug's components lie in it.
pub const COMPARED_BAND_HZ: (f64, f64) = (50.0, 1000.0);
/// Each bin is averaged with its neighbours within this distance (Hz).
const SMOOTHING_HZ: f64 = 25.0;
/// The length of a model's render compared (s): several glugs at any pour time.
pub const RENDER_S: f64 = 10.0;
/// The default bottle: a scene of nothing but the tilt of a model file.
const DEFAULT_BOTTLE: &str = "tilt_deg = 135.0\n";

/// One recording against its liquid's model and the default bottle.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// The recording's name.
    pub recording: String,
    /// Correlation of the smoothed dB spectra, recording against the fitted model.
    pub fitted: f64,
    /// …and against the default bottle.
    pub default: f64,
}

/// The smoothed dB spectrum of `spectrum` at each of its bins within the compared band.
pub fn smoothed_db(spectrum: &Spectrum) -> Vec<(f64, f64)> {
    let reach = (SMOOTHING_HZ / spectrum.bin_hz).round() as usize;
    let (low, high) = COMPARED_BAND_HZ;
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

/// The correlation of the smoothed dB spectra of `recording` and `model` over the band (the
/// model's read at the recording's bins, linearly between its own).
pub fn spectral_correlation(recording: &Spectrum, model: &Spectrum) -> f64 {
    let ours = smoothed_db(recording);
    let theirs = smoothed_db(model);
    if ours.len() < 3 || theirs.len() < 2 {
        return f64::NAN;
    }
    let at = |hz: f64| {
        let after = theirs
            .partition_point(|p| p.0 < hz)
            .clamp(1, theirs.len() - 1);
        let ((f0, v0), (f1, v1)) = (theirs[after - 1], theirs[after]);
        v0 + (v1 - v0) * ((hz - f0) / (f1 - f0)).clamp(0.0, 1.0)
    };
    let pairs: Vec<(f64, f64)> = ours.iter().map(|&(hz, db)| (db, at(hz))).collect();
    pearson(&pairs)
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

/// The samples of the model file `model_toml` (a scene) rendered for [`RENDER_S`] at
/// `sample_rate`, the bottle kept full (it glugs all along); the renderer's message if it
/// refuses.
pub fn render_model(model_toml: &str, sample_rate: u32) -> Result<Vec<f32>, String> {
    let mut table: toml::Table =
        toml::from_str(model_toml).map_err(|error| keys::syntax_message(&error, model_toml))?;
    keys::insert(
        &mut table,
        "sample_rate",
        toml::Value::Integer(sample_rate.into()),
    );
    keys::insert(&mut table, "duration_s", toml::Value::Float(RENDER_S));
    // The bottle kept full: it glugs all along, at the level of the recordings' start, so that
    // the spectrum is of many glugs rather than a few.
    keys::insert(
        &mut table,
        "output.drain",
        toml::Value::String("follow".into()),
    );
    let text = toml::to_string(&table).map_err(|error| error.to_string())?;
    let scene = Scene::parse(&text).map_err(|error| error.to_string())?;
    render_scene_to_vec(&scene)
        .map(|(samples, _)| samples)
        .map_err(|error| error.to_string())
}

/// The default bottle rendered as [`render_model`] renders a model.
pub fn render_default(sample_rate: u32) -> Result<Vec<f32>, String> {
    render_model(DEFAULT_BOTTLE, sample_rate)
}

/// Every recording of `fit` against its liquid's model and the default bottle.
pub fn compare(fit: &SessionFit) -> Result<Vec<Comparison>, String> {
    let mut comparisons = Vec::new();
    for recording in &fit.recordings {
        let Some(liquid) = fit
            .liquids
            .iter()
            .find(|l| l.liquid == recording.spec.liquid)
        else {
            continue;
        };
        let fs = recording.sample_rate;
        let model = Spectrum::of(&render_model(&liquid.model_toml, fs)?, f64::from(fs));
        let default = Spectrum::of(&render_default(fs)?, f64::from(fs));
        comparisons.push(Comparison {
            recording: recording.name(),
            fitted: spectral_correlation(&recording.spectrum, &model),
            default: spectral_correlation(&recording.spectrum, &default),
        });
    }
    Ok(comparisons)
}
