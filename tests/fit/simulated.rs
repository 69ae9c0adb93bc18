//! The fit on glugs of the independent simulator (`bubbles.rs`): bubbles ringing at Minnaert's
//! resonance with a rising pitch, the bottle's air column, overlapping glugs, reverberation,
//! noise, hum and clipping, at 44.1 kHz and at 8 kHz. Tolerances: the bubble's frequency (as
//! heard, at the centre of its ring) within 5 % of the median drawn, the column's within 3 %, both
//! decays within 30 %, the bubble's share c within 0.12, the interval between glugs within 10 %;
//! most glugs found and used.

use sake_glug_engine::Constant;
use sake_glug_fit::{fit_session, FitSession};

use super::bubbles::{minnaert_radius, simulate, Pour};
use super::*;

fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    sorted[sorted.len() / 2]
}

fn within(what: &str, value: f64, truth: f64, share: f64) {
    assert!(
        (value / truth - 1.0).abs() <= share,
        "{what}: fitted {value}, truth {truth}, allowed ±{} %",
        100.0 * share
    );
}

fn pour(sample_rate: f64, seed: u64) -> Pour {
    Pour {
        sample_rate,
        duration_s: 4.0,
        rate_per_s: 10.0,
        radius_m: minnaert_radius(120.0),
        radius_sigma: 0.05,
        rise: 0.15,
        damping: 0.1,
        column_m: 0.18,
        column_decay: 30.0,
        bubble_share: 0.6,
        reverb: (0.05, 0.3),
        noise: 0.003,
        hum: 0.01,
        clip: 0.9,
        seed,
    }
}

fn recovers(sample_rate: f64) {
    let pour = pour(sample_rate, 3);
    let simulated = simulate(&pour);
    let folder = tempfile::tempdir().unwrap();
    let wav = folder.path().join("pour.wav");
    write_wav(&wav, &simulated.samples, sample_rate as u32);
    let fit = fit_session(&FitSession::of_clips(&[wav], None, None).unwrap()).unwrap();
    let recording = &fit.recordings[0];
    let (detected, used) = (recording.detected.len(), recording.units.len());
    let glugs = simulated.onsets.len();
    eprintln!(
        "{sample_rate} Hz: {glugs} glugs, {detected} detected, {used} used, {:.0} % explained",
        100.0 * recording.explained
    );
    assert!(used * 10 >= glugs * 8, "{used} of {glugs} glugs used");
    assert!(
        detected <= glugs + glugs / 10,
        "{detected} detected for {glugs}"
    );
    let estimate = |key: &str| super::estimate(&fit, 0, key);
    // The model's pitch as heard: a bubble's rising pitch is written as a glide where its units
    // agree on one (MODEL.md §13), and its f1 is then the pitch the glide approaches.
    let scene = Scene::parse(&fit.liquids[0].model_toml).unwrap();
    eprintln!(
        "  f1 {:.1} Hz, heard at {:.1} (truth {:.1}), f2 {:.1} Hz (truth {:.1}), B1 {:.1} /s \
         (truth {:.1}), B2 {:.1} /s (truth {}), c {:.3} (truth {})",
        estimate("glug.f1_hz"),
        heard_hz(&scene, 0),
        median(&simulated.bubble_hz),
        estimate("glug.f2_hz"),
        simulated.column_hz,
        estimate("glug.b1_per_s"),
        median(&simulated.bubble_decay),
        estimate("glug.b2_per_s"),
        pour.column_decay,
        estimate("viscosity_c"),
        pour.bubble_share
    );
    within(
        "f1 (the bubble), as heard",
        heard_hz(&scene, 0),
        median(&simulated.bubble_hz),
        0.05,
    );
    within(
        "f2 (the column), as heard",
        heard_hz(&scene, 1),
        simulated.column_hz,
        0.03,
    );
    within(
        "B1",
        estimate("glug.b1_per_s"),
        median(&simulated.bubble_decay),
        0.3,
    );
    within("B2", estimate("glug.b2_per_s"), pour.column_decay, 0.3);
    let c = estimate("viscosity_c");
    assert!(
        (c - pour.bubble_share).abs() <= 0.12,
        "c: fitted {c}, truth {}",
        pour.bubble_share
    );
    // The model glugs at the recording's rate: its interval is the pocket over C/T.
    let intervals: Vec<f64> = simulated.onsets.windows(2).map(|w| w[1] - w[0]).collect();
    let interval =
        Constant::Pocket.range().default * estimate("pour_time_s") / estimate("bottle.capacity_ml");
    within("interval", interval, median(&intervals), 0.1);
}

#[test]
fn simulated_glugs_at_44_khz_give_back_their_physics() {
    recovers(44_100.0);
}

#[test]
fn simulated_glugs_at_8_khz_give_back_their_physics() {
    recovers(8_000.0);
}
