//! `Engine::process_unchanged`, which the C library calls while no control call came: blocks of
//! any size under the controls of the block before give the very samples, units and state of
//! `Engine::process_observed` in large blocks, through steps of the gain, refills and a limiter
//! at work.

use sake_glug_engine::{ControlValues, Controls, Engine, ModelConfig, UnitOnset, Voicing};

const FS: f64 = 48_000.0;

/// What a render leaves: its samples, its units (sample, fraction and output gain, as bits),
/// and V at each change.
struct Rendered {
    samples: Vec<u32>,
    units: Vec<[u64; 3]>,
    volumes: Vec<u64>,
}

/// The controls from sample `at` on: tilt 135°, the gain stepped at 1.5 s (past the ceiling,
/// so that the limiter works) and back at 2.5 s.
fn controls_from(at: usize) -> ControlValues {
    let second = at as f64 / FS;
    let gain_db = if (1.5..2.5).contains(&second) {
        24.0
    } else {
        -6.0
    };
    ControlValues {
        tilt_deg: 135.0,
        gain_db,
        ..ControlValues::default()
    }
}

/// The samples where the controls change, a refill asked for at 3.2 s, and the end.
const CHANGES_S: [f64; 4] = [1.5, 2.5, 3.2, 4.0];

/// Renders 4 s in blocks cycling through `blocks`, cut at each change; blocks after the first
/// one under the same controls go through `process_unchanged` when `unchanged` is set.
fn render(blocks: &[usize], unchanged: bool) -> Rendered {
    let mut engine = Engine::new(FS, ModelConfig::default());
    let changes = CHANGES_S.map(|second| (second * FS) as usize);
    let mut rendered = Rendered {
        samples: Vec::new(),
        units: Vec::new(),
        volumes: Vec::new(),
    };
    let keep = |onset: &UnitOnset, voicing: Voicing, units: &mut Vec<[u64; 3]>| {
        units.push([
            onset.sample,
            onset.fraction.to_bits(),
            voicing.output_gain.to_bits(),
        ]);
    };
    let mut done = 0;
    let mut next_block = 0;
    let mut same_as_last = false;
    for (index, &change) in changes.iter().enumerate() {
        let controls = Controls::constant(controls_from(done));
        while done < change {
            let len = blocks[next_block % blocks.len()].min(change - done);
            next_block += 1;
            let mut out = vec![0.0; len];
            let units = &mut rendered.units;
            let mut on_unit = |onset: &UnitOnset, voicing| keep(onset, voicing, units);
            if unchanged && same_as_last {
                engine.process_unchanged(&controls, &mut out, &mut on_unit);
            } else {
                engine.process_observed(&controls, &mut out, &mut on_unit);
            }
            same_as_last = true;
            rendered
                .samples
                .extend(out.iter().map(|sample| sample.to_bits()));
            done += len;
        }
        rendered.volumes.push(engine.volume_ml().to_bits());
        same_as_last = false;
        if index == 2 {
            engine.refill();
        }
    }
    let units = &mut rendered.units;
    engine.report_deferred_units(&mut |onset, voicing| keep(onset, voicing, units));
    rendered
}

#[test]
fn unchanged_blocks_give_the_samples_units_and_state_of_large_blocks() {
    let whole = render(&[4096], false);
    assert!(
        whole
            .samples
            .iter()
            .any(|&bits| f32::from_bits(bits).abs() == ModelConfig::default().ceiling as f32),
        "the gain must take the samples to the ceiling, so that the limiter works"
    );
    assert!(whole.units.len() > 20, "the pour must glug");
    for blocks in [&[1][..], &[16], &[37], &[64], &[16, 5, 64, 43, 100]] {
        let cut = render(blocks, true);
        let first_difference = whole
            .samples
            .iter()
            .zip(&cut.samples)
            .position(|(a, b)| a != b);
        assert_eq!(first_difference, None, "blocks of {blocks:?}: samples");
        assert_eq!(whole.units, cut.units, "blocks of {blocks:?}: units");
        assert_eq!(whole.volumes, cut.volumes, "blocks of {blocks:?}: V");
    }
}
