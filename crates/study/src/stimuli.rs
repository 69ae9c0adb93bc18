//! The stimuli rendered once each by the offline renderer, and matched in level (MODEL.md §15).

use super::spec::{Equalize, Spec};
use super::StudyError;
use sake_glug_render::render_scene_to_vec;

/// One stimulus as presented: its samples with its equalisation gain applied.
#[derive(Debug, Clone)]
pub struct Rendered {
    /// The samples, at the spec's (or the audio interface's) sample rate, gain applied.
    pub samples: Vec<f32>,
    /// The equalisation gain applied (dB; 0 with `equalize = "none"`).
    pub gain_db: f64,
    /// The matched level before the gain (peak or RMS, linear; the peak with `none`).
    pub level: f64,
}

/// The level `equalize` measures of `samples` (the peak for `none`, as printed).
pub fn level_of(equalize: Equalize, samples: &[f32]) -> f64 {
    match equalize {
        Equalize::Peak | Equalize::None => samples
            .iter()
            .fold(0.0f64, |peak, &sample| peak.max((sample as f64).abs())),
        Equalize::Rms => {
            let energy: f64 = samples.iter().map(|&s| s as f64 * s as f64).sum();
            (energy / samples.len().max(1) as f64).sqrt()
        }
    }
}

/// Renders every stimulus of `spec` at `sample_rate` and matches their levels: each is scaled
/// down to the quietest one's level, so no gain is above 0 dB and nothing can clip.
pub fn render_stimuli(spec: &Spec, sample_rate: u32) -> Result<Vec<Rendered>, StudyError> {
    let mut rendered = Vec::with_capacity(spec.stimuli.len());
    for stimulus in &spec.stimuli {
        let scene = stimulus
            .scene
            .clone()
            .with_sample_rate(sample_rate as f64)
            .map_err(|error| StudyError::Stimulus {
                path: spec.path.clone(),
                name: stimulus.name.clone(),
                message: error.to_string(),
            })?;
        let (samples, _) = render_scene_to_vec(&scene).map_err(|error| StudyError::Stimulus {
            path: spec.path.clone(),
            name: stimulus.name.clone(),
            message: error.to_string(),
        })?;
        rendered.push(Rendered {
            level: level_of(spec.equalize, &samples),
            samples,
            gain_db: 0.0,
        });
    }
    if spec.equalize == Equalize::None {
        return Ok(rendered);
    }
    if let Some(silent) = rendered.iter().position(|stimulus| stimulus.level == 0.0) {
        return Err(StudyError::Stimulus {
            path: spec.path.clone(),
            name: spec.stimuli[silent].name.clone(),
            message: format!(
                "it is silent, so `equalize = \"{}\"` cannot match it to the others",
                spec.equalize.name()
            ),
        });
    }
    let target = rendered
        .iter()
        .map(|stimulus| stimulus.level)
        .fold(f64::INFINITY, f64::min);
    for stimulus in &mut rendered {
        let gain = target / stimulus.level;
        stimulus.gain_db = 20.0 * gain.log10();
        for sample in &mut stimulus.samples {
            *sample = (*sample as f64 * gain) as f32;
        }
    }
    Ok(rendered)
}
