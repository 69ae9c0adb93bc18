//! The default real-time path against the f64 direct reference (MODEL.md §9): below −100 dB.

use crate::support::{error_db, reference_render, render_in_blocks};
use sake_glug::offline::Scene;

fn assert_matches_reference(scene_text: &str, seconds: f64) {
    let scene = Scene::parse(scene_text).unwrap();
    let len = (seconds * scene.sample_rate as f64) as usize;
    let fast = render_in_blocks(&scene, len, &[512]);
    let reference = reference_render(&scene, len);
    let error = error_db(&fast, &reference);
    assert!(error < -100.0, "{error:.1} dB for\n{scene_text}");
}

#[test]
fn the_default_pour_matches_the_reference() {
    assert_matches_reference(
        "deterministic = true\ntilt_deg = [[0.0, 90.0], [0.5, 135.0]]",
        6.0,
    );
}

#[test]
fn a_seeded_random_pour_matches_the_reference() {
    assert_matches_reference("seed = 5\ntilt_deg = [[0.0, 90.0], [0.5, 135.0]]", 6.0);
}

#[test]
fn other_sample_rates_match_the_reference() {
    for rate in [44_100, 96_000] {
        assert_matches_reference(
            &format!("sample_rate = {rate}\nseed = 2\ntilt_deg = [[0.0, 100.0], [1.0, 150.0]]"),
            4.0,
        );
    }
}

#[test]
fn follow_mode_with_automated_fill_and_gain_matches_the_reference() {
    assert_matches_reference(
        r#"
        deterministic = true
        tilt_deg = 120.0
        fill_percent = [[0.0, 100.0], [3.0, 30.0]]
        viscosity_c = [[0.0, 0.0], [3.0, 1.0]]
        [output]
        drain = "follow"
        gain_db = [[0.0, 0.0], [3.0, -20.0]]
        "#,
        3.0,
    );
}

#[test]
fn slow_decays_and_high_frequencies_match_the_reference() {
    assert_matches_reference(
        r#"
        seed = 9
        tilt_deg = 140.0
        [glug]
        f1_hz = 950.0
        f2_hz = 23000.0
        b1_per_s = 2.0
        b2_per_s = 300.0
        "#,
        4.0,
    );
}
