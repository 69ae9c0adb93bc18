//! Text from outside the program (a scene, a file name, a field of a take) made safe to echo in
//! a message: a control character printed raw can retitle or recolour a terminal, move its
//! cursor or split a log line.

use std::borrow::Cow;

/// `text` with every control character escaped as Rust writes it (`\n`, `\t`, `\u{1b}`), the
/// rest as it is; borrowed when there is nothing to escape.
pub fn printable(text: &str) -> Cow<'_, str> {
    if !text.chars().any(char::is_control) {
        return Cow::Borrowed(text);
    }
    let mut escaped = String::with_capacity(text.len() + 8);
    for character in text.chars() {
        if character.is_control() {
            escaped.extend(character.escape_debug());
        } else {
            escaped.push(character);
        }
    }
    Cow::Owned(escaped)
}

/// The most characters of an outside field a message quotes: enough to see what it is, never a
/// whole line of some other file.
pub const QUOTED_CHARS: usize = 32;

/// `field` as a message quotes it: its first [`QUOTED_CHARS`] characters (an ellipsis marks a
/// cut), control characters escaped.
pub fn quoted(field: &str) -> String {
    let cut = match field.char_indices().nth(QUOTED_CHARS) {
        Some((end, _)) => format!("{}…", &field[..end]),
        None => field.to_owned(),
    };
    printable(&cut).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quoted_field_is_cut_and_escaped() {
        assert_eq!(quoted("short"), "short");
        let long = "x".repeat(100);
        assert_eq!(quoted(&long), format!("{}…", "x".repeat(QUOTED_CHARS)));
        assert_eq!(quoted("a\u{1b}[31m"), "a\\u{1b}[31m");
    }
}
