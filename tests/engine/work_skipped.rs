//! Doing only what a scene needs, as properties (the costs are in benches/scaling.rs): a settled
//! engine renders silence without walking the pour or the bank, and gives the very samples it
//! would give sample by sample; units stop being computed once below −120 dB.

use sake_glug::engine::{ControlValues, Controls, Engine, ModelConfig};

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

/// Renders 10 s in blocks of `block` samples with constant controls per block, cut where the
/// controls change as a host cuts its blocks at events.
fn render(block: usize) -> (Vec<f32>, Vec<bool>) {
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
        engine.process(
            &Controls::constant(values, -6.0),
            &mut out[start..start + n],
        );
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
fn units_stop_being_computed_below_minus_120_db() {
    let mut engine = Engine::new(FS, ModelConfig::default().deterministic());
    let mut out = vec![0.0f32; 4800];
    let pour = Controls::constant(controls_at(0.0), -6.0);
    let upright = Controls::constant(controls_at(4.0), -6.0);
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
