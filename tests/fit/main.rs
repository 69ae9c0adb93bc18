//! `sake-glug fit` (MODEL.md §13): known models rendered by the engine, written as WAV files and
//! weight logs, fitted, and the truth found within the tolerances stated here; every bad input
//! refused or warned about.

mod bad_input;
mod bubbles;
mod command;
mod emptying;
mod emptying_fit;
mod family;
mod listening;
mod real;
mod round_trip;
mod simulated;

use std::path::{Path, PathBuf};

use sake_glug_engine::{UnitOnset, Voicing};
use sake_glug_fit::{fit_session, FitSession, SessionFit};
use sake_glug_render::{render_scene, BottleReport, RenderError, RenderObserver, Scene};

/// The page that reports the fit on data it was not tuned on; its tables are written by the
/// tests that hold them.
const FIT_PAGE: &str = "docs/fit.md";

/// Holds docs/fit.md's block `name` (between `<!-- generated:NAME:begin -->` and its end) to
/// `table`, or writes it there with `SAKE_GLUG_WRITE_FIT_TABLES`; `command` is the one that
/// writes it, named when they differ.
pub fn documented(name: &str, table: &str, command: &str) {
    let page = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(FIT_PAGE);
    let text = std::fs::read_to_string(&page).expect("docs/fit.md");
    let begin = format!("<!-- generated:{name}:begin -->\n");
    let end = format!("<!-- generated:{name}:end -->");
    let (start, stop) = (
        text.find(&begin).expect("the block's start") + begin.len(),
        text.find(&end).expect("the block's end"),
    );
    if std::env::var_os("SAKE_GLUG_WRITE_FIT_TABLES").is_some() {
        std::fs::write(&page, format!("{}{table}{}", &text[..start], &text[stop..])).unwrap();
    } else {
        assert_eq!(
            &text[start..stop],
            table,
            "{FIT_PAGE}'s table `{name}` is not what the fit gives: run `{command}`"
        );
    }
}

/// A render's samples, the engine's units and its volume 5 times a second (a scale's log).
pub struct Rendered {
    pub sample_rate: u32,
    pub samples: Vec<f32>,
    pub onsets: Vec<UnitOnset>,
    pub volume: Vec<(f64, f64)>,
}

struct Recorder {
    sample_rate: f64,
    onsets: Vec<UnitOnset>,
    volume: Vec<(f64, f64)>,
}

impl Recorder {
    /// Samples between two readings of the scale: 5 a second.
    fn log_every(&self) -> u64 {
        (self.sample_rate / 5.0) as u64
    }
}

impl RenderObserver for Recorder {
    fn unit_started(&mut self, onset: &UnitOnset, _voicing: Voicing) {
        self.onsets.push(*onset);
    }
    fn next_bottle_report(&self, position: u64) -> Option<u64> {
        Some((position / self.log_every() + 1) * self.log_every())
    }
    fn bottle(&mut self, report: &BottleReport) {
        // The render reports after every block; the scale reads only on its own clock.
        if report.position.is_multiple_of(self.log_every()) {
            self.volume
                .push((report.position as f64 / self.sample_rate, report.volume_ml));
        }
    }
}

/// Renders the scene `text`.
pub fn render(text: &str) -> Rendered {
    let scene = Scene::parse(text).expect("a valid scene");
    let mut recorder = Recorder {
        sample_rate: scene.sample_rate as f64,
        onsets: Vec::new(),
        volume: vec![(
            0.0,
            scene.config.capacity_ml * scene.lanes.fill_percent.value_at(0.0) / 100.0,
        )],
    };
    let mut samples = Vec::new();
    render_scene(
        &scene,
        |block| {
            samples.extend_from_slice(block);
            Ok::<(), RenderError>(())
        },
        &mut recorder,
    )
    .expect("the scene renders");
    Rendered {
        sample_rate: scene.sample_rate,
        samples,
        onsets: recorder.onsets,
        volume: recorder.volume,
    }
}

/// Gaussian-like noise (a sum of uniforms from a fixed LCG) of standard deviation `sigma`.
pub fn add_noise(samples: &mut [f32], sigma: f64, seed: u64) {
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut uniform = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for sample in samples {
        let normal = (0..12).map(|_| uniform()).sum::<f64>();
        *sample += (sigma * normal) as f32;
    }
}

/// The RMS of the samples where the signal is above a tenth of its peak: "the glugs' level".
pub fn glug_rms(samples: &[f32]) -> f64 {
    let peak = samples.iter().fold(0.0f32, |p, y| p.max(y.abs())) as f64;
    let loud: Vec<f64> = samples
        .iter()
        .map(|&y| y as f64)
        .filter(|y| y.abs() > 0.1 * peak)
        .collect();
    (loud.iter().map(|y| y * y).sum::<f64>() / loud.len().max(1) as f64).sqrt()
}

/// Writes a 32-bit float WAV.
pub fn write_wav(path: &Path, samples: &[f32], sample_rate: u32) {
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate,
        bits_per_sample: 32,
        sample_format: hound::SampleFormat::Float,
    };
    let mut writer = hound::WavWriter::create(path, spec).unwrap();
    for &sample in samples {
        writer.write_sample(sample).unwrap();
    }
    writer.finalize().unwrap();
}

/// Writes a weight log `time_s,grams` of the volumes at `density`.
pub fn write_weight(path: &Path, volume: &[(f64, f64)], density: f64) {
    let mut text = String::from("time_s,grams\n");
    for &(t, v) in volume {
        text.push_str(&format!("{t},{}\n", v * density));
    }
    std::fs::write(path, text).unwrap();
}

/// A recording of a session: its render, tilt, liquid, and whether it has a weight log.
pub struct Take<'a> {
    pub name: &'a str,
    pub rendered: &'a Rendered,
    pub tilt_deg: f64,
    pub liquid: Option<&'a str>,
    pub weight: bool,
    pub noise_db: Option<f64>,
}

/// Writes the takes and their session into `folder`; returns the session file.
pub fn write_session(folder: &Path, capacity_ml: f64, takes: &[Take]) -> PathBuf {
    let mut session = format!("capacity_ml = {capacity_ml}\n");
    for (index, take) in takes.iter().enumerate() {
        let mut samples = take.rendered.samples.clone();
        if let Some(db) = take.noise_db {
            let sigma = glug_rms(&samples) * 10f64.powf(db / 20.0);
            add_noise(&mut samples, sigma, index as u64 + 1);
        }
        let wav = format!("{}.wav", take.name);
        write_wav(&folder.join(&wav), &samples, take.rendered.sample_rate);
        session.push_str(&format!(
            "\n[[recording]]\naudio = \"{wav}\"\ntilt_deg = {}\nstart_ml = {}\n",
            take.tilt_deg, take.rendered.volume[0].1
        ));
        if let Some(liquid) = take.liquid {
            session.push_str(&format!("liquid = \"{liquid}\"\n"));
        }
        if take.weight {
            let csv = format!("{}.csv", take.name);
            write_weight(&folder.join(&csv), &take.rendered.volume, 1.0);
            session.push_str(&format!(
                "weight = {{ csv = \"{csv}\", column = \"grams\", density_g_per_ml = 1.0 }}\n"
            ));
        }
    }
    let path = folder.join("session.toml");
    std::fs::write(&path, session).unwrap();
    path
}

/// Fits the session at `path`.
pub fn fit(path: &Path) -> SessionFit {
    let session = FitSession::load(path).expect("a valid session");
    fit_session(&session).expect("the session fits")
}

/// Mode k's pitch as `scene`'s model plays it where its ring's energy is centred, 1/(2B) after a
/// glug's onset: its own f, moved by its glide (MODEL.md §5.2) there. A simulator's pitch as heard
/// is judged against this, not against the own f a glide approaches.
pub fn heard_hz(scene: &Scene, k: usize) -> f64 {
    use sake_glug_engine::Constant;
    let [hz, decay, ratio, time_ms] = [
        [Constant::F1, Constant::F2],
        [Constant::B1, Constant::B2],
        [Constant::F1GlideRatio, Constant::F2GlideRatio],
        [Constant::F1GlideTime, Constant::F2GlideTime],
    ]
    .map(|constants| (constants[k].spec().get)(&scene.config));
    hz * (1.0 + (ratio - 1.0) * (-0.5 / decay / (1e-3 * time_ms)).exp())
}

/// The estimate of `key` for `liquid` (panics if there is none).
pub fn estimate(fit: &SessionFit, liquid: usize, key: &str) -> f64 {
    fit.liquids[liquid]
        .estimates
        .iter()
        .find(|e| e.key == key)
        .unwrap_or_else(|| panic!("no estimate `{key}`"))
        .value
}
