//! Text from outside the program (a scene, a file name, a field of a take) made safe to echo in
//! a message: a control character printed raw can retitle or recolour a terminal, move its
//! cursor or split a log line, and a long field quoted whole can fill a terminal with a file.
//! And text written into a CSV cell made safe to open in a spreadsheet.

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
/// whole line of a file.
pub const QUOTED_CHARS: usize = 32;

/// The start of `field`: at most [`QUOTED_CHARS`] characters, then `…` if it was cut, not yet
/// escaped (for a message that escapes it, as `{:?}` does). A field of another file quoted in a
/// message never carries that file whole (a 50 MB field, or the next line of a file that is no
/// CSV).
pub fn cut_short(field: &str) -> String {
    match field.char_indices().nth(QUOTED_CHARS) {
        Some((end, _)) => format!("{}…", &field[..end]),
        None => field.to_owned(),
    }
}

/// The start of `field` for a message to quote: [`cut_short`], printable.
pub fn quoted(field: &str) -> String {
    printable(&cut_short(field)).into_owned()
}

/// A message from a library (a TOML or CSV error) whose spans between backquotes or double
/// quotes, which quote the input, are each cut as [`quoted`] cuts a field (an unclosed quote runs
/// to the end); printable.
pub fn cut_quotes(message: &str) -> String {
    let mut cut = String::with_capacity(message.len().min(1024));
    let mut rest = message;
    while let Some(open) = rest.find(['`', '"']) {
        let mark = &rest[open..open + 1];
        cut += &printable(&rest[..open + 1]);
        let inside = &rest[open + 1..];
        let (span, after) = match inside.find(mark) {
            Some(close) => (&inside[..close], &inside[close..close + 1]),
            None => (inside, ""),
        };
        cut += &quoted(span);
        cut += after;
        rest = &inside[span.len() + after.len()..];
    }
    cut + &printable(rest)
}

/// The first characters of a cell that a spreadsheet reads as a formula (OWASP's list: `=`, `+`,
/// `-`, `@`, tab, carriage return), and the quote that marks a cell as text.
const FORMULA_STARTS: [char; 6] = ['=', '+', '-', '@', '\t', '\r'];
const TEXT_MARK: char = '\'';

/// `text` as a CSV cell a spreadsheet shows as text, never runs: a cell that starts like a formula
/// (see `FORMULA_STARTS`), or with the text mark `'` itself, gets a leading `'` (OWASP's CSV
/// injection rule), which spreadsheets hide; [`from_csv_cell`] takes it off again.
pub fn csv_cell(text: &str) -> Cow<'_, str> {
    match text.chars().next() {
        Some(first) if FORMULA_STARTS.contains(&first) || first == TEXT_MARK => {
            Cow::Owned(format!("{TEXT_MARK}{text}"))
        }
        _ => Cow::Borrowed(text),
    }
}

/// The text [`csv_cell`] wrote: a leading `'` taken off.
pub fn from_csv_cell(cell: &str) -> &str {
    cell.strip_prefix(TEXT_MARK).unwrap_or(cell)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_field_is_quoted_cut_short() {
        let long = "x".repeat(1000);
        assert_eq!(quoted(&long), format!("{}…", "x".repeat(QUOTED_CHARS)));
        assert_eq!(quoted("a\u{1b}b"), "a\\u{1b}b");
        let message = format!("unknown field `{long}`, expected `a` or \"{long}");
        assert_eq!(
            cut_quotes(&message),
            format!(
                "unknown field `{}…`, expected `a` or \"{}…",
                "x".repeat(32),
                "x".repeat(32)
            )
        );
    }

    #[test]
    fn formula_cells_are_written_as_text_and_read_back() {
        for name in [
            "=cmd|' /C calc'!A0",
            "=HYPERLINK(\"http://evil\",\"x\")",
            "+1+1",
            "-1",
            "@SUM(1)",
            "\tx",
            "\rx",
            "'quoted",
        ] {
            let cell = csv_cell(name);
            assert!(cell.starts_with('\''), "{cell}");
            assert_eq!(from_csv_cell(&cell), name);
        }
        assert_eq!(csv_cell("model"), "model");
        assert_eq!(from_csv_cell("model"), "model");
    }
}
