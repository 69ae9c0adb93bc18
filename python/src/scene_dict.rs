//! A scene given as a dict, read into the TOML table it stands for, by hand rather than by
//! pythonize: pythonize recurses once per level with no limit, so a dict that contains itself, or
//! one nested some ten thousand deep, overflowed the stack and killed the interpreter. Here every
//! level is counted and every container on the way down remembered, so those are refused with
//! what was wrong, and a scene no file could hold is refused before it is copied whole.

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use sake_glug_io::text::printable;
use sake_glug_render::MAX_SCENE_BYTES;

/// The deepest a dict scene may nest: a scene nests three levels (a table, a lane, a point), so
/// this leaves room for any scene to come while keeping the walk's recursion shallow.
pub const MAX_SCENE_DEPTH: usize = 32;

/// The most values a dict scene may hold: each takes at least two bytes of a scene file (a digit
/// and a separator), so more could not fit in the largest scene file read.
const MAX_SCENE_VALUES: u64 = MAX_SCENE_BYTES / 2;

/// Longest key or value quoted in a message; the rest is cut.
const SHOWN_CHARS: usize = 32;

/// The TOML table a dict scene stands for, or why it stands for none (the message names the
/// key). Python's bool, int, float and str are its values, lists and tuples its arrays, dicts
/// (with str keys) its tables.
pub fn toml_table(dict: &Bound<'_, PyDict>) -> Result<toml::Table, String> {
    let mut walk = Walk {
        path: Vec::new(),
        open: Vec::new(),
        values: 0,
    };
    walk.table(dict)
}

/// A step down a scene: a table's key or an array's index.
enum Step {
    Key(String),
    Index(usize),
}

struct Walk {
    /// Where the walk is, from the scene's top.
    path: Vec<Step>,
    /// The containers the walk is inside of (their addresses, alive while it is).
    open: Vec<usize>,
    /// Values read so far.
    values: u64,
}

impl Walk {
    fn table(&mut self, dict: &Bound<'_, PyDict>) -> Result<toml::Table, String> {
        self.enter(dict.as_any())?;
        let mut table = toml::Table::new();
        for (key, value) in dict.iter() {
            let key = key
                .cast::<PyString>()
                .map_err(|_| {
                    self.error(&format!(
                        "has a key of type {}: a scene's keys are str",
                        type_name(&key)
                    ))
                })?
                .to_cow()
                .map_err(|error| self.error(&format!("has a key that is no text: {error}")))?
                .into_owned();
            self.path.push(Step::Key(key));
            let value = self.value(&value)?;
            let Some(Step::Key(key)) = self.path.pop() else {
                unreachable!("the step pushed above")
            };
            table.insert(key, value);
        }
        self.open.pop();
        Ok(table)
    }

    fn array<'py>(
        &mut self,
        container: &Bound<'py, PyAny>,
        items: impl Iterator<Item = Bound<'py, PyAny>>,
    ) -> Result<toml::Value, String> {
        self.enter(container)?;
        let mut array = Vec::new();
        for (index, item) in items.enumerate() {
            self.path.push(Step::Index(index));
            array.push(self.value(&item)?);
            self.path.pop();
        }
        self.open.pop();
        Ok(toml::Value::Array(array))
    }

    fn value(&mut self, value: &Bound<'_, PyAny>) -> Result<toml::Value, String> {
        self.values += 1;
        if self.values > MAX_SCENE_VALUES {
            return Err(format!(
                "invalid scene: the dict holds more than {MAX_SCENE_VALUES} values, more than a \
                 scene file of at most {} MiB could",
                MAX_SCENE_BYTES >> 20
            ));
        }
        // bool first: a Python bool is an int too.
        if let Ok(flag) = value.cast::<PyBool>() {
            return Ok(toml::Value::Boolean(flag.is_true()));
        }
        if let Ok(int) = value.cast::<PyInt>() {
            return int.extract::<i64>().map(toml::Value::Integer).map_err(|_| {
                self.error(&format!(
                    "= {}: beyond the whole numbers a scene holds (64-bit)",
                    shown(&int.to_string())
                ))
            });
        }
        if let Ok(float) = value.cast::<PyFloat>() {
            return Ok(toml::Value::Float(float.value()));
        }
        if let Ok(text) = value.cast::<PyString>() {
            return text
                .to_cow()
                .map(|text| toml::Value::String(text.into_owned()))
                .map_err(|error| self.error(&format!("is no text: {error}")));
        }
        if let Ok(dict) = value.cast::<PyDict>() {
            return self.table(dict).map(toml::Value::Table);
        }
        if let Ok(list) = value.cast::<PyList>() {
            return self.array(value, list.iter());
        }
        if let Ok(tuple) = value.cast::<PyTuple>() {
            return self.array(value, tuple.iter());
        }
        Err(self.error(&format!(
            "is of type {}: a scene's values are bool, int, float, str, list, tuple or dict",
            type_name(value)
        )))
    }

    /// Steps into `container`, refused if it is one the walk is already inside of, or too deep.
    fn enter(&mut self, container: &Bound<'_, PyAny>) -> Result<(), String> {
        let address = container.as_ptr() as usize;
        if self.open.contains(&address) {
            return Err(self.error(&format!(
                "refers back to a {} it is inside of: a scene cannot contain itself",
                type_name(container)
            )));
        }
        if self.open.len() == MAX_SCENE_DEPTH {
            return Err(self.error(&format!(
                "nests deeper than the {MAX_SCENE_DEPTH} levels a scene may"
            )));
        }
        self.open.push(address);
        Ok(())
    }

    /// "invalid scene: `glug.f1_hz` …", or "invalid scene: the dict …" at the top.
    fn error(&self, what: &str) -> String {
        if self.path.is_empty() {
            return format!("invalid scene: the dict {what}");
        }
        let mut path = String::new();
        for step in &self.path {
            match step {
                Step::Key(key) if path.is_empty() => path += &shown(key),
                Step::Key(key) => path += &format!(".{}", shown(key)),
                Step::Index(index) => path += &format!("[{index}]"),
            }
        }
        format!("invalid scene: `{}` {what}", shown(&path))
    }
}

/// Outside text for a message: control characters escaped, cut to [`SHOWN_CHARS`].
pub fn shown(text: &str) -> String {
    let escaped = printable(text);
    match escaped.char_indices().nth(SHOWN_CHARS) {
        Some((end, _)) => format!("{}…", &escaped[..end]),
        None => escaped.into_owned(),
    }
}

fn type_name(value: &Bound<'_, PyAny>) -> String {
    value
        .get_type()
        .name()
        .map_or_else(|_| "unknown".into(), |name| shown(&name.to_string()))
}
