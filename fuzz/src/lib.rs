//! The fuzz targets' code: what each target asserts ([`checks`], shared with the ordinary test
//! suite) and the saved state's structure-aware mutations ([`hostile_state`]).

// The CLAP host of the plugin tests: the state target drives the plugin through its entry point
// exactly as they do.
#[path = "../../tests/plugin/clap_host.rs"]
mod clap_host;

pub mod checks;
pub mod hostile_state;
