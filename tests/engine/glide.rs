//! The glide of MODEL.md §5.2: each component may start at ρ times its frequency and approach it
//! with a time constant τ. Every path against the closed form written out here, the default path
//! against the f64 reference (§9) within −100 dB, a ratio of 1 changing no bit, every block size
//! giving the same samples, and a glide that would start at Nyquist omitted (§6).

use std::f64::consts::TAU;

use crate::support::{error_db, reference_render, render_in_blocks};
use sake_glug_engine::pour::UnitShape;
use sake_glug_engine::{
    AnchoredF32, Glide, RecursiveF32, RecursiveF64, Synthesis, UnitOnset, GRID,
};
use sake_glug_render::Scene;

const FS: f64 = 48_000.0;

/// One unit with only its f2 component sounding (c = 0), gliding by `ratio` with `glide_ms`.
fn gliding_unit(frequency_hz: f64, decay_per_s: f64, ratio: f64, glide_ms: f64) -> UnitOnset {
    UnitOnset {
        sample: 3,
        fraction: 0.375,
        volume_ml: 300.0,
        tilt_deg: 135.0,
        pocket_ml: 5.0,
        amplitude: 1.0,
        viscosity: 0.0,
        shape: UnitShape {
            frequency_hz: [80.0, frequency_hz],
            frequency_spread: [1.0, 1.0],
            decay_per_s: [45.0, decay_per_s],
            amplitude_factor: 1.0,
            glide: Glide {
                ratio: [1.0, ratio],
                time_ms: [20.0, glide_ms],
            },
        },
        actuator_gain: [1.0, 1.0],
    }
}

/// MODEL.md §5.2 as it is written: e^(−Bτ)·sin(2π·f·[τ + (ρ − 1)·τ_k·(1 − e^(−τ/τ_k))]).
fn closed_form(onset: &UnitOnset, sample: u64) -> f64 {
    let tau = (sample as f64 - onset.sample as f64 - onset.fraction) / FS;
    if tau <= 0.0 {
        return 0.0;
    }
    let (f, b) = (onset.shape.frequency_hz[1], onset.shape.decay_per_s[1]);
    let (ratio, glide_s) = (
        onset.shape.glide.ratio[1],
        onset.shape.glide.time_ms[1] / 1000.0,
    );
    let phase = TAU * f * (tau + (ratio - 1.0) * glide_s * (1.0 - (-tau / glide_s).exp()));
    (-b * tau).exp() * phase.sin()
}

/// The unit alone on path `S`, rendered as the engine renders: spans within grid periods.
fn render_unit<S: Synthesis>(onset: &UnitOnset, len: usize) -> Vec<f32> {
    let mut bank = S::new(FS);
    assert!(bank.start_unit(onset), "the unit must sound");
    let mut out = vec![0.0f32; len];
    for (period, chunk) in out.chunks_mut(GRID).enumerate() {
        bank.synthesize((period * GRID) as u64, chunk);
        bank.advance(((period + 1) * GRID) as u64);
    }
    out
}

/// The largest difference from the closed form, relative to the unit's amplitude of 1, in dB,
/// while the component sounds (MODEL.md §6 drops it once e^(−Bτ) < 10⁻⁶).
fn error_against_closed_form(onset: &UnitOnset, samples: &[f32]) -> f64 {
    let sounds = |n: usize| {
        let tau = (n as f64 - onset.sample as f64 - onset.fraction) / FS;
        (-onset.shape.decay_per_s[1] * tau).exp() >= 1e-6
    };
    let worst = samples
        .iter()
        .enumerate()
        .filter(|&(n, _)| sounds(n))
        .map(|(n, &y)| (y as f64 - closed_form(onset, n as u64)).abs())
        .fold(0.0, f64::max);
    20.0 * worst.log10()
}

#[test]
fn every_path_follows_the_glides_closed_form() {
    // Down and up, a sweep within a few cycles and one through the whole glug, one near
    // Nyquist at its start.
    let cases = [
        (300.0, 40.0, 2.0, 20.0),
        (300.0, 40.0, 0.5, 20.0),
        (1150.0, 150.0, 4.0, 0.5),
        (200.0, 5.0, 0.25, 500.0),
        (5_900.0, 60.0, 4.0, 3.0),
    ];
    for (frequency_hz, decay_per_s, ratio, glide_ms) in cases {
        let onset = gliding_unit(frequency_hz, decay_per_s, ratio, glide_ms);
        let len = 48_000;
        let anchored = error_against_closed_form(&onset, &render_unit::<AnchoredF32>(&onset, len));
        let recursive =
            error_against_closed_form(&onset, &render_unit::<RecursiveF64>(&onset, len));
        let single = error_against_closed_form(&onset, &render_unit::<RecursiveF32>(&onset, len));
        println!(
            "f {frequency_hz} Hz, ρ {ratio}, τ {glide_ms} ms: anchored f32 {anchored:.1} dB, \
             recursive f64 {recursive:.1} dB, recursive f32 {single:.1} dB"
        );
        assert!(anchored < -120.0, "anchored: {anchored:.1} dB");
        assert!(recursive < -130.0, "recursive f64: {recursive:.1} dB");
        // An f32 recursion drifts between its anchors (as without a glide); it stays audible
        // as the same sound.
        assert!(single < -60.0, "recursive f32: {single:.1} dB");
    }
}

#[test]
fn a_glide_down_that_would_start_at_nyquist_is_omitted() {
    // ρ·f = 28 kHz ≥ 24 kHz: omitted; 21 kHz: it sounds.
    let mut bank = AnchoredF32::new(FS);
    assert!(!bank.start_unit(&gliding_unit(7_000.0, 40.0, 4.0, 20.0)));
    assert_eq!(bank.len(), 0);
    assert!(bank.start_unit(&gliding_unit(7_000.0, 40.0, 3.0, 20.0)));
    // A glide up starts below its own frequency: only that one counts.
    assert!(bank.start_unit(&gliding_unit(23_000.0, 40.0, 0.25, 20.0)));
    assert!(!bank.start_unit(&gliding_unit(24_000.0, 40.0, 0.25, 20.0)));
}

/// Scenes that glide, with the headspace law and the spreads drawn on top.
const GLIDING_SCENES: [&str; 3] = [
    r#"
    seed = 3
    tilt_deg = [[0.0, 90.0], [0.5, 135.0]]
    [bottle]
    capacity_ml = 720.0
    pocket_ml = 9.0
    headspace_ml = 45.0
    [glug]
    f1_hz = 190.0
    f2_hz = 1150.0
    b2_per_s = 150.0
    f1_headspace_exponent = 0.5
    f1_glide_ratio = 1.8
    f1_glide_ms = 15.0
    f2_glide_ratio = 0.6
    f2_glide_ms = 40.0
    "#,
    r#"
    sample_rate = 44100
    seed = 8
    tilt_deg = [[0.0, 100.0], [1.0, 150.0]]
    viscosity_c = 0.5
    [glug]
    f1_glide_ratio = 4.0
    f1_glide_ms = 0.5
    f2_glide_ratio = 0.25
    f2_glide_ms = 500.0
    b2_per_s = 8.0
    "#,
    r#"
    sample_rate = 96000
    seed = 21
    tilt_deg = 140.0
    [glug]
    f1_hz = 950.0
    f2_hz = 9000.0
    f2_glide_ratio = 2.5
    f2_glide_ms = 2.0
    "#,
];

#[test]
fn a_gliding_pour_matches_the_reference() {
    for text in GLIDING_SCENES {
        let scene = Scene::parse(text).unwrap();
        let len = 4 * scene.sample_rate as usize;
        let fast = render_in_blocks(&scene, len, &[512]);
        let reference = reference_render(&scene, len);
        let error = error_db(&fast, &reference);
        println!("{error:.1} dB for {text}");
        assert!(error < -100.0, "{error:.1} dB for\n{text}");
        // The glide is heard: without it the render is another.
        let mut still = scene.clone();
        still.config.glide.ratio = [1.0, 1.0];
        let unglided = render_in_blocks(&still, len, &[512]);
        let glide_db = error_db(&unglided, &reference);
        assert!(
            glide_db > -20.0,
            "the glide changes the sound: {glide_db:.1} dB"
        );
    }
}

#[test]
fn a_glide_ratio_of_1_changes_no_bit_whatever_its_time() {
    let plain = "seed = 4\ntilt_deg = [[0.0, 90.0], [0.5, 135.0]]\n";
    let with_times = format!(
        "{plain}[glug]\nf1_glide_ratio = 1.0\nf2_glide_ratio = 1.0\nf1_glide_ms = 0.5\n\
         f2_glide_ms = 437.0\n"
    );
    let (plain, with_times) = (
        Scene::parse(plain).unwrap(),
        Scene::parse(&with_times).unwrap(),
    );
    assert_ne!(plain.config, with_times.config);
    let len = 5 * 48_000;
    assert_eq!(
        render_in_blocks(&plain, len, &[512]),
        render_in_blocks(&with_times, len, &[512])
    );
    // One component gliding leaves the other's samples as they were: c = 1 sounds f1 alone.
    let only_f1 = "deterministic = true\nviscosity_c = 1.0\ntilt_deg = 135.0\n";
    let f2_glides = format!("{only_f1}[glug]\nf2_glide_ratio = 2.0\n");
    assert_eq!(
        render_in_blocks(&Scene::parse(only_f1).unwrap(), len, &[512]),
        render_in_blocks(&Scene::parse(&f2_glides).unwrap(), len, &[512])
    );
}

#[test]
fn a_glide_gives_the_same_samples_at_every_block_size() {
    let scene = Scene::parse(GLIDING_SCENES[0]).unwrap();
    let len = 3 * 48_000;
    let whole = render_in_blocks(&scene, len, &[len]);
    assert!(whole.iter().any(|&y| y != 0.0));
    for blocks in [
        &[1][..],
        &[7, 64, 513][..],
        &[63, 1, 65, 4096][..],
        &[8192][..],
    ] {
        let cut = render_in_blocks(&scene, len, blocks);
        let first_difference = (0..len).find(|&n| cut[n].to_bits() != whole[n].to_bits());
        assert_eq!(first_difference, None, "blocks {blocks:?}");
    }
}
