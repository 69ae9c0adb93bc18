//! Each recording of a fit against its liquid's model and the default bottle, rendered as it
//! was made, with the measures of [`super::compare`]: the comparison the report, the JSON and
//! the picture give. Apart from those measures, which the fit itself listens with, so that they
//! do not depend on the fit's result.

use super::compare::{
    log_spectral_distance, render_default, render_model, spectral_correlation, split_hz,
    AsRecorded, Comparison,
};
use super::listen::hear;
use super::recording::RecordingFit;
use super::session_fit::SessionFit;
use super::spectrum::Spectrum;

/// One recording against its liquid's model and the default bottle, with the two renders.
pub struct Compared {
    /// The measures.
    pub comparison: Comparison,
    /// The fitted model's render and the default bottle's, as the recording was made.
    pub renders: [Vec<f32>; 2],
    /// Their spectra.
    pub spectra: [Spectrum; 2],
}

/// `recording` of `fit` against its liquid's model and the default bottle, each rendered as the
/// recording was made (None: its liquid has no model).
pub fn compare_recording(
    fit: &SessionFit,
    recording: &RecordingFit,
) -> Result<Option<Compared>, String> {
    let Some(liquid) = fit
        .liquids
        .iter()
        .find(|l| l.liquid == recording.spec.liquid)
    else {
        return Ok(None);
    };
    let made = AsRecorded::of(recording, fit.session.capacity_ml);
    let rate = f64::from(made.sample_rate);
    let split = split_hz(liquid.modes);
    let renders = [
        render_model(&liquid.model_toml, &made)?,
        render_default(&made)?,
    ];
    let spectra = [
        Spectrum::of(&renders[0], rate),
        Spectrum::of(&renders[1], rate),
    ];
    let comparison = Comparison {
        recording: recording.name(),
        rendered: made.describe(),
        fitted: spectral_correlation(&recording.spectrum, &spectra[0]),
        default: spectral_correlation(&recording.spectrum, &spectra[1]),
        distance: [
            log_spectral_distance(&recording.spectrum, &spectra[0], rate),
            log_spectral_distance(&recording.spectrum, &spectra[1], rate),
        ],
        split_hz: split,
        heard: [
            hear(&recording.excerpt, rate, split),
            hear(&renders[0], rate, split),
            hear(&renders[1], rate, split),
        ],
    };
    Ok(Some(Compared {
        comparison,
        renders,
        spectra,
    }))
}

/// Every recording of `fit` against its liquid's model and the default bottle, each rendered as
/// the recording was made.
pub fn compare(fit: &SessionFit) -> Result<Vec<Comparison>, String> {
    let mut comparisons = Vec::new();
    for recording in &fit.recordings {
        if let Some(compared) = compare_recording(fit, recording)? {
            comparisons.push(compared.comparison);
        }
    }
    Ok(comparisons)
}
