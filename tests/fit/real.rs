//! Real recordings (tests/fixtures/recordings, CC0): clips of liquid the paper's model was not
//! made from. On each glug-like clip: as many units as a plain onset detector hears glugs; the
//! model glugging at the clip's rate; each used unit's stronger component at that unit's own
//! spectral peak (found here by a plain DFT, not the fit's FFT); the model no farther from the
//! recording than the default bottle; and a recording the units explain poorly said to be so (the
//! report's warning and the model file's header). A real bottle emptying is heard as one: its
//! pitch falls in the model as in the clip, and its bright mode is there. A brook's babble and a
//! splash, which no unit of eq. 1 describes, are refused with the reasons; lava's bubbling over a
//! rumble is fitted, but said to be described poorly.

use std::f64::consts::TAU;
use std::path::PathBuf;

use sake_glug_fit::compare::Comparison;
use sake_glug_fit::comparisons::compare;
use sake_glug_fit::{
    fit_session, Audio, FitError, FitSession, SessionFit, AT_PEAK_SHARE, LOW_EXPLAINED,
};

fn clip(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/recordings")
        .join(name)
}

/// The frequency (Hz) of the strongest peak of `samples` under a Hann window, by a DFT at 2 Hz
/// steps from 20 Hz to Nyquist.
fn strongest_peak_hz(samples: &[f64], fs: f64) -> f64 {
    let width = samples.len() as f64;
    let windowed: Vec<f64> = samples
        .iter()
        .enumerate()
        .map(|(n, y)| y * (0.5 - 0.5 * (TAU * n as f64 / width).cos()))
        .collect();
    let power = |hz: f64| {
        let (mut re, mut im) = (0.0, 0.0);
        for (n, y) in windowed.iter().enumerate() {
            let phase = TAU * hz * n as f64 / fs;
            re += y * phase.cos();
            im -= y * phase.sin();
        }
        re * re + im * im
    };
    (10..(fs / 4.0) as usize)
        .map(|step| (2.0 * step as f64, power(2.0 * step as f64)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map_or(f64::NAN, |(hz, _)| hz)
}

/// The fit of one clip alone (a session of the defaults) and its spectral comparison, with the
/// figures printed for the report: units used of those detected, the energy they explain, the
/// correlations of the fitted model's and the default bottle's spectra with the recording's.
fn fitted(name: &str) -> (SessionFit, Comparison) {
    let session = FitSession::of_clips(&[clip(name)], None, None).unwrap();
    let fit = fit_session(&session).unwrap_or_else(|error| panic!("{name}: {error}"));
    let comparison = compare(&fit).unwrap().remove(0);
    let recording = &fit.recordings[0];
    eprintln!(
        "{name}: {} of {} units used, explaining {:.0} % of its energy; spectral correlation \
         with the fitted model {:.2}, with the default bottle {:.2}",
        recording.units.len(),
        recording.detected.len(),
        100.0 * recording.explained,
        comparison.fitted,
        comparison.default
    );
    (fit, comparison)
}

/// A recording the units explain poorly is said to be so, in the warnings and in the model file;
/// one they explain well carries no caution.
fn is_judged_honestly(name: &str, fit: &SessionFit) {
    let model = &fit.liquids[0].model_toml;
    if fit.recordings[0].explained >= LOW_EXPLAINED {
        assert!(!model.contains("# Caution"), "{name}: {model}");
    } else {
        let warnings = fit.warnings.join("\n");
        assert!(
            warnings.contains("describes this recording poorly"),
            "{name}: {warnings}"
        );
        assert!(
            model.contains("# Caution: the units fitted explain only"),
            "{name}: {model}"
        );
    }
}

/// The checks of a clip of glugs (issue 36): as many units detected as a plain onset detector
/// hears glugs, within 20 % (no glug split into several units); the model, rendered as the clip
/// was made, glugging at the clip's rate within 10 %; each used unit's stronger component at its
/// own span's spectral peak; the model no farther from the recording than the default bottle by
/// the log-spectral distance; and an honest word on how much of the recording the units explain.
/// Every check that fails is named, with its numbers, before the test stops.
fn is_fitted_like_glugs(name: &str) {
    let (fit, comparison) = fitted(name);
    let recording = &fit.recordings[0];
    let (detected, used) = (recording.detected.len(), recording.units.len());
    let [heard, model, _] = &comparison.heard;
    let glugs = heard.onsets_s.len();
    eprintln!(
        "{name}: {used} of {detected} units used for {glugs} glugs heard; {:.2} glugs a second, \
         the model {:.2}; log-spectral distance {:.1} dB, the default bottle's {:.1} dB",
        heard.rate_per_s, model.rate_per_s, comparison.distance[0], comparison.distance[1]
    );
    let mut failed = Vec::new();
    if detected < 5 {
        failed.push(format!("{detected} units detected"));
    }
    if (detected as f64 / glugs as f64 - 1.0).abs() > 0.2 {
        failed.push(format!("{detected} units detected for {glugs} glugs heard"));
    }
    if (model.rate_per_s / heard.rate_per_s - 1.0).abs() > 0.1 {
        failed.push(format!(
            "the model glugs {:.2} times a second, the recording {:.2}",
            model.rate_per_s, heard.rate_per_s
        ));
    }
    // Each used unit against its own span of the recording, less the units before it.
    let audio = Audio::read(&clip(name), name).unwrap();
    let fs = f64::from(audio.sample_rate);
    for (index, unit) in recording.units.iter().enumerate() {
        let (first, end) = unit.fit.window;
        let span: Vec<f64> = (first..end)
            .map(|n| {
                let t = n as f64 / fs;
                f64::from(audio.samples[n])
                    - recording.units[..index]
                        .iter()
                        .map(|u| u.fit.value_at(t))
                        .sum::<f64>()
            })
            .collect();
        let peak_hz = strongest_peak_hz(&span, fs);
        let stronger = unit.fit.stronger().unwrap();
        let heard_hz = stronger.heard_hz;
        // A gliding mode may peak anywhere along its sweep, from ρ·f to f.
        let (low_hz, high_hz) = stronger.glide.map_or((heard_hz, heard_hz), |glide| {
            let start_hz = glide.ratio * stronger.frequency_hz;
            (
                start_hz.min(stronger.frequency_hz),
                start_hz.max(stronger.frequency_hz),
            )
        });
        let tolerance = (AT_PEAK_SHARE * peak_hz).max(fs / span.len() as f64) + 2.0;
        if peak_hz < low_hz - tolerance || peak_hz > high_hz + tolerance {
            failed.push(format!(
                "the unit at {:.3} s rings at {heard_hz:.1} Hz (through {low_hz:.1} … {high_hz:.1}), \
                 its span peaks at {peak_hz:.1} Hz",
                unit.fit.onset_s
            ));
        }
    }
    if comparison.distance[0] > comparison.distance[1] {
        failed.push(format!(
            "the model is farther from the recording than the default bottle: {comparison:?}"
        ));
    }
    assert!(failed.is_empty(), "{name}: {}", failed.join("; "));
    is_judged_honestly(name, &fit);
}

/// A clip no unit of eq. 1 describes (or too few, with nothing nearer by listening) is refused,
/// with the reasons, and no model is written: what happened instead, if not.
fn refusal_missed(name: &str) -> Option<String> {
    let session = FitSession::of_clips(&[clip(name)], None, None).unwrap();
    match fit_session(&session) {
        Err(
            error @ (FitError::NoUnitDescribed { .. }
            | FitError::NoGlugs { .. }
            | FitError::NothingNearer { .. }
            | FitError::NoModelNearer { .. }),
        ) => {
            let message = error.to_string();
            eprintln!("{name}: {message}");
            let said = message.contains("no model is written") || message.contains("no glugs");
            (!said).then(|| format!("{name}: {message}"))
        }
        Err(error) => Some(format!("{name}: {error}")),
        Ok(fit) => Some(format!(
            "{name}: a model was fitted: {} of {} units used",
            fit.recordings[0].units.len(),
            fit.recordings[0].detected.len()
        )),
    }
}

#[test]
fn real_bubbles_are_fitted_by_their_own_peaks_and_judged_honestly() {
    for name in ["opensfx-bubbles-44k.wav", "opensfx-bubbles-8k.wav"] {
        is_fitted_like_glugs(name);
    }
}

/// A real bottle emptying (isbeorn's "bottle glugs", CC0): five glugs whose low mode falls from
/// about 200 to 90 Hz as the headspace grows, each with a short bright mode near 1.1–1.35 kHz.
/// Besides a glug clip's checks, the model must fall in pitch as the clip does over its glugs
/// (within 15 %), follow the headspace (γ1 written), carry the bright mode (the energy above the
/// split within 10 points of the recording's, where the default bottle has almost none), and be
/// nearer the recording by the log-spectral distance than the default bottle.
#[test]
fn a_real_bottle_emptying_falls_in_pitch_and_keeps_its_bright_mode() {
    let name = "isbeorn-bottle-glugs-44k.wav";
    is_fitted_like_glugs(name);
    let (fit, comparison) = fitted(name);
    let [heard, model, default] = &comparison.heard;
    let glugs = heard.onsets_s.len();
    let (fall, model_fall) = (heard.fall_over(glugs), model.fall_over(glugs));
    eprintln!(
        "{name}: pitch falls {fall:.2}× over {glugs} glugs, the model {model_fall:.2}×, the \
         default bottle {:.2}×; energy above {:.0} Hz: recording {:.2}, model {:.2}, default {:.2}",
        default.fall_over(glugs),
        comparison.split_hz,
        heard.high_share,
        model.high_share,
        default.high_share
    );
    assert!(fall > 1.5, "{name}: the clip's pitch falls only {fall}×");
    assert!(
        (model_fall / fall - 1.0).abs() <= 0.15,
        "{name}: the model falls {model_fall}×, the clip {fall}×"
    );
    let exponent = fit.liquids[0]
        .estimates
        .iter()
        .find(|e| e.key == sake_glug_engine::Constant::F1Exponent.quantity().scene_key)
        .unwrap();
    assert!(exponent.in_model && exponent.value > 0.0, "{exponent:?}");
    assert!(
        (model.high_share - heard.high_share).abs() <= 0.1 && default.high_share < 0.05,
        "{name}: energy above the split {:.2} in the model, {:.2} in the clip, {:.2} in the \
         default bottle",
        model.high_share,
        heard.high_share,
        default.high_share
    );
    assert!(
        comparison.distance[0] < comparison.distance[1],
        "{name}: {comparison:?}"
    );
}

/// Lava bubbling over a low rumble (Minetest Game's env_sounds, CC0): the units the fit keeps
/// ring at the rumble's 60–150 Hz, not at the pops', so it must say the model describes the
/// recording poorly.
#[test]
fn lava_bubbling_over_a_rumble_is_said_to_be_described_poorly() {
    let name = "lava-bubbles-22k.wav";
    let (fit, _) = fitted(name);
    assert!(
        fit.recordings[0].explained < LOW_EXPLAINED,
        "{name}: the units explain {:.0} % of it",
        100.0 * fit.recordings[0].explained
    );
    is_judged_honestly(name, &fit);
}

/// The glug checks on the lava clip, for the lead to judge (issue 28). Measured on 2026-11-25: 23
/// of 46 units used (not most), explaining 29 % of its energy; spectral correlation 0.97 with the
/// fitted model, 0.79 with the default bottle (closer: passes); four used units (at 0.426, 0.463,
/// 0.597 and 1.899 s) ring at 149.1, 115.1, 106.2 and 92.8 Hz where a plain DFT of their spans
/// (less the units before them) peaks at 20.0 Hz, the bottom of its scan.
#[test]
#[ignore = "fails on lava-bubbles-22k.wav: 23 of 46 units used, 4 used units off their span's \
            DFT peak (20 Hz); the numbers are in the comment above"]
fn lava_bubbling_is_fitted_like_glugs() {
    is_fitted_like_glugs("lava-bubbles-22k.wav");
}

#[test]
fn a_brooks_babble_and_a_splash_are_refused_with_the_reasons() {
    let missed: Vec<String> = ["brook-11k.wav", "opensfx-splat-44k.wav"]
        .into_iter()
        .filter_map(refusal_missed)
        .collect();
    assert!(missed.is_empty(), "{}", missed.join("\n"));
}

/// The Tux Paint toilet (held-out-4, seen): of its 8 units the paper's model describes 1, too few
/// for any constant, and no model by listening sounds nearer than the default bottle. It is
/// refused with that reason (MODEL.md §13), where the fit wrote the default bottle itself, a model
/// of no recording (red with the rule left out: "a model was fitted: 1 of 8 units used").
#[test]
fn a_clip_with_too_few_units_and_nothing_nearer_by_ear_is_refused() {
    let name = "held-out-4/tuxpaint-toilet-8k.wav";
    assert_eq!(refusal_missed(name), None);
    let session = FitSession::of_clips(&[clip(name)], None, None).unwrap();
    let message = fit_session(&session).unwrap_err().to_string();
    assert!(
        message.contains("no model fitted by listening sounds nearer"),
        "{message}"
    );
}
