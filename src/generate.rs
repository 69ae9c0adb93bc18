//! `sake-glug generate` (hidden): the man pages and the shell completions that a release ships,
//! written from this command line's own clap definition, so they cannot drift from it.
//! `cargo xtask dist` runs it on the release binary it packages.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Subcommand};
use clap_complete::Shell;

#[derive(Args)]
pub struct GenerateArgs {
    #[command(subcommand)]
    what: What,
}

#[derive(Subcommand)]
enum What {
    /// A man page for the command and one for each subcommand (sake-glug.1,
    /// sake-glug-render.1, …), written into DIR.
    Man {
        #[arg(value_name = "DIR")]
        dir: PathBuf,
    },
    /// The completion script for SHELL, on stdout.
    Completion {
        #[arg(value_name = "SHELL")]
        shell: Shell,
    },
}

pub fn run(args: GenerateArgs) -> ExitCode {
    let command = crate::command();
    match args.what {
        What::Man { dir } => match clap_mangen::generate_to(command, &dir) {
            Ok(()) => ExitCode::SUCCESS,
            Err(error) => {
                eprintln!("error: man pages into {}: {error}", dir.display());
                ExitCode::FAILURE
            }
        },
        What::Completion { shell } => {
            // Into memory first: clap_complete panics on a write that fails.
            let mut script = Vec::new();
            clap_complete::generate(shell, &mut command.clone(), "sake-glug", &mut script);
            match std::io::stdout().write_all(&script) {
                Ok(()) => ExitCode::SUCCESS,
                Err(error) => {
                    eprintln!("error: the {shell} completion on stdout: {error}");
                    ExitCode::FAILURE
                }
            }
        }
    }
}
