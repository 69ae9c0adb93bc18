//! The headspace law of MODEL.md §5.1: each unit's frequencies follow the air above the liquid
//! as it starts, the draw of §7 on top, and with both exponents at 0 nothing changes; a mode the
//! law drives below 20 Hz is not sounded (§6).

use crate::support::{pour_onsets, reference_render, render_in_blocks, tilt_only};
use sake_glug_engine::{Constant, ModelConfig};
use sake_glug_render::Scene;

fn with_law(exponents: [f64; 2], headspace_ml: f64) -> ModelConfig {
    let mut config = ModelConfig::default();
    Constant::Headspace.set(&mut config, headspace_ml);
    Constant::F1Exponent.set(&mut config, exponents[0]);
    Constant::F2Exponent.set(&mut config, exponents[1]);
    config
}

#[test]
fn each_units_frequencies_follow_the_air_above_its_liquid() {
    let (headspace_ml, exponents) = (25.0, [0.5, -0.25]);
    let config = with_law(exponents, headspace_ml).deterministic();
    let (onsets, _) = pour_onsets(48_000.0, config, |_| tilt_only(135.0), 5.0);
    assert!(onsets.len() > 30, "{} units", onsets.len());
    for onset in &onsets {
        let air_ml = headspace_ml + 300.0 - onset.volume_ml;
        for (k, exponent) in exponents.into_iter().enumerate() {
            // Quoted at a full bottle's first glug: one pocket (5 ml) poured.
            let expected = config.frequency_hz[k] * ((headspace_ml + 5.0) / air_ml).powf(exponent);
            let got = onset.shape.frequency_hz[k];
            assert!(
                (got / expected - 1.0).abs() < 1e-12,
                "f{} at {} ml: {got} Hz, the law gives {expected} Hz",
                k + 1,
                onset.volume_ml
            );
        }
    }
    // A Helmholtz f1 falls from glug to glug, the negative exponent's f2 rises.
    let first_and_last = |k: usize| {
        (
            onsets[0].shape.frequency_hz[k],
            onsets[onsets.len() - 1].shape.frequency_hz[k],
        )
    };
    let (f1_first, f1_last) = first_and_last(0);
    let (f2_first, f2_last) = first_and_last(1);
    assert!(f1_last < 0.5 * f1_first, "f1 {f1_first} → {f1_last} Hz");
    assert!(f2_last > f2_first, "f2 {f2_first} → {f2_last} Hz");
}

#[test]
fn the_frequency_spread_draws_on_top_of_the_law_and_moves_no_other_draw() {
    let plain = ModelConfig::default();
    let falling = with_law([0.5, 0.5], 40.0);
    let (still, _) = pour_onsets(44_100.0, plain, |_| tilt_only(135.0), 4.0);
    let (moving, _) = pour_onsets(44_100.0, falling, |_| tilt_only(135.0), 4.0);
    assert_eq!(still.len(), moving.len());
    for (a, b) in still.iter().zip(&moving) {
        // The same onsets, volumes, decays and draws; only f moves, by the law's factor.
        assert_eq!(
            (a.sample, a.fraction, a.volume_ml, a.shape.decay_per_s),
            (b.sample, b.fraction, b.volume_ml, b.shape.decay_per_s)
        );
        assert_eq!(a.shape.frequency_spread, b.shape.frequency_spread);
        let factor = (45.0 / (40.0 + 300.0 - a.volume_ml)).sqrt();
        for k in 0..2 {
            let expected = a.shape.frequency_hz[k] * factor;
            assert!((b.shape.frequency_hz[k] / expected - 1.0).abs() < 1e-12);
        }
    }
}

#[test]
fn exponents_of_0_leave_every_unit_as_the_paper_has_it_whatever_the_headspace() {
    let (default, _) = pour_onsets(48_000.0, ModelConfig::default(), |_| tilt_only(135.0), 5.0);
    let (still, _) = pour_onsets(
        48_000.0,
        with_law([0.0, 0.0], 0.001),
        |_| tilt_only(135.0),
        5.0,
    );
    assert_eq!(default, still);
}

/// A law that carries f1 from 80 Hz to 12 Hz as the bottle empties (a law fitted near full,
/// played to empty), with only f1 sounding (c = 1): from the first unit whose f1 lies below
/// 20 Hz nothing sounds, on the default path and in the reference, once the last glug above it
/// has decayed.
#[test]
fn a_mode_the_law_drives_below_20_hz_is_not_sounded() {
    let scene = Scene::parse(
        r#"
        deterministic = true
        duration_s = 6.0
        tilt_deg = 135.0
        viscosity_c = 1.0
        [bottle]
        headspace_ml = 2.0
        [glug]
        f1_headspace_exponent = 0.5
        "#,
    )
    .unwrap();
    let fs = scene.sample_rate as f64;
    let (onsets, _) = pour_onsets(fs, scene.config, |_| tilt_only(135.0), 6.0);
    let below = onsets
        .iter()
        // MODEL.md §6's floor, as the model states it.
        .position(|onset| onset.shape.frequency_hz[0] < 20.0)
        .expect("the law takes f1 below 20 Hz");
    assert!(
        below > 10 && onsets.len() - below > 10,
        "{below} units above 20 Hz, {} below",
        onsets.len() - below
    );
    // −120 dB of B1 = 45/s takes 0.31 s.
    let last_above = &onsets[below - 1];
    let quiet_from = last_above.sample as usize + (0.35 * fs) as usize;
    let len = (6.0 * fs) as usize;
    assert!(quiet_from < len - fs as usize);
    let fast = render_in_blocks(&scene, len, &[512]);
    let reference = reference_render(&scene, len);
    assert!(fast[..quiet_from].iter().any(|&y| y != 0.0));
    let loudest_fast = fast[quiet_from..]
        .iter()
        .fold(0.0f32, |m, y| m.max(y.abs()));
    let loudest_reference = reference[quiet_from..]
        .iter()
        .fold(0.0f64, |m, y| m.max(y.abs()));
    assert!(
        loudest_fast < 1e-6 && loudest_reference < 1e-6,
        "units below 20 Hz sound: default path {loudest_fast:e}, reference {loudest_reference:e}"
    );
}
