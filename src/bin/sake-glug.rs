//! The offline renderer's command line.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use sake_glug::render::{self, RenderError};
use sake_glug::scene::{Scene, SceneError};
use sake_glug::wav::{SampleFormat, WavError, WavFile};

#[derive(Parser)]
#[command(name = "sake-glug", version, about = "The glug of a poured sake bottle, rendered offline")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Renders a scene file (or the built-in pour) to a mono WAV file.
    Render(RenderArgs),
    /// Error against run time of every synthesis path (MODEL.md §9); see docs/accuracy.md.
    Accuracy(sake_glug::report_cli::AccuracyArgs),
    /// Stiff and extreme cases: finite, bounded, no slow-down; see docs/stability.md.
    Stability(sake_glug::report_cli::StabilityArgs),
}

#[derive(Args)]
struct RenderArgs {
    /// Scene file (TOML, see MODEL.md §10); without it, the built-in default pour.
    scene: Option<PathBuf>,
    /// Where to write the WAV file.
    #[arg(short, long, default_value = "pour.wav")]
    output: PathBuf,
    /// Overrides the scene's sample rate (Hz).
    #[arg(long)]
    sample_rate: Option<f64>,
    /// Sample format of the WAV file.
    #[arg(long, value_enum, default_value_t = SampleFormat::F32)]
    format: SampleFormat,
}

#[derive(Debug, thiserror::Error)]
enum CliError {
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    Render(#[from] RenderError),
    #[error(transparent)]
    Wav(#[from] WavError),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => run_render(args),
        Command::Accuracy(args) => return sake_glug::report_cli::accuracy(args),
        Command::Stability(args) => return sake_glug::report_cli::stability(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::FAILURE
        }
    }
}

fn run_render(args: RenderArgs) -> Result<(), CliError> {
    let mut scene = match &args.scene {
        Some(path) => Scene::load(path)?,
        None => Scene::default(),
    };
    if let Some(sample_rate) = args.sample_rate {
        scene = scene.with_sample_rate(sample_rate)?;
    }
    let progress = progress_bar(scene.duration_samples());
    let mut wav = WavFile::create(&args.output, scene.sample_rate, args.format)?;
    let summary = render::render(
        &scene,
        |block| wav.write(block).map_err(CliError::from),
        |done| progress.set_position(done),
    )?;
    progress.finish_and_clear();
    wav.commit()?;
    println!(
        "{}: {:.2} s at {} Hz, {} glug units, peak {:.1} dBFS, {:.0}× faster than real time",
        args.output.display(),
        summary.duration_s(),
        summary.sample_rate,
        summary.units,
        20.0 * (summary.peak.max(1e-12) as f64).log10(),
        summary.realtime_factor(),
    );
    Ok(())
}

/// A progress bar on a terminal; nothing at all when stderr is redirected.
fn progress_bar(total_samples: Option<u64>) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = match total_samples {
        Some(total) => ProgressBar::new(total),
        None => ProgressBar::new_spinner(),
    };
    bar.set_draw_target(ProgressDrawTarget::stderr());
    if let Ok(style) = ProgressStyle::with_template("{bar:40} {percent:>3}% {msg}") {
        bar.set_style(style);
    }
    bar
}
