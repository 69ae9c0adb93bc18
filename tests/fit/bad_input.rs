//! Every bad input of a session refused with its file and key, or warned about.

use sake_glug_fit::{fit_session, FitError, FitSession};

use super::*;

fn session_error(folder: &Path, text: &str) -> String {
    let path = folder.join("session.toml");
    std::fs::write(&path, text).unwrap();
    match FitSession::load(&path).and_then(|session| fit_session(&session)) {
        Ok(_) => panic!("the session was accepted"),
        Err(error) => error.to_string(),
    }
}

fn assert_has(message: &str, parts: &[&str]) {
    for part in parts {
        assert!(message.contains(part), "`{part}` missing from: {message}");
    }
}

#[test]
fn a_missing_file_an_unknown_key_and_no_volume_are_named() {
    let folder = tempfile::tempdir().unwrap();
    let missing = session_error(
        folder.path(),
        "[[recording]]\naudio = \"gone.wav\"\ntilt_deg = 135\nstart_ml = 300\n",
    );
    assert_has(&missing, &["recording[0].audio", "gone.wav"]);
    let unknown = session_error(
        folder.path(),
        "[[recording]]\naudio = \"a.wav\"\ntilt_deg = 135\nstart_ml = 300\nangle = 3\n",
    );
    assert_has(&unknown, &["angle"]);
    let no_volume = session_error(
        folder.path(),
        "[[recording]]\naudio = \"a.wav\"\ntilt_deg = 135\n",
    );
    assert_has(&no_volume, &["recording[0]", "start_ml"]);
    let tilt = session_error(
        folder.path(),
        "[[recording]]\naudio = \"a.wav\"\ntilt_deg = 200\nstart_ml = 1\n",
    );
    assert_has(&tilt, &["recording[0].tilt_deg", "200"]);
    let none = session_error(folder.path(), "capacity_ml = 300\n");
    assert_has(&none, &["no [[recording]]"]);
}

#[test]
fn a_slow_rate_silence_and_no_glugs_are_refused() {
    let folder = tempfile::tempdir().unwrap();
    let session = "[[recording]]\naudio = \"a.wav\"\ntilt_deg = 135\nstart_ml = 300\n";
    let wav = folder.path().join("a.wav");
    write_wav(&wav, &vec![0.1; 8000], 4000);
    assert_has(
        &session_error(folder.path(), session),
        &["recording[0].audio", "4000 Hz", "8000"],
    );
    write_wav(&wav, &vec![0.25; 25_000], 25_000);
    assert_has(
        &session_error(folder.path(), session),
        &["recording[0].audio", "silent (peak 0 after"],
    );
    let mut noise = vec![0.0f32; 50_000];
    add_noise(&mut noise, 0.01, 5);
    write_wav(&wav, &noise, 25_000);
    assert_has(&session_error(folder.path(), session), &["no glugs found"]);
}

#[test]
fn a_rising_weight_log_is_refused_with_its_line() {
    let rendered = render("sample_rate = 25000\ntilt_deg = 135.0\nduration_s = 2.0\n");
    let folder = tempfile::tempdir().unwrap();
    let take = Take {
        name: "pour",
        rendered: &rendered,
        tilt_deg: 135.0,
        liquid: None,
        weight: true,
        noise_db: None,
    };
    let path = write_session(folder.path(), 300.0, &[take]);
    // Filled instead of poured: the log read backwards.
    let mut filling = rendered.volume.clone();
    let times: Vec<f64> = filling.iter().map(|p| p.0).collect();
    filling.reverse();
    for (point, time) in filling.iter_mut().zip(times) {
        point.0 = time;
    }
    write_weight(&folder.path().join("pour.csv"), &filling, 1.0);
    let error = fit_session(&FitSession::load(&path).unwrap()).unwrap_err();
    assert!(
        matches!(error, FitError::WeightLog { line: 3, .. }),
        "{error}"
    );
    assert_has(
        &error.to_string(),
        &[
            "recording[0].weight.csv",
            "pour.csv",
            "line 3",
            "grams",
            "rises",
        ],
    );
}

#[test]
fn clipping_and_a_single_tilt_are_warned_about() {
    let rendered =
        render("sample_rate = 25000\ntilt_deg = 135.0\nduration_s = 2.0\noutput.gain_db = 12.0\n");
    assert!(rendered.samples.iter().filter(|y| y.abs() >= 1.0).count() > 10);
    let folder = tempfile::tempdir().unwrap();
    let take = Take {
        name: "loud",
        rendered: &rendered,
        tilt_deg: 135.0,
        liquid: None,
        weight: false,
        noise_db: None,
    };
    let fit = fit(&write_session(folder.path(), 300.0, &[take]));
    let warnings = fit.warnings.join("\n");
    assert_has(
        &warnings,
        &[
            "clipped",
            "`curves.drain` needs recordings at several tilts",
            "no weight log",
        ],
    );
    let kept: Vec<&str> = fit.liquids[0]
        .kept_default
        .iter()
        .map(|(key, _)| key.as_str())
        .collect();
    assert!(
        kept.contains(&"curves.drain") && kept.contains(&"bottle.pocket_ml"),
        "{kept:?}"
    );
}

/// A bottle kept full (follow mode) glugs for ever at one amplitude: counted at the default
/// pocket, its units pour far more than it holds. Those units get no volume, and a law through
/// the others with no measurable slope gives no zero: `silent_below_ml` keeps its default rather
/// than a number brought into range.
#[test]
fn a_pour_longer_than_its_bottle_and_a_flat_amplitude_law_are_warned_about() {
    let rendered = render(
        "sample_rate = 25000\ntilt_deg = 135.0\nduration_s = 10.0\n[output]\ndrain = \"follow\"\n",
    );
    let folder = tempfile::tempdir().unwrap();
    let take = Take {
        name: "full",
        rendered: &rendered,
        tilt_deg: 135.0,
        liquid: None,
        weight: false,
        noise_db: Some(-30.0),
    };
    let fit = fit(&write_session(folder.path(), 300.0, &[take]));
    let warnings = fit.warnings.join("\n");
    assert_has(
        &warnings,
        &[
            "`recording[0]`",
            "more than its start_ml = 300 ml",
            "no volume",
        ],
    );
    assert!(!warnings.contains("silent_below_ml"), "{warnings}");
    let liquid = &fit.liquids[0];
    let (_, why) = liquid
        .kept_default
        .iter()
        .find(|(key, _)| key == "amplitude.silent_below_ml")
        .unwrap_or_else(|| panic!("kept: {:?}", liquid.kept_default));
    assert_has(why, &["does not fall measurably with V"]);
    assert!(
        !liquid.model_toml.contains("silent_below_ml ="),
        "{}",
        liquid.model_toml
    );
}

/// A session of one recording `a.wav` in `folder`, its samples `samples` at 25 kHz.
fn one_recording(folder: &Path, samples: &[f32]) -> String {
    write_wav(&folder.join("a.wav"), samples, 25_000);
    let path = folder.join("session.toml");
    std::fs::write(
        &path,
        "[[recording]]\naudio = \"a.wav\"\ntilt_deg = 135\nstart_ml = 300\n",
    )
    .unwrap();
    match FitSession::load(&path).and_then(|session| fit_session(&session)) {
        Ok(_) => panic!("the recording was accepted"),
        Err(error) => error.to_string(),
    }
}

/// Issue 31: three NaN or infinite samples are named as such, with their count and the first.
#[test]
fn non_finite_samples_are_named_with_their_count_and_the_first() {
    let rendered = render("sample_rate = 25000\ntilt_deg = 135.0\nduration_s = 1.0\n");
    let mut samples = rendered.samples.clone();
    samples[1000] = f32::NAN;
    samples[2000] = f32::INFINITY;
    samples[3000] = f32::NEG_INFINITY;
    let folder = tempfile::tempdir().unwrap();
    let message = one_recording(folder.path(), &samples);
    assert_has(
        &message,
        &[
            "a.wav",
            "3 sample(s) are not finite",
            "the first at sample 1000",
        ],
    );
    assert!(!message.contains("silent"), "{message}");
}

/// Issue 31: a single 3e38 sample among glugs is an isolated spike, not "no glugs".
#[test]
fn an_isolated_spike_is_named_as_such() {
    let rendered = render("sample_rate = 25000\ntilt_deg = 135.0\nduration_s = 1.0\n");
    let mut samples = rendered.samples.clone();
    samples[12_345] = 3e38;
    let folder = tempfile::tempdir().unwrap();
    let message = one_recording(folder.path(), &samples);
    assert_has(&message, &["a.wav", "isolated spike", "sample 12345"]);
    assert!(!message.contains("no glugs"), "{message}");
}

/// Issue 31: a weight log ten times too large (or from a scale not zeroed for the bottle) gives
/// volumes a 300 ml bottle cannot hold: refused with the figures, not fitted.
#[test]
fn a_weight_log_beyond_the_bottle_is_refused_with_its_volumes() {
    let rendered = render("sample_rate = 25000\ntilt_deg = 135.0\nduration_s = 2.0\n");
    let folder = tempfile::tempdir().unwrap();
    let take = Take {
        name: "pour",
        rendered: &rendered,
        tilt_deg: 135.0,
        liquid: None,
        weight: true,
        noise_db: None,
    };
    let path = write_session(folder.path(), 300.0, &[take]);
    // The session gives no start_ml: a volume is the weight over the density.
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("start_ml = 300\n", "");
    std::fs::write(&path, text).unwrap();
    write_weight(&folder.path().join("pour.csv"), &rendered.volume, 10.0);
    let error = match fit_session(&FitSession::load(&path).unwrap()) {
        Ok(fit) => panic!("fitted: pocket {}", estimate(&fit, 0, "bottle.pocket_ml")),
        Err(error) => error.to_string(),
    };
    assert_has(
        &error,
        &["pour.csv", "3000.0 ml", "300 ml cannot hold", "zeroed"],
    );
}

/// Issue 31: a file that is no weight log, its first line named as both columns, and a field of
/// a million characters: a message quotes at most the first 32 characters of a field.
#[test]
fn a_weight_log_error_quotes_no_more_than_the_start_of_a_field() {
    let folder = tempfile::tempdir().unwrap();
    std::fs::write(folder.path().join("a.wav"), b"").unwrap();
    let header = "root:x:0:0:root:/root:/bin/bash";
    let second = "daemon:x:1:1:daemon:/usr/sbin:/usr/sbin/nologin-and-a-long-secret-tail";
    std::fs::write(
        folder.path().join("passwd"),
        format!("{header}\n{second}\n"),
    )
    .unwrap();
    let session = format!(
        "[[recording]]\naudio = \"a.wav\"\ntilt_deg = 135\n\
         weight = {{ csv = \"passwd\", time = \"{header}\", column = \"{header}\" }}\n"
    );
    let path = folder.path().join("session.toml");
    std::fs::write(&path, session).unwrap();
    let spec = &FitSession::load(&path).unwrap().recordings[0];
    let weight = spec.weight.as_ref().unwrap();
    let error = sake_glug_fit::WeightLog::read(weight, &spec.key, None, 300.0)
        .unwrap_err()
        .to_string();
    assert!(!error.contains(second), "{error}");
    assert!(!error.contains("secret"), "{error}");
    assert_has(
        &error,
        &["passwd", "line 2", "daemon:x:1:1:daemon:/usr/sbin:/u…"],
    );
    // A field of a million characters.
    let huge = "9".repeat(500_000) + "x" + &"9".repeat(500_000);
    std::fs::write(
        folder.path().join("passwd"),
        format!("time_s,grams\n0,{huge}\n"),
    )
    .unwrap();
    let weight = sake_glug_fit::WeightSpec {
        csv: folder.path().join("passwd"),
        time: "time_s".into(),
        column: "grams".into(),
        density_g_per_ml: 1.0,
    };
    let error = sake_glug_fit::WeightLog::read(&weight, "recording[0]", None, 300.0)
        .unwrap_err()
        .to_string();
    assert!(
        error.len() < 400,
        "{} characters: {}",
        error.len(),
        &error[..400]
    );
}

/// Issue 31: a recording whose fit cannot fit in memory is refused before it is read, with the
/// figures: an 8-bit WAV whose header announces 4 GB of samples (8 bytes each in a fit).
#[test]
fn a_recording_too_large_for_memory_is_refused_up_front() {
    let folder = tempfile::tempdir().unwrap();
    let data_bytes: u32 = 0xFFFF_FF00;
    let mut wav = Vec::new();
    wav.extend_from_slice(b"RIFF");
    wav.extend_from_slice(&(data_bytes.wrapping_add(36)).to_le_bytes());
    wav.extend_from_slice(b"WAVEfmt ");
    wav.extend_from_slice(&16u32.to_le_bytes());
    wav.extend_from_slice(&1u16.to_le_bytes()); // PCM
    wav.extend_from_slice(&1u16.to_le_bytes()); // mono
    wav.extend_from_slice(&8_000u32.to_le_bytes());
    wav.extend_from_slice(&8_000u32.to_le_bytes());
    wav.extend_from_slice(&1u16.to_le_bytes());
    wav.extend_from_slice(&8u16.to_le_bytes());
    wav.extend_from_slice(b"data");
    wav.extend_from_slice(&data_bytes.to_le_bytes());
    wav.extend_from_slice(&[128u8; 64]);
    let path = folder.path().join("a.wav");
    std::fs::write(&path, wav).unwrap();
    let needed = u64::from(data_bytes) * sake_glug_fit::FIT_BYTES_PER_SAMPLE;
    match sake_glug_render::available_bytes() {
        Some(available) if available < needed => {
            let error = sake_glug_fit::Audio::read(&path, "recording[0].audio")
                .unwrap_err()
                .to_string();
            assert_has(
                &error,
                &["a.wav", "4294967040 samples", "of memory", "available"],
            );
        }
        // A machine with more memory than that reads the 64 samples there are.
        _ => eprintln!("skipped: this machine has more than {needed} bytes available"),
    }
}
