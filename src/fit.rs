//! `sake-glug fit`: a model from recordings (MODEL.md §13); the work is in `sake_glug_fit`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

use sake_glug_fit::{fit_session, write_fit, FitOutputs, FitSession};

#[derive(Args)]
pub struct FitArgs {
    /// The session file (TOML): capacity_ml and the [[recording]]s (MODEL.md §13).
    session: PathBuf,
    /// The model of a session of one liquid: a scene file `sake-glug render` plays.
    #[arg(
        short,
        long = "output",
        value_name = "MODEL.toml",
        conflicts_with = "out_dir"
    )]
    output: Option<PathBuf>,
    /// Writes DIR/<liquid>.toml for every liquid of the session.
    #[arg(long, value_name = "DIR")]
    out_dir: Option<PathBuf>,
    /// The report: every estimate with its 95 % interval, the units used, the warnings.
    #[arg(long, value_name = "FIT.md")]
    report: Option<PathBuf>,
    /// The plot: unit fits, the spectrum, Asum against V, V(t) per tilt.
    #[arg(long, value_name = "FIT.png")]
    plot: Option<PathBuf>,
}

pub fn run(args: FitArgs) -> ExitCode {
    let outputs = FitOutputs {
        model: args.output,
        out_dir: args.out_dir,
        report: args.report,
        plot: args.plot,
    };
    if outputs == FitOutputs::default() {
        eprintln!("error: nothing to write: give -o MODEL.toml, --out-dir DIR, --report or --plot");
        return ExitCode::from(2);
    }
    let result = FitSession::load(&args.session)
        .and_then(|session| fit_session(&session))
        .and_then(|fit| Ok((write_fit(&fit, &outputs)?, fit)));
    match result {
        Ok((files, fit)) => {
            for liquid in &fit.liquids {
                eprintln!("{}: {} units fitted", liquid.liquid, liquid.units);
            }
            for warning in &fit.warnings {
                eprintln!("warning: {warning}");
            }
            for (path, bytes) in files {
                eprintln!("wrote {} ({bytes} bytes)", path.display());
            }
            ExitCode::SUCCESS
        }
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::FAILURE
        }
    }
}
