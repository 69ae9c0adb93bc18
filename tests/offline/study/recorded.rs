//! Recorded stimuli (`audio = "FILE.wav"`, `start_s`): the spec's `duration_s` of the file from
//! `start_s`, read through the one reader, level-matched with the others, the same samples at
//! every presentation; at another rate than the interface's, resampled with the project's
//! resampler; refused with the file and the reason when too short, silent, clipped, at a rate no
//! interface plays, or not a WAV.

use std::path::Path;

use sake_glug_study::{level_of, render_stimuli, Equalize, Source, Spec};

use super::{log_rows, run, session};

const RATE: u32 = 48_000;

/// A 1 s mono float WAV of what `sample` makes of the time.
fn write_wav(path: &Path, rate: u32, sample: impl Fn(f64) -> f32) {
    write_wav_of(path, rate, 1, sample);
}

/// A mono float WAV of `seconds`.
fn write_wav_of(path: &Path, rate: u32, seconds: u32, sample: impl Fn(f64) -> f32) {
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: rate,
        bits_per_sample: 32,
        sample_format: hound::SampleFormat::Float,
    };
    let mut writer = hound::WavWriter::create(path, spec).unwrap();
    for n in 0..rate * seconds {
        writer
            .write_sample(sample(f64::from(n) / f64::from(rate)))
            .unwrap();
    }
    writer.finalize().unwrap();
}

fn tone(t: f64) -> f32 {
    (0.6 * (-3.0 * t).exp() * (2.0 * std::f64::consts::PI * 300.0 * t).sin()) as f32
}

fn recorded_spec(extra: &str) -> String {
    format!(
        r#"
design = "2afc"
target = "recording"
duration_s = 0.3
gap_s = 0.1
repetitions = 2
seed = 1
equalize = "rms"
[stimuli.recording]
audio = "take.wav"
start_s = 0.2
{extra}
[stimuli.model]
preset = "water"
"#
    )
}

fn load(dir: &Path, text: &str) -> Result<Spec, String> {
    let path = dir.join("study.toml");
    std::fs::write(&path, text).unwrap();
    Spec::load(&path).map_err(|error| error.to_string())
}

#[test]
fn a_recording_is_its_excerpt_level_matched_at_the_interfaces_rate() {
    let dir = tempfile::tempdir().unwrap();
    write_wav(&dir.path().join("take.wav"), RATE, tone);
    let spec = load(dir.path(), &recorded_spec("")).unwrap();
    assert!(matches!(spec.stimuli[0].source, Source::Recording(_)));
    assert_eq!(spec.sample_rate(), RATE);
    let rendered = render_stimuli(&spec, RATE).unwrap();
    let recording = &rendered[0];
    assert_eq!(recording.samples.len(), (0.3 * f64::from(RATE)) as usize);
    // The file's samples from 0.2 s, times the stimulus's gain.
    let gain = 10f64.powf(recording.gain_db / 20.0);
    for (index, &sample) in recording.samples.iter().enumerate() {
        let original = tone(f64::from(9600 + index as u32) / f64::from(RATE));
        assert!(
            (f64::from(sample) - f64::from(original) * gain).abs() < 1e-6,
            "sample {index}"
        );
    }
    let levels: Vec<f64> = rendered
        .iter()
        .map(|stimulus| level_of(Equalize::Rms, &stimulus.samples))
        .collect();
    assert!((levels[0] / levels[1] - 1.0).abs() < 1e-4, "{levels:?}");
}

/// A 48 kHz recording on a 44.1 kHz interface: the excerpt resampled (rubato's FFT resampler,
/// the renderer's), as long as a rendered stimulus of the spec's `duration_s`, the tone on time
/// and at its level away from the excerpt's cut ends, and level-matched with the others.
#[test]
fn a_recording_at_another_rate_is_resampled_to_the_interfaces() {
    let dir = tempfile::tempdir().unwrap();
    write_wav(&dir.path().join("take.wav"), RATE, tone);
    let spec = load(dir.path(), &recorded_spec("")).unwrap();
    let interface = 44_100;
    let rendered = render_stimuli(&spec, interface).unwrap();
    let recording = &rendered[0];
    assert_eq!(recording.samples.len(), rendered[1].samples.len());
    assert_eq!(
        recording.samples.len(),
        (0.3 * f64::from(interface)).round() as usize
    );
    let gain = 10f64.powf(recording.gain_db / 20.0);
    // The cut at each end rings for a few milliseconds; between, the tone at 44.1 kHz.
    let edge = 441;
    let worst = recording.samples[edge..recording.samples.len() - edge]
        .iter()
        .enumerate()
        .map(|(index, &sample)| {
            let t = 0.2 + (edge + index) as f64 / f64::from(interface);
            (f64::from(sample) / gain - f64::from(tone(t))).abs()
        })
        .fold(0.0, f64::max);
    assert!(worst < 1e-4, "worst error {worst}");
    let levels: Vec<f64> = rendered
        .iter()
        .map(|stimulus| level_of(Equalize::Rms, &stimulus.samples))
        .collect();
    assert!((levels[0] / levels[1] - 1.0).abs() < 1e-4, "{levels:?}");
    // Read and resampled the same way every time.
    assert_eq!(
        render_stimuli(&spec, interface).unwrap()[0].samples,
        recording.samples
    );
}

#[test]
fn a_dry_run_plays_the_same_recorded_samples_at_every_presentation() {
    let dir = tempfile::tempdir().unwrap();
    write_wav(&dir.path().join("take.wav"), RATE, tone);
    std::fs::write(dir.path().join("study.toml"), recorded_spec("")).unwrap();
    session(
        dir.path(),
        "p1",
        "log.csv",
        &["--dry-run", "dry"],
        &format!("\n{}", "2\n".repeat(4)),
    );
    let files: Vec<_> = std::fs::read_dir(dir.path().join("dry"))
        .unwrap()
        .map(|entry| entry.unwrap().path())
        .filter(|path| path.to_string_lossy().ends_with("-recording.wav"))
        .collect();
    assert_eq!(files.len(), 4, "two trials of each order");
    let first = std::fs::read(&files[0]).unwrap();
    for file in &files {
        assert_eq!(std::fs::read(file).unwrap(), first, "{}", file.display());
        let reader = hound::WavReader::open(file).unwrap();
        assert_eq!(reader.spec().sample_rate, RATE);
    }
    assert_eq!(log_rows(&dir.path().join("log.csv")).len(), 4);
}

#[test]
fn bad_recordings_are_refused_with_the_file_and_the_reason() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path();
    write_wav(&folder.join("take.wav"), RATE, tone);
    // Too short: 0.2 s + 0.3 s of a 1 s file is fine; from 0.8 s it is not.
    let spec = load(
        folder,
        &recorded_spec("").replace("start_s = 0.2", "start_s = 0.8"),
    )
    .unwrap();
    let error = render_stimuli(&spec, RATE).unwrap_err().to_string();
    assert!(
        error.contains("take.wav") && error.contains("too short"),
        "{error}"
    );
    // Too short at another rate than the interface's: checked at the file's own.
    let spec = load(
        folder,
        &recorded_spec("").replace("start_s = 0.2", "start_s = 0.8"),
    )
    .unwrap();
    let error = render_stimuli(&spec, 44_100).unwrap_err().to_string();
    assert!(
        error.contains("take.wav") && error.contains("too short"),
        "{error}"
    );
    // Silent, clipped.
    write_wav(&folder.join("take.wav"), RATE, |_| 0.0);
    let spec = load(folder, &recorded_spec("")).unwrap();
    let error = render_stimuli(&spec, RATE).unwrap_err().to_string();
    assert!(error.contains("take.wav: the excerpt is silent"), "{error}");
    write_wav(&folder.join("take.wav"), RATE, |t| {
        (4.0 * tone(t)).clamp(-1.0, 1.0)
    });
    let spec = load(folder, &recorded_spec("")).unwrap();
    let error = render_stimuli(&spec, RATE).unwrap_err().to_string();
    assert!(
        error.contains("take.wav: the excerpt is clipped"),
        "{error}"
    );
    // A rate no interface plays, refused as the spec is read.
    write_wav(&folder.join("take.wav"), 4_000, tone);
    let error = load(folder, &recorded_spec("")).unwrap_err();
    assert!(
        error.contains("stimulus `recording`")
            && error.contains("at 4000 Hz, a rate no interface plays"),
        "{error}"
    );
    // Not a WAV; missing; a scene key beside `audio`.
    std::fs::write(folder.join("take.wav"), "not audio").unwrap();
    let error = load(folder, &recorded_spec("")).unwrap_err();
    assert!(error.contains("take.wav: not a WAV file"), "{error}");
    std::fs::remove_file(folder.join("take.wav")).unwrap();
    let error = load(folder, &recorded_spec("")).unwrap_err();
    assert!(error.contains("take.wav"), "{error}");
    write_wav(&folder.join("take.wav"), RATE, tone);
    let error = load(folder, &recorded_spec("viscosity_c = 0.5")).unwrap_err();
    assert!(
        error.contains("`viscosity_c`: a recording (`audio`) takes `start_s` only"),
        "{error}"
    );
}

/// `sake-glug experiment --discriminate RECORDING.wav MODEL.toml`: the two commands of a study
/// of a fit, the session (here its dry run: a triangle test by default) and its analysis; then
/// the 2AFC design asked for, and a design the runner has not refused by name.
#[test]
fn a_recording_against_its_model_in_two_commands() {
    let dir = tempfile::tempdir().unwrap();
    write_wav_of(&dir.path().join("take.wav"), RATE, 3, |t| tone(t % 1.0));
    // A model file as `sake-glug fit` writes one, of a liquid that glugs within the excerpt.
    std::fs::write(dir.path().join("model.toml"), "viscosity_c = 0.1\n").unwrap();
    let model = "model.toml";
    let session = [
        "--discriminate",
        "take.wav",
        model,
        "--start-s",
        "0.5",
        "--repetitions",
        "3",
        "--participant",
        "p1",
        "--log",
        "log.csv",
        "--dry-run",
        "dry",
    ];
    let output = run(dir.path(), &session, &format!("\n{}", "1\n".repeat(18)));
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains("triangle design, 18 trials"), "{stdout}");
    assert!(
        stdout.contains("Two are alike: which one is different?"),
        "{stdout}"
    );
    let analysed = std::process::Command::new(env!("CARGO_BIN_EXE_sake-glug"))
        .current_dir(dir.path())
        .args(["analyze", "discrimination", "--dry-run-logs", "log.csv"])
        .output()
        .unwrap();
    assert!(analysed.status.success());
    let report = String::from_utf8_lossy(&analysed.stdout);
    assert!(
        report.contains("of 18 right") && report.contains("triangle"),
        "{report}"
    );

    let mut two_afc = session.to_vec();
    two_afc.extend(["--design", "2afc"]);
    two_afc = two_afc
        .into_iter()
        .map(|arg| match arg {
            "log.csv" => "2afc.csv",
            "dry" => "dry-2afc",
            other => other,
        })
        .collect();
    let output = run(dir.path(), &two_afc, &format!("\n{}", "1\n".repeat(6)));
    assert!(output.status.success());
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(stdout.contains("2afc design, 6 trials"), "{stdout}");
    assert!(stdout.contains("Which one is the recording?"), "{stdout}");

    let mut tetrad = session.to_vec();
    tetrad.extend(["--design", "tetrad"]);
    tetrad.retain(|arg| !["--dry-run", "dry"].contains(arg));
    let refused = run(dir.path(), &tetrad, "");
    assert_eq!(refused.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&refused.stderr);
    assert!(
        stderr.contains("--design `tetrad`: one of `triangle`, `2afc`, `abx`"),
        "{stderr}"
    );
}
