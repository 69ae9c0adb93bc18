//! Parameters: stable IDs, ranges inside the engine's, text that round-trips (the procedure of
//! clap-validator's param-conversions test), and the engine receiving exactly the shown decimal.

use std::sync::Arc;

use crate::host::TestHost;
use nice_plug::prelude::*;
use sake_glug_engine::config;
use sake_glug_engine::config::CEILING_DB;
use sake_glug_engine::{Constant, Control};
use sake_glug_plugin::GlugParams;

const MAIN_IDS: [&str; 5] = ["tilt", "visc", "fill", "pour", "gain"];
const MODEL_IDS: [&str; 19] = [
    "f1", "f2", "b1", "b2", "pocket", "cap", "tjit", "fjit", "dsig", "headsp", "f1exp", "f2exp",
    "f1glide", "f2glide", "f1glms", "f2glms", "seed", "drain", "ceil",
];

fn param_map() -> Vec<(String, ParamPtr, String)> {
    let params: Arc<dyn Params> = Arc::new(GlugParams::default());
    // Keep the params alive for the pointers: leak one instance per test process.
    let params: &'static Arc<dyn Params> = Box::leak(Box::new(params));
    params.param_map()
}

#[test]
fn ids_are_stable_and_grouped() {
    let map = param_map();
    let ids: Vec<&str> = map.iter().map(|(id, _, _)| id.as_str()).collect();
    let expected: Vec<&str> = MAIN_IDS.iter().chain(MODEL_IDS.iter()).copied().collect();
    assert_eq!(ids, expected);
    for (id, _, group) in &map {
        let want = if MAIN_IDS.contains(&id.as_str()) {
            ""
        } else {
            "Model"
        };
        assert_eq!(group, want, "{id}");
    }
}

#[test]
fn every_value_text_value_round_trips() {
    for (id, ptr, _) in param_map() {
        for step in 0..=400 {
            let start = step as f32 / 400.0;
            unsafe {
                let text = ptr.normalized_value_to_string(start, true);
                let value = ptr
                    .string_to_normalized_value(&text)
                    .unwrap_or_else(|| panic!("{id}: {text:?} does not parse"));
                let again = ptr.normalized_value_to_string(value, true);
                assert_eq!(
                    text, again,
                    "{id}: {start} -> {text:?} -> {value} -> {again:?}"
                );
                let final_value = ptr.string_to_normalized_value(&again);
                assert_eq!(
                    final_value,
                    Some(value),
                    "{id}: second round trip of {again:?}"
                );
                // Without the unit too, as hosts may strip it.
                let bare = ptr.normalized_value_to_string(start, false);
                assert_eq!(
                    ptr.string_to_normalized_value(&bare),
                    Some(value),
                    "{id}: {bare:?}"
                );
            }
        }
    }
}

#[test]
fn ranges_lie_within_the_engine_ranges() {
    let quantities = Control::ALL
        .iter()
        .map(|control| control.quantity())
        .chain(Constant::ALL.iter().map(|constant| constant.quantity()));
    for quantity in quantities {
        let (min, max) = quantity.knob_bounds();
        let range = quantity.range;
        assert!(
            range.contains(min) && range.contains(max),
            "{}",
            quantity.name
        );
        assert!(range.contains(range.default), "{}", quantity.name);
    }
    let ceiling_min = 10f64.powf(CEILING_DB.range.min / 20.0);
    assert!(config::CEILING.contains(ceiling_min) && config::CEILING.contains(1.0));
}

#[test]
fn the_engine_gets_the_decimal_the_host_typed() {
    let host = TestHost::new(48_000.0, 2);
    for (id, text) in [
        ("pour", "4.2"),
        ("tilt", "97.35"),
        ("visc", "0.29"),
        ("fill", "87.3"),
        ("gain", "-6.1"),
    ] {
        host.set_text(id, text);
    }
    host.set_text("f1", "81.7");
    host.set_text("b2", "38.9");
    host.set_text("seed", "7");
    host.set_text("drain", "Follow");
    host.set_text("ceil", "-6.0");
    let params = host.plugin.glug_params();
    let values = params.control_values();
    assert_eq!(
        (
            values.pour_time_s,
            values.tilt_deg,
            values.viscosity,
            values.fill_percent
        ),
        (4.2, 97.35, 0.29, 87.3)
    );
    assert_eq!(params.control_values().gain_db, -6.1);
    let model = params.model_config();
    assert_eq!(model.frequency_hz[0], 81.7);
    assert_eq!(model.decay_per_s[1], 38.9);
    assert_eq!(model.seed, 7);
    assert_eq!(model.drain, sake_glug_engine::DrainMode::Follow);
    assert_eq!(model.ceiling, 10f64.powf(-6.0 / 20.0));
}
