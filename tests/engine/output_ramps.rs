//! MODEL.md §6: output gain and ceiling reach a new value along a 10 ms ramp, so that moving
//! them while glugs ring does not click, and the ramp depends only on the targets sample by
//! sample: the same samples at every block size, through silence as well.

use crate::support::{error_db, largest_step, reference_render, render_in_blocks};
use sake_glug_engine::config::OUTPUT_RAMP_S;
use sake_glug_engine::{ControlValues, Controls, Engine, Lane, ModelConfig};
use sake_glug_render::Scene;

const RATE: f64 = 48_000.0;
/// Where the gain or the ceiling moves: a unit of the pour below rings there.
const MOVE_AT: usize = 48_200;
const LEN: usize = 72_000;

fn ramp_len() -> usize {
    (RATE * OUTPUT_RAMP_S).round() as usize
}

fn pouring() -> ControlValues {
    ControlValues {
        tilt_deg: 135.0,
        ..ControlValues::default()
    }
}

/// The pour under `gain_db` (one value per sample) in blocks of `block`, with the ceiling
/// `ceilings.0` until `ceilings.1` takes over at `MOVE_AT`.
fn render(gain_db: &[f64], ceilings: (f64, f64), block: usize) -> Vec<f32> {
    render_moving_at(MOVE_AT, gain_db, ceilings, block)
}

/// [`render`] with the ceiling moving at `move_at`.
fn render_moving_at(
    move_at: usize,
    gain_db: &[f64],
    ceilings: (f64, f64),
    block: usize,
) -> Vec<f32> {
    let config = |ceiling| ModelConfig {
        ceiling,
        ..ModelConfig::default()
    };
    let mut engine = Engine::new(RATE, config(ceilings.0));
    let mut out = vec![0.0f32; gain_db.len()];
    let mut done = 0;
    while done < out.len() {
        let mut len = block.min(out.len() - done);
        if done < move_at {
            len = len.min(move_at - done);
        } else if done == move_at {
            engine.set_config(config(ceilings.1));
        }
        let controls = Controls {
            gain_db: Lane::Samples(&gain_db[done..done + len]),
            ..Controls::constant(ControlValues {
                gain_db: 0.0,
                ..pouring()
            })
        };
        engine.process(&controls, &mut out[done..done + len]);
        done += len;
    }
    out
}

fn gain_step(from_db: f64, to_db: f64) -> Vec<f64> {
    (0..LEN)
        .map(|n| if n < MOVE_AT { from_db } else { to_db })
        .collect()
}

#[test]
fn a_gain_jump_while_glugs_ring_ramps_without_a_click() {
    let ramp = ramp_len();
    let jumped = render(&gain_step(-18.0, 0.0), (1.0, 1.0), 512);
    let quiet = render(&gain_step(-18.0, -18.0), (1.0, 1.0), 512);
    let loud = render(&gain_step(0.0, 0.0), (1.0, 1.0), 512);
    let ringing = jumped[MOVE_AT - 100..MOVE_AT]
        .iter()
        .fold(0.0f32, |peak, y| peak.max(y.abs()));
    assert!(ringing > 0.01, "nothing rings at the jump ({ringing})");
    // The synthesis does not depend on the gain: before the jump the quiet render, once the
    // ramp is over the loud one, sample for sample.
    assert_eq!(jumped[..MOVE_AT], quiet[..MOVE_AT]);
    assert_eq!(jumped[MOVE_AT + ramp - 1..], loud[MOVE_AT + ramp - 1..]);
    assert_ne!(jumped[MOVE_AT], loud[MOVE_AT], "the gain jumped at once");
    // No click: across the ramp no step is larger than the loud signal's usual largest step.
    let across = largest_step(&jumped[MOVE_AT - 1..MOVE_AT + ramp + 1]);
    let usual = largest_step(&loud);
    assert!(across <= usual, "a step of {across} against {usual}");
}

#[test]
fn a_ceiling_lowered_while_glugs_ring_ramps_down_to_it() {
    let ramp = ramp_len();
    let low = 0.01;
    let gain = gain_step(0.0, 0.0);
    let unlimited = render(&gain, (1.0, 1.0), 512);
    // The ceiling comes down at the loudest sample of a ringing glug: cut there, it would click.
    let move_at = (MOVE_AT..MOVE_AT + 1_000)
        .max_by(|a, b| unlimited[*a].abs().total_cmp(&unlimited[*b].abs()))
        .unwrap();
    assert!(
        unlimited[move_at].abs() > 5.0 * low as f32,
        "the ceiling would not bite"
    );
    let lowered = render_moving_at(move_at, &gain, (1.0, low), 512);
    assert_eq!(lowered[..move_at], unlimited[..move_at]);
    // Once the ramp is over, the new ceiling holds...
    assert!(lowered[move_at + ramp - 1..]
        .iter()
        .all(|y| y.abs() <= low as f32));
    // ...and it came down without a click: no step larger than the signal's usual ones, those of
    // the glug before (open) and of the pour after (limited).
    let across = largest_step(&lowered[move_at - 1..move_at + ramp + 1]);
    let usual = largest_step(&lowered[move_at - 4_800..move_at])
        .max(largest_step(&lowered[move_at + ramp..]));
    assert!(across <= usual, "a step of {across} against {usual}");
}

#[test]
fn the_ramps_give_the_same_samples_at_every_block_size() {
    // Jumps of gain while pouring, while silent (before the first glug) and mid-ramp, and a
    // ceiling that moves: the ramp runs through silence and across blocks the same way.
    let gain_db: Vec<f64> = (0..LEN)
        .map(|n| match n {
            0..=99 => 6.0,
            100..=3_999 => -30.0,
            4_000..=4_099 => 0.0,
            4_100..=MOVE_AT => -3.0 + n as f64 * 1e-4,
            _ => -12.0,
        })
        .collect();
    let reference = render(&gain_db, (1.0, 0.3), 1);
    assert!(reference.iter().any(|y| *y != 0.0));
    for block in [64, 511, 4096] {
        assert_eq!(
            render(&gain_db, (1.0, 0.3), block),
            reference,
            "block {block}"
        );
    }
}

#[test]
fn a_reset_starts_at_the_gain_and_ceiling_asked_for() {
    // A bottle that glugs within the ramp's first milliseconds: a ramp left over from before
    // the reset would show in them.
    let early = |ceiling| ModelConfig {
        ceiling,
        pocket_ml: 0.01,
        ..ModelConfig::default()
    };
    let fast_pour = ControlValues {
        pour_time_s: 0.05,
        ..pouring()
    };
    let mut fresh = Engine::new(RATE, early(0.05));
    let mut expected = vec![0.0f32; 4 * ramp_len()];
    fresh.process(
        &Controls::constant(ControlValues {
            gain_db: -3.0,
            ..fast_pour
        }),
        &mut expected,
    );
    assert!(expected[..ramp_len()].iter().any(|y| *y != 0.0));
    assert_eq!(fresh.gain_now(), 10f64.powf(-3.0 / 20.0));
    assert_eq!(fresh.ceiling_now(), 0.05);

    let mut reused = Engine::new(RATE, early(1.0));
    let mut before = vec![0.0f32; 48_000];
    reused.process(
        &Controls::constant(ControlValues {
            gain_db: 12.0,
            ..fast_pour
        }),
        &mut before,
    );
    reused.set_config(early(0.05));
    reused.reset();
    let mut after = vec![0.0f32; expected.len()];
    reused.process(
        &Controls::constant(ControlValues {
            gain_db: -3.0,
            ..fast_pour
        }),
        &mut after,
    );
    assert_eq!(after, expected);
}

#[test]
fn gain_steps_match_the_reference() {
    // The reference follows MODEL.md §6's ramp with its own copy of the rule.
    let scene = Scene::parse(
        r#"
        seed = 9
        duration_s = 3.0
        tilt_deg = 135.0
        [output]
        gain_db = [[0.0, -20.0], [1.0, -20.0], [1.0, 6.0], [1.004, 6.0], [1.004, -40.0],
                   [2.0, -40.0], [2.0, 0.0]]
        "#,
    )
    .unwrap();
    let len = 3 * 48_000;
    let fast = render_in_blocks(&scene, len, &[333, 4096, 7]);
    let error = error_db(&fast, &reference_render(&scene, len));
    assert!(error < -100.0, "{error:.1} dB");
}
