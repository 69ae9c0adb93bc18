//! `sake-glug accuracy`: the error of every synthesis path against the f64 reference.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

use sake_glug_render::MAX_DURATION_S;
use sake_glug_reports::accuracy;

#[derive(Args, Debug)]
pub struct AccuracyArgs {
    /// Render lengths in seconds, as the default shows them (commas work too); each above 0 and
    /// at most a day.
    #[arg(
        long,
        num_args = 1..,
        value_delimiter = ',',
        default_values_t = accuracy::LENGTHS_S,
        value_parser = length_s
    )]
    lengths: Vec<f64>,
    /// Sample rate (Hz), a whole number in a scene's range.
    #[arg(long, default_value_t = 48_000.0, value_parser = crate::sample_rate_hz)]
    sample_rate: f64,
    /// Also draw the work-precision diagram to this PNG file.
    #[arg(long)]
    plot: Option<PathBuf>,
}

/// A render length: a number of seconds above 0 and at most [`MAX_DURATION_S`], as a scene's
/// render may last; anything else (`inf`, `nan`, `0`) is refused before a render starts.
fn length_s(text: &str) -> Result<f64, String> {
    let length: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number of seconds"))?;
    if length > 0.0 && length <= MAX_DURATION_S {
        Ok(length)
    } else {
        Err(format!(
            "{length} s is no render length: above 0 and at most {MAX_DURATION_S} s"
        ))
    }
}

/// Prints the accuracy table (Markdown) and draws the plot if asked; fails if any row is NaN or
/// the default path misses the budget of MODEL.md §9 at any of the lengths given.
pub fn run(args: AccuracyArgs) -> ExitCode {
    let cases = accuracy::cases();
    for case in &cases {
        eprintln!("case {}: {}", case.name, case.purpose);
    }
    let rows = accuracy::measure(&cases, &args.lengths, args.sample_rate, |row| {
        eprintln!(
            "  {} / {} / {}: max {:.1} dB, rms {:.1} dB, {:.0}× real time",
            row.case,
            row.path.name(),
            accuracy::length_label(row.length_s),
            row.max_error_db,
            row.rms_error_db,
            row.times_real_time
        );
    });
    print!("{}", accuracy::table(&rows));
    if let Some(file) = &args.plot {
        if let Err(error) = sake_glug_reports::draw_accuracy_plot(&rows, file) {
            eprintln!("error: {error}");
            return ExitCode::FAILURE;
        }
        eprintln!("plot written to {}", file.display());
    }
    let failures = accuracy::budget_failures(&rows);
    for failure in &failures {
        eprintln!("error: {failure}");
    }
    if failures.is_empty() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
