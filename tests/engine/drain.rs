//! MODEL.md §2–3: the bottle drains at C/T·h(θ), stops at r(θ)·C, and glugs only above s(θ)·C;
//! §12: with curves of its own, the same by those.

use crate::support::{pour_onsets, tilt_only};
use sake_glug_engine::curves::BottleCurves;
use sake_glug_engine::{ControlValues, Curve, ModelConfig, Pour};

/// `curve`'s default value at `tilt_deg`.
fn default_at(curve: Curve, tilt_deg: f64) -> f64 {
    curve.of(&BottleCurves::default()).at(tilt_deg)
}

const FS: f64 = 48_000.0;

/// Samples until less than a nanolitre is left (600 000 f64 subtractions may leave a few
/// picolitres for one more sample).
fn samples_until_empty(config: ModelConfig, controls: ControlValues) -> u64 {
    let mut pour = Pour::new(FS, config);
    pour.reset();
    (0..)
        .find(|&sample| {
            pour.step(sample, controls, |_| {});
            pour.volume_ml() < 1e-6
        })
        .unwrap()
        + 1
}

#[test]
fn a_full_bottle_at_135_degrees_empties_in_the_pour_time() {
    for pour_time_s in [5.0, 2.0, 12.5] {
        let controls = ControlValues {
            pour_time_s,
            ..tilt_only(135.0)
        };
        let dry_at = samples_until_empty(ModelConfig::default(), controls) as f64 / FS;
        assert!(
            (dry_at - pour_time_s).abs() <= 1.0 / FS,
            "pour time {pour_time_s} s: dry after {dry_at} s"
        );
    }
}

#[test]
fn outflow_rate_follows_the_tilt_response() {
    // 155° pours as fast as 135°; upright-ish 90° at a third of it; 180° at 0.733 of it.
    for (tilt, h) in [(155.0, 1.0), (90.0, 0.333), (180.0, 0.733), (115.0, 0.833)] {
        let mut pour = Pour::new(FS, ModelConfig::default());
        pour.reset();
        let first = pour.step(0, tilt_only(tilt), |_| {});
        let expected = 300.0 / 5.0 * h / FS;
        assert!((first.amount_ml - expected).abs() < 1e-15, "tilt {tilt}");
    }
}

#[test]
fn nothing_pours_while_the_volume_is_at_or_below_the_rest_level() {
    for tilt in [60.0, 74.5, 79.0, 84.0, 90.0, 96.0, 100.0] {
        let rest_percent = default_at(Curve::Rest, tilt) * 100.0;
        let at_rest = ControlValues {
            fill_percent: rest_percent,
            ..tilt_only(tilt)
        };
        let (onsets, _) = pour_onsets(FS, ModelConfig::default(), |_| at_rest, 0.5);
        assert!(onsets.is_empty(), "tilt {tilt}");
        let mut pour = Pour::new(FS, ModelConfig::default());
        pour.reset();
        for sample in 0..1000 {
            assert_eq!(
                pour.step(sample, at_rest, |_| {}).amount_ml,
                0.0,
                "tilt {tilt}"
            );
        }
    }
}

#[test]
fn draining_stops_exactly_at_the_rest_level() {
    for tilt in [74.5, 90.0, 100.0] {
        let mut pour = Pour::new(FS, ModelConfig::default());
        pour.reset();
        for sample in 0..(20.0 * FS) as u64 {
            pour.step(sample, tilt_only(tilt), |_| {});
        }
        assert!(
            (pour.volume_ml() - default_at(Curve::Rest, tilt) * 300.0).abs() < 1e-9,
            "tilt {tilt}"
        );
    }
}

#[test]
fn nothing_glugs_while_the_volume_is_at_or_below_the_submerged_level() {
    let config = ModelConfig::default().deterministic();
    // At 100° the bottle pours from 300 ml down to 25 ml but glugs only above 110.1 ml.
    let (onsets, glugging) = pour_onsets(FS, config, |_| tilt_only(100.0), 20.0);
    let submerged_ml = default_at(Curve::Submerged, 100.0) * 300.0;
    let max_outflow_per_sample = 300.0 / 5.0 * 0.833 / FS;
    assert!(!onsets.is_empty());
    for onset in &onsets {
        assert!(onset.volume_ml > submerged_ml - max_outflow_per_sample);
    }
    assert!((glugging - (300.0 - submerged_ml)).abs() < max_outflow_per_sample);
    // Below the submerged level the liquid still flows, as a smooth stream.
    let mut pour = Pour::new(FS, config);
    pour.reset();
    for sample in 0..(20.0 * FS) as u64 {
        pour.step(sample, tilt_only(100.0), |_| {});
    }
    assert!(pour.volume_ml() < submerged_ml - 80.0);
}

/// The first sample's outflow at `tilt_deg` from a full bottle (ml).
fn first_outflow_ml(config: ModelConfig, tilt_deg: f64) -> f64 {
    let mut pour = Pour::new(FS, config);
    pour.reset();
    pour.step(0, tilt_only(tilt_deg), |_| {}).amount_ml
}

#[test]
fn a_drain_curve_of_its_own_sets_the_rate_where_it_differs() {
    // The default h is 1 at 135° and at 155°; this one falls to 0.8 at 155°.
    let mut config = ModelConfig::default();
    config.curves.drain = Curve::Drain
        .from_points(&[(60.0, 0.1), (135.0, 1.0), (155.0, 0.8), (180.0, 0.6)])
        .unwrap();
    let rate = |config, tilt| first_outflow_ml(config, tilt) * FS;
    let default = ModelConfig::default();
    assert!((rate(default, 155.0) - 60.0).abs() < 1e-9);
    assert!((rate(config, 155.0) - 0.8 * 60.0).abs() < 1e-9);
    assert!((rate(config, 145.0) - 0.9 * 60.0).abs() < 1e-9);
    // Where both curves are 1 the rate is the same: the pour time still holds at 135°.
    assert_eq!(rate(config, 135.0), rate(default, 135.0));
}

#[test]
fn rest_and_submerged_curves_of_their_own_set_where_it_stops_and_stops_glugging() {
    let mut config = ModelConfig::default().deterministic();
    config.curves.rest = Curve::Rest
        .from_points(&[(90.0, 1.0), (150.0, 0.2)])
        .unwrap();
    config.curves.submerged = Curve::Submerged
        .from_points(&[(90.0, 1.0), (150.0, 0.5)])
        .unwrap();
    // At 150° the pour stops at 60 ml, and glugs only above 150 ml (to within the sample that
    // crosses it).
    let per_sample_ml = 60.0 / FS;
    let (onsets, glugging) = pour_onsets(FS, config, |_| tilt_only(150.0), 8.0);
    assert!(
        (glugging - 150.0).abs() < per_sample_ml,
        "{glugging} ml glugged"
    );
    assert!(onsets.len() >= 29, "{} units", onsets.len());
    assert!(onsets
        .iter()
        .all(|onset| onset.volume_ml > 150.0 - per_sample_ml));
    let mut pour = Pour::new(FS, config);
    pour.reset();
    for sample in 0..(8.0 * FS) as u64 {
        pour.step(sample, tilt_only(150.0), |_| {});
    }
    assert!(
        (pour.volume_ml() - 60.0).abs() < 1e-9,
        "{} ml",
        pour.volume_ml()
    );
}
