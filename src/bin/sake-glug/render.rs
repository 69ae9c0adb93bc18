//! `sake-glug render`: a scene (or the built-in pour) to a WAV file, all or nothing.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use sake_glug::offline::{
    render_scene, RenderError, SampleFormat, Scene, SceneError, WavError, WavFile,
};

#[derive(Args)]
pub struct RenderArgs {
    /// Scene file (TOML, see MODEL.md §10); without it, the built-in default pour.
    scene: Option<PathBuf>,
    /// Where to write the WAV file.
    #[arg(short, long, default_value = "pour.wav")]
    output: PathBuf,
    /// Overrides the scene's sample rate (Hz).
    #[arg(long)]
    sample_rate: Option<f64>,
    /// Sample format of the WAV file: f32, s24 or s16.
    #[arg(long, default_value = "f32")]
    format: SampleFormat,
}

#[derive(Debug, thiserror::Error)]
enum RenderCommandError {
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    Render(#[from] RenderError),
    #[error(transparent)]
    Wav(#[from] WavError),
}

/// Runs the command; prints a one-line summary, or the error and exits 1.
pub fn run(args: RenderArgs) -> ExitCode {
    match render(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error}");
            ExitCode::FAILURE
        }
    }
}

fn render(args: RenderArgs) -> Result<(), RenderCommandError> {
    let mut scene = match &args.scene {
        Some(path) => Scene::load(path)?,
        None => Scene::default(),
    };
    if let Some(sample_rate) = args.sample_rate {
        scene = scene.with_sample_rate(sample_rate)?;
    }
    let progress = progress_bar(scene.duration_samples());
    let mut wav = WavFile::create(&args.output, scene.sample_rate, args.format)?;
    let summary = render_scene(
        &scene,
        |block| wav.write(block).map_err(RenderCommandError::from),
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
