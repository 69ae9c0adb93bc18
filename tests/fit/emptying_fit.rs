//! A bottle emptying, from the independent simulator of `emptying.rs` (a Helmholtz cavity whose
//! air grows by a pocket a glug, a short bright bubble mode, a room, noise and hum), fitted from a
//! bare clip and from a session with its weight log, at 8–48 kHz: the fit must hear the pitch
//! fall (γ of the headspace law, MODEL.md §5.1) and the bright mode (c), and its model must keep
//! the clip's rhythm (the rate, a unit per glug) and fall in pitch as the clip does when rendered
//! as the clip was made.

use std::path::Path;

use sake_glug_engine::{Constant, Control};
use sake_glug_fit::compare::Comparison;
use sake_glug_fit::comparisons::compare;
use sake_glug_fit::{fit_session, FitSession, SessionFit};

use super::emptying::{helmholtz_hz, simulate, Params, Simulated};
use super::{estimate, write_wav, write_weight};

/// The glugs over which a model's pitch fall is held to the clip's.
const FIRST_GLUGS: usize = 12;

/// What the fit gave back, against the simulator's truths.
struct Recovered {
    exponent: f64,
    full_hz: f64,
    viscosity: f64,
    units: usize,
    comparison: Comparison,
}

fn recovered(fit: &SessionFit) -> Recovered {
    let key = |constant: Constant| constant.quantity().scene_key;
    Recovered {
        exponent: estimate(fit, 0, key(Constant::F1Exponent)),
        full_hz: estimate(fit, 0, key(Constant::F1)),
        viscosity: estimate(fit, 0, Control::Viscosity.quantity().scene_key),
        units: fit.liquids[0].units,
        comparison: compare(fit).unwrap().remove(0),
    }
}

/// The bottle's own checks: γ within 0.1, f1 (its cavity at a full bottle's first glug, where
/// MODEL.md §5.1 quotes it) within 5 %, c (the cavity's share) within 0.08, the rendered model's rate within 10 %, the units within 20 % of
/// the glugs, and the rendered model's pitch falling as the clip's does over its glugs.
fn assert_heard(what: &str, params: &Params, simulated: &Simulated, got: &Recovered) {
    let full_hz = helmholtz_hz(
        simulated.air_ml[0],
        params.neck_radius_m,
        params.neck_length_m,
    );
    let glugs = simulated.onsets.len();
    let fall = simulated.cavity_hz[0] / simulated.cavity_hz[glugs - 1];
    let heard_model = &got.comparison.heard[1];
    eprintln!(
        "{what}: γ {:.3} (truth {}), f1 {:.1} Hz (truth {full_hz:.1}), c {:.3} (truth {:.3}), \
         {} units for {glugs} glugs, model {:.2} glugs/s (truth {:.2}), model's fall over \
         {glugs} glugs {:.2}× (truth {fall:.2}×)",
        got.exponent,
        simulated.cavity_exponent,
        got.full_hz,
        got.viscosity,
        simulated.low_mode_share,
        got.units,
        heard_model.rate_per_s,
        simulated.rate_per_s,
        heard_model.fall_over(glugs),
    );
    assert!(
        (got.exponent - simulated.cavity_exponent).abs() <= 0.1,
        "{what}: γ {}",
        got.exponent
    );
    assert!(
        (got.full_hz / full_hz - 1.0).abs() <= 0.05,
        "{what}: f1 {} Hz, truth {full_hz} Hz",
        got.full_hz
    );
    assert!(
        (got.viscosity - simulated.low_mode_share).abs() <= 0.08,
        "{what}: c {}",
        got.viscosity
    );
    assert!(
        (heard_model.rate_per_s / simulated.rate_per_s - 1.0).abs() <= 0.1,
        "{what}: the model glugs {} times a second, the clip {}",
        heard_model.rate_per_s,
        simulated.rate_per_s
    );
    assert!(
        (got.units as f64 / glugs as f64 - 1.0).abs() <= 0.2,
        "{what}: {} units for {glugs} glugs",
        got.units
    );
    // Its first glugs: a model keeps a(V)'s silence below V0 (its default where the clip does
    // not show one), so its last glugs may be silent where the clip's are not.
    let first = glugs.min(FIRST_GLUGS);
    let (model_fall, fall) = (
        heard_model.fall_over(first),
        simulated.cavity_hz[0] / simulated.cavity_hz[first - 1],
    );
    assert!(
        (model_fall / fall - 1.0).abs() <= 0.15,
        "{what}: the model falls {model_fall}× over its first {first} glugs, the clip {fall}×"
    );
}

fn bare_clip(folder: &Path, params: &Params) -> (Simulated, SessionFit) {
    let simulated = simulate(params);
    let wav = folder.join("clip.wav");
    write_wav(&wav, &simulated.samples, params.sample_rate as u32);
    let session = FitSession::of_clips(&[wav], Some(params.capacity_ml), None).unwrap();
    (simulated, fit_session(&session).unwrap())
}

fn with_weight_log(folder: &Path, params: &Params) -> (Simulated, SessionFit) {
    let simulated = simulate(params);
    write_wav(
        &folder.join("pour.wav"),
        &simulated.samples,
        params.sample_rate as u32,
    );
    write_weight(&folder.join("pour.csv"), &simulated.weight_log, 1.0);
    let session = folder.join("session.toml");
    std::fs::write(
        &session,
        format!(
            "capacity_ml = {}\n[[recording]]\naudio = \"pour.wav\"\ntilt_deg = 135.0\n\
             start_ml = {}\nweight = {{ csv = \"pour.csv\", column = \"grams\" }}\n",
            params.capacity_ml, params.start_ml
        ),
    )
    .unwrap();
    let session = FitSession::load(&session).unwrap();
    (simulated, fit_session(&session).unwrap())
}

#[test]
fn a_glass_bottle_emptying_is_heard_from_a_bare_clip() {
    for rate in [48_000.0, 22_050.0] {
        let folder = tempfile::tempdir().unwrap();
        let params = Params::glass_bottle(rate);
        let (simulated, fit) = bare_clip(folder.path(), &params);
        assert_heard(
            &format!("bare clip at {rate} Hz"),
            &params,
            &simulated,
            &recovered(&fit),
        );
    }
}

#[test]
fn a_glass_bottle_emptying_is_heard_from_its_weight_log() {
    for rate in [44_100.0, 8_000.0] {
        let folder = tempfile::tempdir().unwrap();
        let params = Params::glass_bottle(rate);
        let (simulated, fit) = with_weight_log(folder.path(), &params);
        let got = recovered(&fit);
        assert_heard(&format!("session at {rate} Hz"), &params, &simulated, &got);
        // With the volumes weighed, H itself is heard.
        let headspace = estimate(&fit, 0, Constant::Headspace.quantity().scene_key);
        assert!(
            (headspace / simulated.headspace_ml - 1.0).abs() <= 0.25,
            "H {headspace} ml, truth {} ml",
            simulated.headspace_ml
        );
    }
}

#[test]
fn a_short_clip_of_five_glugs_falls_as_it_does() {
    let folder = tempfile::tempdir().unwrap();
    let params = Params::short_clip(44_100.0);
    let (simulated, fit) = bare_clip(folder.path(), &params);
    let got = recovered(&fit);
    let glugs = simulated.onsets.len();
    let fall = simulated.cavity_hz[0] / simulated.cavity_hz[glugs - 1];
    let model_fall = got.comparison.heard[1].fall_over(glugs);
    let onsets: Vec<f64> = fit.recordings[0]
        .units
        .iter()
        .map(|u| u.fit.onset_s)
        .collect();
    eprintln!(
        "short clip: {} units at {onsets:.3?} for {glugs} glugs at {:.3?}, γ {:.3}, c {:.3} \
         (truth {:.3}), model's fall {model_fall:.2}× (clip {fall:.2}×), energy above {:.0} Hz: \
         model {:.2}, clip {:.2}",
        got.units,
        simulated.onsets,
        got.exponent,
        got.viscosity,
        simulated.low_mode_share,
        got.comparison.split_hz,
        got.comparison.heard[1].high_share,
        got.comparison.heard[0].high_share
    );
    assert!(
        (got.units as f64 / glugs as f64 - 1.0).abs() <= 0.2,
        "{} units at {onsets:?} for glugs at {:?}",
        got.units,
        simulated.onsets
    );
    assert!(
        (model_fall / fall - 1.0).abs() <= 0.15,
        "{model_fall} against {fall}"
    );
    assert!(
        (got.viscosity - simulated.low_mode_share).abs() <= 0.08,
        "c {}",
        got.viscosity
    );
}

/// The simulator's own truths agree with its physics, so that the checks above hold the fit to
/// a bottle and not to a slip of the simulator: each glug's air is H + C − V_i, V_i falls by its
/// pocket, the cavity rings at Helmholtz's frequency of that air, the bubble below Nyquist, the
/// weight log ends where the last glug left the bottle, the energies add up to their shares.
#[test]
fn the_simulated_bottle_is_what_its_physics_says() {
    for params in [Params::glass_bottle(22_050.0), Params::short_clip(8_000.0)] {
        let simulated = simulate(&params);
        let glugs = simulated.onsets.len();
        let mut before_ml = params.start_ml;
        for glug in 0..glugs {
            let volume_ml = simulated.volume_ml[glug];
            assert!((before_ml - simulated.pocket_ml[glug] - volume_ml).abs() < 1e-9);
            before_ml = volume_ml;
            let air_ml = params.headspace_ml + params.capacity_ml - volume_ml;
            assert!((simulated.air_ml[glug] - air_ml).abs() < 1e-9);
            let hz = helmholtz_hz(air_ml, params.neck_radius_m, params.neck_length_m);
            assert!((simulated.cavity_hz[glug] / hz - 1.0).abs() < 1e-12);
            assert!(simulated.amplitude[glug] > 0.0 && simulated.bubble_decay[glug] > 0.0);
            assert!(simulated.bubble_hz[glug] > simulated.cavity_hz[glug]);
        }
        let (_, last_ml) = *simulated.weight_log.last().unwrap();
        assert!((last_ml - simulated.volume_ml[glugs - 1]).abs() < 1e-9);
        assert!(simulated.flow_end_s >= simulated.onsets[glugs - 1]);
        assert!(simulated.drain_ml_per_s > 0.0 && simulated.cavity_decay > 0.0);
        let bubble: f64 = simulated.bubble_energy.iter().sum();
        let cavity: f64 = simulated.cavity_energy.iter().sum();
        assert!((bubble / (bubble + cavity) - simulated.bubble_energy_share).abs() < 1e-12);
        assert!((simulated.bubble_share + simulated.low_mode_share - 1.0).abs() < 1e-12);
    }
}
