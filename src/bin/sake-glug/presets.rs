//! `sake-glug presets`: the starting points the plugin's preset menu offers, as scene files, and
//! (`--vstpreset DIR`) as the VST3 preset files a host lists.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

use sake_glug::engine::{Preset, PRESETS};
use sake_glug::offline::Scene;

#[derive(Args, Debug)]
pub struct PresetsArgs {
    /// Prints this preset as a scene file; without it, lists every preset.
    name: Option<String>,
    /// Writes every preset as DIR/<name>.vstpreset, the state the VST3 plugin saves for it
    /// (needs a build with the `plugin` feature).
    #[arg(long, value_name = "DIR", conflicts_with = "name")]
    vstpreset: Option<PathBuf>,
}

/// Lists the presets (`id  name: description`), prints one as TOML, or writes the VST3 files.
pub fn run(args: PresetsArgs) -> ExitCode {
    if let Some(folder) = args.vstpreset {
        return write_vstpresets(&folder);
    }
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
                eprintln!("error: no preset `{name}`; `sake-glug presets` lists them");
                ExitCode::from(2)
            }
        },
    }
}

#[cfg(feature = "plugin")]
fn write_vstpresets(folder: &std::path::Path) -> ExitCode {
    match sake_glug::plugin::vstpreset::write_all(folder) {
        Ok(paths) => {
            for path in paths {
                println!("{} written", path.display());
            }
            ExitCode::SUCCESS
        }
        Err(error) => {
            eprintln!(
                "error: writing the presets into {}: {error}",
                folder.display()
            );
            ExitCode::FAILURE
        }
    }
}

#[cfg(not(feature = "plugin"))]
fn write_vstpresets(_folder: &std::path::Path) -> ExitCode {
    eprintln!(
        "error: this sake-glug was built without the plugin, whose state the files hold; \
         build it with `--features cli,plugin`"
    );
    ExitCode::from(2)
}
