//! `sake-glug`: the offline renderer and the reports on the command line. One file per
//! subcommand; the work is in the library, which knows nothing of `clap`.

mod accuracy;
mod analyze;
mod experiment;
mod fit;
mod generate;
mod measure_actuator;
mod parameters;
mod presets;
mod render;
mod stability;

use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};

use sake_glug_render::Scene;

#[derive(Parser)]
#[command(
    name = "sake-glug",
    version,
    about = "The glug of a poured sake bottle, rendered offline"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Renders a scene file (or the built-in pour) to a mono WAV file.
    Render(Box<render::RenderArgs>),
    /// Error against run time of every synthesis path (MODEL.md §9); see docs/accuracy.md.
    Accuracy(accuracy::AccuracyArgs),
    /// Stiff and extreme cases: finite, bounded, no slow-down; see docs/stability.md.
    Stability(stability::StabilityArgs),
    /// Lists the presets, or prints one as a scene file.
    Presets(presets::PresetsArgs),
    /// Every control and model constant: parameter id, pedalboard key, scene key, range, step
    /// and default.
    Parameters(parameters::ParametersArgs),
    /// Fits a model (a scene file) to recordings of a bottle: see MODEL.md §13.
    Fit(fit::FitArgs),
    /// Analyses study logs (Thurstone scaling of paired comparisons, a psychometric fit of
    /// constant stimuli, discrimination), or plans a study by simulation.
    Analyze(analyze::AnalyzeArgs),
    /// Runs a listening study's session for one participant (its summary is written from the
    /// designs' list: [`experiment::with_designs`]).
    Experiment(experiment::ExperimentArgs),
    /// Measures an actuator's response on a JACK server (stepped sines out, its accelerometer
    /// in) and writes its profile: see MODEL.md §18.1.
    MeasureActuator(measure_actuator::MeasureActuatorArgs),
    /// The man pages and shell completions of a release (for `cargo xtask dist`).
    #[command(hide = true)]
    Generate(generate::GenerateArgs),
}

/// A `--sample-rate` as a scene's `sample_rate` is checked (in range, whole), refused by the
/// command line (exit status 2) before anything is rendered.
fn sample_rate_hz(text: &str) -> Result<f64, String> {
    let sample_rate: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number of Hz"))?;
    Scene::default()
        .with_sample_rate(sample_rate)
        .map(|_| sample_rate)
        .map_err(|error| error.to_string())
}

/// The command line as `--help`, the man pages and the completions show it: clap's definition
/// with the help written from the code's own lists (the study's designs).
pub fn command() -> clap::Command {
    Cli::command().mut_subcommand("experiment", experiment::with_designs)
}

fn main() -> ExitCode {
    let cli = Cli::from_arg_matches(&command().get_matches()).unwrap_or_else(|error| error.exit());
    match cli.command {
        Command::Render(args) => render::run(*args),
        Command::Accuracy(args) => accuracy::run(args),
        Command::Stability(args) => stability::run(args),
        Command::Presets(args) => presets::run(args),
        Command::Parameters(args) => parameters::run(args),
        Command::Fit(args) => fit::run(args),
        Command::Analyze(args) => analyze::run(args),
        Command::Experiment(args) => experiment::run(args),
        Command::MeasureActuator(args) => measure_actuator::run(args),
        Command::Generate(args) => generate::run(args),
    }
}
