//! The platform files of a real render: every one passes its platform's rules, marks the
//! engine's own glugs within its own step, and the rumble motors share the weight as the
//! model shares it between f1 and f2.

use std::path::{Path, PathBuf};

use sake_glug_render::sinks::DUALSENSE_RATE_HZ;
use sake_glug_render::steps::ANDROID_STEP_MS;
use sake_glug_render::{render_to_files, Output, OutputError, OutputFormat, OutputOptions, Scene};

use super::{android_ogg, android_waveform, android_xml, dualsense, haps, rumble};
use crate::clips_rendered::{engine_units, onset_s, SCENE};
use crate::command::{files_in, sake_glug};

/// The onsets (s) of the audible units the engine starts for `scene`.
fn audible_onsets(scene: &Scene) -> Vec<f64> {
    engine_units(scene)
        .iter()
        .filter(|unit| unit.amplitude > 0.0)
        .map(|unit| onset_s(unit, scene))
        .collect()
}

/// Renders `scene` once into every platform format and the mono WAV, in `directory`.
fn render(scene: &Scene, directory: &Path) -> Vec<(OutputFormat, PathBuf)> {
    let formats = [
        OutputFormat::WAV,
        OutputFormat::ANDROID_XML,
        OutputFormat::ANDROID_WAVEFORM,
        OutputFormat::RUMBLE,
        OutputFormat::HAPS,
        OutputFormat::DUALSENSE,
        OutputFormat::ANDROID_OGG,
    ];
    let outputs: Vec<Output> = formats
        .iter()
        .map(|&format| Output {
            format,
            path: directory.join(format.file_name("pour")),
        })
        .collect();
    render_to_files(scene, "pour", &outputs, &OutputOptions::default(), |_| {}).unwrap();
    outputs.into_iter().map(|o| (o.format, o.path)).collect()
}

fn file_of(files: &[(OutputFormat, PathBuf)], format: OutputFormat) -> &Path {
    &files.iter().find(|(f, _)| *f == format).unwrap().1
}

fn text(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap()
}

/// How far each onset is from the nearest of `marks`, the worst of them (s).
fn worst_distance(onsets: &[f64], marks: &[f64]) -> f64 {
    onsets
        .iter()
        .map(|onset| {
            marks
                .iter()
                .map(|mark| (mark - onset).abs())
                .fold(f64::INFINITY, f64::min)
        })
        .fold(0.0, f64::max)
}

/// The start times (s) of entries given their durations (ms).
fn starts(durations_ms: impl Iterator<Item = u64>) -> Vec<f64> {
    let mut at = 0;
    durations_ms
        .map(|d| {
            let start = at;
            at += d;
            start as f64 / 1000.0
        })
        .collect()
}

#[test]
fn a_real_render_writes_valid_platform_files_with_the_engines_onsets() {
    let directory = tempfile::tempdir().unwrap();
    let scene = Scene::parse(SCENE).unwrap();
    let files = render(&scene, directory.path());
    let onsets = audible_onsets(&scene);
    assert!(onsets.len() > 20, "{} audible glugs", onsets.len());
    let half_ms = 0.0005 + 1e-9;

    // Android XML: an entry starts within half a millisecond of every onset, and the entries
    // that start at an onset vibrate.
    let xml = text(file_of(&files, OutputFormat::ANDROID_XML));
    let violations = android_xml::validate(&xml);
    assert!(violations.is_empty(), "{violations:#?}");
    let entries = android_xml::parse(&xml);
    let entry_starts = starts(entries.iter().map(|e| e.duration_ms));
    assert!(worst_distance(&onsets, &entry_starts) <= half_ms);
    for onset in &onsets {
        let index = entry_starts
            .iter()
            .position(|start| (start - onset).abs() <= half_ms)
            .unwrap();
        assert!(
            (1..=255).contains(&entries[index].amplitude),
            "at {onset} s"
        );
    }
    assert!(entries
        .iter()
        .all(|e| e.duration_ms <= ANDROID_STEP_MS || e.amplitude == 0));

    // The waveform JSON holds the same entries.
    let waveform = text(file_of(&files, OutputFormat::ANDROID_WAVEFORM));
    let violations = android_waveform::validate(&waveform);
    assert!(violations.is_empty(), "{violations:#?}");
    let pairs: Vec<(i64, i64)> = entries
        .iter()
        .map(|e| (e.duration_ms as i64, e.amplitude as i64))
        .collect();
    assert_eq!(android_waveform::parse(&waveform), pairs);

    // Rumble: every onset shows as a rise of the motors within one frame.
    let rumble_text = text(file_of(&files, OutputFormat::RUMBLE));
    let violations = rumble::validate(&rumble_text);
    assert!(violations.is_empty(), "{violations:#?}");
    let rumble = rumble::parse(&rumble_text);
    let sum: Vec<f64> = rumble.frames.iter().map(|f| f.1 + f.2).collect();
    for onset in &onsets {
        let k = (onset * rumble.rate_hz) as usize;
        let before = if k == 0 { 0.0 } else { sum[k - 1] };
        assert!(
            sum[k].max(sum[(k + 1).min(sum.len() - 1)]) > before,
            "no rise within a frame of the glug at {onset} s"
        );
    }

    // .haps: one note per audible glug, starting at its onset.
    let haps_text = text(file_of(&files, OutputFormat::HAPS));
    let violations = haps::validate(&haps_text);
    assert!(violations.is_empty(), "{violations:#?}");
    let melodies = haps::parse(&haps_text);
    let note_starts: Vec<f64> = melodies[0].iter().map(|n| n.start_s).collect();
    assert_eq!(note_starts.len(), onsets.len());
    assert!(worst_distance(&onsets, &note_starts) < 1e-9);

    // DualSense: 4 channels; the actuators are the render's own samples, the audio silent.
    let bytes = std::fs::read(file_of(&files, OutputFormat::DUALSENSE)).unwrap();
    let violations = dualsense::validate(&bytes);
    assert!(violations.is_empty(), "{violations:#?}");
    let frames = dualsense::parse(&bytes);
    let wav: Vec<f32> = hound::WavReader::open(file_of(&files, OutputFormat::WAV))
        .unwrap()
        .samples::<f32>()
        .map(Result::unwrap)
        .collect();
    assert_eq!(scene.sample_rate, DUALSENSE_RATE_HZ);
    assert_eq!(frames.len(), wav.len());
    for (frame, y) in frames.iter().zip(&wav) {
        let expected = (*y as f64 * 32_768.0).round().clamp(-32_768.0, 32_767.0) as i16;
        assert_eq!(*frame, [0, 0, expected, expected]);
    }

    // Android Ogg: one audio channel (silent) and one haptic channel that decodes back to the
    // render within Vorbis' loss: its error is 30 dB below the signal.
    let bytes = std::fs::read(file_of(&files, OutputFormat::ANDROID_OGG)).unwrap();
    let violations = android_ogg::validate(&bytes);
    assert!(violations.is_empty(), "{violations:#?}");
    let decoded = android_ogg::parse(&bytes);
    assert_eq!(decoded.sample_rate, scene.sample_rate);
    assert_eq!((decoded.channels.len(), decoded.haptic_channels), (2, 1));
    let haptic = &decoded.channels[1];
    assert_eq!(haptic.len(), wav.len());
    assert!(decoded.channels[0].iter().all(|y| y.abs() < 1e-3));
    let power = |samples: &mut dyn Iterator<Item = f64>| samples.map(|y| y * y).sum::<f64>();
    let signal = power(&mut wav.iter().map(|&y| y as f64));
    let error = power(&mut haptic.iter().zip(&wav).map(|(&d, &y)| (d - y) as f64));
    let snr_db = 10.0 * (signal / error).log10();
    eprintln!("the Ogg's haptic channel: {snr_db:.1} dB above its coding error");
    assert!(snr_db > 30.0, "{snr_db} dB");
}

/// The low motor's share of the energy, Σ low² / Σ (low² + high²), of a pour at viscosity `c`.
fn low_share(c: f64) -> f64 {
    let scene = Scene::parse(&format!(
        "seed = 3\nduration_s = 3.0\ntilt_deg = 140.0\nviscosity_c = {c}\n"
    ))
    .unwrap();
    let directory = tempfile::tempdir().unwrap();
    let path = directory.path().join("pour.json");
    let output = Output {
        format: OutputFormat::RUMBLE,
        path: path.clone(),
    };
    render_to_files(&scene, "pour", &[output], &OutputOptions::default(), |_| {}).unwrap();
    let rumble = rumble::parse(&text(&path));
    let low: f64 = rumble.frames.iter().map(|f| f.1 * f.1).sum();
    let high: f64 = rumble.frames.iter().map(|f| f.2 * f.2).sum();
    assert!(low + high > 0.0, "a silent pour at c = {c}");
    low / (low + high)
}

/// The model gives the low component (f1) the share c of each glug's amplitude: a more
/// viscous liquid moves the weight to the low motor.
#[test]
fn viscosity_moves_the_rumble_to_the_low_motor() {
    let shares: Vec<(f64, f64)> = [0.1, 0.33, 0.6, 0.9]
        .into_iter()
        .map(|c| (c, low_share(c)))
        .collect();
    eprintln!("low motor's share of the energy by viscosity: {shares:?}");
    for pair in shares.windows(2) {
        assert!(pair[1].1 > pair[0].1, "{shares:?}");
    }
}

#[test]
fn one_command_writes_every_platform_file() {
    let directory = tempfile::tempdir().unwrap();
    let scene = directory.path().join("pour.toml");
    std::fs::write(&scene, "seed = 5\nduration_s = 1.0\ntilt_deg = 140.0\n").unwrap();
    let formats = "wav,haptic,ahap,android-xml,android-waveform,android-ogg,dualsense,rumble,haps";
    let output = sake_glug(
        directory.path(),
        &[
            "render",
            "pour.toml",
            "--out-dir",
            "clips",
            "--formats",
            formats,
        ],
    );
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let mut expected: Vec<String> = formats
        .split(',')
        .map(|name| OutputFormat::of_name(name).unwrap().file_name("pour"))
        .collect();
    expected.sort();
    assert_eq!(files_in(&directory.path().join("clips")), expected);
}

/// The fidelity report finds each format's onsets within its own step of the model's, and
/// the envelope of each clip format within a few dB.
#[test]
fn the_fidelity_report_measures_every_format_within_its_step() {
    use sake_glug_render::fidelity::measure;
    let scene = Scene::parse(SCENE).unwrap();
    let rows = measure(&scene, "pour", &OutputOptions::default()).unwrap();
    let step_ms = |format: OutputFormat| match format.name() {
        "android-xml" | "android-waveform" => Some(0.5),
        "rumble" => Some(10.0),
        "haptic" | "ahap" | "haps" => Some(1e-6),
        _ => None,
    };
    let unplayed = [OutputFormat::PLOT, OutputFormat::UNITS, OutputFormat::STATE];
    assert_eq!(
        rows.len(),
        OutputFormat::ALL.len() - unplayed.len(),
        "every format but the plot and the tables"
    );
    assert!(rows.iter().all(|row| !unplayed.contains(&row.format)));
    for row in &rows {
        assert!(row.bytes > 0, "{row:?}");
        match (
            step_ms(row.format),
            row.onset_error_ms,
            row.envelope_error_db,
        ) {
            (Some(step), Some((mean, worst)), Some(db)) => {
                assert!(mean <= worst && worst <= step + 1e-9, "{row:?}");
                assert!(db < 3.0, "{row:?}");
            }
            (None, None, None) => {}
            _ => panic!("{row:?} is not measured as its kind"),
        }
    }
}

/// At another rate than 48 kHz the fidelity report measures the DualSense file too (resampled),
/// and says so.
#[test]
fn the_fidelity_report_says_a_dualsense_file_is_resampled() {
    use sake_glug_render::fidelity::measure;
    let scene = Scene::parse("sample_rate = 44100\nduration_s = 1.0\ntilt_deg = 140.0\n").unwrap();
    let rows = measure(&scene, "pour", &OutputOptions::default()).unwrap();
    let row = rows
        .iter()
        .find(|row| row.format == OutputFormat::DUALSENSE)
        .unwrap();
    assert!(row.bytes > 0, "{row:?}");
    assert!(
        row.limits.contains("resampled from the scene's 44100 Hz"),
        "{row:?}"
    );
}

/// A rumble rate outside its range is refused before anything is written, naming what was
/// wrong: by the command line, and by the format.
#[test]
fn a_rumble_rate_out_of_range_is_refused_up_front() {
    let directory = tempfile::tempdir().unwrap();
    let output = sake_glug(
        directory.path(),
        &["render", "--rumble-rate", "0", "-o", "rumble:pour.json"],
    );
    assert_eq!(output.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&output.stderr).contains("--rumble-rate"));
    // The format refuses it itself, for a program that calls the renderer.
    let path = directory.path().join("pour.json");
    let output = Output {
        format: OutputFormat::RUMBLE,
        path: path.clone(),
    };
    let mut options = OutputOptions::default();
    options.platforms.rumble_rate_hz = 0.0;
    let scene = Scene::parse("duration_s = 1.0\ntilt_deg = 140.0\n").unwrap();
    let error = render_to_files(&scene, "pour", &[output], &options, |_| {}).unwrap_err();
    assert!(
        matches!(error, OutputError::RumbleRate { .. })
            && error.to_string().contains("1 to 1000 Hz"),
        "{error}"
    );
    assert!(files_in(directory.path()).is_empty());
}

/// The actuator channel of a `dualsense` file, full scale ±1.
fn actuator(path: &Path) -> Vec<f64> {
    dualsense::parse(&std::fs::read(path).unwrap())
        .iter()
        .map(|frame| f64::from(frame[2]) / 32_768.0)
        .collect()
}

/// The DualSense plays 48 kHz only: a scene at 44.1 kHz is resampled. Its file is held against
/// the DualSense file of the same scene rendered at 48 kHz: as many frames; the envelope (RMS
/// every 5 ms, where the 48 kHz render is within 40 dB of its loudest) within 0.05 dB on
/// average and 0.5 dB at worst; each audible glug where the 48 kHz render has it, within
/// 0.01 ms, under half a sample (the least-squares alignment of the 5 ms after each onset);
/// and the whole waveform 50 dB above the difference. (The pure tone's frequency and level:
/// the resampler's own tests, crates/render/src/resample.rs.)
#[test]
fn a_dualsense_file_at_another_rate_follows_the_48_khz_render() {
    let directory = tempfile::tempdir().unwrap();
    let at_48k = Scene::parse(&format!("duration_s = 3.0\n{SCENE}")).unwrap();
    assert_eq!(at_48k.sample_rate, DUALSENSE_RATE_HZ);
    let at_44k = at_48k.clone().with_sample_rate(44_100.0).unwrap();
    let written = |scene: &Scene, name: &str| {
        let path = directory.path().join(name);
        let output = Output {
            format: OutputFormat::DUALSENSE,
            path: path.clone(),
        };
        render_to_files(scene, "pour", &[output], &OutputOptions::default(), |_| {}).unwrap();
        actuator(&path)
    };
    let (reference, resampled) = (written(&at_48k, "48k.wav"), written(&at_44k, "44k.wav"));
    assert_eq!(resampled.len(), reference.len());

    let frame = 240;
    let rms = |samples: &[f64]| -> Vec<f64> {
        samples
            .chunks(frame)
            .map(|chunk| (chunk.iter().map(|y| y * y).sum::<f64>() / chunk.len() as f64).sqrt())
            .collect()
    };
    let (expected, got) = (rms(&reference), rms(&resampled));
    let loudest = expected.iter().copied().fold(0.0, f64::max);
    let errors_db: Vec<f64> = expected
        .iter()
        .zip(&got)
        .filter(|(&level, _)| level >= 0.01 * loudest)
        .map(|(&level, &other)| (20.0 * (other.max(1e-6) / level).log10()).abs())
        .collect();
    let mean_db = errors_db.iter().sum::<f64>() / errors_db.len() as f64;
    let worst_db = errors_db.iter().copied().fold(0.0, f64::max);

    let onsets = audible_onsets(&at_48k);
    assert!(onsets.len() > 20, "{} audible glugs", onsets.len());
    let window = 240;
    let shifts_ms: Vec<f64> = onsets
        .iter()
        .map(|&onset| {
            let start = (onset * DUALSENSE_RATE_HZ as f64) as usize;
            let here = &reference[start..(start + window).min(reference.len())];
            // The lag (in samples, ±1 ms) at which the resampled file matches best: the least
            // squared difference.
            let misfit = |lag: i64| -> f64 {
                here.iter()
                    .enumerate()
                    .map(|(n, y)| {
                        let m = (start + n) as i64 + lag;
                        let other = resampled.get(m.max(0) as usize).copied().unwrap_or(0.0);
                        (y - other).powi(2)
                    })
                    .sum()
            };
            let best = (-48..=48)
                .min_by(|&a, &b| misfit(a).total_cmp(&misfit(b)))
                .unwrap();
            // Refined between samples by the parabola through the best three.
            let (left, centre, right) = (misfit(best - 1), misfit(best), misfit(best + 1));
            let offset = 0.5 * (left - right) / (left - 2.0 * centre + right);
            (best as f64 + offset) * 1000.0 / DUALSENSE_RATE_HZ as f64
        })
        .collect();
    let worst_shift_ms = shifts_ms.iter().map(|s| s.abs()).fold(0.0, f64::max);
    let power = |samples: &mut dyn Iterator<Item = f64>| samples.map(|y| y * y).sum::<f64>();
    let error = power(&mut reference.iter().zip(&resampled).map(|(x, y)| x - y));
    let snr_db = 10.0 * (power(&mut reference.iter().copied()) / error).log10();
    eprintln!(
        "44.1 kHz resampled against 48 kHz: envelope {mean_db:.3} dB mean, {worst_db:.3} dB \
         worst over {} frames; {} onsets within {worst_shift_ms:.4} ms; {snr_db:.1} dB above \
         the difference",
        errors_db.len(),
        onsets.len()
    );
    assert!(
        mean_db < 0.05 && worst_db < 0.5,
        "{mean_db} dB, {worst_db} dB"
    );
    assert!(worst_shift_ms < 0.01, "{shifts_ms:?}");
    assert!(snr_db > 50.0, "{snr_db} dB");
}
