//! The stimuli rendered once each by the offline renderer (or read, for a recording), and matched
//! in level (MODEL.md §15).

use super::spec::{Equalize, Source, Spec};
use super::StudyError;
use sake_glug_io::text::{printable, quoted};
use sake_glug_render::{available_bytes, human_bytes, render_scene, RenderError};

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

/// Bytes of a stimulus's sample as it is held (f32).
const SAMPLE_BYTES: u64 = std::mem::size_of::<f32>() as u64;

/// Renders every stimulus of `spec` at `sample_rate` and matches their levels: each is scaled
/// down to the quietest one's level, so no gain is above 0 dB and nothing can clip.
///
/// Every stimulus is held in memory for the session (the audio interface plays from it); their
/// memory is known from the spec, so a set that cannot fit (a day-long `duration_s`) is refused
/// with the figure before anything is rendered, against the memory the system has available and
/// against what this process may allocate.
pub fn render_stimuli(spec: &Spec, sample_rate: u32) -> Result<Vec<Rendered>, StudyError> {
    let mut buffers = reserve_stimuli(spec, sample_rate)?;
    let mut rendered = Vec::with_capacity(spec.stimuli.len());
    for stimulus in &spec.stimuli {
        let fail = |message: String| StudyError::Stimulus {
            path: spec.path.clone(),
            name: quoted(&stimulus.name),
            message,
        };
        let mut samples = buffers.pop().expect("one buffer a stimulus");
        match &stimulus.source {
            Source::Recording(recording) => {
                samples = recording
                    .excerpt(spec.duration_s, sample_rate)
                    .map_err(fail)?;
            }
            Source::Scene(scene) => {
                let scene = (**scene)
                    .clone()
                    .with_sample_rate(sample_rate as f64)
                    .map_err(|error| fail(error.to_string()))?;
                render_scene(
                    &scene,
                    |block| {
                        samples.extend_from_slice(block);
                        Ok::<(), RenderError>(())
                    },
                    &mut |_: u64| {},
                )
                .map_err(|error| fail(error.to_string()))?;
            }
        }
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
            name: quoted(&spec.stimuli[silent].name),
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

/// An empty buffer for each stimulus of `spec` with room for all its samples, taken before any is
/// rendered; or the refusal, with what they need.
fn reserve_stimuli(spec: &Spec, sample_rate: u32) -> Result<Vec<Vec<f32>>, StudyError> {
    // Every stimulus lasts the spec's duration (the scenes are the spec's with its duration_s).
    let samples = (spec.duration_s * f64::from(sample_rate)).round() as u64;
    let count = spec.stimuli.len() as u64;
    let needed = samples.saturating_mul(SAMPLE_BYTES).saturating_mul(count);
    let refuse = |why: String| {
        StudyError::Memory(format!(
            "{}: the {count} stimuli of {} s at {sample_rate} Hz are held in memory for the \
             session, {} ({} each); {why}. Shorten `duration_s`, or use fewer stimuli",
            printable(&spec.path.to_string_lossy()),
            spec.duration_s,
            human_bytes(needed),
            human_bytes(samples.saturating_mul(SAMPLE_BYTES)),
        ))
    };
    if let Some(available) = available_bytes().filter(|&available| needed > available) {
        return Err(refuse(format!(
            "more than the {} available",
            human_bytes(available)
        )));
    }
    let mut buffers = Vec::with_capacity(spec.stimuli.len());
    for _ in 0..count {
        let mut buffer = Vec::new();
        usize::try_from(samples)
            .ok()
            .and_then(|samples| buffer.try_reserve_exact(samples).ok())
            .ok_or_else(|| {
                refuse("more than this process may allocate (its memory limit)".into())
            })?;
        buffers.push(buffer);
    }
    Ok(buffers)
}
