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
