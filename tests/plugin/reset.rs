//! MODEL.md §8 in the plugin: activation, a transport start and a playhead jump reset the bottle
//! and re-seed the generator, so a bounce always starts from the same state; a note-on refills.
//! And the plugin renders the engine's samples exactly, whatever the host's block size.

use nice_plug::prelude::Plugin;

use crate::host::{note_on, peak, Playhead, TestHost};
use sake_glug::engine::{Controls, Engine};

const RATE: f32 = 48_000.0;

fn pouring_host() -> TestHost {
    let host = TestHost::new(RATE, 2);
    host.set_text("tilt", "135");
    host.set_text("seed", "7");
    host.set_text("pour", "2");
    host
}

fn engine_render(host: &TestHost, total: usize) -> Vec<f32> {
    let params = host.plugin.glug_params();
    let mut engine = Engine::new(RATE as f64, params.model_config());
    let mut out = vec![0.0; total];
    engine.process(
        &Controls::constant(params.control_values(), params.gain_db()),
        &mut out,
    );
    out
}

#[test]
fn plugin_equals_the_engine_at_any_block_size() {
    let total = 48_000;
    let reference = {
        let mut host = pouring_host();
        host.plugin.reset();
        engine_render(&host, total)
    };
    assert!(peak(&reference) > 0.05);
    for block in [1, 32, 441, 512, 4096, 8192] {
        let mut host = pouring_host();
        host.plugin.reset();
        assert_eq!(host.render_mono(total, block), reference, "block {block}");
    }
}

/// Plays `blocks` blocks of 512 from `start`, with the transport running.
fn play(host: &mut TestHost, start: i64, blocks: usize) -> Vec<f32> {
    let mut out = Vec::new();
    for index in 0..blocks {
        let playhead = Playhead {
            playing: true,
            position: Some(start + 512 * index as i64),
        };
        out.extend(host.process(512, Vec::new(), playhead).swap_remove(0));
    }
    out
}

#[test]
fn every_transport_start_begins_the_same_bounce() {
    let mut host = pouring_host();
    // Sound while stopped (live play) drains the bottle and advances the generator...
    let live = host.render_mono(48_000, 512);
    assert!(peak(&live) > 0.0);
    // ...but pressing play starts from a full bottle and a fresh seed, every time.
    let first = play(&mut host, 0, 60);
    let stopped = host.process(512, Vec::new(), Playhead::default());
    assert!(stopped[0].iter().all(|s| s.is_finite()));
    let second = play(&mut host, 0, 60);
    assert_eq!(first, second);
    assert_eq!(
        first,
        engine_render(&host, first.len()),
        "a bounce equals the offline render"
    );
}

#[test]
fn a_playhead_jump_resets_and_continuous_play_does_not() {
    let mut host = pouring_host();
    let straight = play(&mut host, 0, 40);
    let mut host = pouring_host();
    let mut jumped = play(&mut host, 0, 20);
    // A locate while playing: the bottle starts again from full.
    jumped.extend(play(&mut host, 96_000, 20));
    assert_eq!(&jumped[..20 * 512], &straight[..20 * 512]);
    assert_eq!(
        &jumped[20 * 512..],
        &straight[..20 * 512],
        "after the jump the bounce restarts"
    );
}

#[test]
fn note_on_refills_without_reseeding_and_fill_drain_is_visible() {
    let mut host = pouring_host();
    host.render_mono(48_000 * 3, 4096);
    let drained = host
        .plugin
        .renderer()
        .expect("activated")
        .engine()
        .volume_ml();
    assert!(
        drained < 150.0,
        "three seconds of a two-second pour drain the bottle: {drained} ml"
    );
    let after_note = host.process(256, vec![note_on(100)], Playhead::default());
    let volume = host
        .plugin
        .renderer()
        .expect("activated")
        .engine()
        .volume_ml();
    assert!(volume > 290.0, "a note-on refills the bottle: {volume} ml");
    assert!(after_note[0].iter().all(|s| s.is_finite()));
    // A refill is not a reset: the glugs after it differ from a fresh start's.
    let refilled = host.render_mono(24_000, 512);
    let mut fresh = pouring_host();
    assert_ne!(refilled, fresh.render_mono(24_000, 512));
}
