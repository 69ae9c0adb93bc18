//! A host automating Output gain and Output ceiling while glugs ring, through the CLAP entry
//! point: nice-plug splits the block at each change, the engine ramps to it (MODEL.md §6), and
//! the samples are the same at every host block size and the same as the engine's own render
//! of those targets, which is what the offline renderer runs.

use crate::clap_host::{ClapInstance, ParamChange};
use crate::host::TestHost;
use sake_glug_engine::{ControlValues, Controls, Engine, Lane};

const RATE: f64 = 48_000.0;
const TOTAL: usize = 96_000;
/// Where the ceiling comes down (dB below full scale).
const CEILING_AT: usize = 50_000;
const CEILING_DB: f64 = -20.0;

/// Output gain (dB) from each sample on: a jump, another mid-ramp, and a last one.
const GAIN_DB: [(usize, f64); 4] = [(0, -6.0), (30_000, 6.0), (30_100, -30.0), (70_000, 0.0)];

fn automation(instance: &ClapInstance) -> Vec<ParamChange> {
    let mut changes: Vec<ParamChange> = GAIN_DB[1..]
        .iter()
        .map(|(at, db)| instance.change(*at as u64, "Output gain", &db.to_string()))
        .collect();
    changes.push(instance.change(CEILING_AT as u64, "Output ceiling", &CEILING_DB.to_string()));
    changes.sort_by_key(|change| change.at);
    changes
}

fn plugin_render(block: usize) -> Vec<f32> {
    let mut instance = ClapInstance::new();
    instance.set_text("Tilt", "135");
    instance.set_text("Seed", "7");
    instance.activate(RATE);
    let changes = automation(&instance);
    instance.render_automated(TOTAL, block, &changes)
}

/// The engine given the same targets sample by sample.
fn engine_render() -> Vec<f32> {
    let host = TestHost::new(RATE as f32, 2);
    host.set_text("tilt", "135");
    host.set_text("seed", "7");
    let params = host.plugin.glug_params();
    let before = params.model_config();
    host.set_text("ceil", &CEILING_DB.to_string());
    let after = params.model_config();
    assert_eq!(after.ceiling, 10f64.powf(CEILING_DB / 20.0));

    let gain_db: Vec<f64> = (0..TOTAL)
        .map(|n| GAIN_DB.iter().rev().find(|(at, _)| n >= *at).unwrap().1)
        .collect();
    let mut engine = Engine::new(RATE, before);
    let mut out = vec![0.0f32; TOTAL];
    for (span, config) in [(0..CEILING_AT, before), (CEILING_AT..TOTAL, after)] {
        engine.set_config(config);
        let controls = Controls {
            gain_db: Lane::Samples(&gain_db[span.clone()]),
            ..Controls::constant(ControlValues {
                gain_db: 0.0,
                ..params.control_values()
            })
        };
        engine.process(&controls, &mut out[span]);
    }
    out
}

#[test]
fn automated_gain_and_ceiling_give_the_engines_samples_at_every_block_size() {
    let expected = engine_render();
    // Glugs ring at every change (at −30 dB too).
    let ringing = |at: usize| expected[at - 200..at].iter().any(|y| y.abs() > 1e-3);
    assert!(GAIN_DB[1..].iter().all(|(at, _)| ringing(*at)) && ringing(CEILING_AT));
    for block in [64, 511, 4096] {
        let rendered = plugin_render(block);
        let first_difference = (0..TOTAL).find(|n| rendered[*n] != expected[*n]);
        assert_eq!(first_difference, None, "block {block}");
    }
}
