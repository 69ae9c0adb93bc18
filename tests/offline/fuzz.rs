//! Property-based fuzz tests for the offline renderer's outside data: scene files (TOML) and their
//! automation lanes, proptest's default of 256 cases a run. Property: never a panic, never a
//! hang, and either a valid scene or an error that names the fault (a scene key, or the line of
//! the file). The libFuzzer targets `scene_toml` and `automation_lanes` (fuzz/) search further
//! with coverage guidance.

use proptest::prelude::*;

use crate::support::fuzz::{self, any_number, toml_number};
use sake_glug_engine::config;
use sake_glug_engine::{Constant, Control, Lane, Quantity, Range};
use sake_glug_render::{Automation, Scene};

/// Every numeric key of a scene, the table it sits in, and the range of its numbers: the
/// controls' and constants' from the engine's tables, and the scene's own.
fn keys() -> Vec<(&'static str, &'static str, Range)> {
    let split = |quantity: &'static Quantity| match quantity.scene_key.split_once('.') {
        Some((table, key)) => (table, key, quantity.range),
        None => ("", quantity.scene_key, quantity.range),
    };
    let tables = Control::ALL
        .iter()
        .map(|control| split(control.quantity()))
        .chain(
            Constant::ALL
                .iter()
                .map(|constant| split(constant.quantity())),
        );
    let scene_own = [
        ("", "sample_rate", config::SAMPLE_RATE_HZ),
        ("", "duration_s", Range::new(0.0, 86_400.0, 1.0)),
        ("", "seed", Range::new(0.0, 1e19, 1.0)),
    ];
    tables.chain(scene_own).collect()
}

/// A number near a key's range: inside, at its edges, just outside, or anything at all.
fn number_near(range: Range) -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => (0.0f64..=1.0).prop_map(move |x| range.min + x * (range.max - range.min)),
        1 => prop::sample::select(vec![range.min, range.max, range.min - 1.0, range.max * 2.0]),
        2 => any_number(),
    ]
}

/// A value as a scene file might hold it: a number, a list of points, or something else.
fn value_text(range: Range) -> impl Strategy<Value = String> {
    let point = (any_number(), number_near(range))
        .prop_map(|(t, v)| format!("[{}, {}]", toml_number(t.abs() % 100.0), toml_number(v)));
    let raw_point = (any_number(), any_number())
        .prop_map(|(t, v)| format!("[{}, {}]", toml_number(t), toml_number(v)));
    prop_oneof![
        4 => number_near(range).prop_map(toml_number),
        3 => prop::collection::vec(point, 0..6).prop_map(|p| format!("[{}]", p.join(", "))),
        1 => prop::collection::vec(raw_point, 0..4).prop_map(|p| format!("[{}]", p.join(", "))),
        1 => prop::sample::select(vec![
            "\"steep\"".to_string(),
            "true".into(),
            "[[1.0]]".into(),
            "[[1.0, 2.0, 3.0]]".into(),
            "[1.0, 2.0]".into(),
            "{ a = 1 }".into(),
            "\"simulate\"".into(),
            "1979-05-27".into(),
            "0x10".into(),
            "-9223372036854775808".into(),
            "18446744073709551615".into(),
        ]),
    ]
}

/// A scene file: some keys with generated values, maybe an unknown key, maybe a drain mode,
/// maybe a deterministic flag, in any order of tables.
fn scene_text() -> impl Strategy<Value = String> {
    let keys = keys();
    let entry = (0..keys.len()).prop_flat_map(move |index| {
        let (table, key, range) = keys[index];
        value_text(range).prop_map(move |value| (table, key.to_string(), value))
    });
    let extra = prop::sample::select(vec![
        ("", "unknown_key".to_string(), "1.0".to_string()),
        ("output", "drain".into(), "\"follow\"".into()),
        ("output", "drain".into(), "\"sideways\"".into()),
        ("", "deterministic".into(), "true".into()),
        ("", "deterministic".into(), "3".into()),
        ("glug", "f3_hz".into(), "1.0".into()),
    ]);
    prop::collection::vec(prop_oneof![6 => entry, 1 => extra], 0..10).prop_map(|entries| {
        let mut tables: Vec<(&str, Vec<String>)> = Vec::new();
        for (table, key, value) in entries {
            let line = format!("{key} = {value}");
            match tables.iter_mut().find(|(name, _)| *name == table) {
                Some((_, lines)) => lines.push(line),
                None => tables.push((table, vec![line])),
            }
        }
        // Top-level keys first, as TOML requires them before any table.
        tables.sort_by_key(|(name, _)| !name.is_empty());
        let mut text = String::new();
        for (table, lines) in tables {
            if !table.is_empty() {
                text += &format!("[{table}]\n");
            }
            for line in lines {
                text += &line;
                text.push('\n');
            }
        }
        text
    })
}

/// What a valid scene must hold: every value in its range, point times finite and in order.
fn assert_valid(scene: &Scene) -> Result<(), TestCaseError> {
    let in_range = |automation: &Automation, range: Range| {
        automation.values().all(|v| range.contains(v))
            && match automation {
                Automation::Constant(_) => true,
                Automation::Points(points) => {
                    !points.is_empty()
                        && points.iter().all(|p| p.0.is_finite() && p.0 >= 0.0)
                        && points.windows(2).all(|w| w[0].0 <= w[1].0)
                }
            }
    };
    prop_assert!(config::SAMPLE_RATE_HZ.contains(scene.sample_rate as f64));
    prop_assert!(scene
        .duration_s
        .is_none_or(|d| d > 0.0 && d <= sake_glug_render::MAX_DURATION_S));
    prop_assert!(in_range(&scene.lanes.tilt_deg, Control::Tilt.range()));
    prop_assert!(in_range(&scene.lanes.viscosity, Control::Viscosity.range()));
    prop_assert!(in_range(&scene.lanes.fill_percent, Control::Fill.range()));
    prop_assert!(in_range(
        &scene.lanes.pour_time_s,
        Control::PourTime.range()
    ));
    prop_assert!(in_range(&scene.lanes.gain_db, Control::Gain.range()));
    prop_assert_eq!(scene.config, scene.config.sanitized());
    Ok(())
}

/// What an error must do: name the key at fault or the place in the file.
fn assert_names_its_fault(text: &str, message: &str) -> Result<(), TestCaseError> {
    let names_a_key = keys()
        .iter()
        .map(|k| k.1)
        .chain(["drain", "deterministic", "unknown_key", "f3_hz"])
        .any(|key| text.contains(key) && message.contains(key));
    let names_a_line = message.contains("line ");
    prop_assert!(
        names_a_key || names_a_line,
        "the error names no key and no line: {message}\nfor\n{text}"
    );
    Ok(())
}

#[test]
fn fuzz_scene_toml() {
    let text = prop_oneof![
        4 => scene_text(),
        // Anything at all: bytes made text, so the parser meets every character.
        1 => prop::collection::vec(any::<u8>(), 0..200)
            .prop_map(|bytes| String::from_utf8_lossy(&bytes).into_owned()),
        1 => "\\PC{0,120}",
    ];
    fuzz::run("scene TOML (Scene::parse)", text, |text| {
        match Scene::parse(&text) {
            Ok(scene) => assert_valid(&scene)?,
            Err(error) => {
                let message = error.to_string();
                prop_assert!(!message.is_empty());
                // Only toml's own layout breaks lines.
                let raw = |character: char| character.is_control() && character != '\n';
                prop_assert!(!message.contains(raw), "{message:?}");
                if text.contains('=') {
                    assert_names_its_fault(&text, &message)?;
                }
            }
        }
        Ok(())
    });
}

#[test]
fn fuzz_automation_lanes() {
    let points = prop::collection::vec((any_number(), number_near(Control::Tilt.range())), 0..8);
    let cut = (
        0u64..20_000,
        1usize..600,
        prop::sample::select(vec![1_000u32, 44_100, 768_000]),
    );
    fuzz::run(
        "automation lanes (tilt_deg points)",
        (points, cut),
        |(points, cut)| {
            let list: Vec<String> = points
                .iter()
                .map(|(t, v)| format!("[{}, {}]", toml_number(*t), toml_number(*v)))
                .collect();
            let text = format!(
                "sample_rate = {}\ntilt_deg = [{}]\n",
                cut.2,
                list.join(", ")
            );
            let scene = match Scene::parse(&text) {
                Ok(scene) => scene,
                Err(error) => {
                    let message = error.to_string();
                    prop_assert!(
                        message.contains("tilt_deg"),
                        "the error does not name tilt_deg: {message}"
                    );
                    return Ok(());
                }
            };
            assert_valid(&scene)?;
            // The lane the engine gets says what value_at says, sample by sample, and a constant
            // lane is constant indeed.
            let (first, len) = (cut.0, cut.1);
            let fs = scene.sample_rate as f64;
            let mut buffer = vec![0.0; len];
            let lane = scene.lanes.tilt_deg.lane(first, fs, &mut buffer);
            for index in 0..len {
                let expected = scene
                    .lanes
                    .tilt_deg
                    .value_at((first + index as u64) as f64 / fs);
                let got = lane.at(index);
                prop_assert!(
                    Control::Tilt.range().contains(got) && got == expected,
                    "sample {}: lane {} against {}",
                    first + index as u64,
                    got,
                    expected
                );
                if let Lane::Constant(value) = lane {
                    prop_assert_eq!(value, expected);
                }
            }
            Ok(())
        },
    );
}
