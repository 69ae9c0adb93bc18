//! The `accuracy` and `stability` commands of the `sake-glug` CLI: their arguments and what they
//! print. The measuring is in [`crate::accuracy`] and [`crate::stability`].

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

use crate::accuracy;
use crate::stability;

#[derive(Args, Debug)]
pub struct AccuracyArgs {
    /// Render lengths in seconds.
    #[arg(long, value_delimiter = ',', default_values_t = accuracy::LENGTHS_S)]
    pub lengths: Vec<f64>,
    /// Sample rate (Hz).
    #[arg(long, default_value_t = 48_000.0)]
    pub sample_rate: f64,
    /// Also draw the work-precision diagram to this PNG file.
    #[arg(long)]
    pub plot: Option<PathBuf>,
}

/// Prints the accuracy table (Markdown) and draws the plot if asked; fails if the default path
/// misses the budget of MODEL.md §9 at any length of an hour or more.
pub fn accuracy(args: AccuracyArgs) -> ExitCode {
    let scenes = accuracy::scenes();
    for scene in &scenes {
        eprintln!("scene {}: {}", scene.name, scene.purpose);
    }
    let rows = accuracy::measure(&scenes, &args.lengths, args.sample_rate, |row| {
        eprintln!(
            "  {} / {} / {}: max {:.1} dB, rms {:.1} dB, {:.0}× real time",
            row.scene,
            row.path.name(),
            accuracy::length_label(row.length_s),
            row.max_error_db,
            row.rms_error_db,
            row.times_real_time
        );
    });
    print!("{}", accuracy::table(&rows));
    if let Some(file) = &args.plot {
        if let Err(error) = accuracy::plot(&rows, file) {
            eprintln!("error: the plot could not be drawn: {error}");
            return ExitCode::FAILURE;
        }
        eprintln!("plot written to {}", file.display());
    }
    let over_budget = rows.iter().any(|row| {
        row.path == accuracy::Path::Default && row.length_s >= 3600.0 && row.max_error_db >= -100.0
    });
    if over_budget {
        eprintln!("error: the default path is above −100 dB on an hour-long render");
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}

#[derive(Args, Debug)]
pub struct StabilityArgs {
    /// Runs the short lengths the test suite uses instead of the report's (24 h renders).
    #[arg(long)]
    pub quick: bool,
}

/// Runs every stability case, prints what each checks and what it measured (Markdown); fails
/// if any case fails.
pub fn stability(args: StabilityArgs) -> ExitCode {
    let scale = if args.quick {
        stability::Scale::Test
    } else {
        stability::Scale::Report
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
    if outcomes.iter().all(|o| o.passed()) {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
