//! `sake-glug stability`: every case of the stability catalogue, or the catalogue itself.

use std::process::ExitCode;

use clap::Args;

use sake_glug_reports::stability::{self, Scale};

#[derive(Args, Debug)]
pub struct StabilityArgs {
    /// Runs the short lengths the test suite uses instead of the report's (24 h renders).
    #[arg(long)]
    quick: bool,
    /// Prints the catalogue of checks and cases (Markdown) and runs nothing.
    #[arg(long)]
    catalogue: bool,
}

/// Runs every stability case, prints what each checks and what it measured (Markdown); fails
/// if any case fails.
pub fn run(args: StabilityArgs) -> ExitCode {
    if args.catalogue {
        print!("{}", stability::catalogue());
        return ExitCode::SUCCESS;
    }
    let scale = if args.quick {
        Scale::Test
    } else {
        Scale::Report
    };
    let outcomes = stability::run_all(scale, |outcome| {
        eprintln!(
            "  {} {}: {}",
            if outcome.passed() { "ok  " } else { "FAIL" },
            outcome.name,
            outcome.summary()
        );
    });
    print!("{}", stability::report(&outcomes));
    if outcomes.iter().all(|outcome| outcome.passed()) {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
