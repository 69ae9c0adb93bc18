//! `sake-glug measure-actuator`: measures a device's response on a JACK server and writes its
//! profile (MODEL.md §18.1).

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;
use sake_glug_actuator::measure::{MeasureError, Measured, Plan, NOISY_BELOW_DB};
use sake_glug_actuator::ActuatorProfile;
use sake_glug_io::pending::{PendingFile, WriteError};
use sake_glug_io::text::quoted;

/// Why a build without the `audio` feature measures nothing.
const NO_AUDIO: &str = "this build plays no audio: build it with `--features audio` (JACK)";

/// The JACK client's name unless `--client-name` gives one.
const CLIENT_NAME: &str = "sake-glug-measure";

#[derive(Args)]
pub struct MeasureActuatorArgs {
    /// The profile to write (TOML), all or nothing.
    #[arg(short, long)]
    output: PathBuf,
    /// The profile's name [default: the output's file name without its extension].
    #[arg(long)]
    name: Option<String>,
    /// The lowest step (Hz).
    #[arg(long, default_value_t = 20.0)]
    from: f64,
    /// The highest step (Hz).
    #[arg(long, default_value_t = 1000.0)]
    to: f64,
    /// Steps to an octave, spaced evenly in log frequency, both ends included.
    #[arg(long, default_value_t = 3.0)]
    per_octave: f64,
    /// The drive's peak (dBFS).
    #[arg(long, default_value_t = -12.0, allow_negative_numbers = true)]
    level: f64,
    /// Skipped at each step's start (s): the interface's round trip and the device's transient.
    #[arg(long, default_value_t = 0.25)]
    settle: f64,
    /// Analysed at each step after the settling (s): at least 8 periods of the lowest step.
    #[arg(long, default_value_t = 0.5)]
    measure: f64,
    /// Measures every step this many times; from 2, the profile gives each point's spread
    /// (`spread_db`: the largest less the smallest level).
    #[arg(long, default_value_t = 1)]
    repeat: usize,
    /// The largest drive the device takes (linear, of full scale), written as `max_amplitude`.
    #[arg(long, default_value_t = 1.0)]
    max_amplitude: f64,
    /// The JACK port the drive plays to [default: the first physical playback port].
    #[arg(long, value_name = "PORT")]
    play_to: Option<String>,
    /// The JACK port the accelerometer is recorded from [default: the first physical capture
    /// port].
    #[arg(long, value_name = "PORT")]
    record_from: Option<String>,
    /// The JACK client's name.
    #[arg(long, default_value = CLIENT_NAME)]
    client_name: String,
    /// Freewheels the JACK server while measuring: it runs each cycle when every client has
    /// finished the last, not on a clock, for a device that is itself a JACK client (a model, a
    /// simulation). Not for hardware: a freewheeling server leaves its sound card.
    #[arg(long)]
    freewheel: bool,
}

#[derive(Debug, thiserror::Error)]
enum Failure {
    #[error(transparent)]
    Measure(#[from] MeasureError),
    #[error(transparent)]
    Write(#[from] WriteError),
    #[error("the measured profile is refused: {0}")]
    Profile(String),
}

pub fn run(args: MeasureActuatorArgs) -> ExitCode {
    match measure(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err((status, error)) => {
            eprintln!("error: {error}");
            ExitCode::from(status)
        }
    }
}

fn measure(args: &MeasureActuatorArgs) -> Result<(), (u8, Failure)> {
    let usage = |error: MeasureError| (2, Failure::from(error));
    if !cfg!(feature = "audio") {
        return Err(usage(MeasureError::Audio(NO_AUDIO.into())));
    }
    let plan = Plan::stepped(
        args.from,
        args.to,
        args.per_octave,
        10f64.powf(args.level / 20.0),
        args.settle,
        args.measure,
        args.repeat,
    )
    .map_err(usage)?;
    let name = match &args.name {
        Some(name) => name.clone(),
        None => args
            .output
            .file_stem()
            .map(|stem| stem.to_string_lossy().into_owned())
            .unwrap_or_else(|| "measured".into()),
    };
    // A name or a drive limit the profile would refuse is refused before anything plays.
    let check = |measured: &Measured| {
        let text = measured
            .profile(&name, None, args.max_amplitude, comments(args, measured))
            .to_toml();
        ActuatorProfile::parse(&text)
            .map(|_| text)
            .map_err(|error| Failure::Profile(error.to_string()))
    };
    let trial = Measured {
        sample_rate_hz: 48_000,
        points: plan.frequencies_hz.iter().map(|&hz| (hz, 0.0)).collect(),
        spread_db: None,
        above_noise_db: Vec::new(),
        replayed: 0,
    };
    check(&trial).map_err(|error| (2, error))?;
    // The file's folder is checked before anything plays too.
    let file = PendingFile::beside(&args.output, ".toml")
        .map_err(|source| (1, Failure::Write(WriteError::at(&args.output)(source))))?;

    let measured = run_on_jack(args, &plan).map_err(|error| (1, error.into()))?;
    let text = check(&measured).map_err(|error| (1, error))?;
    print_table(&measured);
    file.writer()
        .and_then(|mut writer| {
            writer.write_all(text.as_bytes())?;
            writer.flush()
        })
        .map_err(|source| (1, Failure::Write(WriteError::at(&args.output)(source))))?;
    PendingFile::commit_all(vec![file]).map_err(|error| (1, error.into()))?;
    println!("wrote {}", quoted(&args.output.display().to_string()));
    Ok(())
}

/// Where the numbers come from, at the file's top.
fn comments(args: &MeasureActuatorArgs, measured: &Measured) -> Vec<String> {
    let mut lines = vec![
        format!(
            "Measured by `sake-glug measure-actuator`: stepped sines from {} to {} Hz, {} to an \
             octave, at {} dBFS, {} s settling and {} s analysed per step, {} time(s), at {} Hz.",
            args.from,
            args.to,
            args.per_octave,
            args.level,
            args.settle,
            args.measure,
            args.repeat,
            measured.sample_rate_hz
        ),
        "Levels are the accelerometer's, 0 dB at the strongest point; the band is the span \
         measured."
            .into(),
    ];
    if args.freewheel {
        lines.push(
            "The JACK server freewheeled while measuring (as fast as its clients allowed).".into(),
        );
    }
    if let Some(weakest) = measured
        .above_noise_db
        .iter()
        .copied()
        .reduce(f64::min)
        .filter(|db| db.is_finite())
    {
        lines.push(format!(
            "The weakest point stood {weakest:.1} dB above what the input heard in silence."
        ));
    }
    lines
}

fn print_table(measured: &Measured) {
    println!("     Hz        dB    spread   above silence");
    for (index, &(hz, db)) in measured.points.iter().enumerate() {
        let spread = measured
            .spread_db
            .as_ref()
            .map_or("-".into(), |spread| format!("{:.2}", spread[index]));
        let above = measured.above_noise_db[index];
        println!("{hz:>8.1} {db:>9.2} {spread:>9} {above:>12.1} dB");
    }
    for (hz, above) in measured.noisy_points() {
        eprintln!(
            "warning: at {hz:.1} Hz the device stood only {above:.1} dB above the silence \
             (under {NOISY_BELOW_DB} dB): its level there is uncertain"
        );
    }
    if measured.replayed > 0 {
        println!(
            "{} step(s) played again after an xrun spoiled them",
            measured.replayed
        );
    }
}

#[cfg(feature = "audio")]
fn run_on_jack(args: &MeasureActuatorArgs, plan: &Plan) -> Result<Measured, MeasureError> {
    let mut rig = sake_glug_actuator::JackRig::open(
        &args.client_name,
        args.play_to.as_deref(),
        args.record_from.as_deref(),
        args.freewheel,
    )?;
    let mut progress = |repeat: usize, step: usize, steps: usize| {
        eprint!(
            "\rrepeat {}/{}, step {}/{steps}",
            repeat + 1,
            plan.repeats,
            step + 1
        );
        if step + 1 == steps {
            eprintln!();
        }
    };
    sake_glug_actuator::measure::measure(plan, &mut rig, &mut progress)
}

#[cfg(not(feature = "audio"))]
fn run_on_jack(_: &MeasureActuatorArgs, _: &Plan) -> Result<Measured, MeasureError> {
    Err(MeasureError::Audio(NO_AUDIO.into()))
}
