//! The saved state's structure-aware mutations, for the `state` target. Its inputs are states as
//! a host hands them back (the CLAP stream: their length, then nice-plug's JSON), so its corpus
//! holds states, which the ordinary tests load as they are. Three mutations in four read the
//! input as a state (or take the one a new instance saves), apply the edits that a description
//! derived with `arbitrary` gives (a parameter of the plugin's real list, or one of its persisted
//! fields, with a hostile value) and write well-formed JSON again; the fourth is libFuzzer's own
//! byte edits, which also reach the JSON parser and the length.

use std::sync::OnceLock;

// The derive names the crate as `arbitrary`.
use libfuzzer_sys::arbitrary::{self, Arbitrary, Unstructured};
use serde_json::{json, Value};

use crate::checks::{bytes_of, json_of};
use crate::clap_host::ClapInstance;

/// One change to a state.
#[derive(Arbitrary, Debug)]
enum Edit {
    /// A parameter of the plugin (the n-th, modulo their number) takes a hostile value.
    Parameter(u8, Hostile),
    /// A parameter is left out.
    Remove(u8),
    /// A persisted field (a MIDI byte, an OSC setting, the state version) takes hostile text.
    Field(u8, HostileField),
    /// A parameter the plugin does not have.
    Unknown(String, Hostile),
    /// The plugin version the state says it was saved with.
    Version(String),
}

/// A value a saved parameter should never hold, or one right at an edge.
#[derive(Arbitrary, Debug)]
enum Hostile {
    /// Beyond f32's range: JSON's `1e39` reads as ±infinity.
    Infinite { negative: bool },
    /// The largest finite f32.
    Largest { negative: bool },
    /// Any f32: negative, tiny, huge, subnormal (a NaN or an infinity is written as JSON's
    /// `null`).
    Float(f32),
    /// What a NaN becomes on its way through JSON: `null`, or the text "NaN".
    NanLike { text: bool },
    /// Any integer, as a seed or an enum index is saved.
    Int(i32),
    /// An enum index around the choices: −2 to 5.
    Index(u8),
    /// A boolean, as a switch is saved.
    Bool(bool),
    /// Text, as an enum's id is saved.
    Text(String),
    /// The value another parameter has in a new instance's state: the right type for some, the
    /// wrong one for others.
    Borrowed(u8),
    /// JSON of another shape than a parameter value.
    Shape(Shape),
}

/// JSON that is no parameter value.
#[derive(Arbitrary, Debug)]
enum Shape {
    Null,
    Array,
    Empty,
    TwoTypes,
    Number(i64),
}

/// Text a persisted field should never hold (each field is saved as JSON text).
#[derive(Arbitrary, Debug)]
enum HostileField {
    Byte(u8),
    Integer(i64),
    Float(f32),
    Null,
    Text(String),
}

/// The state a new instance saves: the real parameter ids, fields and value types.
fn template() -> &'static Value {
    static TEMPLATE: OnceLock<Value> = OnceLock::new();
    TEMPLATE.get_or_init(|| json_of(&ClapInstance::new().save()))
}

/// The keys of the template's `params` or `fields`.
fn keys(section: &str) -> Vec<&'static String> {
    template()[section].as_object().unwrap().keys().collect()
}

fn pick<T: Copy>(items: &[T], n: u8) -> T {
    items[n as usize % items.len()]
}

impl Hostile {
    fn json(&self) -> Value {
        match *self {
            Hostile::Infinite { negative } => json!({ "f32": if negative { -1e39 } else { 1e39 } }),
            Hostile::Largest { negative } => {
                json!({ "f32": if negative { f32::MIN } else { f32::MAX } })
            }
            Hostile::Float(value) => json!({ "f32": value }),
            Hostile::NanLike { text } => {
                json!({ "f32": if text { json!("NaN") } else { Value::Null } })
            }
            Hostile::Int(value) => json!({ "i32": value }),
            Hostile::Index(n) => json!({ "i32": (n % 8) as i32 - 2 }),
            Hostile::Bool(value) => json!({ "bool": value }),
            Hostile::Text(ref text) => json!({ "string": text }),
            Hostile::Borrowed(n) => template()["params"][pick(&keys("params"), n)].clone(),
            Hostile::Shape(ref shape) => match *shape {
                Shape::Null => Value::Null,
                Shape::Array => json!([1, 2]),
                Shape::Empty => json!({}),
                Shape::TwoTypes => json!({ "f32": 1.0, "i32": 2 }),
                Shape::Number(n) => json!(n),
            },
        }
    }
}

impl HostileField {
    fn text(&self) -> String {
        match self {
            HostileField::Byte(n) => n.to_string(),
            HostileField::Integer(n) => n.to_string(),
            HostileField::Float(x) => x.to_string(),
            HostileField::Null => "null".into(),
            HostileField::Text(text) => text.clone(),
        }
    }
}

/// `bytes` as a state whose `params` and `fields` are objects, whatever its length says.
fn parse(bytes: &[u8]) -> Option<Value> {
    let state: Value = serde_json::from_slice(bytes.get(8..)?).ok()?;
    (state["params"].is_object() && state["fields"].is_object()).then_some(state)
}

fn apply(state: &mut Value, edit: &Edit) {
    match edit {
        Edit::Parameter(n, value) => state["params"][pick(&keys("params"), *n)] = value.json(),
        Edit::Remove(n) => {
            if let Some(params) = state["params"].as_object_mut() {
                params.remove(pick(&keys("params"), *n));
            }
        }
        Edit::Field(n, text) => {
            state["fields"][pick(&keys("fields"), *n)] = Value::String(text.text())
        }
        Edit::Unknown(id, value) => state["params"][id] = value.json(),
        Edit::Version(version) => state["version"] = Value::String(version.clone()),
    }
}

/// Bytes for `arbitrary` from libFuzzer's seed (splitmix64).
fn entropy(seed: u32) -> Vec<u8> {
    let mut x = u64::from(seed);
    (0..32)
        .flat_map(|_| {
            x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = x;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            (z ^ (z >> 31)).to_le_bytes()
        })
        .collect()
}

/// libFuzzer's custom mutator: changes the input in `data[..size]` in place, within `max_size`
/// bytes, and returns its new size.
pub fn mutate(data: &mut [u8], size: usize, max_size: usize, seed: u32) -> usize {
    if seed % 4 == 0 {
        return libfuzzer_sys::fuzzer_mutate(data, size, max_size);
    }
    // Now and then a fresh start from a new instance's state.
    let mut state: Value = parse(&data[..size])
        .filter(|_| seed % 16 != 1)
        .unwrap_or_else(|| template().clone());
    let edits: Vec<Edit> = Unstructured::new(&entropy(seed))
        .arbitrary()
        .unwrap_or_default();
    if edits.is_empty() {
        return libfuzzer_sys::fuzzer_mutate(data, size, max_size);
    }
    for edit in &edits {
        apply(&mut state, edit);
    }
    let bytes = bytes_of(&state);
    if bytes.len() > max_size {
        return libfuzzer_sys::fuzzer_mutate(data, size, max_size);
    }
    data[..bytes.len()].copy_from_slice(&bytes);
    bytes.len()
}
