//! Doing only what a scene needs, as properties (the costs are in benches/scaling.rs): a settled
//! engine renders silence without walking the pour or the bank, and gives the very samples of a
//! run that cannot take that shortcut; a unit sounds until −120 dB and is not computed after.

use sake_glug_engine::{ControlValues, Controls, Engine, Lane, ModelConfig, GRID};

const FS: f64 = 48_000.0;

/// Tilt 135° for 3 s, upright for 5 s, then (after a refill) 135° again for 2 s.
fn controls_at(second: f64) -> ControlValues {
    ControlValues {
        tilt_deg: if (3.0..8.0).contains(&second) {
            0.0
        } else {
            135.0
        },
        ..ControlValues::default()
    }
}

/// How the controls of a block reach the engine.
#[derive(Clone, Copy, PartialEq)]
enum Lanes {
    /// [`Lane::Constant`]: the engine may skip a settled block.
    Constant,
    /// [`Lane::Samples`], one value per sample even where nothing changes: the engine cannot
    /// know the controls are still, so it steps the pour and the output stage at every sample.
    PerSample,
}

/// Renders 10 s in blocks of `block` samples, cut where the controls change as a host cuts its
/// blocks at events; returns the samples and whether the engine was settled after each block.
fn render(block: usize) -> (Vec<f32>, Vec<bool>) {
    render_with(block, Lanes::Constant)
}

fn render_with(block: usize, lanes: Lanes) -> (Vec<f32>, Vec<bool>) {
    let mut engine = Engine::new(FS, ModelConfig::default());
    let len = (10.0 * FS) as usize;
    let changes = [(3.0 * FS) as usize, (8.0 * FS) as usize, len];
    let mut out = vec![0.0f32; len];
    let mut settled = Vec::new();
    let mut start = 0;
    while start < len {
        let next_change = changes.iter().copied().find(|&c| c > start).unwrap_or(len);
        let n = block.min(next_change - start);
        if start == (8.0 * FS) as usize {
            engine.refill();
        }
        let values = controls_at(start as f64 / FS);
        let per_sample = [
            vec![values.tilt_deg; n],
            vec![values.viscosity; n],
            vec![values.fill_percent; n],
            vec![values.pour_time_s; n],
            vec![-6.0; n],
        ];
        let controls = match lanes {
            Lanes::Constant => Controls::constant(ControlValues {
                gain_db: -6.0,
                ..values
            }),
            Lanes::PerSample => Controls {
                tilt_deg: Lane::Samples(&per_sample[0]),
                viscosity: Lane::Samples(&per_sample[1]),
                fill_percent: Lane::Samples(&per_sample[2]),
                pour_time_s: Lane::Samples(&per_sample[3]),
                gain_db: Lane::Samples(&per_sample[4]),
            },
        };
        engine.process(&controls, &mut out[start..start + n]);
        settled.push(engine.is_settled());
        start += n;
    }
    (out, settled)
}

#[test]
fn settled_silence_is_the_same_in_any_block_size() {
    let (whole, settled) = render(8000);
    assert!(
        settled.iter().any(|&s| s),
        "the engine never settled, so nothing was tested"
    );
    for block in [1, 63, 64, 4096] {
        let (cut, _) = render(block);
        let first_difference = whole
            .iter()
            .zip(&cut)
            .position(|(a, b)| a.to_bits() != b.to_bits());
        assert_eq!(first_difference, None, "block {block}");
    }
    // The second pour sounds after the silence: the shortcut left the engine ready for it.
    assert!(whole[(8.5 * FS) as usize..].iter().any(|y| y.abs() > 0.01));
}

#[test]
fn the_settled_shortcut_gives_the_samples_of_a_run_that_cannot_take_it() {
    let (shortcut, settled) = render_with(4096, Lanes::Constant);
    assert!(
        settled.iter().any(|&s| s),
        "the constant run must take the shortcut"
    );
    // The shortcut needs constant lanes (`Lane::Constant`): lanes of samples never take it,
    // even where their samples do not change (the engine then only knows the pour rests).
    let (sample_by_sample, _) = render_with(4096, Lanes::PerSample);
    let first_difference = shortcut
        .iter()
        .zip(&sample_by_sample)
        .position(|(a, b)| a.to_bits() != b.to_bits());
    assert_eq!(first_difference, None);
    assert!(shortcut.iter().any(|y| y.abs() > 0.01));
}

/// One unit (0.09 s at 135° lets one 5 ml pocket in) with only component `index` (c = 1 or 0),
/// rendered for 1 s: the samples, the onset time (samples) and the component's decay (1/s).
fn lone_component(index: usize) -> (Vec<f32>, f64, f64, f64) {
    let config = ModelConfig::default().deterministic();
    let mut engine = Engine::new(FS, config);
    let viscosity = if index == 0 { 1.0 } else { 0.0 };
    let mut out = vec![0.0f32; FS as usize];
    for (block, chunk) in out.chunks_mut(480).enumerate() {
        let values = ControlValues {
            tilt_deg: if block < 9 { 135.0 } else { 0.0 },
            viscosity,
            ..ControlValues::default()
        };
        engine.process(
            &Controls::constant(ControlValues {
                gain_db: -6.0,
                ..values
            }),
            chunk,
        );
    }
    assert_eq!(engine.stats().units_started, 1);
    let unit = *engine.last_unit().unwrap();
    let amplitude = unit.component_amplitudes()[index] * 10f64.powf(-6.0 / 20.0);
    let onset = unit.sample as f64 + unit.fraction;
    (out, onset, amplitude, unit.shape.decay_per_s[index])
}

#[test]
fn a_unit_sounds_until_minus_120_db_and_stops_within_a_period() {
    for index in [0, 1] {
        let (out, onset, amplitude, decay_per_s) = lone_component(index);
        // e^(−Bτ) reaches 10⁻⁶ (−120 dB) at this sample.
        let silent_at = onset + 1e6f64.ln() / decay_per_s * FS;
        // Over the last 12.5 ms before it (a cycle of 80 Hz), the unit still sounds as its
        // closed form, at about 10⁻⁶ of its start: not zero, not dropped early.
        let (from, to) = (silent_at as usize - 600, silent_at as usize);
        let frequency_hz = [80.0, 300.0][index];
        let mut loudest = 0.0f64;
        for (n, &y) in out.iter().enumerate().take(to).skip(from) {
            let tau = (n as f64 - onset) / FS;
            let envelope = amplitude * (-decay_per_s * tau).exp();
            let exact = envelope * (std::f64::consts::TAU * frequency_hz * tau).sin();
            assert!(
                (y as f64 - exact).abs() < 0.05 * envelope,
                "component {index} at sample {n}: {y} against {exact:e}"
            );
            loudest = loudest.max(y.abs() as f64);
        }
        assert!(
            loudest > 0.9e-6 * amplitude,
            "component {index}: {loudest:e}"
        );
        // Dropped at the first period start past −120 dB: nothing after the next one.
        let dropped_by = (silent_at as usize / GRID + 1) * GRID;
        assert!(
            out[dropped_by..].iter().all(|&y| y == 0.0),
            "component {index}"
        );
    }
}

#[test]
fn units_stop_being_computed_below_minus_120_db() {
    let mut engine = Engine::new(FS, ModelConfig::default().deterministic());
    let mut out = vec![0.0f32; 4800];
    let pour = Controls::constant(ControlValues {
        gain_db: -6.0,
        ..controls_at(0.0)
    });
    let upright = Controls::constant(ControlValues {
        gain_db: -6.0,
        ..controls_at(4.0)
    });
    for _ in 0..10 {
        engine.process(&pour, &mut out);
    }
    assert!(engine.sounding_components() > 0);
    // B2 = 40 /s is the slower decay: −120 dB after ln(10⁶)/40 ≈ 0.35 s.
    for _ in 0..4 {
        engine.process(&upright, &mut out);
    }
    assert_eq!(engine.sounding_components(), 0);
    assert!(engine.is_settled());
}
