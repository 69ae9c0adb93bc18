//! The web binding's Rust core (crates/web/src/live.rs), natively: the renderer's samples in an
//! AudioWorklet's 128-frame blocks at 44.1 and 48 kHz, the units it tabulates, no allocation per
//! block under a counting allocator, and every bad argument refused with a message rather than a
//! panic (which would abort a WebAssembly instance). The same code built for WebAssembly is
//! tested through its JavaScript package by web/test/ (`cargo xtask test` runs both).

#[path = "../capi/allocations.rs"]
mod allocations;
#[path = "../support/mod.rs"]
mod support;

use sake_glug_engine::Control;
use sake_glug_render::Scene;
use sake_glug_web::{LiveGlug, MAX_BLOCK_FRAMES, UNIT_FIELDS};

use allocations::counted;
use support::offline;

fn control(param_id: &str) -> u32 {
    Control::ALL
        .iter()
        .position(|control| control.quantity().param_id == param_id)
        .unwrap() as u32
}

/// Blocks of `block` frames until the pour has settled, cut where the last unit fell silent:
/// the samples and every unit's numbers.
fn until_settled(live: &mut LiveGlug, block: usize) -> (Vec<f32>, Vec<Vec<f64>>) {
    let (mut samples, mut units) = (Vec::new(), Vec::new());
    loop {
        live.process(block as f64).unwrap();
        samples.extend_from_slice(live.output());
        units.extend(live.units().chunks(UNIT_FIELDS.len()).map(<[f64]>::to_vec));
        if live.state().settled == 1 {
            samples.truncate(live.state().active_until as usize);
            return (samples, units);
        }
        assert!(samples.len() < 48_000 * 600, "no end within 10 minutes");
    }
}

/// The built-in pour (the default scene) through the binding.
fn builtin_pour(live: &mut LiveGlug, sample_rate: f64, block: usize) -> (Vec<f32>, Vec<Vec<f64>>) {
    live.set(control("tilt"), 90.0).unwrap();
    live.ramp(control("tilt"), 135.0, (sample_rate / 2.0).floor())
        .unwrap();
    until_settled(live, block)
}

fn field(name: &str) -> usize {
    UNIT_FIELDS.iter().position(|&field| field == name).unwrap()
}

#[test]
fn blocks_of_128_frames_give_the_renderers_samples_and_units_at_44_1_and_48_khz() {
    for sample_rate in [44_100.0, 48_000.0] {
        let scene = Scene::default().with_sample_rate(sample_rate).unwrap();
        let (expected, expected_units) = offline(&scene);
        let mut live = LiveGlug::new(sample_rate, None, None).unwrap();
        let (samples, units) = builtin_pour(&mut live, sample_rate, 128);
        assert_eq!(samples.len(), expected.len(), "{sample_rate} Hz: length");
        let first = samples
            .iter()
            .zip(&expected)
            .position(|(a, b)| a.to_bits() != b.to_bits());
        assert_eq!(
            first, None,
            "{sample_rate} Hz: the first sample that differs"
        );
        assert_eq!(units.len(), expected_units.len(), "{sample_rate} Hz: units");
        for (unit, (onset, voicing)) in units.iter().zip(&expected_units) {
            assert_eq!(unit[field("sample")], onset.sample as f64);
            assert_eq!(unit[field("frame")], ((onset.sample + 1) % 128) as f64);
            assert_eq!(unit[field("fraction")], onset.fraction);
            assert_eq!(unit[field("volumeMl")], onset.volume_ml);
            assert_eq!(unit[field("viscosityC")], onset.viscosity);
            assert_eq!(unit[field("f1Hz")], onset.shape.frequency_hz[0]);
            assert_eq!(unit[field("b2PerS")], onset.shape.decay_per_s[1]);
            assert_eq!(
                unit[field("amplitude")],
                voicing.output_gain * onset.amplitude
            );
            assert_eq!(unit[field("audible")], f64::from(u8::from(voicing.audible)));
        }
        assert!(units.len() > 10, "{sample_rate} Hz: it glugs");
    }
}

#[test]
fn a_preset_and_a_model_text_play_as_the_renderer_plays_them() {
    let syrup = Scene::preset_toml(sake_glug_engine::Preset::find("syrup").unwrap());
    let (expected, _) = offline(&Scene::parse(&syrup).unwrap());
    let mut live = LiveGlug::preset(48_000.0, "syrup", None).unwrap();
    let (samples, _) = builtin_pour(&mut live, 48_000.0, 128);
    assert!(samples == expected, "syrup: the renderer's samples");

    let model = "viscosity_c = 0.5\n[glug]\nf1_hz = 95.0\n[bottle]\nheadspace_ml = 40.0\n";
    let model_file = sake_glug_model_file::ModelFile::parse("model", model).unwrap();
    let scene = Scene::parse_with_model(
        sake_glug_render::DEFAULT_SCENE,
        std::path::Path::new(""),
        &model_file,
    )
    .unwrap();
    let (expected, _) = offline(&scene);
    let mut live = LiveGlug::new(48_000.0, Some(model), None).unwrap();
    let (samples, _) = builtin_pour(&mut live, 48_000.0, 128);
    assert!(samples == expected, "a model text: the renderer's samples");
}

#[test]
fn a_block_and_the_control_calls_never_allocate() {
    let mut live = LiveGlug::new(48_000.0, None, None).unwrap();
    let (units, calls) = counted(|| {
        let mut units = 0;
        live.set(control("tilt"), 90.0).unwrap();
        live.ramp(control("tilt"), 150.0, 24_000.0).unwrap();
        for block in 0..2_000 {
            match block {
                400 => live.refill().unwrap(),
                900 => live.reset().unwrap(),
                901 => live.ramp(control("tilt"), 135.0, 100.0).unwrap(),
                1200 => live.set(control("visc"), 0.7).unwrap(),
                _ => {}
            }
            live.process(128.0).unwrap();
            units += live.unit_count();
        }
        units
    });
    assert!(units > 20, "the pour glugged ({units} units)");
    assert_eq!(calls, 0, "allocator calls while rendering blocks");
}

#[test]
fn bad_arguments_are_refused_with_a_message() {
    let refused = |result: Result<LiveGlug, sake_glug_web::LiveError>| match result {
        Ok(_) => panic!("accepted"),
        Err(error) => error.0,
    };
    let message = refused(LiveGlug::new(
        48_000.0,
        Some("[bottle]\ncapacity_ml = ["),
        None,
    ));
    assert!(message.starts_with("model text:"), "{message}");
    let message = refused(LiveGlug::new(
        48_000.0,
        Some("[bottle]\nwidth = 3.0\n"),
        None,
    ));
    assert!(message.contains("width"), "{message}");
    let message = refused(LiveGlug::new(f64::NAN, None, None));
    assert!(message.contains("sample_rate"), "{message}");
    let message = refused(LiveGlug::new(44_100.5, None, None));
    assert!(message.contains("whole number"), "{message}");
    let message = refused(LiveGlug::new(48_000.0, None, Some(-1.0)));
    assert!(message.contains("seed"), "{message}");
    let message = refused(LiveGlug::preset(48_000.0, "beer", None));
    assert!(
        message.contains("no preset `beer`") && message.contains("syrup"),
        "{message}"
    );

    let mut live = LiveGlug::new(48_000.0, None, None).unwrap();
    let message = live.set(control("tilt"), f64::NAN).unwrap_err().0;
    // Said to be no number, not merely out of range (which NaN also is).
    assert!(
        message.contains("Tilt (tilt)") && message.contains("NaN is not a finite number"),
        "{message}"
    );
    let message = live.set(control("visc"), 1.5).unwrap_err().0;
    assert!(message.contains("outside its range, 0 to 1"), "{message}");
    let message = live.ramp(control("tilt"), 135.0, 0.5).unwrap_err().0;
    assert!(message.contains("ramp's length"), "{message}");
    let message = live.set(9, 1.0).unwrap_err().0;
    assert!(message.contains("no control 9"), "{message}");
    for frames in [MAX_BLOCK_FRAMES as f64 + 1.0, 1e12, -1.0, 12.5, f64::NAN] {
        let message = live.process(frames).unwrap_err().0;
        assert!(message.contains("a block is a whole number"), "{message}");
    }
    let message = live.set_actuator(Some("[response]\n")).unwrap_err().0;
    assert!(message.starts_with("actuator profile:"), "{message}");
    let huge = "#".repeat(sake_glug_actuator::MAX_PROFILE_BYTES as usize + 1);
    let message = live.set_actuator(Some(&huge)).unwrap_err().0;
    assert!(message.contains("over the limit"), "{message}");
    // Refused calls changed nothing: the handle still plays the built-in pour.
    let (samples, _) = builtin_pour(&mut live, 48_000.0, MAX_BLOCK_FRAMES);
    assert!(samples == offline(&Scene::default()).0);
}

#[test]
fn a_full_queue_is_refused_until_a_block_takes_it() {
    let mut live = LiveGlug::new(48_000.0, None, None).unwrap();
    let mut queued = 0;
    while live.set(control("tilt"), 100.0).is_ok() {
        queued += 1;
    }
    assert_eq!(queued, sake_glug::SAKE_GLUG_MAX_QUEUED_CONTROLS);
    let message = live.refill().unwrap_err().0;
    assert!(message.contains("render a block first"), "{message}");
    live.process(1.0).unwrap();
    live.refill().unwrap();
}

#[test]
fn a_phones_gravity_is_the_bottles_tilt_as_the_plugin_reads_it() {
    use sake_glug_web::live::tilt_of;
    assert_eq!(tilt_of([0.0, 1.0, 0.0], "+y").unwrap(), Some(0.0));
    assert_eq!(tilt_of([0.0, 0.0, 9.81], "+y").unwrap(), Some(90.0));
    assert_eq!(tilt_of([0.0, -2.0, 0.0], "+y").unwrap(), Some(180.0));
    assert_eq!(tilt_of([0.0, 0.0, 0.0], "+y").unwrap(), None);
    let message = tilt_of([0.0, 1.0, 0.0], "up").unwrap_err().0;
    assert!(message.contains("is not an axis"), "{message}");
}

#[test]
fn an_actuator_profile_compensates_as_the_c_library_does() {
    let profile = sake_glug_actuator::SHIPPED
        .iter()
        .find(|(name, _)| *name == "lra")
        .map(|(_, text)| *text)
        .unwrap();
    let mut live = LiveGlug::new(48_000.0, None, None).unwrap();
    live.set_actuator(Some(profile)).unwrap();
    let (samples, _) = builtin_pour(&mut live, 48_000.0, 128);
    let scene = Scene {
        actuator: Some(
            sake_glug_actuator::ActuatorProfile::parse(profile)
                .unwrap()
                .response(),
        ),
        ..Scene::default()
    };
    let (expected, _) = offline(&scene);
    assert!(samples == expected, "the renderer's --actuator lra");
    assert!(
        samples != offline(&Scene::default()).0,
        "the profile changed the pour"
    );
}

#[test]
fn a_clip_of_units_is_refused_when_its_numbers_are_not_units() {
    use sake_glug_web::live::{clip, CLIP_UNIT_FIELDS};
    let unit = [0.1, 0.5, 0.33, 80.0, 300.0, 45.0, 40.0];
    assert_eq!(unit.len(), CLIP_UNIT_FIELDS.len());
    let rumble = clip("rumble", &unit, 0.5, "web", 1.0).unwrap();
    assert!(rumble.contains("\"frames\""), "{rumble}");
    let message = clip("rumble", &unit[..6], 0.5, "web", 1.0).unwrap_err().0;
    assert!(message.contains("7 numbers each"), "{message}");
    let message = clip("rumble", &[f64::NAN; 7], 0.5, "web", 1.0)
        .unwrap_err()
        .0;
    assert!(message.contains("not finite"), "{message}");
    let message = clip("ogg", &unit, 0.5, "web", 1.0).unwrap_err().0;
    assert!(message.contains("no clip format `ogg`"), "{message}");
    let message = clip("ahap", &unit, -1.0, "web", 1.0).unwrap_err().0;
    assert!(message.contains("finite number of seconds"), "{message}");
}
