//! The dotted keys of the product's TOML files (`glug.f1_hz` is `f1_hz` in `[glug]`), one way:
//! split, joined, flattened, inserted, taken out one by one with the rest refused as unknown;
//! and a TOML syntax error made printable. Scenes, model files, study specs and the fit's model
//! all use them (feature `toml`).

use crate::text::{cut_quotes, printable, quoted};

/// The section and the name of a dotted key (`None` for a top-level key).
pub fn split(key: &str) -> (Option<&str>, &str) {
    match key.split_once('.') {
        Some((section, name)) => (Some(section), name),
        None => (None, key),
    }
}

/// `section.name`, or `name` at the top (`section` empty).
pub fn join(section: &str, name: &str) -> String {
    if section.is_empty() {
        name.to_owned()
    } else {
        format!("{section}.{name}")
    }
}

/// Every value of `table` that is not a table, at its dotted key, in the table's order.
pub fn flatten(table: &toml::Table) -> Vec<(String, toml::Value)> {
    let mut leaves = Vec::new();
    flatten_into("", table, &mut leaves);
    leaves
}

fn flatten_into(prefix: &str, table: &toml::Table, leaves: &mut Vec<(String, toml::Value)>) {
    for (name, value) in table {
        let key = join(prefix, name);
        match value {
            toml::Value::Table(inner) => flatten_into(&key, inner, leaves),
            value => leaves.push((key, value.clone())),
        }
    }
}

/// The table that holds `key`'s name in `table`, made (and a section that is not a table made
/// one) on the way, and that name.
fn holder<'a, 'k>(table: &'a mut toml::Table, key: &'k str) -> (&'a mut toml::Table, &'k str) {
    match key.split_once('.') {
        None => (table, key),
        Some((section, rest)) => {
            let inner = table
                .entry(section)
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            if !inner.is_table() {
                *inner = toml::Value::Table(toml::Table::new());
            }
            holder(inner.as_table_mut().expect("made a table"), rest)
        }
    }
}

/// Sets `value` at the dotted `key` of `table`, making its sections.
pub fn insert(table: &mut toml::Table, key: &str, value: toml::Value) {
    let (table, name) = holder(table, key);
    table.insert(name.to_owned(), value);
}

/// Sets `value` at the dotted `key` of `table` unless the key is set, or its section is set to
/// something that is not a table (left for validation to refuse).
pub fn insert_if_absent(table: &mut toml::Table, key: &str, value: &toml::Value) {
    let target = match key.split_once('.') {
        None => Some((table, key)),
        Some((section, name)) => table
            .entry(section)
            .or_insert_with(|| toml::Value::Table(toml::Table::new()))
            .as_table_mut()
            .map(|table| (table, name)),
    };
    if let Some((table, name)) = target {
        table.entry(name).or_insert_with(|| value.clone());
    }
}

/// toml's message for an error in `text`, on one line: where (`line L, column C`) and what,
/// each span it quotes of the file cut short and printable ([`cut_quotes`]). toml's own layout
/// shows the line at fault whole, which may be a file's worth of text.
pub fn syntax_message(error: &toml::de::Error, text: &str) -> String {
    let what = cut_quotes(error.message().trim_end());
    let Some(start) = error.span().map(|span| span.start) else {
        return what;
    };
    let before = text.get(..start).unwrap_or(text);
    let line = 1 + before.matches('\n').count();
    let column = 1 + before.rsplit('\n').next().unwrap_or("").chars().count();
    format!("line {line}, column {column}: {what}")
}

/// A file's TOML from which each key is taken as it is read; whatever is left at the end is
/// unknown, and refused with the keys that are known. Messages are printable.
pub struct KeyedTable {
    table: toml::Table,
    /// Every key read or asked for, for the message that refuses an unknown one.
    known: Vec<String>,
}

impl KeyedTable {
    /// Parses `text`; a syntax error gives [`syntax_message`].
    pub fn parse(text: &str) -> Result<Self, String> {
        let table = toml::from_str(text).map_err(|error| syntax_message(&error, text))?;
        Ok(Self::new(table))
    }

    /// Walks `table`.
    pub fn new(table: toml::Table) -> Self {
        Self {
            table,
            known: Vec::new(),
        }
    }

    /// The table as it is now.
    pub fn table_mut(&mut self) -> &mut toml::Table {
        &mut self.table
    }

    /// The value at `key`, taken out of the table and converted.
    pub fn take<T: serde::de::DeserializeOwned>(&mut self, key: &str) -> Result<Option<T>, String> {
        self.known.push(key.to_owned());
        let (section, name) = split(key);
        let table = match section {
            None => &mut self.table,
            Some(section) => match self.table.get_mut(section) {
                None => return Ok(None),
                Some(toml::Value::Table(table)) => table,
                Some(other) => {
                    return Err(printable(&format!(
                        "`{section}`: invalid type: {}, expected a table",
                        other.type_str()
                    ))
                    .into_owned())
                }
            },
        };
        match table.remove(name) {
            None => Ok(None),
            Some(value) => value
                .try_into()
                .map(Some)
                .map_err(|error: toml::de::Error| {
                    // toml ends a message without a place in the file with a line break.
                    format!("`{key}`: {}", cut_quotes(error.to_string().trim_end()))
                }),
        }
    }

    /// Refuses whatever key is left: none of the file's.
    pub fn refuse_unknown(self) -> Result<(), String> {
        // The names known inside `section` (`None`: at the top, sections included).
        let names_in = |section: Option<&str>| {
            let mut names: Vec<&str> = Vec::new();
            for key in &self.known {
                let name = match (key.split_once('.'), section) {
                    (Some((outer, name)), Some(wanted)) if outer == wanted => name,
                    (Some((outer, _)), None) => outer,
                    (None, None) => key.as_str(),
                    _ => continue,
                };
                if !names.contains(&name) {
                    names.push(name);
                }
            }
            names
        };
        let unknown = |name: &str, place: String, known: Vec<&str>| {
            let known: Vec<String> = known.iter().map(|name| format!("`{name}`")).collect();
            format!(
                "unknown field `{}`{place}, expected one of {}",
                quoted(name),
                printable(&known.join(", "))
            )
        };
        for (name, value) in &self.table {
            let inside = names_in(Some(name));
            if inside.is_empty() {
                if !self.known.contains(name) {
                    return Err(unknown(name, String::new(), names_in(None)));
                }
            } else if let Some(key) = value.as_table().and_then(|table| table.keys().next()) {
                return Err(unknown(key, format!(" in [{}]", quoted(name)), inside));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_flatten_and_insert_back() {
        let mut table = toml::Table::new();
        insert(&mut table, "glug.f1_hz", toml::Value::Float(80.0));
        insert(&mut table, "tilt_deg", toml::Value::Float(135.0));
        insert_if_absent(&mut table, "glug.f1_hz", &toml::Value::Float(1.0));
        insert_if_absent(&mut table, "glug.f2_hz", &toml::Value::Float(300.0));
        assert_eq!(
            flatten(&table),
            vec![
                ("glug.f1_hz".to_owned(), toml::Value::Float(80.0)),
                ("glug.f2_hz".to_owned(), toml::Value::Float(300.0)),
                ("tilt_deg".to_owned(), toml::Value::Float(135.0)),
            ]
        );
        assert_eq!(split("glug.f1_hz"), (Some("glug"), "f1_hz"));
        assert_eq!(join("", "seed"), "seed");
    }

    #[test]
    fn unknown_keys_are_refused_with_the_known_ones() {
        let mut keys = KeyedTable::parse("a = 1\n[s]\nb = 2\nc = 3").unwrap();
        assert_eq!(keys.take::<i64>("a").unwrap(), Some(1));
        assert_eq!(keys.take::<i64>("s.b").unwrap(), Some(2));
        assert_eq!(
            keys.refuse_unknown().unwrap_err(),
            "unknown field `c` in [s], expected one of `b`"
        );
        let long = "k".repeat(100_000);
        let message = KeyedTable::parse(&format!("{long} = 1"))
            .unwrap()
            .refuse_unknown()
            .unwrap_err();
        assert!(message.len() < 200, "{message}");
        let mut keys = KeyedTable::parse("s = 1").unwrap();
        assert!(keys
            .take::<i64>("s.b")
            .unwrap_err()
            .contains("expected a table"));
    }

    /// A scene, model or spec that quotes a whole line or field of itself in a message can fill
    /// a terminal with a file: toml's own layout shows the line at fault whole.
    #[test]
    fn messages_quote_a_file_cut_short_with_its_place() {
        let line = format!("a = \"{}\" x", "v".repeat(100_000));
        let message = KeyedTable::parse(&format!("# c\n{line}")).err().unwrap();
        assert!(message.starts_with("line 2, column "), "{message}");
        assert!(message.len() < 200, "{}", &message[..200]);
        let mut keys =
            KeyedTable::parse(&format!("b = \"{}\"", "\\u001b".repeat(100_000))).unwrap();
        let message = keys.take::<f64>("b").unwrap_err();
        assert!(message.starts_with("`b`: "), "{message}");
        assert!(
            message.len() < 300 && !message.contains('\u{1b}'),
            "{message}"
        );
    }
}
