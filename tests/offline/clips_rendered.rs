//! The clips of a real render: one pass writes WAV, CSV, `.haptic`, `.ahap` and the plot; each
//! clip passes its format's rules, marks the engine's own glugs at their onsets, and follows
//! the WAV; batches survive a bad scene; no file is partial, none is too long for its format.

use std::path::{Path, PathBuf};

use sake_glug_engine::{UnitOnset, Voicing};
use sake_glug_render::{
    render_scene, render_to_files, Output, OutputError, OutputOptions, RenderError, RenderObserver,
    Scene, WavError,
};

use crate::clip_rules::{ahap, haptic};
use crate::command::{files_in, sake_glug};

/// A pour with the viscosity and gain automated, so that every mapping is exercised (the
/// platform formats' tests render it too).
pub(crate) const SCENE: &str = r#"
seed = 7
tilt_deg = [[0.0, 90.0], [0.4, 140.0], [2.5, 140.0], [2.6, 0.0]]
viscosity_c = [[0.0, 0.1], [2.5, 0.9]]
[output]
gain_db = [[0.0, -3.0], [2.5, -9.0]]
"#;

/// Every unit the engine starts for `scene`, watched through the renderer's own observer.
pub(crate) fn engine_units(scene: &Scene) -> Vec<UnitOnset> {
    struct Units(Vec<UnitOnset>);
    impl RenderObserver for Units {
        fn unit_started(&mut self, onset: &UnitOnset, _voicing: Voicing) {
            self.0.push(*onset);
        }
    }
    let mut units = Units(Vec::new());
    render_scene(scene, |_| Ok::<(), RenderError>(()), &mut units).unwrap();
    units.0
}

pub(crate) fn onset_s(unit: &UnitOnset, scene: &Scene) -> f64 {
    (unit.sample as f64 + unit.fraction) / scene.sample_rate as f64
}

fn read_wav(path: &Path) -> Vec<f32> {
    hound::WavReader::open(path)
        .unwrap()
        .samples::<f32>()
        .map(Result::unwrap)
        .collect()
}

fn render_all(directory: &Path) -> (Scene, Vec<PathBuf>) {
    let scene = Scene::parse(SCENE).unwrap();
    let outputs: Vec<PathBuf> = ["pour.wav", "pour.csv", "pour.haptic", "pour.ahap"]
        .iter()
        .map(|name| directory.join(name))
        .collect();
    let files: Vec<Output> = outputs
        .iter()
        .map(|path| Output::of_path(path).unwrap())
        .collect();
    render_to_files(&scene, "test", &files, &OutputOptions::default(), |_| {}).unwrap();
    (scene, outputs)
}

#[test]
fn one_render_writes_valid_clips_with_the_engines_glugs_at_their_onsets() {
    let directory = tempfile::tempdir().unwrap();
    let (scene, outputs) = render_all(directory.path());
    let audible: Vec<f64> = engine_units(&scene)
        .iter()
        .filter(|unit| unit.amplitude > 0.0)
        .map(|unit| onset_s(unit, &scene))
        .collect();
    assert!(audible.len() > 20, "{} audible glugs", audible.len());

    let haptic_text = std::fs::read_to_string(&outputs[2]).unwrap();
    assert_eq!(haptic::validate(&haptic_text).len(), 0, "{haptic_text}");
    let emphases: Vec<f64> = haptic::parse(&haptic_text)
        .amplitude
        .iter()
        .filter(|point| point.emphasis.is_some())
        .map(|point| point.time)
        .collect();
    let ahap_text = std::fs::read_to_string(&outputs[3]).unwrap();
    assert_eq!(ahap::validate(&ahap_text).len(), 0);
    let transients: Vec<f64> = ahap::parse(&ahap_text)
        .iter()
        .filter(|event| event.event_type == "HapticTransient")
        .map(|event| event.time)
        .collect();
    for (what, marks) in [("emphasis", &emphases), ("transient", &transients)] {
        assert_eq!(marks.len(), audible.len(), "one {what} per audible glug");
        for (mark, onset) in marks.iter().zip(&audible) {
            assert!(
                (mark - onset).abs() < 1e-3,
                "{what} at {mark} s, glug at {onset} s"
            );
        }
    }
}

#[test]
fn the_csv_holds_the_wavs_samples_and_the_envelope_follows_them() {
    let directory = tempfile::tempdir().unwrap();
    let (scene, outputs) = render_all(directory.path());
    let wav = read_wav(&outputs[0]);
    let csv: Vec<f32> = std::fs::read_to_string(&outputs[1])
        .unwrap()
        .lines()
        .map(|line| line.parse().unwrap())
        .collect();
    assert_eq!(csv, wav, "CSV and WAV hold the same samples");

    // The felt envelope, linear between its breakpoints, bounds the waveform and is reached by
    // it: right after every onset the signal comes within a factor of 3 of the envelope.
    let envelope = haptic::parse(&std::fs::read_to_string(&outputs[2]).unwrap()).amplitude;
    let fs = scene.sample_rate as f64;
    let envelope_at = |t: f64| {
        let next = envelope.partition_point(|point| point.time <= t);
        if next == 0 || next == envelope.len() {
            return envelope[next.min(envelope.len() - 1)].amplitude;
        }
        let (a, b) = (&envelope[next - 1], &envelope[next]);
        a.amplitude + (b.amplitude - a.amplitude) * (t - a.time) / (b.time - a.time).max(1e-12)
    };
    for (n, y) in wav.iter().enumerate() {
        let t = n as f64 / fs;
        assert!(
            y.abs() as f64 <= envelope_at(t) + 1e-4,
            "|y| = {} above the envelope {} at {t} s",
            y.abs(),
            envelope_at(t)
        );
    }
    for point in envelope.iter().filter(|point| point.emphasis.is_some()) {
        let start = (point.time * fs) as usize;
        let peak = wav[start..(start + (0.01 * fs) as usize).min(wav.len())]
            .iter()
            .fold(0.0f32, |peak, y| peak.max(y.abs()));
        assert!(
            peak as f64 >= point.amplitude / 3.0,
            "at {} s the signal peaks at {peak}, the envelope says {}",
            point.time,
            point.amplitude
        );
    }
}

#[test]
fn a_render_too_long_for_a_wav_is_refused_before_a_byte_is_written() {
    let directory = tempfile::tempdir().unwrap();
    // A day at 768 kHz in f32: about 250 GiB.
    let scene = Scene::parse("duration_s = 86400.0\nsample_rate = 768000\n").unwrap();
    let output = Output::of_path(directory.path().join("day.wav")).unwrap();
    let error =
        render_to_files(&scene, "day", &[output], &OutputOptions::default(), |_| {}).unwrap_err();
    assert!(
        matches!(error, OutputError::Wav(WavError::TooLong { .. })),
        "{error}"
    );
    assert_eq!(std::fs::read_dir(directory.path()).unwrap().count(), 0);
}

#[test]
fn a_batch_renders_every_good_scene_and_reports_the_bad_one() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    std::fs::write(
        dir.join("short.toml"),
        "duration_s = 0.5\ntilt_deg = 135.0\n",
    )
    .unwrap();
    std::fs::write(dir.join("broken.toml"), "tilt_deg = 400.0\n").unwrap();
    std::fs::write(
        dir.join("water.toml"),
        "duration_s = 1.0\ntilt_deg = 120.0\n",
    )
    .unwrap();
    let output = sake_glug(
        dir,
        &[
            "render",
            "short.toml",
            "broken.toml",
            "water.toml",
            "--out-dir",
            "clips",
            "--formats",
            "wav,haptic,ahap",
        ],
    );
    assert_eq!(
        output.status.code(),
        Some(1),
        "a failed scene fails the batch"
    );
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("broken") && stderr.contains("tilt_deg"),
        "{stderr}"
    );
    assert_eq!(
        files_in(&dir.join("clips")),
        [
            "short.ahap",
            "short.haptic",
            "short.wav",
            "water.ahap",
            "water.haptic",
            "water.wav"
        ],
        "the good scenes are written, no partial or temporary file is left"
    );
}

#[test]
fn an_unknown_extension_is_refused_before_anything_is_rendered() {
    let directory = tempfile::tempdir().unwrap();
    let output = sake_glug(
        directory.path(),
        &["render", "-o", "pour.wav", "-o", "pour.mp3"],
    );
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("pour.mp3") && stderr.contains("unknown output format"),
        "{stderr}"
    );
    assert!(
        files_in(directory.path()).is_empty(),
        "not even the WAV is written"
    );
}

#[test]
fn the_plot_comes_from_the_same_render() {
    let directory = tempfile::tempdir().unwrap();
    let output = sake_glug(
        directory.path(),
        &["render", "-o", "pour.haptic", "--plot", "pour.png"],
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert_eq!(files_in(directory.path()), ["pour.haptic", "pour.png"]);
    let png = std::fs::read(directory.path().join("pour.png")).unwrap();
    assert_eq!(&png[1..4], b"PNG");
}
