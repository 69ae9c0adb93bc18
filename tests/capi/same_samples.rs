//! The C library gives the offline renderer's samples, bit for bit: the built-in pour at audio
//! and haptic rates and at any block size, steps and ramps as a scene's lanes, a model file's
//! text as `--model`, a refill as a take's, a reset as a new handle; and the units it reports are
//! the renderer's.

use sake_glug::*;
use sake_glug_engine::{Engine, UnitOnset, Voicing, PRESETS};
use sake_glug_model_file::ModelFile;
use sake_glug_render::{Scene, DEFAULT_SCENE};

use super::{builtin_pour, Live};
use crate::support::offline;

fn assert_same_samples(live: &[f32], offline: &[f32], what: &str) {
    assert_eq!(live.len(), offline.len(), "{what}: length");
    let first_difference = live
        .iter()
        .zip(offline)
        .position(|(a, b)| a.to_bits() != b.to_bits());
    assert_eq!(first_difference, None, "{what}: first sample that differs");
    assert!(offline.iter().any(|&y| y != 0.0), "{what}: it glugs");
}

fn assert_same_units(live: &[SakeGlugUnit], offline: &[(UnitOnset, Voicing)], what: &str) {
    assert_eq!(live.len(), offline.len(), "{what}: units");
    for (unit, (onset, voicing)) in live.iter().zip(offline) {
        assert_eq!(unit.sample, onset.sample, "{what}");
        assert_eq!(unit.fraction.to_bits(), onset.fraction.to_bits(), "{what}");
        assert_eq!(
            unit.volume_ml.to_bits(),
            onset.volume_ml.to_bits(),
            "{what}"
        );
        assert_eq!(unit.f1_hz, onset.shape.frequency_hz[0], "{what}");
        assert_eq!(unit.b2_per_s, onset.shape.decay_per_s[1], "{what}");
        assert_eq!(unit.viscosity_c, onset.viscosity, "{what}");
        assert_eq!(
            unit.amplitude,
            voicing.output_gain * onset.amplitude,
            "{what}"
        );
        assert_eq!(unit.audible, u32::from(voicing.audible), "{what}");
    }
}

#[test]
fn the_builtin_pour_is_the_renderers_at_audio_and_haptic_rates() {
    // 2 kHz: a controller's PCM haptics; 8 kHz: a phone's haptic channel; then audio rates.
    for sample_rate in [2_000u32, 8_000, 44_100, 48_000, 96_000] {
        let scene = Scene::default()
            .with_sample_rate(sample_rate as f64)
            .unwrap();
        let (expected, expected_units) = offline(&scene);
        let (samples, units) = builtin_pour(&Live::paper(sample_rate as f64), sample_rate, 4096);
        let what = format!("{sample_rate} Hz");
        assert_same_samples(&samples, &expected, &what);
        assert_same_units(&units, &expected_units, &what);
    }
}

#[test]
fn calls_of_1_16_64_and_4096_frames_give_the_same_samples() {
    let (expected, expected_units) = offline(&Scene::default());
    for block in [1, 16, 64, 4096, 333] {
        let (samples, units) = builtin_pour(&Live::paper(48_000.0), 48_000, block);
        let what = format!("calls of {block} frames");
        assert_same_samples(&samples, &expected, &what);
        assert_same_units(&units, &expected_units, &what);
        // Each unit is reported by the call it is first heard in, at its frame there.
        for unit in &units {
            assert_eq!(
                unit.frame as u64,
                (unit.sample + 1) % block as u64,
                "{what}"
            );
        }
    }
}

/// Renders `frames` frames in uneven calls.
fn run(live: &Live, frames: usize, samples: &mut Vec<f32>) {
    let mut done = 0;
    for call in [1usize, 700, 64, 4095].iter().cycle() {
        let len = (*call).min(frames - done);
        let mut block = vec![0.0; len];
        live.process(&mut block);
        samples.extend_from_slice(&block);
        done += len;
        if done == frames {
            return;
        }
    }
}

#[test]
fn steps_and_ramps_are_the_lanes_of_a_scene() {
    // At 0.25 s tilt and gain ramp, at 0.75 s viscosity steps and tilt ramps down; each ramp
    // starts from the value its control has then (a finished ramp's target).
    let scene = Scene::parse(
        "tilt_deg = [[0.0, 100.0], [0.25, 100.0], [0.45, 150.0], [0.75, 150.0], [1.75, 40.0]]\n\
         viscosity_c = [[0.0, 0.5], [0.75, 0.5], [0.75, 0.8]]\n\
         output.gain_db = [[0.0, -6.0], [0.25, -6.0], [0.35, -12.0]]\n\
         pour_time_s = 3.0\n",
    )
    .unwrap();
    let (expected, expected_units) = offline(&scene);
    let live = Live::paper(48_000.0);
    live.set(SakeGlugControl::Tilt, 100.0);
    live.set(SakeGlugControl::Viscosity, 0.5);
    live.set(SakeGlugControl::PourTime, 3.0);
    let mut samples = Vec::new();
    run(&live, 12_000, &mut samples);
    live.ramp(SakeGlugControl::Tilt, 150.0, 9_600);
    live.ramp(SakeGlugControl::Gain, -12.0, 4_800);
    run(&live, 24_000, &mut samples);
    live.set(SakeGlugControl::Viscosity, 0.8);
    live.ramp(SakeGlugControl::Tilt, 40.0, 48_000);
    let (rest, _) = live.until_settled(512);
    samples.extend(rest);
    samples.truncate(live.state().active_until as usize);
    assert_same_samples(&samples, &expected, "steps and ramps");
    assert!(expected_units.len() > 10);
}

/// Renders `frames` frames in calls of `block` frames (the last one shorter).
fn run_in_calls_of(live: &Live, block: usize, frames: usize, samples: &mut Vec<f32>) {
    let mut buffer = vec![0.0; block];
    let mut done = 0;
    while done < frames {
        let len = block.min(frames - done);
        live.process(&mut buffer[..len]);
        samples.extend_from_slice(&buffer[..len]);
        done += len;
    }
}

#[test]
fn a_change_after_many_unchanged_small_calls_acts_at_its_sample() {
    // Thousands of 16-frame calls under the same controls (pouring, then the emptied bottle's
    // silence), each change arriving in the middle of a grid period (12 000 = 187.5 × 64).
    let scene = Scene::parse(
        "pour_time_s = 1.0
         tilt_deg = [[0.0, 135.0], [0.25, 135.0], [0.25, 100.0], [0.5, 100.0], [0.5, 150.0]]
         output.gain_db = [[0.0, -6.0], [0.25, -6.0], [0.25, -12.0]]
         fill_percent = [[0.0, 100.0], [3.25, 100.0], [3.25, 40.0]]
",
    )
    .unwrap();
    let (expected, expected_units) = offline(&scene);
    let live = Live::paper(48_000.0);
    live.set(SakeGlugControl::PourTime, 1.0);
    live.set(SakeGlugControl::Tilt, 135.0);
    let mut samples = Vec::new();
    run_in_calls_of(&live, 16, 12_000, &mut samples);
    live.set(SakeGlugControl::Tilt, 100.0);
    live.set(SakeGlugControl::Gain, -12.0);
    run_in_calls_of(&live, 16, 12_000, &mut samples);
    live.set(SakeGlugControl::Tilt, 150.0);
    run_in_calls_of(&live, 16, 132_000, &mut samples);
    assert_eq!(
        live.state().settled,
        1,
        "the bottle emptied before the refill"
    );
    live.set(SakeGlugControl::Fill, 40.0);
    let (rest, _) = live.until_settled(16);
    samples.extend(rest);
    samples.truncate(live.state().active_until as usize);
    assert_same_samples(&samples, &expected, "changes after unchanged calls");
    assert!(expected_units.len() > 10);
}

#[test]
fn a_ramp_to_its_own_value_and_a_ramp_of_no_samples_are_steps() {
    let (expected, _) = offline(&Scene::parse("tilt_deg = 135.0\n").unwrap());
    let live = Live::paper(48_000.0);
    live.ramp(SakeGlugControl::Tilt, 135.0, 0);
    live.ramp(SakeGlugControl::Gain, -6.0, 10_000);
    let (samples, _) = live.until_settled(1000);
    assert_same_samples(&samples, &expected, "steps");
}

#[test]
fn a_model_files_text_plays_as_the_renderers_model() {
    for name in ["fitted", "falling-pitch", "gliding"] {
        a_model_plays_as_the_renderers(name);
    }
}

/// The model `tests/fixtures/models/<name>.toml` through the C library and the renderer.
fn a_model_plays_as_the_renderers(name: &str) {
    let text = std::fs::read_to_string(format!("tests/fixtures/models/{name}.toml")).unwrap();
    let model = ModelFile::parse(name, &text).unwrap();
    let seed = 77;
    let scene_text = format!("seed = {seed}\n{DEFAULT_SCENE}");
    let scene = Scene::parse_with_model(&scene_text, std::path::Path::new(""), &model).unwrap();
    let (expected, expected_units) = offline(&scene);
    let live = Live::create(48_000.0, Some(&text), seed).unwrap();
    let (samples, units) = builtin_pour(&live, 48_000, 4096);
    assert_same_samples(&samples, &expected, name);
    assert_same_units(&units, &expected_units, name);
    // The seed matters: another gives other glugs.
    let other = Live::create(48_000.0, Some(&text), seed + 1).unwrap();
    assert_ne!(builtin_pour(&other, 48_000, 4096).0, expected);
}

#[test]
fn every_shipped_preset_plays_as_the_renderers_file_of_it() {
    // The preset files hold the built-in pour's tilt; the handle is given it by calls.
    for preset in &PRESETS {
        let seed = 5;
        let file = std::fs::read_to_string(format!("presets/{}.toml", preset.id)).unwrap();
        let scene = Scene::parse(&format!("seed = {seed}\n{file}")).unwrap();
        let (expected, expected_units) = offline(&scene);
        let live = Live::preset(48_000.0, preset.id, seed).unwrap();
        let (samples, units) = builtin_pour(&live, 48_000, 4096);
        assert_same_samples(&samples, &expected, preset.id);
        assert_same_units(&units, &expected_units, preset.id);
    }
}

#[test]
fn a_refill_acts_at_the_first_sample_of_the_next_call_as_a_takes_does() {
    // The renderer acts on a take's refill before the sample it is due at.
    let scene = Scene::parse("tilt_deg = 135.0\nduration_s = 8.0\n").unwrap();
    let refill_at = 150_000u64;
    let mut engine = Engine::new(48_000.0, scene.config);
    let mut lanes = sake_glug_render::LaneBuffers::default();
    let mut expected = vec![0.0f32; 8 * 48_000];
    for (index, block) in expected.chunks_mut(1000).enumerate() {
        let position = index as u64 * 1000;
        if position == refill_at {
            engine.refill();
        }
        let controls = scene.controls(position, &mut lanes, block.len());
        engine.process(&controls, block);
    }
    let live = Live::paper(48_000.0);
    live.set(SakeGlugControl::Tilt, 135.0);
    let mut samples = Vec::new();
    run(&live, refill_at as usize, &mut samples);
    assert_eq!(unsafe { sake_glug_refill(live.raw()) }, SakeGlugStatus::Ok);
    run(&live, 8 * 48_000 - refill_at as usize, &mut samples);
    assert_same_samples(&samples, &expected, "a refill");
}

#[test]
fn a_reset_starts_the_pour_again_as_a_new_handle() {
    let live = Live::paper(48_000.0);
    let (first, _) = builtin_pour(&live, 48_000, 4096);
    // Mid-way through a second pour's ramp, a reset; the ramp stops where it was.
    live.ramp(SakeGlugControl::Tilt, 170.0, 48_000);
    let mut ignored = vec![0.0; 5000];
    live.process(&mut ignored);
    assert_eq!(unsafe { sake_glug_reset(live.raw()) }, SakeGlugStatus::Ok);
    let (again, _) = builtin_pour(&live, 48_000, 4096);
    assert_same_samples(&again, &first, "after a reset");
}

#[test]
fn interleaved_channels_each_hold_the_mono_signal() {
    let (mono, _) = builtin_pour(&Live::paper(48_000.0), 48_000, 4096);
    let live = Live::paper(48_000.0);
    live.set(SakeGlugControl::Tilt, 90.0);
    live.ramp(SakeGlugControl::Tilt, 135.0, 24_000);
    let channels = 3;
    let mut frames = vec![0.0f32; 1000 * channels];
    let mut interleaved = Vec::new();
    while interleaved.len() < mono.len() * channels {
        let status = unsafe {
            sake_glug_process_interleaved(live.raw(), frames.as_mut_ptr(), 1000, channels)
        };
        assert_eq!(status, SakeGlugStatus::Ok);
        interleaved.extend_from_slice(&frames);
    }
    for (index, &sample) in mono.iter().enumerate() {
        for channel in 0..channels {
            assert_eq!(
                interleaved[index * channels + channel].to_bits(),
                sample.to_bits()
            );
        }
    }
}

#[test]
fn the_state_is_the_engines() {
    let live = Live::paper(48_000.0);
    live.set(SakeGlugControl::Tilt, 135.0);
    let mut block = vec![0.0; 48_000];
    live.process(&mut block);
    let state = live.state();
    let mut engine = Engine::new(48_000.0, Default::default());
    let mut lanes = sake_glug_render::LaneBuffers::default();
    let controls = Scene::parse("tilt_deg = 135.0")
        .unwrap()
        .controls(0, &mut lanes, 48_000);
    engine.process(&controls, &mut block);
    assert_eq!(state.position, 48_000);
    assert_eq!(state.volume_ml, engine.volume_ml());
    assert_eq!(
        state.outflow_ml_per_s,
        engine.last_outflow().amount_ml * 48_000.0
    );
    assert_eq!(state.submerged, u32::from(engine.last_outflow().submerged));
    assert_eq!(state.tilt_deg, 135.0);
    assert_eq!(state.settled, 0);
    assert!(state.outflow_ml_per_s > 0.0 && state.volume_ml < 300.0);
}

#[test]
fn a_ramps_every_value_is_its_two_point_lanes() {
    // The tilt of each sample, as the state reports it after a call of one frame, against the
    // scene's lane with the ramp's two points, bit for bit: ramps that start anywhere, last any
    // number of samples and go either way, at rates whose sample times are inexact.
    for (sample_rate, start, samples, from, to) in [
        (48_000u32, 0u64, 24_000u64, 90.0, 135.0),
        (44_100, 12_345, 7_777, 17.3, 151.9),
        (2_000, 333, 1_001, 170.0, 0.1),
        (96_000, 5, 3, 45.0, 45.5),
    ] {
        let fs = sample_rate as f64;
        let (t0, t1) = (start as f64 / fs, (start + samples) as f64 / fs);
        let scene = Scene::parse(&format!(
            "sample_rate = {sample_rate}\ntilt_deg = [[{t0:?}, {from:?}], [{t1:?}, {to:?}]]\n"
        ))
        .unwrap();
        let live = Live::paper(fs);
        live.set(SakeGlugControl::Tilt, from);
        let mut ignored = vec![0.0f32; start as usize];
        if start > 0 {
            live.process(&mut ignored);
        }
        live.ramp(SakeGlugControl::Tilt, to, samples);
        let mut one = [0.0f32];
        for sample in start..start + samples + 3 {
            live.process(&mut one);
            let expected = scene.values_at(sample).sanitized().tilt_deg;
            let tilt = live.state().tilt_deg;
            assert_eq!(
                tilt.to_bits(),
                expected.to_bits(),
                "{sample_rate} Hz, sample {sample}"
            );
        }
    }
}

#[test]
fn an_actuator_profile_plays_as_the_renderers_actuator() {
    let text = std::fs::read_to_string("actuators/haptuator-mark2.toml").unwrap();
    let profile = sake_glug_actuator::ActuatorProfile::parse(&text).unwrap();
    let scene = Scene {
        actuator: Some(profile.response()),
        ..Scene::default()
    };
    let (expected, expected_units) = offline(&scene);
    let live = Live::paper(48_000.0);
    let text = std::ffi::CString::new(text).unwrap();
    assert_eq!(
        unsafe { sake_glug::sake_glug_set_actuator(live.raw(), text.as_ptr()) },
        SakeGlugStatus::Ok
    );
    let (samples, units) = builtin_pour(&live, 48_000, 333);
    assert_same_samples(&samples, &expected, "haptuator-mark2");
    assert_same_units(&units, &expected_units, "haptuator-mark2");
    // The compensation changed the samples; NULL takes it off again (from the next call on).
    assert_ne!(samples, offline(&Scene::default()).0);
    let bad = std::ffi::CString::new(
        "name = \"x\"\nresponse = [[2.0, 0.0]]\nband_hz = [2.0, 3.0]\nmax_amplitude = 1.0\n\
         sample_rate_hz = 48000\n",
    )
    .unwrap();
    assert_eq!(
        unsafe { sake_glug::sake_glug_set_actuator(live.raw(), bad.as_ptr()) },
        SakeGlugStatus::InvalidProfile
    );
    let message = super::last_error();
    assert!(message.contains("`response`"), "{message}");
    let plain = Live::paper(48_000.0);
    assert_eq!(
        unsafe { sake_glug::sake_glug_set_actuator(plain.raw(), std::ptr::null()) },
        SakeGlugStatus::Ok
    );
    assert_eq!(
        builtin_pour(&plain, 48_000, 4096).0,
        offline(&Scene::default()).0
    );
}
