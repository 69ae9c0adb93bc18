//! `sake-glug fit`: a model from recordings (MODEL.md §13): a session file, or WAV clips alone;
//! the work is in `sake_glug_fit`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

use sake_glug_fit::{fit_json, fit_session, write_fit, FitError, FitOutputs, FitSession};

#[derive(Args)]
pub struct FitArgs {
    /// A session file (TOML: capacity_ml and the [[recording]]s, MODEL.md §13), or one or more
    /// WAV clips of one bottle held at one tilt, full at each clip's first sample.
    #[arg(value_name = "SESSION.toml | CLIP.wav", required = true)]
    inputs: Vec<PathBuf>,
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
    /// The report: every estimate with its 95 % interval (or why it has none), the units
    /// detected and used, the energy they explain, the warnings.
    #[arg(long, value_name = "FIT.md")]
    report: Option<PathBuf>,
    /// The plot: unit fits, the spectrum, Asum against V, V(t) per tilt.
    #[arg(long, value_name = "FIT.png")]
    plot: Option<PathBuf>,
    /// A row per detected unit: its fit, whether it was used and why not.
    #[arg(long, value_name = "UNITS.csv")]
    units: Option<PathBuf>,
    /// The first recording beside the fitted model's render: waveforms, spectra, units.
    #[arg(long, value_name = "COMPARE.png")]
    compare: Option<PathBuf>,
    /// Prints the fit as one JSON object on stdout (units, energy explained, estimates).
    #[arg(long)]
    json: bool,
    /// Clips only: the bottle's capacity (ml; default the model's).
    #[arg(long, value_name = "ML")]
    capacity_ml: Option<f64>,
    /// Clips only: the tilt the bottle was held at (degrees; default 135).
    #[arg(long, value_name = "DEG")]
    tilt_deg: Option<f64>,
}

pub fn run(args: FitArgs) -> ExitCode {
    let outputs = FitOutputs {
        model: args.output,
        out_dir: args.out_dir,
        report: args.report,
        plot: args.plot,
        units: args.units,
        compare: args.compare,
    };
    if outputs == FitOutputs::default() && !args.json {
        eprintln!(
            "error: nothing to write: give -o MODEL.toml, --out-dir DIR, --report, --plot, \
             --units, --compare or --json"
        );
        return ExitCode::from(2);
    }
    let session = FitSession::from_inputs(&args.inputs, args.capacity_ml, args.tilt_deg);
    // Inputs that make no one fit are a usage error, as clap's own.
    if let Err(error @ FitError::Inputs(_)) = &session {
        eprintln!("error: {error}");
        return ExitCode::from(2);
    }
    let result = session
        .and_then(|session| fit_session(&session))
        .and_then(|fit| Ok((write_fit(&fit, &outputs)?, fit)));
    match result {
        Ok((files, fit)) => {
            for recording in &fit.recordings {
                eprintln!(
                    "{}: {} audible glug units, {} used, explaining {:.0} % of its energy",
                    sake_glug_io::text::printable(&recording.name()),
                    recording.detected.len(),
                    recording.units.len(),
                    100.0 * recording.explained.max(0.0)
                );
            }
            for liquid in &fit.liquids {
                eprintln!(
                    "{}: {} audible glug units fitted",
                    liquid.liquid, liquid.units
                );
            }
            for warning in &fit.warnings {
                eprintln!("warning: {}", sake_glug_io::text::printable(warning));
            }
            for (path, bytes) in files {
                eprintln!("wrote {} ({bytes} bytes)", path.display());
            }
            if args.json {
                println!("{}", fit_json(&fit));
            }
            ExitCode::SUCCESS
        }
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::FAILURE
        }
    }
}
