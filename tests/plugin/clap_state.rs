//! The plugin's saved state through nice-plug's real state path: the CLAP entry point, the
//! plugin factory and the `clap.state` extension, exactly as a host calls them. A state saved
//! by an older version (a fixture) loads with the same parameter values and is migrated.

use std::ffi::{c_char, c_void};
use std::path::Path;
use std::ptr::null;

use clap_sys::entry::clap_plugin_entry;
use clap_sys::ext::state::{clap_plugin_state, CLAP_EXT_STATE};
use clap_sys::factory::plugin_factory::{clap_plugin_factory, CLAP_PLUGIN_FACTORY_ID};
use clap_sys::host::clap_host;
use clap_sys::plugin::clap_plugin;
use clap_sys::stream::{clap_istream, clap_ostream};
use clap_sys::version::CLAP_VERSION;
use serde_json::Value;

unsafe extern "C" fn no_extension(_: *const clap_host, _: *const c_char) -> *const c_void {
    null()
}
unsafe extern "C" fn no_request(_: *const clap_host) {}

/// A host that offers no extensions: enough for the plugin to save and load its state.
static HOST: clap_host = clap_host {
    clap_version: CLAP_VERSION,
    host_data: std::ptr::null_mut(),
    name: c"sake-glug state test".as_ptr(),
    vendor: c"".as_ptr(),
    url: c"".as_ptr(),
    version: c"1".as_ptr(),
    get_extension: Some(no_extension),
    request_restart: Some(no_request),
    request_process: Some(no_request),
    request_callback: Some(no_request),
};

/// One plugin instance created through the CLAP factory.
struct ClapInstance {
    plugin: *const clap_plugin,
    state: *const clap_plugin_state,
}

impl ClapInstance {
    fn new() -> Self {
        let entry: &clap_plugin_entry = &sake_glug::plugin::clap_entry;
        unsafe {
            assert!((entry.init.unwrap())(c"".as_ptr()));
            let factory = (entry.get_factory.unwrap())(CLAP_PLUGIN_FACTORY_ID.as_ptr())
                as *const clap_plugin_factory;
            let descriptor = ((*factory).get_plugin_descriptor.unwrap())(factory, 0);
            let plugin = ((*factory).create_plugin.unwrap())(factory, &HOST, (*descriptor).id);
            assert!(!plugin.is_null());
            assert!(((*plugin).init.unwrap())(plugin));
            let state = ((*plugin).get_extension.unwrap())(plugin, CLAP_EXT_STATE.as_ptr())
                as *const clap_plugin_state;
            assert!(!state.is_null(), "the plugin offers clap.state");
            Self { plugin, state }
        }
    }

    /// The bytes a host would store in its project.
    fn save(&self) -> Vec<u8> {
        unsafe extern "C" fn write(
            s: *const clap_ostream,
            buffer: *const c_void,
            size: u64,
        ) -> i64 {
            let bytes = unsafe { &mut *((*s).ctx as *mut Vec<u8>) };
            bytes.extend_from_slice(unsafe {
                std::slice::from_raw_parts(buffer as *const u8, size as usize)
            });
            size as i64
        }
        let mut bytes = Vec::new();
        let stream = clap_ostream {
            ctx: &mut bytes as *mut Vec<u8> as *mut c_void,
            write: Some(write),
        };
        assert!(unsafe { ((*self.state).save.unwrap())(self.plugin, &stream) });
        bytes
    }

    /// Loads bytes as a host restores a project; false if the plugin refuses them.
    fn load(&self, bytes: &[u8]) -> bool {
        struct Reader<'a>(&'a [u8]);
        unsafe extern "C" fn read(s: *const clap_istream, buffer: *mut c_void, size: u64) -> i64 {
            let reader = unsafe { &mut *((*s).ctx as *mut Reader) };
            let count = reader.0.len().min(size as usize);
            unsafe {
                std::ptr::copy_nonoverlapping(reader.0.as_ptr(), buffer as *mut u8, count);
            }
            reader.0 = &reader.0[count..];
            count as i64
        }
        let mut reader = Reader(bytes);
        let stream = clap_istream {
            ctx: &mut reader as *mut Reader as *mut c_void,
            read: Some(read),
        };
        unsafe { ((*self.state).load.unwrap())(self.plugin, &stream) }
    }
}

impl Drop for ClapInstance {
    fn drop(&mut self) {
        unsafe { ((*self.plugin).destroy.unwrap())(self.plugin) };
    }
}

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
    assert_eq!(now["params"], old_json["params"], "every parameter value");
    for (field, value) in old_json["fields"].as_object().unwrap() {
        assert_eq!(&now["fields"][field], value, "field {field}");
    }
    let version: u8 = serde_json::from_str(now["fields"]["state_version"].as_str().unwrap())
        .expect("the version is saved");
    assert_eq!(version, sake_glug::plugin::STATE_VERSION);
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
    sake_glug::plugin::migrate_state(&mut old);
    let version = sake_glug::plugin::STATE_VERSION.to_string();
    assert_eq!(old.fields.get("state_version"), Some(&version));
    assert_eq!(
        serde_json::to_string(&old.params).unwrap(),
        params,
        "no value moves"
    );
    let mut newer = old.clone();
    newer.fields.insert("state_version".into(), "200".into());
    sake_glug::plugin::migrate_state(&mut newer);
    assert_eq!(newer.fields["state_version"], "200");
}
