//! MODEL.md §12: the amplitude law's V0 and its spread. Asum_i = a(V_i)·exp(σ_A·z_i), z_i
//! standard normal, drawn only while σ_A > 0 and from a stream of its own, so the onsets, f and
//! B of a pour are the same at every σ_A.

use crate::support::pour_onsets;
use sake_glug_engine::{ControlValues, Controls, Engine, ModelConfig, Pour, UnitOnset};

const FS: f64 = 48_000.0;

/// A minute of follow-mode pouring at 135° while the fill level falls from 100 % to 20 %: some
/// 700 units at every V down past V0, where a(V) is 0.
fn minute_of_units(config: ModelConfig) -> Vec<UnitOnset> {
    let config = ModelConfig {
        drain: sake_glug_engine::DrainMode::Follow,
        ..config
    };
    let controls = |sample: u64| ControlValues {
        tilt_deg: 135.0,
        fill_percent: 100.0 - 80.0 * sample as f64 / (60.0 * FS),
        ..ControlValues::default()
    };
    pour_onsets(FS, config, controls, 60.0).0
}

/// The log of each unit's Asum over its Asum without spread, where that is above 0.
fn log_factors(spread: &[UnitOnset], plain: &[UnitOnset]) -> Vec<f64> {
    spread
        .iter()
        .zip(plain)
        .filter(|(_, plain)| plain.amplitude > 0.0)
        .map(|(spread, plain)| (spread.amplitude / plain.amplitude).ln())
        .collect()
}

#[test]
fn the_spread_scatters_asum_log_normally_with_its_sigma_and_moves_no_other_draw() {
    let plain = minute_of_units(ModelConfig::default());
    for sigma in [0.2, 0.6] {
        let spread = minute_of_units(ModelConfig {
            amplitude_spread: sigma,
            ..ModelConfig::default()
        });
        // The same units at the same instants and volumes, with the same f and B.
        assert_eq!(spread.len(), plain.len());
        for (a, b) in spread.iter().zip(&plain) {
            assert_eq!(
                (a.sample, a.fraction, a.volume_ml),
                (b.sample, b.fraction, b.volume_ml)
            );
            assert_eq!(
                (a.shape.frequency_hz, a.shape.decay_per_s),
                (b.shape.frequency_hz, b.shape.decay_per_s)
            );
            assert_eq!(a.amplitude == 0.0, b.amplitude == 0.0);
        }
        let logs = log_factors(&spread, &plain);
        let n = logs.len() as f64;
        assert!(n > 400.0, "{n} units above V0");
        let mean = logs.iter().sum::<f64>() / n;
        let sd = (logs.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        // Fitted: centred on a(V) (log mean 0) with the given σ, within four standard errors.
        assert!(
            mean.abs() < 4.0 * sigma / n.sqrt(),
            "σ_A {sigma}: log mean {mean}"
        );
        assert!(
            (sd - sigma).abs() < 4.0 * sigma / (2.0 * (n - 1.0)).sqrt(),
            "σ_A {sigma}: fitted σ {sd}"
        );
        // Normal in the log: about 68 % within one σ, 95 % within two.
        let within = |k: f64| logs.iter().filter(|x| x.abs() < k * sigma).count() as f64 / n;
        assert!((within(1.0) - 0.683).abs() < 0.05, "{}", within(1.0));
        assert!((within(2.0) - 0.954).abs() < 0.025, "{}", within(2.0));
    }
}

#[test]
fn a_spread_of_0_draws_nothing() {
    // Half a pour at σ_A = 0, then σ_A = 0.5: the first factor drawn is the first of a pour at
    // 0.5 throughout, so the units at 0 drew none.
    let spread = ModelConfig {
        amplitude_spread: 0.5,
        ..ModelConfig::default()
    };
    let controls = |_| ControlValues {
        tilt_deg: 135.0,
        ..ControlValues::default()
    };
    let from_start = pour_onsets(FS, spread, controls, 1.0).0;
    let mut pour = Pour::new(FS, ModelConfig::default());
    pour.reset();
    let mut late = Vec::new();
    for sample in 0..(2.0 * FS) as u64 {
        if sample == FS as u64 {
            pour.set_config(spread);
        }
        pour.step(sample, controls(sample), |onset| {
            if sample >= FS as u64 {
                late.push(*onset)
            }
        });
    }
    assert!(!late.is_empty());
    assert_eq!(
        late[0].shape.amplitude_factor,
        from_start[0].shape.amplitude_factor
    );
    assert_ne!(late[0].shape.amplitude_factor, 1.0);
}

#[test]
fn the_ceiling_holds_whatever_the_spread() {
    let config = ModelConfig {
        amplitude_spread: 3.0,
        ceiling: 0.5,
        ..ModelConfig::default()
    };
    let mut engine = Engine::new(FS, config);
    let values = ControlValues {
        tilt_deg: 135.0,
        gain_db: 24.0,
        ..ControlValues::default()
    };
    let mut out = vec![0.0f32; 4 * FS as usize];
    engine.process(&Controls::constant(values), &mut out);
    let peak = out.iter().fold(0.0f32, |peak, y| peak.max(y.abs()));
    assert!(peak <= 0.5, "{peak}");
    assert!(
        engine.limiter_events() > 0,
        "the spread must reach the ceiling here"
    );
}

#[test]
fn a_v0_of_its_own_silences_the_units_below_it_and_scales_those_above() {
    let own = ModelConfig {
        silent_below: sake_glug_engine::SilentBelow::Ml(200.0),
        ..ModelConfig::default().deterministic()
    };
    let units = minute_of_units(own);
    assert!(units.len() > 400);
    for unit in &units {
        let expected = ((unit.volume_ml - 200.0) / (300.0 - 200.0)).max(0.0);
        assert!((unit.amplitude - expected).abs() < 1e-12, "{unit:?}");
    }
    assert!(units.iter().any(|unit| unit.amplitude == 0.0));
}
