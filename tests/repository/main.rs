//! No pointer to nowhere: every repository path that README.md, docs/*.md and the comments of the
//! code name exists, every `--test`, `--bench` and `--bin` names a target of a manifest, and the
//! map of the code (docs/code-map.md) puts every source file of `src/` and `crates/` where it is;
//! and the generated docs/paper.md has every row filled.
//!
//! It reads files only, so it needs none of the crate's features.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// How a repository path starts: one of the top-level folders, or it is a top-level file.
const FOLDERS: [&str; 16] = [
    "src/",
    "actuators/",
    "crates/",
    "include/",
    "bindings/",
    "examples/",
    "fuzz/",
    "tests/",
    "docs/",
    "benches/",
    "xtask/",
    "presets/",
    "experiments/",
    "python/",
    "web/",
    ".ci/",
];
const FILES: [&str; 9] = [
    "README.md",
    "Cargo.toml",
    "Cargo.lock",
    "bundler.toml",
    "rustfmt.toml",
    "LICENSE",
    "CHANGELOG.md",
    "about.toml",
    "about.hbs",
];

/// The folders whose Rust sources' comments are read.
const CODE: [&str; 6] = ["src", "crates", "tests", "benches", "xtask", "python/src"];

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

/// Installing the wheel fetches its dependencies from PyPI (issue 49): README.md's Python install
/// line names each one python/pyproject.toml declares, and PyPI.
#[test]
fn the_python_install_line_names_what_pip_fetches() {
    let pyproject: toml::Table = toml::from_str(&read(Path::new("python/pyproject.toml"))).unwrap();
    let dependencies = pyproject["project"]["dependencies"]
        .as_array()
        .expect("a list of dependencies");
    let readme = read(Path::new("README.md"));
    let start = readme
        .find("- **Python:**")
        .expect("README's Python install line");
    let line = &readme[start..];
    let line = line[..line.find("\n\n").unwrap_or(line.len())].to_lowercase();
    assert!(line.contains("pypi"), "{line}");
    for dependency in dependencies {
        let name = dependency.as_str().unwrap();
        let name = name
            .split(|c: char| !(c.is_ascii_alphanumeric() || "-_.".contains(c)))
            .next()
            .unwrap()
            .to_lowercase();
        assert!(
            line.contains(&name),
            "README's Python install line names no {name}: {line}"
        );
    }
}

/// The guide is written for someone who installed a package: no user page shows a command or a
/// path of a source build (`cargo run`, `target/release`); those are the developer page's. The
/// README says the tarball unpacks into a folder and that `~/.local/bin` must be on PATH.
#[test]
fn the_user_pages_of_the_guide_name_no_source_build() {
    const SOURCE_BUILD: [&str; 2] = ["cargo run", "target/release"];
    let pages: Vec<PathBuf> = files_under("docs/guide", "md")
        .into_iter()
        .filter(|page| page.file_name() != Some("developer.md".as_ref()))
        .collect();
    assert!(pages.len() > 3, "no guide pages found: {pages:?}");
    let mut found = Vec::new();
    for page in &pages {
        for (number, line) in read(page).lines().enumerate() {
            for source_build in SOURCE_BUILD.iter().filter(|s| line.contains(*s)) {
                found.push(format!("{}:{}: {source_build}", page.display(), number + 1));
            }
        }
    }
    assert!(
        found.is_empty(),
        "user pages of the guide name a source build (move it to developer.md):\n{}",
        found.join("\n")
    );
    let readme = read(Path::new("README.md"));
    for said in ["unpacks into the folder", "~/.local/bin", "PATH"] {
        assert!(
            readme.contains(said),
            "README's install says nothing of {said}"
        );
    }
}

/// A link to a heading (`page.md#anchor`, or `#anchor` within a page) finds it: every heading of
/// README.md and docs/ is an anchor as GitHub makes it (lower case, spaces to hyphens, other
/// punctuation left out), and the pages link to one another by those.
#[test]
fn every_link_between_pages_resolves_to_its_heading() {
    let (mut broken, mut checked) = (Vec::new(), 0);
    for line in prose().iter().filter(|line| line.file.ends_with(".md")) {
        for (target, anchor) in link_anchors(&line.text) {
            checked += 1;
            let page = if target.is_empty() {
                PathBuf::from(&line.file)
            } else {
                Path::new(&line.file)
                    .parent()
                    .unwrap_or(Path::new(""))
                    .join(target)
            };
            let headings = headings(&read(&page));
            if !headings.iter().any(|heading| anchor_of(heading) == anchor) {
                broken.push(format!(
                    "{}:{}: {}#{anchor} has no such heading",
                    line.file,
                    line.number,
                    page.display()
                ));
            }
        }
    }
    assert!(
        checked > 0,
        "no link to a heading found: the scan is broken"
    );
    assert!(broken.is_empty(), "{}", broken.join("\n"));
}

/// The headings of a Markdown page, outside its fenced code.
fn headings(page: &str) -> Vec<String> {
    let mut fenced = false;
    let mut found = Vec::new();
    for line in page.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        } else if !fenced && line.starts_with('#') {
            found.push(line.trim_start_matches('#').trim().to_owned());
        }
    }
    found
}

/// A heading's anchor as GitHub makes it.
fn anchor_of(heading: &str) -> String {
    heading
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || matches!(c, ' ' | '-' | '_'))
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The local links of a Markdown line that name a heading, as (page, anchor); the page is empty
/// for a heading of the same page.
fn link_anchors(text: &str) -> impl Iterator<Item = (&str, &str)> {
    text.split("](").skip(1).filter_map(|rest| {
        let target = rest.split(')').next()?;
        let (page, anchor) = target.split_once('#')?;
        (!page.contains("://") && (page.is_empty() || page.ends_with(".md")))
            .then_some((page, anchor))
    })
}

/// A fixture git ignores passes every local run and is missing from every clone (the real
/// recordings were, behind `*.wav`): nothing under tests/fixtures may be ignored and untracked.
#[test]
fn every_fixture_is_in_the_repository() {
    let output = std::process::Command::new("git")
        .args([
            "ls-files",
            "--others",
            "--ignored",
            "--exclude-standard",
            "--",
            "tests/fixtures",
        ])
        .current_dir(ROOT)
        .output()
        .expect("git runs (the test reads what the repository holds)");
    assert!(output.status.success(), "git ls-files failed: {output:?}");
    let ignored = String::from_utf8_lossy(&output.stdout);
    assert!(
        ignored.trim().is_empty(),
        "fixtures git ignores, so a clone lacks them (see .gitignore):\n{ignored}"
    );
}

#[test]
fn every_cargo_target_named_exists() {
    // The root manifest and every crate's: a `--bin` may be the plugin crate's app.
    let manifests: Vec<toml::Table> = std::iter::once(PathBuf::from("Cargo.toml"))
        .chain(
            std::fs::read_dir(Path::new(ROOT).join("crates"))
                .expect("crates/")
                .map(|entry| entry.expect("a crate").path().join("Cargo.toml")),
        )
        .map(|path| {
            std::fs::read_to_string(Path::new(ROOT).join(&path))
                .unwrap_or_else(|error| panic!("{}: {error}", path.display()))
                .parse()
                .unwrap_or_else(|error| panic!("{}: {error}", path.display()))
        })
        .collect();
    let (mut stale, mut checked) = (Vec::new(), 0);
    for line in prose() {
        for (kind, name) in targets_in(&line.text) {
            checked += 1;
            let known: Vec<String> = manifests
                .iter()
                .flat_map(|manifest| target_names(manifest, kind))
                .collect();
            if !known.contains(&name.to_owned()) {
                stale.push(format!(
                    "{}:{}: `--{kind} {name}` names no [[{kind}]] of a manifest ({})",
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

/// docs/paper.md is written by `cargo xtask docs paper` (xtask/src/paper.rs): every section of
/// the paper it compares is there, and every row of its tables has a figure in each column and a
/// verdict, none of them NaN or infinite (a run that failed half-way, or a value lost, shows).
#[test]
fn the_papers_numbers_are_generated_with_every_row_filled() {
    let page = read(Path::new("docs/paper.md"));
    assert!(
        page.contains("Generated by `cargo xtask docs`"),
        "docs/paper.md has no stamp: regenerate it with `cargo xtask docs paper`"
    );
    let sections = [
        "## §3 Paired comparison",
        "## §4.4 Constant stimuli",
        "## §5, fig. 7",
        "## §3.1 The 5 s pour",
        "## §4.3, §5, eq. 2",
        "## The product's defaults",
    ];
    for section in sections {
        assert!(page.contains(section), "docs/paper.md has no {section:?}");
    }
    let verdicts = [
        "reproduced",
        "close",
        "differs",
        "not comparable",
        "the model fits",
        "the model does not fit",
        "derived",
    ];
    let mut rows = 0;
    for (number, line) in page.lines().enumerate() {
        let Some(inner) = line.strip_prefix('|').and_then(|l| l.strip_suffix('|')) else {
            continue;
        };
        let cells: Vec<&str> = inner.split('|').map(str::trim).collect();
        if cells
            .iter()
            .all(|cell| cell.chars().all(|c| "-: ".contains(c)))
            || cells.first() == Some(&"quantity")
            || cells.first() == Some(&"point")
        {
            continue;
        }
        rows += 1;
        let place = format!("docs/paper.md:{}: {line}", number + 1);
        assert!(cells.len() >= 4, "{place}: too few columns");
        for cell in &cells {
            assert!(!cell.is_empty(), "{place}: an empty cell");
            let lower = cell.to_lowercase();
            assert!(
                !lower
                    .split(|c: char| !c.is_alphanumeric())
                    .any(|word| word == "nan" || word == "inf"),
                "{place}: a number that is none"
            );
        }
        let verdict = cells.last().unwrap();
        assert!(
            verdicts.iter().any(|known| verdict.starts_with(known)),
            "{place}: no verdict"
        );
    }
    assert!(
        rows >= 25,
        "docs/paper.md has {rows} rows: the tables were cut short"
    );
}

#[test]
fn the_code_map_puts_every_source_file_where_it_is() {
    let map = code_map();
    assert!(map.len() > 10, "the map was not found: the scan is broken");
    let mut wrong = Vec::new();
    // Each file of src/ and crates/ is named by the deepest entry that holds it: its own line,
    // or its folder's, whose text lists it. A folder's `mod.rs` is its front door, which the
    // map's preamble names once for all.
    let sources = files_under("src", "rs")
        .into_iter()
        .chain(files_under("crates", "rs"));
    for file in sources {
        let file = file.display().to_string();
        let Some(entry) = map
            .iter()
            .filter(|entry| {
                entry.path == file || (entry.is_folder() && file.starts_with(&entry.path))
            })
            .max_by_key(|entry| entry.path.len())
        else {
            wrong.push(format!("{file}: no entry of the map holds it"));
            continue;
        };
        let name = file.rsplit('/').next().unwrap_or(&file);
        if entry.path != file && name != "mod.rs" && !entry.names().any(|named| named == name) {
            wrong.push(format!(
                "{file}: {MAP}:{} ({}) does not name {name}",
                entry.line, entry.path
            ));
        }
    }
    // Each file a folder's entry names is in that folder, at some depth.
    for entry in map.iter().filter(|entry| entry.is_folder()) {
        let held = files_under(&entry.path, "rs");
        for named in entry.names() {
            let here = held
                .iter()
                .any(|file| file.file_name().is_some_and(|file| file == named));
            if !here {
                wrong.push(format!(
                    "{MAP}:{}: {named} is not in {}",
                    entry.line, entry.path
                ));
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "the map of the code ({MAP}) is wrong in {} places:\n{}",
        wrong.len(),
        wrong.join("\n")
    );
}

/// The map of the code.
const MAP: &str = "docs/code-map.md";

/// One entry of the map of `src/` and `crates/`: a folder (ending in `/`) or a file, the line it
/// starts on, and its text with the lines that continue it.
struct MapEntry {
    path: String,
    line: usize,
    text: String,
}

impl MapEntry {
    fn is_folder(&self) -> bool {
        self.path.ends_with('/')
    }

    /// The Rust file names the entry's text gives (`bottle.rs`), without a folder.
    fn names(&self) -> impl Iterator<Item = &str> {
        self.text
            .split(|c: char| !(c.is_ascii_alphanumeric() || "_-./".contains(c)))
            .filter(|word| word.ends_with(".rs") && !word.contains('/'))
    }
}

/// The entries of the map under `src/` and `crates/`: the fenced block after "## The map",
/// where a top-level entry starts in the first column, an entry inside a folder's two spaces in,
/// and a line further in continues the entry above.
fn code_map() -> Vec<MapEntry> {
    let map = read(Path::new(MAP));
    let lines: Vec<&str> = map.lines().collect();
    let heading = lines
        .iter()
        .position(|line| *line == "## The map")
        .expect("the code map has a \"## The map\" section");
    let fence = heading
        + lines[heading..]
            .iter()
            .position(|line| line.starts_with("```"))
            .expect("the section has a fenced map");
    let (mut entries, mut folder) = (Vec::<MapEntry>::new(), String::new());
    for (index, line) in lines.iter().enumerate().skip(fence + 1) {
        if line.starts_with("```") {
            break;
        }
        let indent = line.len() - line.trim_start().len();
        let (first, rest) = line
            .trim_start()
            .split_once(' ')
            .unwrap_or((line.trim_start(), ""));
        let path = match indent {
            0 => {
                folder = if first.ends_with('/') {
                    first.to_owned()
                } else {
                    String::new()
                };
                first.to_owned()
            }
            2 => format!("{folder}{first}"),
            _ => {
                if let Some(entry) = entries.last_mut() {
                    entry.text.push(' ');
                    entry.text.push_str(line.trim());
                }
                continue;
            }
        };
        entries.push(MapEntry {
            path,
            line: index + 1,
            text: rest.trim().to_owned(),
        });
    }
    entries.retain(|entry| entry.path.starts_with("src/") || entry.path.starts_with("crates/"));
    entries
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

/// The names of a manifest's `[[kind]]` targets.
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
