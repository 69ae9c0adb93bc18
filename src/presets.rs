//! `sake-glug presets`: the starting points the plugin's preset menu offers, as scene files.

use std::process::ExitCode;

use clap::Args;

use sake_glug_engine::{Preset, PRESETS};
use sake_glug_io::text::quoted;
use sake_glug_render::Scene;

#[derive(Args, Debug)]
pub struct PresetsArgs {
    /// Prints this preset as a scene file; without it, lists every preset.
    name: Option<String>,
}

/// Lists the presets (`id  name: description`) or prints one as TOML.
pub fn run(args: PresetsArgs) -> ExitCode {
    match args.name {
        None => {
            for preset in &PRESETS {
                println!("{:<13} {}: {}", preset.id, preset.name, preset.description);
            }
            ExitCode::SUCCESS
        }
        Some(name) => match Preset::find(&name) {
            Some(preset) => {
                print!("{}", Scene::preset_toml(preset));
                ExitCode::SUCCESS
            }
            None => {
                eprintln!(
                    "error: no preset `{}`; `sake-glug presets` lists them",
                    quoted(&name)
                );
                ExitCode::from(2)
            }
        },
    }
}
