//! What the README shows that the code writes: each generated block is the command's output.

use std::path::Path;

use crate::command::sake_glug;

/// The text between `<!-- generated:NAME:begin -->` and its end marker in README.md.
fn generated_block(name: &str) -> String {
    let readme = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md"))
        .expect("README.md");
    let begin = format!("<!-- generated:{name}:begin -->\n");
    let end = format!("<!-- generated:{name}:end -->");
    let start = readme.find(&begin).expect("begin marker") + begin.len();
    let stop = start + readme[start..].find(&end).expect("end marker");
    readme[start..stop].to_owned()
}

#[test]
fn the_parameter_table_is_the_codes() {
    let output = sake_glug(Path::new("."), &["parameters"]);
    assert!(output.status.success());
    assert_eq!(
        generated_block("parameters"),
        String::from_utf8(output.stdout).unwrap(),
        "README.md's table of parameters is stale (run `cargo xtask docs`)"
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
    assert_eq!(
        generated_block("fidelity"),
        String::from_utf8(output.stdout).unwrap(),
        "README.md's fidelity table is stale (run `cargo xtask docs`)"
    );
}
