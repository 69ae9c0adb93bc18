//! What README.md and the guide (docs/guide/) show of the command line is the code's: each
//! generated block is the command's output, and every `sake-glug` command they write names
//! subcommands and options the command line has.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::command::sake_glug;

/// README.md and every page of the guide, relative to the repository's root.
fn pages() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut pages = vec![PathBuf::from("README.md")];
    let mut guide: Vec<PathBuf> = std::fs::read_dir(root.join("docs/guide"))
        .expect("docs/guide")
        .map(|entry| PathBuf::from("docs/guide").join(entry.unwrap().file_name()))
        .filter(|path| path.extension().is_some_and(|ext| ext == "md"))
        .collect();
    guide.sort();
    pages.extend(guide);
    pages
}

fn read(page: &Path) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(page))
        .unwrap_or_else(|error| panic!("{}: {error}", page.display()))
}

/// The text between `<!-- generated:NAME:begin -->` and its end marker, in whichever page holds
/// it (exactly one may), with that page.
fn generated_block(name: &str) -> (PathBuf, String) {
    let begin = format!("<!-- generated:{name}:begin -->\n");
    let end = format!("<!-- generated:{name}:end -->");
    let mut found: Vec<(PathBuf, String)> = pages()
        .into_iter()
        .filter_map(|page| {
            let text = read(&page);
            let start = text.find(&begin)? + begin.len();
            let stop = start + text[start..].find(&end).expect("an end marker");
            Some((page, text[start..stop].to_owned()))
        })
        .collect();
    assert_eq!(
        found.len(),
        1,
        "the block {name} must be on exactly one page"
    );
    found.pop().unwrap()
}

#[test]
fn the_parameter_table_is_the_codes() {
    let output = sake_glug(Path::new("."), &["parameters"]);
    assert!(output.status.success());
    let (page, block) = generated_block("parameters");
    assert_eq!(
        block,
        String::from_utf8(output.stdout).unwrap(),
        "{}'s table of parameters is stale (run `cargo xtask docs`)",
        page.display()
    );
}

#[test]
fn the_fidelity_table_is_the_codes() {
    let directory = tempfile::tempdir().unwrap();
    let output = sake_glug(
        directory.path(),
        &["render", "--fidelity", "-o", "pour.wav"],
    );
    assert!(output.status.success());
    let (page, block) = generated_block("fidelity");
    assert_eq!(
        block,
        String::from_utf8(output.stdout).unwrap(),
        "{}'s fidelity table is stale (run `cargo xtask docs`)",
        page.display()
    );
}

/// A command the pages write: where, and its words after `sake-glug`.
struct Written {
    place: String,
    words: Vec<String>,
}

/// Every `sake-glug …` command in the pages' code: the lines of fenced blocks (a line ending in
/// `\` continues on the next) and the inline code spans of each paragraph (a span may run over
/// lines). `cargo run --release -- ARGS` is `sake-glug ARGS`. A command ends at a shell comment,
/// a pipe, `&&` or `;`.
fn written_commands() -> Vec<Written> {
    let mut commands = Vec::new();
    for page in pages() {
        let text = read(&page);
        let mut fenced = false;
        let mut continued = String::new();
        // The paragraph being read outside the fences, and the line it starts on.
        let mut paragraph = (0, String::new());
        for (index, line) in text.lines().enumerate() {
            let mut code = Vec::new();
            let ends_paragraph = line.trim().is_empty() || line.trim_start().starts_with("```");
            if ends_paragraph || fenced {
                let (first, prose) = std::mem::take(&mut paragraph);
                code.extend(
                    prose
                        .split('`')
                        .skip(1)
                        .step_by(2)
                        .map(|span| (first, span.replace('\n', " "))),
                );
            }
            if line.trim_start().starts_with("```") {
                fenced = !fenced;
            } else if fenced {
                continued.push_str(line);
                if let Some(rest) = continued.strip_suffix('\\') {
                    continued = format!("{rest} ");
                } else {
                    code.push((index, std::mem::take(&mut continued)));
                }
            } else if !ends_paragraph {
                if paragraph.1.is_empty() {
                    paragraph.0 = index;
                }
                paragraph.1.push_str(line);
                paragraph.1.push('\n');
            }
            for (line_index, span) in code {
                let place = format!("{}:{}", page.display(), line_index + 1);
                commands.extend(commands_in(&span).into_iter().map(|words| Written {
                    place: place.clone(),
                    words,
                }));
            }
        }
    }
    commands
}

/// The words after each `sake-glug ` that starts a command in a piece of code.
fn commands_in(code: &str) -> Vec<Vec<String>> {
    let code = code.replace("cargo run --release -- ", "sake-glug ");
    code.match_indices("sake-glug ")
        .filter(|(at, _)| {
            code[..*at]
                .chars()
                .last()
                .is_none_or(|c| c.is_whitespace() || c == '(' || c == '$')
        })
        .map(|(at, _)| {
            code[at + "sake-glug ".len()..]
                .split(['#', '|', ';'])
                .next()
                .unwrap_or_default()
                .split("&&")
                .next()
                .unwrap_or_default()
                .split_whitespace()
                .map(str::to_owned)
                .collect()
        })
        .collect()
}

/// `sake-glug PATH… --help`, or None where that is no command.
fn help(path: &[String], cache: &mut BTreeMap<Vec<String>, Option<String>>) -> Option<String> {
    cache
        .entry(path.to_vec())
        .or_insert_with(|| {
            let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
            args.push("--help");
            let output = sake_glug(Path::new("."), &args);
            output
                .status
                .success()
                .then(|| String::from_utf8(output.stdout).unwrap())
        })
        .clone()
}

#[test]
fn every_command_the_pages_write_is_the_command_lines() {
    let mut cache = BTreeMap::new();
    let root_help = help(&[], &mut cache).expect("sake-glug --help");
    let (mut wrong, mut checked) = (Vec::new(), 0);
    for written in written_commands() {
        // The subcommands: the leading lower-case words whose help differs from their parent's.
        let mut path: Vec<String> = Vec::new();
        let mut path_help = root_help.clone();
        for word in &written.words {
            if !word.chars().all(|c| c.is_ascii_lowercase() || c == '-') || word.starts_with('-') {
                break;
            }
            let mut longer = path.clone();
            longer.push(word.clone());
            match help(&longer, &mut cache) {
                Some(text) if text != path_help => {
                    path = longer;
                    path_help = text;
                }
                _ => break,
            }
        }
        if path.is_empty()
            && !written
                .words
                .first()
                .is_some_and(|word| word.starts_with('-'))
        {
            wrong.push(format!(
                "{}: `sake-glug {}` names no subcommand",
                written.place,
                written.words.join(" ")
            ));
            continue;
        }
        for word in &written.words {
            let option = word
                .trim_start_matches('[')
                .split(['=', ']', ',', ')'])
                .next()
                .unwrap_or_default();
            if option.starts_with("--") && option.len() > 2 {
                checked += 1;
                let known = path_help.split(|c: char| !(c.is_ascii_alphanumeric() || c == '-'));
                if !known.clone().any(|name| name == option) {
                    wrong.push(format!(
                        "{}: `sake-glug {}` has no option {option}",
                        written.place,
                        path.join(" ")
                    ));
                }
            }
        }
    }
    assert!(
        checked > 50,
        "only {checked} options found: is the reader broken?"
    );
    assert!(
        wrong.is_empty(),
        "commands the pages write that the command line does not have:\n{}",
        wrong.join("\n")
    );
}
