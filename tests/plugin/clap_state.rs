//! The plugin's saved state through nice-plug's real state path: the CLAP entry point, the
//! plugin factory and the `clap.state` extension, exactly as a host calls them. A state saved
//! by an older version (a fixture) loads with the same parameter values and is migrated.

use std::path::Path;

use serde_json::Value;

use crate::clap_host::ClapInstance;
use sake_glug_engine::ADDED_RULES;

/// The JSON inside saved bytes (the CLAP wrapper prefixes its length).
fn json(bytes: &[u8]) -> Value {
    serde_json::from_slice(&bytes[8..]).expect("the state is JSON")
}

fn fixture(name: &str) -> Vec<u8> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/state")
        .join(name);
    std::fs::read(&path).unwrap_or_else(|error| panic!("{}: {error}", path.display()))
}

#[test]
fn state_saved_to_bytes_loads_from_those_bytes() {
    let source = ClapInstance::new();
    assert!(source.load(&fixture("v0-session.state")));
    let saved = source.save();
    let target = ClapInstance::new();
    assert_ne!(
        json(&target.save()),
        json(&saved),
        "the test must change the state"
    );
    assert!(target.load(&saved));
    assert_eq!(
        target.save(),
        saved,
        "save, load, save gives the same bytes"
    );
}

#[test]
fn a_state_saved_before_state_versions_loads_with_the_same_values() {
    let old = fixture("v0-session.state");
    let old_json = json(&old);
    assert!(
        old_json["fields"].get("state_version").is_none(),
        "a version-0 fixture"
    );
    let instance = ClapInstance::new();
    assert!(instance.load(&old));
    let now = json(&instance.save());
    let (now_params, old_params) = (
        now["params"].as_object().unwrap(),
        old_json["params"].as_object().unwrap(),
    );
    for (id, value) in old_params {
        assert_eq!(&now_params[id], value, "parameter {id}");
    }
    // The parameters added since (the headspace law and the glide, MODEL.md §5.1, §5.2) load
    // at their defaults.
    let added: Vec<&String> = now_params
        .keys()
        .filter(|id| !old_params.contains_key(*id))
        .collect();
    let law: Vec<&str> = ADDED_RULES
        .iter()
        .map(|constant| constant.quantity().param_id)
        .collect();
    assert_eq!(added.len(), law.len(), "{added:?}");
    for constant in ADDED_RULES {
        let id = constant.quantity().param_id;
        assert_eq!(
            now_params[id]["f32"].as_f64(),
            Some(constant.range().default),
            "{id}"
        );
    }
    for (field, value) in old_json["fields"].as_object().unwrap() {
        assert_eq!(&now["fields"][field], value, "field {field}");
    }
    let version: u8 = serde_json::from_str(now["fields"]["state_version"].as_str().unwrap())
        .expect("the version is saved");
    assert_eq!(version, sake_glug_plugin::STATE_VERSION);
}

#[test]
fn bytes_that_are_no_state_are_refused_without_a_panic() {
    let instance = ClapInstance::new();
    let before = instance.save();
    for bytes in [
        &b""[..],
        &[0xff; 8][..],
        &[3, 0, 0, 0, 0, 0, 0, 0, b'{', b'x', b'}'][..],
    ] {
        assert!(!instance.load(bytes), "{bytes:?} loaded");
    }
    assert_eq!(instance.save(), before, "a refused state changes nothing");
}

#[test]
fn the_fixture_was_saved_by_the_plugin_itself() {
    // Its text is what the CLAP wrapper writes: a little-endian length, then JSON of that length.
    let bytes = fixture("v0-session.state");
    let length = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    assert_eq!(length, bytes.len() - 8);
    assert!(
        json(&bytes)["version"].is_string(),
        "the plugin's version string"
    );
}

#[test]
fn migration_brings_old_states_up_to_date_and_leaves_newer_ones_alone() {
    use nice_plug::prelude::PluginState;
    let mut old: PluginState = serde_json::from_slice(&fixture("v0-session.state")[8..]).unwrap();
    let params = serde_json::to_string(&old.params).unwrap();
    sake_glug_plugin::migrate_state(&mut old);
    let version = sake_glug_plugin::STATE_VERSION.to_string();
    assert_eq!(old.fields.get("state_version"), Some(&version));
    assert_eq!(
        serde_json::to_string(&old.params).unwrap(),
        params,
        "no value moves"
    );
    let mut newer = old.clone();
    newer.fields.insert("state_version".into(), "200".into());
    sake_glug_plugin::migrate_state(&mut newer);
    assert_eq!(newer.fields["state_version"], "200");
}
