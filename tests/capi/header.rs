//! include/sake_glug.h is what cbindgen makes of crates/capi/src/ today
//! (`SAKE_GLUG_WRITE_HEADER=1 cargo test --test capi header` rewrites it), and the header's
//! controls are the engine's, in the engine's order.

use std::path::Path;

use sake_glug::SakeGlugControl;
use sake_glug_engine::Control;

const HEADER: &str = "include/sake_glug.h";
const CRATE: &str = "crates/capi";

/// The header as cbindgen writes it from the C library's sources and settings.
fn generated_header() -> String {
    let config = cbindgen::Config::from_file(Path::new(CRATE).join("cbindgen.toml")).unwrap();
    let mut text = Vec::new();
    cbindgen::Builder::new()
        .with_config(config)
        .with_src(Path::new(CRATE).join("src/lib.rs"))
        .with_src(Path::new(CRATE).join("src/types.rs"))
        .generate()
        .expect("cbindgen reads crates/capi/src")
        .write(&mut text);
    String::from_utf8(text).unwrap()
}

#[test]
fn the_committed_header_is_current() {
    let generated = generated_header();
    if std::env::var_os("SAKE_GLUG_WRITE_HEADER").is_some() {
        std::fs::write(HEADER, &generated).unwrap();
    }
    let committed = std::fs::read_to_string(HEADER).unwrap_or_default();
    assert!(
        committed == generated,
        "{HEADER} is out of date: `SAKE_GLUG_WRITE_HEADER=1 cargo test --test capi header` \
         writes it again"
    );
    for function in ["sake_glug_create", "sake_glug_process", "sake_glug_units"] {
        assert!(
            committed.contains(&format!("{function}(")),
            "{function} is declared"
        );
    }
}

#[test]
fn the_headers_controls_are_the_engines_in_its_order() {
    let names = ["tilt", "visc", "fill", "pour", "gain"];
    for (index, control) in SakeGlugControl::ALL.into_iter().enumerate() {
        assert_eq!(control as usize, index);
        assert_eq!(
            Control::ALL[index].quantity().param_id,
            names[index],
            "{control:?}"
        );
        assert_eq!(
            SakeGlugControl::engine_control(index as i32),
            Some(Control::ALL[index])
        );
    }
    assert_eq!(
        SakeGlugControl::engine_control(Control::ALL.len() as i32),
        None
    );
}

/// The names `pattern` finds in `text`: the first capture of each line it matches.
fn names(text: &str, take: impl Fn(&str) -> Option<String>) -> Vec<String> {
    text.lines().filter_map(take).collect()
}

/// Compiles `source` (C or C++) against include/ with every warning an error; the compiler's
/// message if it refuses.
fn compile(compiler: &str, extension: &str, flags: &[&str], source: &str) -> Result<(), String> {
    let folder = tempfile::tempdir().unwrap();
    let file = folder.path().join(format!("uses_every_name.{extension}"));
    std::fs::write(&file, source).unwrap();
    let output = std::process::Command::new(compiler)
        .args(flags)
        .args(["-Wall", "-Wextra", "-Werror", "-Iinclude", "-c", "-o"])
        .arg(folder.path().join("out.o"))
        .arg(&file)
        .output()
        .unwrap_or_else(|error| panic!("{compiler}: {error} (CI installs gcc and g++)"));
    if output.status.success() {
        Ok(())
    } else {
        Err(String::from_utf8_lossy(&output.stderr).into_owned())
    }
}

/// Every macro and enum constant of sake_glug.h, and every control of sake_glug.hpp, used in a
/// C file and a C++ file that compile with -Wall -Wextra -Werror (a macro naming what the header
/// does not declare, as `SakeGlugControl_ALL` once did, fails here).
#[test]
fn every_name_of_the_headers_compiles_in_c_and_cpp() {
    let header = std::fs::read_to_string(HEADER).unwrap();
    let macros = names(&header, |line| {
        let name = line.strip_prefix("#define ")?.split_whitespace().next()?;
        (name != "SAKE_GLUG_H").then(|| name.to_owned())
    });
    let constants = names(&header, |line| {
        let name = line.trim().split(" = ").next()?;
        (line.contains(" = ") && name.starts_with("SAKE_GLUG_") && !line.contains('('))
            .then(|| name.to_owned())
    });
    assert!(
        macros.len() >= 5 && constants.len() >= 5,
        "{macros:?} {constants:?}"
    );
    let uses: String = macros
        .iter()
        .chain(&constants)
        .map(|name| format!("    (void)({name});\n"))
        .collect();
    let c = format!("#include \"sake_glug.h\"\nvoid uses_every_name(void);\nvoid uses_every_name(void) {{\n{uses}}}\n");
    compile("cc", "c", &["-std=c11"], &c).unwrap_or_else(|error| panic!("{error}\n{c}"));
    let cpp_header = std::fs::read_to_string("include/sake_glug.hpp").unwrap();
    let controls = names(&cpp_header, |line| {
        let name = line.trim().split(" = SAKE_GLUG_CONTROL_").next()?;
        line.contains(" = SAKE_GLUG_CONTROL_")
            .then(|| name.to_owned())
    });
    assert_eq!(controls.len(), Control::ALL.len(), "{controls:?}");
    let cpp_uses: String = controls
        .iter()
        .map(|name| format!("    (void)(sake_glug::Control::{name});\n"))
        .collect();
    let cpp = format!(
        "#include \"sake_glug.hpp\"\nvoid uses_every_name();\nvoid uses_every_name() {{\n{uses}{cpp_uses}}}\n"
    );
    compile("c++", "cpp", &["-std=c++17"], &cpp).unwrap_or_else(|error| panic!("{error}\n{cpp}"));
}
