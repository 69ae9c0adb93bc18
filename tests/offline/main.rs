//! The offline renderer: scene files, the `sake-glug` command line, the same samples on every
//! run and at every block size, and what a render leaves on disk and holds in memory.

#[path = "../support/mod.rs"]
mod support;

mod actuator;
mod cli;
mod clip_rules;
mod clips_rendered;
mod command;
mod determinism;
mod every_input;
mod files;
mod fuzz;
mod guide;
// FIFOs, devices and links as Unix makes them.
#[cfg(unix)]
mod inputs;
mod levels;
mod memory;
mod model_files;
mod presets;
mod research_fuzz;
mod scene_files;
mod study;
mod tables;
mod takes;
mod variations;
