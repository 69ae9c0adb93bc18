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
