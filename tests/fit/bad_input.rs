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
        &["recording[0].audio", "silent"],
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
