//! No pointer to nowhere: every repository path that README.md, docs/*.md and the comments of the
//! code name exists, and every `--test`, `--bench` and `--bin` names a target of Cargo.toml.
//!
//! It reads files only, so it needs none of the crate's features.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// How a repository path starts: one of the top-level folders, or it is a top-level file.
const FOLDERS: [&str; 10] = [
    "src/",
    "fuzz/",
    "tests/",
    "docs/",
    "benches/",
    "xtask/",
    "presets/",
    "experiments/",
    "python/",
    ".ci/",
];
const FILES: [&str; 5] = [
    "README.md",
    "Cargo.toml",
    "Cargo.lock",
    "bundler.toml",
    "rustfmt.toml",
];

/// The folders whose Rust sources' comments are read.
const CODE: [&str; 4] = ["src", "tests", "benches", "xtask"];

/// A line of prose: the file it is in (relative to the root), its number, its text.
struct Line {
    file: String,
    number: usize,
    text: String,
}

#[test]
fn every_repository_path_named_exists() {
    let (mut stale, mut checked) = (Vec::new(), 0);
    for line in prose() {
        let mut named = paths_in(&line.text);
        if line.file.ends_with(".md") {
            let dir = Path::new(&line.file).parent().unwrap_or(Path::new(""));
            named.extend(link_targets(&line.text).map(|target| dir.join(target)));
        }
        for path in named {
            checked += 1;
            if !Path::new(ROOT).join(&path).exists() {
                stale.push(format!(
                    "{}:{}: {} does not exist",
                    line.file,
                    line.number,
                    path.display()
                ));
            }
        }
    }
    stale.dedup();
    assert!(checked > 0, "no path found: the scan is broken");
    assert!(
        stale.is_empty(),
        "{} pointers to nowhere:\n{}",
        stale.len(),
        stale.join("\n")
    );
}

#[test]
fn every_cargo_target_named_exists() {
    let manifest: toml::Table = std::fs::read_to_string(Path::new(ROOT).join("Cargo.toml"))
        .expect("Cargo.toml")
        .parse()
        .expect("Cargo.toml is TOML");
    let (mut stale, mut checked) = (Vec::new(), 0);
    for line in prose() {
        for (kind, name) in targets_in(&line.text) {
            checked += 1;
            let known = target_names(&manifest, kind);
            if !known.contains(&name.to_owned()) {
                stale.push(format!(
                    "{}:{}: `--{kind} {name}` names no [[{kind}]] of Cargo.toml ({})",
                    line.file,
                    line.number,
                    known.join(", ")
                ));
            }
        }
    }
    assert!(checked > 0, "no target found: the scan is broken");
    assert!(
        stale.is_empty(),
        "{} targets that do not exist:\n{}",
        stale.len(),
        stale.join("\n")
    );
}

/// Every line of README.md and docs/*.md, and every comment line of the Rust sources.
fn prose() -> Vec<Line> {
    let mut markdown = vec![PathBuf::from("README.md")];
    markdown.extend(files_under("docs", "md"));
    let mut lines = Vec::new();
    for file in markdown {
        let text = read(&file);
        lines.extend(text.lines().enumerate().map(|(index, text)| Line {
            file: file.display().to_string(),
            number: index + 1,
            text: text.to_owned(),
        }));
    }
    for file in CODE.iter().flat_map(|folder| files_under(folder, "rs")) {
        lines.extend(
            comments(&read(&file))
                .into_iter()
                .map(|(number, text)| Line {
                    file: file.display().to_string(),
                    number,
                    text,
                }),
        );
    }
    lines
}

fn read(file: &Path) -> String {
    std::fs::read_to_string(Path::new(ROOT).join(file))
        .unwrap_or_else(|error| panic!("{}: {error}", file.display()))
}

/// The files ending in `.extension` under `folder`, at any depth, sorted, relative to the root.
fn files_under(folder: &str, extension: &str) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut pending = vec![PathBuf::from(folder)];
    while let Some(dir) = pending.pop() {
        for entry in std::fs::read_dir(Path::new(ROOT).join(&dir)).expect("a readable folder") {
            let name = entry.expect("a folder entry").file_name();
            let path = dir.join(&name);
            if Path::new(ROOT).join(&path).is_dir() {
                if name != "target" {
                    pending.push(path);
                }
            } else if path.extension().is_some_and(|ext| ext == extension) {
                found.push(path);
            }
        }
    }
    found.sort();
    found
}

/// Can be part of a path as prose writes it.
fn in_path(c: char) -> bool {
    c.is_ascii_alphanumeric() || "_-./<>*{}".contains(c)
}

/// The repository paths a line names: words that start with a top-level folder or are a
/// top-level file. Patterns and placeholders (`presets/<id>.toml`, `tests/*.rs`) are skipped; a
/// sentence's full stop is not part of the path.
fn paths_in(text: &str) -> Vec<PathBuf> {
    text.split(|c| !in_path(c))
        .map(|word| word.trim_end_matches('.'))
        .filter(|word| {
            FOLDERS.iter().any(|folder| word.starts_with(folder)) || FILES.contains(word)
        })
        .filter(|word| !word.contains(['<', '*', '{']))
        .map(PathBuf::from)
        .collect()
}

/// The local targets of a Markdown line's links, `[text](target)`, without their `#anchor`.
fn link_targets(text: &str) -> impl Iterator<Item = &str> {
    text.split("](").skip(1).filter_map(|rest| {
        let target = rest.split(')').next()?.split('#').next()?;
        (!target.is_empty() && !target.contains("://") && !target.starts_with("mailto:"))
            .then_some(target)
    })
}

/// The targets a line names after `--test`, `--bench` or `--bin`, as (kind, name).
fn targets_in(text: &str) -> Vec<(&'static str, &str)> {
    let mut named = Vec::new();
    for kind in ["test", "bench", "bin"] {
        let flag = format!("--{kind}");
        for (at, _) in text.match_indices(&flag) {
            let rest = &text[at + flag.len()..];
            let Some(rest) = rest.strip_prefix([' ', '=']) else {
                continue;
            };
            let name = rest
                .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == '-'))
                .next()
                .unwrap_or_default();
            if !name.is_empty() && !name.starts_with('-') {
                named.push((kind, name));
            }
        }
    }
    named
}

/// The names of Cargo.toml's `[[kind]]` targets.
fn target_names(manifest: &toml::Table, kind: &str) -> Vec<String> {
    manifest
        .get(kind)
        .and_then(|targets| targets.as_array())
        .into_iter()
        .flatten()
        .filter_map(|target| target.get("name")?.as_str().map(str::to_owned))
        .collect()
}

/// The comments of a Rust source (`//`, `///`, `//!`, `/* */`) by line number. String and
/// character literals are skipped, so a `//` inside a string is no comment.
fn comments(source: &str) -> BTreeMap<usize, String> {
    let chars: Vec<char> = source.chars().collect();
    // The line of each character.
    let line: Vec<usize> = chars
        .iter()
        .scan(1, |line, &c| {
            let here = *line;
            *line += usize::from(c == '\n');
            Some(here)
        })
        .collect();
    let ident =
        |at: Option<usize>| at.is_some_and(|at| chars[at].is_alphanumeric() || chars[at] == '_');
    let mut comments: BTreeMap<usize, String> = BTreeMap::new();
    let mut block_depth = 0;
    let mut i = 0;
    while i < chars.len() {
        let (c, next) = (chars[i], chars.get(i + 1).copied());
        if block_depth > 0 {
            match (c, next) {
                ('*', Some('/')) => (block_depth -= 1, i += 2),
                ('/', Some('*')) => (block_depth += 1, i += 2),
                _ => (comments.entry(line[i]).or_default().push(c), i += 1),
            };
        } else if c == '/' && next == Some('/') {
            let end = chars[i..]
                .iter()
                .position(|&c| c == '\n')
                .map_or(chars.len(), |n| i + n);
            comments
                .entry(line[i])
                .or_default()
                .extend(&chars[i + 2..end]);
            i = end;
        } else if c == '/' && next == Some('*') {
            block_depth = 1;
            i += 2;
        } else if c == '"' {
            // A string: up to the next quote not escaped.
            i += 1;
            while i < chars.len() && chars[i] != '"' {
                i += if chars[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
        } else if c == 'r'
            && matches!(next, Some('"' | '#'))
            && (!ident(i.checked_sub(1)) || (chars[i - 1] == 'b' && !ident(i.checked_sub(2))))
        {
            // A raw string, r"…" or r#"…"#: up to a quote followed by as many hashes.
            let hashes = chars[i + 1..].iter().take_while(|&&c| c == '#').count();
            if chars.get(i + 1 + hashes) != Some(&'"') {
                i += 1;
                continue;
            }
            let closing: Vec<char> = std::iter::once('"')
                .chain(std::iter::repeat_n('#', hashes))
                .collect();
            i += hashes + 2;
            while i < chars.len() && !chars[i..].starts_with(&closing) {
                i += 1;
            }
            i += closing.len();
        } else if c == '\'' {
            // A character literal ('x', '\n', '\u{…}'), or else a lifetime.
            if next == Some('\\') {
                i += 3;
                while i < chars.len() && chars[i] != '\'' {
                    i += 1;
                }
                i += 1;
            } else if chars.get(i + 2) == Some(&'\'') {
                i += 3;
            } else {
                i += 1;
            }
        } else {
            i += 1;
        }
    }
    comments
}
