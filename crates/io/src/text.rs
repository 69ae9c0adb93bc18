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

/// The most characters of a field of another file that a message quotes: enough to see what it
/// is, never a whole line.
pub const QUOTED_FIELD_CHARS: usize = 32;

/// The start of `field`: at most [`QUOTED_FIELD_CHARS`] characters, then `…` if it was cut. A
/// field of another file quoted in a message never carries that file whole (a 50 MB field, or the
/// next line of a file that is no CSV); quote it with `{:?}` or [`printable`].
pub fn cut_short(field: &str) -> String {
    match field.char_indices().nth(QUOTED_FIELD_CHARS) {
        Some((end, _)) => format!("{}…", &field[..end]),
        None => field.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_field_is_cut_and_a_short_one_kept() {
        let long = "é".repeat(50_000);
        assert_eq!(
            cut_short(&long),
            format!("{}…", "é".repeat(QUOTED_FIELD_CHARS))
        );
        assert_eq!(cut_short("short"), "short");
    }
}
