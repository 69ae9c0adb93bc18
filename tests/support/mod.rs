//! Helpers shared by the integration tests.
#![allow(dead_code)]

pub mod fuzz;

use sake_glug_engine::synthesis::reference;
use sake_glug_engine::{
    AnchoredF32, ControlSource, ControlValues, Engine, ModelConfig, Pour, UnitOnset, Voicing,
};
use sake_glug_render::{render_scene, LaneBuffers, RenderError, RenderObserver, Scene};
use sake_glug_reports::accuracy;
use sake_glug_reports::timing::{self, RenderSpec};

/// Renders `len` samples of `scene` on the default path, cutting time into blocks of the sizes
/// `block_sizes` yields (cycled).
pub fn render_in_blocks(scene: &Scene, len: usize, block_sizes: &[usize]) -> Vec<f32> {
    let mut engine = Engine::new(scene.sample_rate as f64, scene.config);
    let mut lanes = LaneBuffers::default();
    let mut out = vec![0.0f32; len];
    let mut done = 0;
    for &size in block_sizes.iter().cycle() {
        if done == len {
            break;
        }
        let size = size.min(len - done);
        let controls = scene.controls(done as u64, &mut lanes, size);
        engine.process(&controls, &mut out[done..done + size]);
        done += size;
    }
    out
}

/// A scene rendered as `sake-glug render` renders it: its samples and its units as the renderer
/// reports them, which the C library's and the web binding's live handles must give bit for bit.
pub fn offline(scene: &Scene) -> (Vec<f32>, Vec<(UnitOnset, Voicing)>) {
    struct Units(Vec<(UnitOnset, Voicing)>);
    impl RenderObserver for Units {
        fn unit_started(&mut self, onset: &UnitOnset, voicing: Voicing) {
            self.0.push((*onset, voicing));
        }
    }
    let mut samples = Vec::new();
    let mut units = Units(Vec::new());
    render_scene(
        scene,
        |block: &[f32]| {
            samples.extend_from_slice(block);
            Ok::<(), RenderError>(())
        },
        &mut units,
    )
    .unwrap();
    (samples, units.0)
}

/// The f64 reference of the same scene.
pub fn reference_render(scene: &Scene, len: usize) -> Vec<f64> {
    reference::evaluate(scene.sample_rate as f64, scene.config, scene, 0..len as u64).samples
}

/// The largest step between neighbouring samples: how a click shows.
pub fn largest_step(samples: &[f32]) -> f32 {
    samples
        .windows(2)
        .map(|pair| (pair[1] - pair[0]).abs())
        .fold(0.0, f32::max)
}

/// Largest absolute error relative to the reference's peak, in dB.
pub fn error_db(fast: &[f32], reference: &[f64]) -> f64 {
    assert!(
        reference.iter().any(|y| *y != 0.0),
        "the reference is silent"
    );
    accuracy::error_db(fast, reference).0
}

/// Every unit a pour starts under constant controls over `seconds`, with the summed outflow
/// that left while the mouth was submerged.
pub fn pour_onsets(
    sample_rate: f64,
    config: ModelConfig,
    controls: impl Fn(u64) -> ControlValues,
    seconds: f64,
) -> (Vec<UnitOnset>, f64) {
    let mut pour = Pour::new(sample_rate, config);
    pour.reset();
    let mut onsets = Vec::new();
    let mut glugging_outflow = 0.0;
    for sample in 0..(seconds * sample_rate) as u64 {
        let outflow = pour.step(sample, controls(sample), |onset| onsets.push(*onset));
        if outflow.submerged {
            glugging_outflow += outflow.amount_ml;
        }
    }
    (onsets, glugging_outflow)
}

pub fn tilt_only(tilt_deg: f64) -> ControlValues {
    ControlValues {
        tilt_deg,
        ..ControlValues::default()
    }
}

/// Renders `len` samples of `controls` on the default path, asking for `sample_rate` as given
/// (the engine brings it into range), in the blocks of the reports.
pub fn render_controls(
    sample_rate: f64,
    config: ModelConfig,
    controls: &impl ControlSource,
    len: u64,
) -> Vec<f32> {
    let whole = 0..len;
    let spec = RenderSpec {
        sample_rate,
        config,
        len,
        keep: std::slice::from_ref(&whole),
        energy_span: 0,
    };
    timing::timed_render::<AnchoredF32>(&spec, controls).kept
}

/// The f64 reference of the same controls, asked for at the same `sample_rate`.
pub fn reference_controls(
    sample_rate: f64,
    config: ModelConfig,
    controls: &impl ControlSource,
    len: u64,
) -> Vec<f64> {
    reference::evaluate(sample_rate, config, controls, 0..len).samples
}

/// A pour with everything automated, randomness on, so any block-dependence would show.
pub const BUSY_SCENE: &str = r#"
seed = 11
duration_s = 3.0
tilt_deg = [[0.0, 70.0], [0.3, 150.0], [1.2, 150.0], [1.2001, 0.0], [1.5, 0.0], [1.6, 140.0]]
viscosity_c = [[0.0, 0.1], [3.0, 0.9]]
fill_percent = [[0.0, 100.0], [1.4, 100.0], [1.4, 90.0]]
pour_time_s = [[0.0, 3.0], [2.0, 4.0]]
[output]
gain_db = [[0.0, -12.0], [2.5, 0.0]]
"#;
