//! The engine takes the pour a span at a time (plain samples in closed form, MODEL.md §3–4
//! unchanged); the f64 reference steps it one sample at a time with `Pour::step`. Both must start
//! the very same units: same sample, same sub-sample fraction, volume, amplitude and shape, bit
//! for bit, over scenes that cross every kind of boundary, at any block size.

use sake_glug_engine::{Engine, Pour, UnitOnset};
use sake_glug_render::{LaneBuffers, Scene};

/// Steps and ramps of every input, refills, rest and submerged levels crossed both ways, follow
/// mode, floods of onsets, pocket volumes that are not nice numbers, odd sample rates.
const SCENES: &[&str] = &[
    // The default pour, and a seeded one.
    "tilt_deg = [[0.0, 90.0], [0.5, 135.0]]\nduration_s = 6.0",
    "seed = 5\ntilt_deg = [[0.0, 90.0], [0.5, 135.0]]\nduration_s = 6.0",
    // The busy scene of the determinism test.
    crate::support::BUSY_SCENE,
    // Held tilts that stop at the rest level, then pour on past the submerged level.
    r#"
    seed = 3
    sample_rate = 44100
    duration_s = 9.0
    tilt_deg = [[0.0, 95.0], [3.0, 95.0], [3.0, 100.0], [6.0, 100.0], [6.0, 180.0]]
    pour_time_s = 7.3
    [bottle]
    capacity_ml = 1000
    pocket_ml = 0.7
    "#,
    // A flood: a tiny pocket poured fast at 96 kHz, with the widest jitter.
    r#"
    seed = 4
    sample_rate = 96000
    duration_s = 1.5
    tilt_deg = 120
    pour_time_s = 0.5
    [bottle]
    capacity_ml = 37
    pocket_ml = 0.013
    [glug]
    timing_jitter = 0.9
    "#,
    // Follow mode with the fill level stepped and ramped.
    r#"
    seed = 8
    duration_s = 4.0
    tilt_deg = [[0.0, 100.0], [4.0, 170.0]]
    fill_percent = [[0.0, 100.0], [1.0, 100.0], [1.0, 60.0], [2.0, 60.0], [4.0, 20.0]]
    [output]
    drain = "follow"
    "#,
    // Refills every 0.7 s (steps of the fill level) while pouring, at 1 kHz.
    r#"
    seed = 2
    sample_rate = 1000
    duration_s = 20.0
    tilt_deg = 150
    pour_time_s = 2.0
    fill_percent = [[0.7, 100], [0.7, 99], [1.4, 99], [1.4, 98], [2.1, 98], [2.1, 97], [9.0, 97], [9.0, 50]]
    "#,
];

/// Every unit the engine starts over `len` samples of `scene`, cut into blocks of `sizes`.
fn engine_onsets(scene: &Scene, len: u64, sizes: &[usize]) -> Vec<UnitOnset> {
    let mut engine = Engine::new(scene.sample_rate as f64, scene.config);
    let mut lanes = LaneBuffers::default();
    let mut out = vec![0.0f32; 8192];
    let mut onsets = Vec::new();
    let mut done = 0u64;
    for &size in sizes.iter().cycle() {
        if done == len {
            break;
        }
        let size = size.min((len - done) as usize);
        let controls = scene.controls(done, &mut lanes, size);
        engine.process_observed(&controls, &mut out[..size], &mut |onset, _| {
            onsets.push(*onset)
        });
        done += size as u64;
    }
    engine.report_deferred_units(&mut |onset, _| onsets.push(*onset));
    onsets
}

/// The bits of everything a unit starts with.
fn bits(onset: &UnitOnset) -> Vec<u64> {
    let shape = onset.shape;
    [
        onset.fraction,
        onset.volume_ml,
        onset.amplitude,
        onset.viscosity,
        shape.frequency_hz[0],
        shape.frequency_hz[1],
        shape.decay_per_s[0],
        shape.decay_per_s[1],
    ]
    .iter()
    .map(|value| value.to_bits())
    .chain([onset.sample])
    .collect()
}

#[test]
fn spans_start_the_same_units_as_the_per_sample_step_of_the_reference() {
    for text in SCENES {
        let scene = Scene::parse(text).unwrap();
        let len = scene.duration_samples().unwrap();
        let reference = pour_onsets_of(&scene, len);
        assert!(
            reference.len() > 20,
            "{} units only in\n{text}",
            reference.len()
        );
        for sizes in [&[4096][..], &[1], &[64], &[63, 1000, 7, 4097]] {
            let fast = engine_onsets(&scene, len, sizes);
            assert_eq!(fast.len(), reference.len(), "blocks {sizes:?}\n{text}");
            for (index, (a, b)) in fast.iter().zip(&reference).enumerate() {
                assert_eq!(bits(a), bits(b), "unit {index}, blocks {sizes:?}\n{text}");
            }
        }
    }
}

/// The onsets of `Pour::step`, sample by sample, exactly as `reference::evaluate` takes them
/// (its synthesis would make the flood scene slow).
fn pour_onsets_of(scene: &Scene, len: u64) -> Vec<UnitOnset> {
    let mut pour = Pour::new(scene.sample_rate as f64, scene.config);
    pour.reset();
    let mut onsets = Vec::new();
    for sample in 0..len {
        pour.step(sample, scene.values_at(sample), |onset| onsets.push(*onset));
    }
    onsets
}
