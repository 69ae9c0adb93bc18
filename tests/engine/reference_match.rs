//! The default real-time path against the f64 direct reference (MODEL.md §9): below −100 dB.
//!
//! The reference computes a(V), the c / (1 − c) split, the gain, the ceiling, the ranges inputs
//! are brought into and the caps of MODEL.md §11 from its own copies of the contract, so these
//! tests fail when the engine's copy of any of them is wrong; only the onset schedule is shared
//! (it is checked on its own by `drain.rs` and `onsets.rs`).

use crate::support::{
    error_db, reference_controls, reference_render, render_controls, render_in_blocks,
};
use sake_glug_engine::{ControlValues, ModelConfig};
use sake_glug_render::Scene;

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

#[test]
fn other_capacities_and_viscosities_match_the_reference() {
    // a(V) scales with C; c far from water's 0.33 weighs the split.
    assert_matches_reference(
        r#"
        seed = 4
        tilt_deg = [[0.0, 95.0], [1.0, 160.0]]
        viscosity_c = [[0.0, 0.9], [2.0, 0.05]]
        [bottle]
        capacity_ml = 720.0
        pocket_ml = 9.0
        "#,
        5.0,
    );
}

#[test]
fn a_bottle_of_its_own_matches_the_reference() {
    // MODEL.md §12: curves, V0 and a spread of its own. The tilt ramps slowly (each sample's
    // levels then come from the engine's span path) and holds (its per-sample path); the bottle
    // drains past the submerged level of its own curves, and at high tilts, where its rest
    // level lies above its submerged level, glugs down to the rest level: in simulate mode with
    // a refill and in follow mode with the fill level falling, so that the reference's own
    // reading of each curve is held against the engine's where it decides an audible unit.
    for (drain, fill) in [
        ("simulate", "[[0.0, 100.0], [7.0, 100.0], [7.0, 80.0]]"),
        ("follow", "[[0.0, 100.0], [8.0, 5.0]]"),
    ] {
        assert_matches_reference(
            &format!(
                r#"
                seed = 11
                tilt_deg = [[0.0, 80.0], [6.0, 130.0], [6.5, 130.0], [8.0, 172.0]]
                fill_percent = {fill}
                [bottle]
                capacity_ml = 500.0
                [amplitude]
                silent_below_ml = 40.0
                spread = 0.4
                [curves]
                rest = [[70.0, 1.0], [95.0, 0.5], [120.0, 0.3], [180.0, 0.2]]
                submerged = [[70.0, 1.0], [100.0, 0.8], [140.0, 0.1], [180.0, 0.05]]
                drain = [[50.0, 0.0], [100.0, 0.5], [135.0, 1.0], [170.0, 0.7]]
                [output]
                drain = "{drain}"
                "#
            ),
            8.0,
        );
    }
}

#[test]
fn a_bottle_whose_pitch_follows_its_headspace_matches_the_reference() {
    // MODEL.md §5.1: a Helmholtz f1 falling and an f2 rising as the bottle empties, with the
    // frequency spread drawn on top, in simulate mode and in follow mode; the reference reads
    // the law from its own V_i.
    for (drain, fill) in [
        ("simulate", "100.0"),
        ("follow", "[[0.0, 100.0], [6.0, 20.0]]"),
    ] {
        assert_matches_reference(
            &format!(
                r#"
                seed = 3
                tilt_deg = [[0.0, 90.0], [0.5, 135.0]]
                fill_percent = {fill}
                [bottle]
                capacity_ml = 720.0
                pocket_ml = 9.0
                headspace_ml = 45.0
                [glug]
                f1_hz = 190.0
                f2_hz = 1150.0
                b2_per_s = 150.0
                f1_headspace_exponent = 0.5
                f2_headspace_exponent = -0.2
                [output]
                drain = "{drain}"
                "#
            ),
            6.0,
        );
    }
}

#[test]
fn a_short_flood_is_started_by_the_contracts_caps() {
    // 625 pockets are due per sample for 10 ms: 8 a sample are started (§11), and of those the
    // start budget admits a burst of 8 units and then 6000 per second, about 68 units, whose
    // 136 components stay under the 256 the bank holds (which the reference does not model).
    let scene = Scene::parse(
        r#"
        deterministic = true
        tilt_deg = 135.0
        pour_time_s = 0.01
        [bottle]
        pocket_ml = 0.001
        "#,
    )
    .unwrap();
    let len = 24_000;
    let window = sake_glug_engine::synthesis::reference::evaluate(
        48_000.0,
        scene.config,
        &scene,
        0..len as u64,
    );
    assert!(
        window.onsets.len() > 1000,
        "the onset cap and the budget must both bite: {} onsets",
        window.onsets.len()
    );
    let fast = render_in_blocks(&scene, len, &[4096]);
    let error = error_db(&fast, &window.samples);
    assert!(error < -100.0, "{error:.1} dB");
}

/// A steady pour at 135° whose inputs `vary` changes by time (s), asked for at `sample_rate`.
fn assert_controls_match(
    what: &str,
    sample_rate: f64,
    config: ModelConfig,
    vary: impl Fn(f64, &mut ControlValues, &mut f64),
) {
    let fs = sake_glug_engine::Engine::new(sample_rate, config).sample_rate();
    let controls = move |sample: u64| {
        let mut values = ControlValues {
            tilt_deg: 135.0,
            ..ControlValues::default()
        };
        let mut gain_db = -6.0;
        vary(sample as f64 / fs, &mut values, &mut gain_db);
        ControlValues { gain_db, ..values }
    };
    let len = (1.5 * fs) as u64;
    let fast = render_controls(sample_rate, config, &controls, len);
    let reference = reference_controls(sample_rate, config, &controls, len);
    let error = error_db(&fast, &reference);
    assert!(error < -100.0, "{what}: {error:.1} dB");
}

#[test]
fn inputs_outside_their_ranges_are_brought_in_as_the_contract_says() {
    let config = ModelConfig::default().deterministic();
    // The sample rate is clamped to 1 kHz … 768 kHz, NaN is 48 kHz.
    for requested in [500.0, 1e6, f64::NAN] {
        assert_controls_match(&format!("fs {requested}"), requested, config, |_, _, _| {});
    }
    // c outside [0, 1] is clamped, NaN is water's 0.33.
    assert_controls_match("viscosity", 48_000.0, config, |t, values, _| {
        values.viscosity = match (t * 4.0) as u32 {
            0 => 1.5,
            1 => f64::NAN,
            2 => -0.5,
            _ => 0.8,
        };
    });
    // The gain is clamped to −120 … +24 dB, NaN is −6 dB: −200 dB must sound at −120 dB.
    for gain in [-200.0, f64::NAN, -119.0] {
        assert_controls_match(&format!("gain {gain}"), 48_000.0, config, |_, _, g| {
            *g = gain
        });
    }
    // The ceiling, reached by a louder gain: 0.3 as asked; 7 and NaN become 1. (The error is
    // relative to the clipped peak, so the overdrive is kept small.)
    for (ceiling, gain) in [(0.3, 0.0), (7.0, 12.0), (f64::NAN, 12.0), (1.0, 30.0)] {
        let clipped = ModelConfig { ceiling, ..config };
        assert_controls_match(
            &format!("ceiling {ceiling} at {gain} dB"),
            48_000.0,
            clipped,
            move |_, _, g| *g = gain,
        );
    }
}
