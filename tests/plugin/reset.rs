//! MODEL.md §8 in the plugin: activation, a transport start and a playhead jump reset the bottle
//! and re-seed the generator, so a bounce always starts from the same state; a note-on refills.
//! And the plugin renders the engine's samples exactly, whatever the host's block size.

use nice_plug::prelude::Plugin;

use crate::host::{cc, note_on, peak, Playhead, TestHost};
use crate::support::largest_step;
use sake_glug_engine::{Controls, Engine};
use sake_glug_plugin::FADE_S;

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
    engine.process(&Controls::constant(params.control_values()), &mut out);
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
    // The units that rang when play was pressed fade out over the first FADE_S; after it
    // both bounces are the offline render's samples.
    let fade = (48_000.0 * FADE_S) as usize;
    let offline = engine_render(&host, first.len());
    assert_eq!(first[fade..], second[fade..]);
    assert_eq!(
        first[fade..],
        offline[fade..],
        "a bounce equals the offline render"
    );
    assert_ne!(
        first[..fade],
        offline[..fade],
        "the old units ring into the fade"
    );
}

#[test]
fn a_bounce_from_silence_equals_the_offline_render_from_its_first_sample() {
    let mut host = pouring_host();
    let first = play(&mut host, 0, 60);
    assert_eq!(first, engine_render(&host, first.len()));
}

#[test]
fn a_transport_start_with_ringing_units_makes_no_click() {
    let mut host = pouring_host();
    // Pour live for a second with the transport stopped, then press play in mid-ring.
    let live = host.render_mono(48_000, 512);
    let usual = largest_step(&live);
    let last = *live.last().unwrap();
    assert!(last.abs() > 0.01, "units ring when play is pressed: {last}");
    let mut bounce = vec![last];
    bounce.extend(play(&mut host, 0, 4));
    let at_start = largest_step(&bounce[..(48_000.0 * FADE_S) as usize + 2]);
    println!("largest step: {at_start:.4} at the transport start, {usual:.4} while pouring");
    assert!(
        at_start <= usual,
        "a step of {at_start} at the start against {usual} while pouring"
    );
}

#[test]
fn the_device_keeps_its_tilt_across_a_transport_start() {
    let mut host = TestHost::new(48_000.0, 1);
    // The device tilts the bottle to 135° (14-bit: CC 16 = 96, CC 48 = 0) with the transport
    // stopped; the Tilt parameter stays at 0°.
    host.process(
        64,
        vec![cc(0, 0, 16, 96), cc(1, 0, 48, 0)],
        Playhead::default(),
    );
    let bounce = play(&mut host, 0, 100);
    assert!(
        peak(&bounce) > 0.05,
        "the bottle still pours after play is pressed"
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
    // After the jump the bounce restarts; the units that rang fade out over FADE_S.
    let fade = (48_000.0 * FADE_S) as usize;
    assert!(
        jumped[20 * 512 + fade..] == straight[fade..20 * 512],
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

#[test]
fn the_editor_is_redrawn_only_while_something_it_shows_changes() {
    let mut host = TestHost::new(RATE, 1);
    // Upright and silent: block after block, nothing the editor draws changes.
    host.render_mono(4096, 512);
    let idle = host.plugin.renderer().unwrap().visible();
    host.render_mono(512, 512);
    let still = host.plugin.renderer().unwrap().visible();
    assert!(!still.needs_redraw_after(idle), "{still:?} after {idle:?}");
    // Pouring: the bottle drains and the scope moves.
    host.set_text("tilt", "135");
    host.render_mono(512, 512);
    let pouring = host.plugin.renderer().unwrap().visible();
    assert!(pouring.needs_redraw_after(still));
    host.render_mono(512, 512);
    assert!(host
        .plugin
        .renderer()
        .unwrap()
        .visible()
        .needs_redraw_after(pouring));
}
