//! The level stage (MODEL.md §19) as a user meets it: `--loudness` and `--true-peak` on the
//! waveform files, `--haptic-peak` on the clips, each file read back as written; and the
//! `.ahap`'s intensity curves within Core Haptics' limit.

use std::path::Path;

use serde_json::Value;

use crate::command::sake_glug;
use sake_glug_render::clips::{ClipSource, Glug};
use sake_glug_render::loudness::LoudnessMeter;
use sake_glug_render::sinks::ahap_json;
use sake_glug_render::{render_scene_to_vec, trim, Scene};

use crate::support::BUSY_SCENE;

/// The mono f32 samples of a WAV the renderer wrote, and its rate.
fn wav(path: &Path) -> (Vec<f32>, u32) {
    let mut reader = hound::WavReader::open(path).unwrap();
    let rate = reader.spec().sample_rate;
    (reader.samples::<f32>().map(Result::unwrap).collect(), rate)
}

/// True peak read independently of the renderer's meter: every sample and three points
/// between each pair (4× oversampling, BS.1770-4 Annex 2), interpolated by a Hann-windowed
/// sinc of 64 taps.
fn true_peak_4x(samples: &[f32]) -> f64 {
    const HALF: isize = 32;
    let kernel = |x: f64| {
        if x == 0.0 {
            return 1.0;
        }
        let window = 0.5 + 0.5 * (std::f64::consts::PI * x / HALF as f64).cos();
        (std::f64::consts::PI * x).sin() / (std::f64::consts::PI * x) * window
    };
    let mut peak = samples.iter().fold(0.0f64, |m, y| m.max(y.abs() as f64));
    for n in 0..samples.len() as isize {
        for phase in 1..4 {
            let offset = phase as f64 / 4.0;
            let mut sum = 0.0;
            for k in (n - HALF + 1)..=(n + HALF) {
                if let Some(&y) = usize::try_from(k).ok().and_then(|k| samples.get(k)) {
                    sum += y as f64 * kernel(n as f64 + offset - k as f64);
                }
            }
            peak = peak.max(sum.abs());
        }
    }
    20.0 * peak.log10()
}

fn integrated_lufs(samples: &[f32], rate: u32) -> f64 {
    let mut meter = LoudnessMeter::mono(rate);
    meter.add(samples);
    meter.loudness().integrated_lufs
}

/// `--loudness -23` brings the WAV to −23 LUFS (the renderer's meter on the file read back;
/// the host tests hold it against pyloudnorm).
#[test]
fn loudness_brings_the_wav_to_its_target() {
    let directory = tempfile::tempdir().unwrap();
    let output = sake_glug(
        directory.path(),
        &["render", "-o", "pour.wav", "--loudness", "-23"],
    );
    assert!(output.status.success(), "{output:?}");
    let summary = String::from_utf8(output.stdout).unwrap();
    assert!(summary.contains("-23.0 LUFS"), "{summary}");
    let (samples, rate) = wav(&directory.path().join("pour.wav"));
    let lufs = integrated_lufs(&samples, rate);
    assert!((lufs + 23.0).abs() <= 0.1, "{lufs} LUFS");
}

/// With a loudness the ceiling cannot allow, the ceiling wins: the true peak, read 4×
/// oversampled by the test's own interpolator, stays at or under −1 dBTP, and the summary says
/// the file is quieter than asked.
#[test]
fn the_true_peak_ceiling_wins_and_holds_when_oversampled() {
    let directory = tempfile::tempdir().unwrap();
    let output = sake_glug(
        directory.path(),
        &[
            "render",
            "-o",
            "pour.wav",
            "--loudness",
            "-10",
            "--true-peak",
            "-1",
        ],
    );
    assert!(output.status.success(), "{output:?}");
    let summary = String::from_utf8(output.stdout).unwrap();
    assert!(
        summary.contains("held by the true-peak ceiling"),
        "{summary}"
    );
    let (samples, rate) = wav(&directory.path().join("pour.wav"));
    let peak = true_peak_4x(&samples);
    assert!(peak <= -1.0 + 0.05, "true peak {peak} dBTP");
    // Held at the ceiling, not far below it.
    assert!(peak >= -1.5, "true peak {peak} dBTP");
    assert!(integrated_lufs(&samples, rate) < -10.5);
}

/// A render too short to gate, or silent, is refused by name, and writes nothing.
#[test]
fn short_or_silent_renders_are_refused_not_raised_to_infinity() {
    let directory = tempfile::tempdir().unwrap();
    let cases = [
        (
            "short.toml",
            "duration_s = 0.3\ntilt_deg = 140.0\n",
            "0.4 s",
        ),
        ("still.toml", "duration_s = 2.0\ntilt_deg = 0.0\n", "silent"),
    ];
    for (name, text, says) in cases {
        std::fs::write(directory.path().join(name), text).unwrap();
        let output = sake_glug(
            directory.path(),
            &["render", name, "-o", "out.wav", "--loudness", "-23"],
        );
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{name}: {stderr}");
        assert!(stderr.contains(says), "{name}: {stderr}");
        assert!(!directory.path().join("out.wav").exists(), "{name}");
    }
}

/// The strongest drive of each haptic file, read from the file as its platform reads it.
fn peak_drive(name: &str, text: &str) -> f64 {
    let fold = |values: Vec<f64>| values.into_iter().fold(0.0, f64::max);
    let json = || serde_json::from_str::<Value>(text).unwrap();
    let numbers = |value: &Value, key: &str| -> Vec<f64> {
        value
            .as_array()
            .unwrap()
            .iter()
            .map(|item| item[key].as_f64().unwrap())
            .collect()
    };
    match name {
        "pour.haptic" => fold(numbers(
            &json()["signals"]["continuous"]["envelopes"]["amplitude"],
            "amplitude",
        )),
        // The continuous events play at intensity × the intensity control; a level is its
        // square (Core Haptics' intensity is perceptual).
        "pour.ahap" => {
            let pattern = json()["Pattern"].as_array().unwrap().clone();
            let continuous = pattern
                .iter()
                .filter(|item| item["Event"]["EventType"] == "HapticContinuous")
                .map(|item| {
                    item["Event"]["EventParameters"][0]["ParameterValue"]
                        .as_f64()
                        .unwrap()
                })
                .fold(0.0, f64::max);
            let control = pattern
                .iter()
                .filter_map(|item| item.get("ParameterCurve"))
                .flat_map(|curve| numbers(&curve["ParameterCurveControlPoints"], "ParameterValue"))
                .fold(0.0, f64::max);
            (continuous * control).powi(2)
        }
        "pour.haps" => {
            let document = json();
            let notes = document["m_vibration"]["m_melodies"][0]["m_notes"]
                .as_array()
                .unwrap()
                .clone();
            fold(
                notes
                    .iter()
                    .flat_map(|note| {
                        numbers(
                            &note["m_hapticEffect"]["m_amplitudeModulation"]["m_keyframes"],
                            "m_value",
                        )
                    })
                    .collect(),
            )
        }
        "pour.xml" => fold(
            text.split("amplitude=\"")
                .skip(1)
                .map(|rest| rest.split('"').next().unwrap().parse::<f64>().unwrap() / 255.0)
                .collect(),
        ),
        "waveform.json" => fold(
            json()["amplitudes"]
                .as_array()
                .unwrap()
                .iter()
                .map(|a| a.as_f64().unwrap() / 255.0)
                .collect(),
        ),
        "rumble.json" => {
            let document = json();
            fold(
                document["frames"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|frame| frame["low"].as_f64().unwrap() + frame["high"].as_f64().unwrap())
                    .collect(),
            )
        }
        _ => unreachable!("{name}"),
    }
}

/// `--haptic-peak` brings every haptic format's strongest moment to the drive asked, read back
/// from each file, with an actuator's compensation and without; without it, the clips keep
/// the output gain's level (the default pour: well under full drive).
#[test]
fn haptic_peak_reaches_its_drive_in_every_haptic_format() {
    let files = [
        "pour.haptic",
        "pour.ahap",
        "pour.haps",
        "pour.xml",
        "android-waveform:waveform.json",
        "rumble:rumble.json",
    ];
    let cases: [(&[&str], Option<f64>); 4] = [
        (&[], None),
        (&["--haptic-peak", "100%"], Some(1.0)),
        (&["--haptic-peak", "-3dB"], Some(10f64.powf(-3.0 / 20.0))),
        (&["--haptic-peak", "0.8", "--actuator", "lra"], Some(0.8)),
    ];
    for (options, drive) in cases {
        let directory = tempfile::tempdir().unwrap();
        let mut args = vec!["render"];
        for file in files {
            args.extend(["-o", file]);
        }
        args.extend(options);
        let output = sake_glug(directory.path(), &args);
        assert!(output.status.success(), "{output:?}");
        for file in files {
            let name = file.rsplit(':').next().unwrap();
            let text = std::fs::read_to_string(directory.path().join(name)).unwrap();
            let peak = peak_drive(name, &text);
            match drive {
                // Android carries 255 levels and rumble 4 decimals a motor: within one step.
                Some(drive) => assert!(
                    (peak - drive).abs() <= 1.0 / 255.0,
                    "{options:?} {name}: {peak}"
                ),
                None => assert!(peak < 0.7, "{name}: {peak}"),
            }
        }
    }
}

/// The largest |sample| of a 4-channel `dualsense` file's actuator channels (3 and 4) and of
/// its audio channels (1 and 2), 0..1 of full scale.
fn dualsense_peaks(path: &Path) -> (f64, f64) {
    let mut reader = hound::WavReader::open(path).unwrap();
    assert_eq!(reader.spec().channels, 4);
    let (mut actuators, mut audio) = (0i32, 0i32);
    for (index, sample) in reader.samples::<i16>().enumerate() {
        let magnitude = i32::from(sample.unwrap()).abs();
        if index % 4 >= 2 {
            actuators = actuators.max(magnitude);
        } else {
            audio = audio.max(magnitude);
        }
    }
    (f64::from(actuators) / 32_768.0, f64::from(audio) / 32_768.0)
}

/// The largest |sample| of an `android-ogg` file's haptic channel (its last) and of its audio
/// channel, decoded as a player decodes them.
fn ogg_peaks(path: &Path) -> (f64, f64) {
    let file = std::fs::File::open(path).unwrap();
    let mut decoder = vorbis_rs::VorbisDecoder::new(std::io::BufReader::new(file)).unwrap();
    assert_eq!(decoder.channels().get(), 2);
    let (mut haptic, mut audio) = (0.0f64, 0.0f64);
    while let Some(block) = decoder.decode_audio_block().unwrap() {
        let peak = |channel: &[f32]| channel.iter().fold(0.0f64, |m, y| m.max(y.abs() as f64));
        audio = audio.max(peak(block.samples()[0]));
        haptic = haptic.max(peak(block.samples()[1]));
    }
    (haptic, audio)
}

/// The haptic channels' peak drives (%) the fidelity table gives the `dualsense` and
/// `android-ogg` rows.
fn fidelity_channel_drives(table: &str) -> Vec<(String, f64)> {
    table
        .lines()
        .filter(|line| line.starts_with("| `dualsense`") || line.starts_with("| `android-ogg`"))
        .map(|line| {
            let name = line.split('`').nth(1).unwrap().to_owned();
            let drive = line
                .split("haptic channel: peak drive ")
                .nth(1)
                .and_then(|rest| rest.split(' ').next())
                .unwrap_or_else(|| panic!("no haptic channel's drive in {line}"));
            (name, drive.parse().unwrap())
        })
        .collect()
}

/// `--haptic-peak` drives the haptic channel of the files that carry one beside their audio
/// (the DualSense's actuators, Android's haptic channel) to the drive asked, read back from
/// each file (16-bit PCM as written; Vorbis as decoded), at the scene's rate and resampled;
/// their audio channels keep the loudness rules (the `.wav`'s samples), and `--fidelity` reads
/// the same drive back. Without it the haptic channel keeps the render's level.
#[test]
fn haptic_peak_drives_the_haptic_channels_of_dualsense_and_android_ogg() {
    let cases: [(&[&str], Option<f64>); 4] = [
        (&[], None),
        (&["--haptic-peak", "100%"], Some(1.0)),
        (
            &[
                "--haptic-peak",
                "-6dB",
                "--loudness",
                "-20",
                "--audio-channels",
                "glug",
            ],
            Some(10f64.powf(-6.0 / 20.0)),
        ),
        (
            &[
                "--haptic-peak",
                "0.8",
                "--sample-rate",
                "44100",
                "--audio-channels",
                "glug",
            ],
            Some(0.8),
        ),
    ];
    for (options, drive) in cases {
        let directory = tempfile::tempdir().unwrap();
        let mut args = vec![
            "render",
            "-o",
            "pour.wav",
            "-o",
            "dualsense:pad.wav",
            "-o",
            "pour.ogg",
        ];
        args.extend(options);
        let output = sake_glug(directory.path(), &args);
        assert!(output.status.success(), "{output:?}");
        let (samples, _) = wav(&directory.path().join("pour.wav"));
        let render_peak = samples.iter().fold(0.0f64, |m, y| m.max(y.abs() as f64));
        let (actuators, pad_audio) = dualsense_peaks(&directory.path().join("pad.wav"));
        let (haptic, ogg_audio) = ogg_peaks(&directory.path().join("pour.ogg"));
        match drive {
            Some(drive) => {
                // 16-bit: within a step (full scale is 32767/32768); resampled at 44.1 kHz.
                assert!(
                    (actuators - drive).abs() <= 1.5 / 32_768.0,
                    "{options:?} dualsense: {actuators}"
                );
                // Vorbis codes the channel lossily: its decoded peak strays from the drive.
                assert!((haptic - drive).abs() <= 0.02, "{options:?} ogg: {haptic}");
            }
            None => {
                assert!(
                    (actuators - render_peak).abs() <= 1.0 / 32_768.0,
                    "{actuators}"
                );
                assert!((haptic - render_peak).abs() <= 0.02, "{haptic}");
            }
        }
        // The audio channels (with --audio-channels glug) are the render's samples at the
        // loudness asked, not driven: the .wav's peak, within the resampling's and the
        // codec's error.
        if options.contains(&"glug") {
            let wav_peak = render_peak;
            let resampled = options.contains(&"44100");
            let tolerance = if resampled { 0.01 } else { 1.0 / 32_768.0 };
            assert!(
                (pad_audio - wav_peak).abs() <= tolerance,
                "{options:?} {pad_audio} vs {wav_peak}"
            );
            assert!(
                (ogg_audio - wav_peak).abs() <= 0.02,
                "{options:?} {ogg_audio} vs {wav_peak}"
            );
            assert!(
                (actuators - pad_audio).abs() > 0.05,
                "the audio is not driven"
            );
        }
    }
    // The fidelity report reads the same drives back.
    let directory = tempfile::tempdir().unwrap();
    let output = sake_glug(
        directory.path(),
        &["render", "--fidelity", "--haptic-peak", "100%"],
    );
    assert!(output.status.success(), "{output:?}");
    let table = String::from_utf8_lossy(&output.stdout);
    let drives = fidelity_channel_drives(&table);
    assert_eq!(drives.len(), 2, "{table}");
    for (name, percent) in drives {
        let tolerance = if name == "dualsense" { 0.05 } else { 2.0 };
        assert!((percent - 100.0).abs() <= tolerance, "{name}: {percent} %");
    }
}

/// The default pour's `.ahap` draws each glug's decay as intensity curves, every one within
/// Core Haptics' 16 points, not as a staircase of short events; a decay too long for one curve
/// goes on in the next, from the point the last ended on.
#[test]
fn the_ahap_draws_decays_as_curves_within_the_limit() {
    let directory = tempfile::tempdir().unwrap();
    let output = sake_glug(directory.path(), &["render", "-o", "pour.ahap"]);
    assert!(output.status.success(), "{output:?}");
    let text = std::fs::read_to_string(directory.path().join("pour.ahap")).unwrap();
    let document: Value = serde_json::from_str(&text).unwrap();
    let pattern = document["Pattern"].as_array().unwrap();
    let count = |kind: &str| {
        pattern
            .iter()
            .filter(|item| item["Event"]["EventType"] == kind)
            .count()
    };
    let curves: Vec<&Value> = pattern
        .iter()
        .filter_map(|item| item.get("ParameterCurve"))
        .collect();
    assert_eq!(count("HapticTransient"), 42);
    assert_eq!(count("HapticContinuous"), 42, "one ring a glug");
    assert_eq!(curves.len(), 42);
    let description = document["Metadata"]["Description"].as_str().unwrap();
    assert!(
        description.contains("59 units, 42 audible"),
        "{description}"
    );

    // One glug decaying for seconds: its ring needs more than one curve.
    let glug = Glug {
        onset_s: 0.1,
        amplitudes: [0.3, 0.3],
        frequency_hz: [80.0, 300.0],
        decay_per_s: [1.0, 1.0],
        viscosity: 0.5,
        actuator_gain: [1.0, 1.0],
    };
    let source = ClipSource {
        duration_s: 8.0,
        glugs: &[glug],
        ceiling: 1.0,
        scene_name: "slow",
        seed: 1,
    };
    let document: Value = serde_json::from_str(&ahap_json(&source)).unwrap();
    let curves: Vec<Vec<(f64, f64)>> = document["Pattern"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|item| item.get("ParameterCurve"))
        .map(|curve| {
            let start = curve["Time"].as_f64().unwrap();
            curve["ParameterCurveControlPoints"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| {
                    (
                        start + p["Time"].as_f64().unwrap(),
                        p["ParameterValue"].as_f64().unwrap(),
                    )
                })
                .collect()
        })
        .collect();
    assert!(curves.len() > 1, "{} curves", curves.len());
    for pair in curves.windows(2) {
        assert!(pair[0].len() <= 16 && pair[1].len() <= 16);
        assert_eq!(
            pair[0].last(),
            pair[1].first(),
            "curves continue each other"
        );
    }
}

/// A file whose samples pass full scale is named, with how many: `--loudness -16
/// --sample-format s16` clipped the default pour's peaks and only said "true peak 0.9 dBTP"
/// (issue 49). The count is the float file's samples beyond ±1; under `--true-peak -1` nothing
/// clips and nothing is said.
#[test]
fn a_file_that_clips_is_named_with_its_count() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    let render = |args: &[&str]| {
        let output = sake_glug(dir, args);
        assert!(output.status.success(), "{output:?}");
        String::from_utf8(output.stderr).unwrap()
    };
    let float = render(&["render", "-o", "loud.wav", "--loudness", "-16"]);
    let (samples, _) = wav(&dir.join("loud.wav"));
    let beyond = samples.iter().filter(|y| y.abs() > 1.0).count();
    assert!(beyond > 0, "the default pour at -16 LUFS passes full scale");
    assert!(
        float.contains(&format!(
            "warning: loud.wav: {beyond} samples pass full scale (kept in the float file"
        )),
        "{float}"
    );
    let integer = render(&[
        "render",
        "-o",
        "loud16.wav",
        "--loudness",
        "-16",
        "--sample-format",
        "s16",
    ]);
    assert!(
        integer.contains(&format!(
            "warning: loud16.wav: {beyond} samples pass full scale, clipped in the file"
        )),
        "{integer}"
    );
    let held = render(&[
        "render",
        "-o",
        "held.wav",
        "--loudness",
        "-16",
        "--true-peak",
        "-1",
        "--sample-format",
        "s16",
    ]);
    assert!(!held.contains("warning"), "{held}");
    assert!(!render(&["render", "-o", "plain.wav"]).contains("warning"));
}

/// The summary's peak is the largest |y| the render wrote, read here from the samples: on a
/// held pour, whose blocks the engine's one output pass measures as it goes; through ramps of
/// tilt and gain, measured after the block; with the limiter at work; and in a trimmed render,
/// whose fade comes after the engine's pass.
#[test]
fn the_summary_peak_is_the_largest_sample_written() {
    let held = "duration_s = 3.0\ntilt_deg = 135.0\n[output]\ndrain = \"follow\"\n";
    let limited = format!("{held}gain_db = 24.0\n");
    let scenes = [
        ("held pour", Scene::parse(held).unwrap()),
        ("ramps", Scene::parse(BUSY_SCENE).unwrap()),
        ("limiter", Scene::parse(&limited).unwrap()),
        ("trimmed", trim::trimmed(Scene::default(), -30.0).unwrap()),
    ];
    assert!(scenes[3].1.fade_out.is_some(), "the trimmed render fades");
    for (name, scene) in scenes {
        let (samples, summary) = render_scene_to_vec(&scene).unwrap();
        let largest = samples.iter().fold(0.0f32, |m, y| m.max(y.abs()));
        assert!(largest > 0.01, "{name}: the scene sounds");
        assert_eq!(summary.peak.to_bits(), largest.to_bits(), "{name}");
        if name == "limiter" {
            assert_eq!(largest, 1.0, "the limiter holds the ceiling");
        }
    }
}
