//! `sake-glug render`: scenes (or the built-in pour) to WAV, `.haptic`, `.ahap`, CSV and a plot,
//! every file of a scene from one render pass, all or nothing.

use std::io::{self, IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use sake_glug_actuator::{shipped_names, ActuatorProfile};
use sake_glug_engine::Preset;
use sake_glug_io::text::{printable, quoted};
use sake_glug_model_file::ModelFile;
use sake_glug_render::beyond_fit::beyond_fit;
use sake_glug_render::clips::HapticBand;
use sake_glug_render::fidelity::{self, fidelity_table, Fidelity};
use sake_glug_render::loudness::{
    parse_loudness, parse_true_peak, HapticPeak, LevelTarget, Loudness,
};
use sake_glug_render::silence::why_silent;
use sake_glug_render::sinks::{AudioChannels, DEFAULT_RUMBLE_RATE_HZ, RUMBLE_RATE_RANGE_HZ};
use sake_glug_render::trim::{check_trim_db, trimmed, DEFAULT_TRIM_DB, TRIM_FADE_S};
use sake_glug_render::variations::{
    draw_takes, manifest_csv, manifest_json, manifest_paths, read_take, set_name_of, take_path,
    Take, TakeOptions, VariationError, MAX_TAKES,
};
use sake_glug_render::{
    human_bytes, render_to_files, Output, OutputError, OutputFormat, OutputOptions,
    PlatformOptions, RenderError, RenderObserver, RenderReport, SampleFormat, Scene, SceneError,
    StateRate, DEFAULT_SCENE,
};

#[derive(Args)]
pub struct RenderArgs {
    /// Scene files (TOML, see MODEL.md §10); without any, the built-in default pour.
    scenes: Vec<PathBuf>,
    #[arg(short, long = "output", value_name = "FILE", value_parser = output, help = format!(
        "A file to write; its extension picks the format ({}), or NAME:FILE names it ({}). \
         Repeat for several files from the same render. Default: pour.wav (with --fidelity: no \
         file)",
        OutputFormat::extensions(),
        OutputFormat::names()
    ))]
    outputs: Vec<Output>,
    /// Writes DIR/<scene name>.<extension> for every scene and every one of --formats.
    #[arg(long, value_name = "DIR", conflicts_with = "outputs")]
    out_dir: Option<PathBuf>,
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "wav",
        requires = "out_dir",
        help = format!("With --out-dir: the formats to write ({})", OutputFormat::names())
    )]
    formats: Vec<String>,
    /// Also draws the pour plot (waveform, clip envelope and onsets, V(t), tilt(t)) to this PNG.
    #[arg(long, value_name = "FILE.png")]
    plot: Option<PathBuf>,
    /// Also writes one row per glug unit to this CSV (the same as -o units:FILE.csv).
    #[arg(long, value_name = "FILE.csv", conflicts_with = "out_dir")]
    units: Option<PathBuf>,
    /// Also writes the bottle's state at --state-rate to this CSV (the same as -o
    /// state:FILE.csv).
    #[arg(long, value_name = "FILE.csv", conflicts_with = "out_dir")]
    state: Option<PathBuf>,
    #[arg(long, value_name = "HZ", value_parser = state_rate, allow_negative_numbers = true, help = format!(
        "Rows per second of the state table: above 0, at most the sample rate. Default: {}",
        StateRate::DEFAULT_HZ
    ))]
    state_rate: Option<StateRate>,
    /// A .csv of samples gets a header line and a time_s column (default: Syntacts' form, one
    /// sample per line).
    #[arg(long)]
    csv_time: bool,
    /// The actuator band (Hz) that .haptic frequencies 0..1 map to, as LOW..HIGH.
    #[arg(long, value_name = "LOW..HIGH", default_value_t = HapticBand::default())]
    haptic_band: HapticBand,
    // The help names the presets from their table.
    #[arg(
        long,
        value_name = "NAME",
        conflicts_with = "scenes",
        help = format!(
            "Renders a preset ({}) instead of a scene file: the default pour with that liquid and bottle",
            Preset::ids()
        )
    )]
    preset: Option<String>,
    /// A recorded take (Standard MIDI File) that drives the scene, read with the plugin's
    /// mapping (or the scene's [midi] table); replaces a take the scene names.
    #[arg(long, value_name = "TAKE.mid")]
    midi: Option<PathBuf>,
    /// A model file (as `sake-glug fit` writes): each scene plays on its bottle and liquid, the
    /// keys a scene sets its own (MODEL.md §12.1).
    #[arg(long, value_name = "MODEL.toml")]
    model: Option<PathBuf>,
    #[arg(long, value_name = "NAME|FILE.toml", help = format!(
        "Compensates every unit for an actuator (MODEL.md §18) so that the device delivers the \
         model's c: a shipped profile ({}) or a profile file (with the keys of the shipped ones)",
        shipped_names().join(", ")
    ))]
    actuator: Option<String>,
    /// With --actuator: equalises the level over the skin's threshold at f1 and f2 (Verrillo's
    /// curve) instead of the acceleration the device delivers.
    #[arg(long, requires = "actuator")]
    felt: bool,
    /// Overrides the scenes' sample rate (Hz).
    #[arg(long, value_parser = crate::sample_rate_hz)]
    sample_rate: Option<f64>,
    /// Sample format of WAV files: f32, s24 or s16.
    #[arg(long, default_value = "f32")]
    sample_format: SampleFormat,
    #[arg(
        long,
        value_name = "HZ",
        default_value_t = DEFAULT_RUMBLE_RATE_HZ,
        value_parser = rumble_rate,
        help = format!(
            "Frames a second of a rumble file ({} to {})",
            RUMBLE_RATE_RANGE_HZ.start(),
            RUMBLE_RATE_RANGE_HZ.end()
        )
    )]
    rumble_rate: f64,
    /// What the audio channels of a dualsense or android-ogg file hold: silent or glug (the
    /// actuators and the haptic channel always hold the glug).
    #[arg(long, value_name = "silent|glug", default_value = "silent")]
    audio_channels: AudioChannels,
    /// Brings every waveform file (.wav, .csv, dualsense, .ogg) to this integrated loudness
    /// (LUFS; ITU-R BS.1770-4, gated as EBU R128), e.g. -23 for broadcast, -16 for games. A
    /// render shorter than 0.4 s or silent is refused. Haptic clips are set by --haptic-peak.
    #[arg(long, value_name = "LUFS", allow_negative_numbers = true, value_parser = parse_loudness)]
    loudness: Option<f64>,
    /// Keeps every waveform file's true peak (4× oversampled) at or under this ceiling (dBTP),
    /// e.g. -1. With --loudness the ceiling wins: the file then ends quieter than asked, and the
    /// summary says by how much.
    #[arg(long, value_name = "DBTP", allow_negative_numbers = true, value_parser = parse_true_peak)]
    true_peak: Option<f64>,
    /// Scales every haptic clip (.haptic, .ahap, .haps, Android XML and waveform, rumble) so its
    /// strongest moment, as the format carries it, reaches this drive: 100%, a level in dB
    /// (-3dB) or a fraction (0.8); and the haptic channels of dualsense and android-ogg so their
    /// largest sample does (their audio channels keep --loudness). The actuator's compensation
    /// (--actuator) comes first. Without it a clip keeps the model's level, output gain
    /// included.
    #[arg(long, value_name = "DRIVE", allow_hyphen_values = true)]
    haptic_peak: Option<HapticPeak>,
    /// Measures what every format keeps of the render (onsets, envelope, what carries c, size,
    /// platform limits) and prints it as a Markdown table on stdout; the summary line then goes
    /// to stderr.
    #[arg(long)]
    fidelity: bool,
    /// Overrides the scene's seed of its random draws (MODEL.md §7); with --variations, the
    /// set's master seed, from which each take draws its own.
    #[arg(long, value_name = "N")]
    seed: Option<u64>,
    #[arg(long, value_name = "N", value_parser = take_count, help = format!(
        "Renders a set of N takes of each scene (1 to {MAX_TAKES}; default: its [variations] \
         table's count), each with its own seed and values drawn from the ranges of the table \
         (MODEL.md §10.2): each output FILE.ext is FILE_01.ext … FILE_NN.ext, and \
         NAME.variations.csv and .json (NAME the first output's) list what each take drew"
    ))]
    variations: Option<u32>,
    /// Renders one take of a set again, bit for bit, from its row in the set's manifest:
    /// NAME.variations.csv:7 (or .json:7) for take 7, applied to the scene given
    #[arg(long, value_name = "MANIFEST:N", value_parser = take_reference, conflicts_with = "variations")]
    take_from: Option<(PathBuf, u32)>,
    #[arg(long, value_name = "DB", num_args = 0..=1, allow_negative_numbers = true,
        value_parser = trim_level, help = format!(
        "Ends each file once its last glug has decayed below DB re the file's peak (default \
         {DEFAULT_TRIM_DB}; write --trim=-40 before a scene file), with a {} ms fade after that \
         point (MODEL.md §10.2)",
        TRIM_FADE_S * 1000.0
    ))]
    trim: Option<Option<f64>>,
    /// The old name of --sample-format, which sat beside --formats: refused, naming the new one.
    #[arg(long = "format", hide = true, num_args = 0..=1, default_missing_value = "")]
    renamed_format: Option<String>,
}

/// One scene to render and the files it becomes.
struct Job {
    /// The scene file, or `None` for the built-in pour.
    scene: Option<PathBuf>,
    name: String,
    outputs: Vec<Output>,
}

#[derive(Debug, thiserror::Error)]
enum JobError {
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    Output(#[from] OutputError),
    #[error("--take-from: {0}")]
    Take(VariationError),
    #[error(transparent)]
    Variation(#[from] VariationError),
    #[error(transparent)]
    Write(#[from] sake_glug_io::WriteError),
}

impl From<RenderError> for JobError {
    fn from(error: RenderError) -> Self {
        Self::Output(OutputError::Render(error))
    }
}

/// Runs the command: every scene is rendered, a bad one is reported and skipped; the exit
/// status is 1 if any failed, 2 if the command line itself is wrong (nothing is rendered then),
/// 128 + the signal's number if a signal stopped it.
pub fn run(mut args: RenderArgs) -> ExitCode {
    // A take rendered again is rendered with the options its set was (its row records them).
    if let Some((manifest, number)) = &args.take_from {
        // A manifest that cannot be read is refused where the take is applied, as before.
        if let Ok(take) = read_take(manifest, *number) {
            match TakeOptions::resolve(args.take_options(), take.recorded) {
                Ok(options) => args.set_take_options(options),
                Err(error) => {
                    eprintln!("error: --take-from: {error}");
                    return ExitCode::from(2);
                }
            }
        }
    }
    let jobs = match plan(&args) {
        Ok(jobs) => jobs,
        Err(message) => {
            eprintln!("error: {message}");
            return ExitCode::from(2);
        }
    };
    let model = match args.model.as_deref().map(ModelFile::load).transpose() {
        Ok(model) => model,
        Err(error) => {
            eprintln!("error: --model: {error}");
            return ExitCode::from(2);
        }
    };
    let actuator = match args
        .actuator
        .as_deref()
        .map(ActuatorProfile::find)
        .transpose()
    {
        Ok(actuator) => actuator.map(|profile| profile.felt_if(args.felt)),
        Err(error) => {
            eprintln!("error: --actuator: {error}");
            return ExitCode::from(2);
        }
    };
    if let Some(directory) = &args.out_dir {
        if let Err(error) = std::fs::create_dir_all(directory) {
            eprintln!("error: cannot create {}: {error}", directory.display());
            return ExitCode::FAILURE;
        }
    }
    let options = OutputOptions {
        sample_format: args.sample_format,
        haptic_band: args.haptic_band,
        csv_time: args.csv_time,
        state_rate: args.state_rate.unwrap_or_default(),
        platforms: PlatformOptions {
            rumble_rate_hz: args.rumble_rate,
            audio_channels: args.audio_channels,
        },
        level: LevelTarget {
            loudness_lufs: args.loudness,
            true_peak_dbtp: args.true_peak,
        },
        haptic_peak: args.haptic_peak,
        measure_loudness: false,
    };
    let stop = Stop::on_signals(jobs.iter().flat_map(|job| job.outputs.clone()).collect());
    let mut out = Console::new(jobs.len());
    let mut failed = 0;
    for (index, job) in jobs.iter().enumerate() {
        let progress = |fraction| out.progress.set(index, fraction);
        let signal_name =
            |signal| signal_hook::low_level::signal_name(signal).unwrap_or("a signal");
        let inputs = JobInputs {
            model: model.as_ref(),
            actuator: actuator.as_ref(),
        };
        match render_job(job, &args, inputs, &options, &stop, progress) {
            Ok(JobDone { takes, manifests }) => {
                let several = jobs.len() > 1 || takes.len() > 1;
                for Rendered {
                    name,
                    report,
                    outside,
                    fidelity,
                    silent,
                    beyond_fit,
                } in takes
                {
                    for leftover in &report.leftovers {
                        out.error(&format!(
                            "warning: {} looks left by an interrupted render; remove it unless \
                             a render is writing it",
                            leftover.display()
                        ));
                    }
                    for reason in silent.iter().chain(&beyond_fit) {
                        out.error(&format!("warning: {name}: {reason}"));
                    }
                    for clipped in &report.clipped {
                        out.error(&format!("warning: {clipped}"));
                    }
                    match fidelity {
                        Some(rows) => {
                            out.error(&summary(&name, &report, &outside, args.haptic_peak));
                            let heading = if several {
                                format!("{name}:\n\n")
                            } else {
                                String::new()
                            };
                            out.summary(&(heading + fidelity_table(&rows).trim_end()));
                        }
                        None => out.summary(&summary(&name, &report, &outside, args.haptic_peak)),
                    }
                }
                if !manifests.is_empty() {
                    let files: Vec<String> = manifests
                        .iter()
                        .map(|(path, bytes)| {
                            format!("{} ({})", path.display(), human_bytes(*bytes))
                        })
                        .collect();
                    out.summary(&format!(
                        "{}: the set's manifest → {}",
                        job.name,
                        files.join(", ")
                    ));
                }
            }
            Err(JobError::Output(OutputError::Render(RenderError::Interrupted))) => {
                let signal = stop.signal().map_or("a signal", signal_name);
                out.error(&format!(
                    "{}: stopped by {signal}; its files were not written",
                    job.name
                ));
            }
            Err(error) => {
                failed += 1;
                out.error(&format!("error: {}: {error}", job.name));
            }
        }
        if let Some(signal) = stop.signal() {
            let left = jobs.len() - index - 1;
            if left > 0 {
                out.error(&format!(
                    "stopped by {}: {left} more scene(s) not rendered",
                    signal_name(signal)
                ));
            }
            out.progress.finish();
            return ExitCode::from((128 + signal).clamp(0, 255) as u8);
        }
    }
    out.progress.finish();
    if failed > 0 && jobs.len() > 1 {
        out.error(&format!("{failed} of {} scenes failed", jobs.len()));
    }
    if let Some(error) = &out.stdout_error {
        out.error(&format!("error: cannot print the summary: {error}"));
    }
    if failed > 0 || out.stdout_error.is_some() {
        ExitCode::FAILURE
    } else {
        ExitCode::SUCCESS
    }
}

/// The signals that stop a render: Ctrl-C, `kill`'s default, a closed terminal. The render stops
/// at its next block and removes its temporary files, and the command ends with 128 + the
/// signal's number; a second signal ends it at once, whatever the render is doing (finishing a
/// clip, syncing), its temporary files removed, with 128 + the second signal's number.
#[cfg(unix)]
const STOP_SIGNALS: [i32; 3] = [
    signal_hook::consts::SIGINT,
    signal_hook::consts::SIGTERM,
    signal_hook::consts::SIGHUP,
];
#[cfg(not(unix))]
const STOP_SIGNALS: [i32; 2] = [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM];

/// The last of [`STOP_SIGNALS`] that came, if any.
struct Stop {
    signal: Arc<AtomicUsize>,
}

impl Stop {
    /// Catches [`STOP_SIGNALS`] for a batch that writes `outputs`.
    fn on_signals(outputs: Vec<Output>) -> Self {
        let signal = Arc::new(AtomicUsize::new(0));
        for number in STOP_SIGNALS {
            // Not being able to catch a signal leaves it as it was: it ends the process.
            let _ = signal_hook::flag::register_usize(number, Arc::clone(&signal), number as usize);
        }
        end_at_a_second_signal(outputs);
        Self { signal }
    }

    fn signal(&self) -> Option<i32> {
        match self.signal.load(Ordering::Relaxed) {
            0 => None,
            number => Some(number as i32),
        }
    }
}

/// Ends the process at a second of [`STOP_SIGNALS`], with the temporary files of `outputs`
/// removed. A thread of its own sees it: it can remove files (a signal handler cannot), wherever
/// the render is.
#[cfg(unix)]
fn end_at_a_second_signal(outputs: Vec<Output>) {
    let Ok(mut signals) = signal_hook::iterator::Signals::new(STOP_SIGNALS) else {
        return;
    };
    std::thread::spawn(move || {
        if let Some(number) = signals.forever().nth(1) {
            sake_glug_render::remove_temporary_files(&outputs);
            let name = signal_hook::low_level::signal_name(number).unwrap_or("a signal");
            eprintln!(
                "stopped by {name}, a second stop signal: ended at once, its temporary files removed"
            );
            std::process::exit(128 + number);
        }
    });
}

/// Without signal_hook's iterator, a second signal stops the render as the first does.
#[cfg(not(unix))]
fn end_at_a_second_signal(_outputs: Vec<Output>) {}

/// The jobs the arguments ask for; every output's format is checked here, before anything is
/// rendered.
fn plan(args: &RenderArgs) -> Result<Vec<Job>, String> {
    if args.renamed_format.is_some() {
        return Err(
            "--format is now --sample-format (the sample format of WAV files); \
                    --formats chooses the kinds of file"
                .into(),
        );
    }
    if let (Some(rate), Some(sample_rate)) = (args.state_rate, args.sample_rate) {
        if rate.hz() > sample_rate {
            return Err(format!(
                "--state-rate {}: above --sample-rate {sample_rate}; a state row is one sample",
                rate.hz()
            ));
        }
    }
    if let Some(name) = &args.preset {
        if Preset::find(name).is_none() {
            return Err(format!(
                "no preset `{}`: choose one of {}",
                quoted(name),
                Preset::ids()
            ));
        }
    }
    let scenes: Vec<Option<PathBuf>> = if args.scenes.is_empty() {
        vec![None]
    } else {
        args.scenes.iter().cloned().map(Some).collect()
    };
    let name_of = |scene: &Option<PathBuf>| {
        let built_in = args.preset.as_deref().unwrap_or("default");
        scene
            .as_deref()
            .and_then(Path::file_stem)
            .map_or(built_in.to_string(), |stem| {
                stem.to_string_lossy().into_owned()
            })
    };
    let mut jobs = Vec::new();
    if let Some(directory) = &args.out_dir {
        if directory.exists() && !directory.is_dir() {
            return Err(format!(
                "--out-dir {}: it is a file, not a folder",
                directory.display()
            ));
        }
        let formats = args
            .formats
            .iter()
            .map(|name| {
                OutputFormat::of_name(name.trim_start_matches('.')).ok_or_else(|| {
                    format!(
                        "unknown format `{name}` in --formats: use {}",
                        OutputFormat::names()
                    )
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        if args.plot.is_some() {
            return Err("with --out-dir, ask for the plot with --formats …,png".into());
        }
        for scene in scenes {
            let name = name_of(&scene);
            let outputs = formats
                .iter()
                .map(|&format| Output {
                    format,
                    path: directory.join(format.file_name(&name)),
                })
                .collect();
            jobs.push(Job {
                scene,
                name,
                outputs,
            });
        }
        let mut names: Vec<&str> = jobs.iter().map(|job| job.name.as_str()).collect();
        names.sort_unstable();
        if let Some(pair) = names.windows(2).find(|pair| pair[0] == pair[1]) {
            return Err(format!(
                "two scenes are named `{}`: their files would overwrite each other in {}",
                pair[0],
                directory.display()
            ));
        }
    } else {
        if scenes.len() > 1 {
            return Err("several scenes need --out-dir DIR (each writes DIR/<name>.<ext>)".into());
        }
        let mut outputs = args.outputs.clone();
        // A report alone (--fidelity) writes no audio unless asked to: pour.wav is the default
        // of a render, not of a measurement (issue 40).
        if outputs.is_empty() && !args.fidelity {
            outputs.push(Output {
                format: OutputFormat::WAV,
                path: PathBuf::from("pour.wav"),
            });
        }
        let tables = [
            (OutputFormat::UNITS, &args.units),
            (OutputFormat::STATE, &args.state),
        ];
        for (format, path) in tables {
            if let Some(path) = path {
                outputs.push(Output {
                    format,
                    path: path.clone(),
                });
            }
        }
        if let Some(plot) = &args.plot {
            match Output::of_path(plot) {
                Ok(output) if output.format == OutputFormat::PLOT => outputs.push(output),
                _ => {
                    return Err(format!(
                        "--plot {}: the plot is a .png file",
                        plot.display()
                    ))
                }
            }
        }
        let scene = scenes.into_iter().next().flatten();
        jobs.push(Job {
            name: name_of(&scene),
            scene,
            outputs,
        });
    }
    Ok(jobs)
}

/// `--state-rate`'s value parser: a finite number of Hz above 0.
fn state_rate(text: &str) -> Result<StateRate, String> {
    let hz: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a number of Hz"))?;
    StateRate::new(hz).map_err(|error| error.to_string())
}

/// `--rumble-rate`'s value parser: a rate in [`RUMBLE_RATE_RANGE_HZ`].
fn rumble_rate(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(hz) if RUMBLE_RATE_RANGE_HZ.contains(&hz) => Ok(hz),
        _ => Err(format!(
            "`{text}` is not a rate from {} to {} Hz",
            RUMBLE_RATE_RANGE_HZ.start(),
            RUMBLE_RATE_RANGE_HZ.end()
        )),
    }
}

impl RenderArgs {
    /// The options a set's manifest records (MODEL.md §10.2), as given.
    fn take_options(&self) -> TakeOptions {
        TakeOptions {
            trim_db: self.trim.map(|level| level.unwrap_or(DEFAULT_TRIM_DB)),
            loudness_lufs: self.loudness,
            true_peak_dbtp: self.true_peak,
            haptic_peak: self.haptic_peak.map(HapticPeak::level),
        }
    }

    /// Sets the options a manifest recorded, each checked when it was read.
    fn set_take_options(&mut self, options: TakeOptions) {
        self.trim = options.trim_db.map(Some);
        self.loudness = options.loudness_lufs;
        self.true_peak = options.true_peak_dbtp;
        self.haptic_peak = options
            .haptic_peak
            .map(|level| HapticPeak::of_level(level).expect("checked as the row was read"));
    }
}

/// `--variations`' value parser: a count of takes from 1 to [`MAX_TAKES`].
fn take_count(text: &str) -> Result<u32, String> {
    match text.trim().parse::<u32>() {
        Ok(count) if (1..=MAX_TAKES).contains(&count) => Ok(count),
        _ => Err(format!(
            "`{text}` is not a number of takes from 1 to {MAX_TAKES}"
        )),
    }
}

/// `--take-from`'s value parser: `MANIFEST:N`, a take's number after the last colon.
fn take_reference(text: &str) -> Result<(PathBuf, u32), String> {
    let bad =
        || format!("`{text}`: give the manifest and the take's number, as pour.variations.csv:7");
    let (path, number) = text.rsplit_once(':').ok_or_else(bad)?;
    let number = number
        .trim()
        .parse::<u32>()
        .ok()
        .filter(|&n| n >= 1)
        .ok_or_else(bad)?;
    if path.is_empty() {
        return Err(bad());
    }
    Ok((PathBuf::from(path), number))
}

/// `--trim`'s value parser: a level in dB below 0.
fn trim_level(text: &str) -> Result<f64, String> {
    let level: f64 = text
        .trim()
        .parse()
        .map_err(|_| format!("`{text}` is not a level in dB, such as -60"))?;
    check_trim_db(level).map_err(|error| error.to_string())
}

/// `-o`'s value parser: `NAME:FILE` or a file its extension names.
fn output(argument: &str) -> Result<Output, String> {
    Output::parse(argument).map_err(|error| error.to_string())
}

/// What one file set of a job did (a scene's, or one take's of a set): its name, its report,
/// the files it read from outside its scene's folder, with --fidelity what every format keeps,
/// why it is silent, if it is, and why it plays a fitted model beyond its recordings, if it does.
struct Rendered {
    name: String,
    report: RenderReport,
    outside: Vec<PathBuf>,
    fidelity: Option<Vec<Fidelity>>,
    silent: Option<String>,
    beyond_fit: Option<String>,
}

/// What a job did: one file set, or a set of takes with its manifests.
struct JobDone {
    takes: Vec<Rendered>,
    /// The set's manifests with their sizes; none for a single render.
    manifests: Vec<(PathBuf, u64)>,
}

/// A built-in scene (the default pour or a preset's), on `model`'s bottle if one is given.
fn built_in(text: &str, model: Option<&ModelFile>) -> Result<Scene, SceneError> {
    match model {
        None => Scene::parse(text),
        Some(model) => Scene::parse_with_model(text, Path::new(""), model),
    }
}

/// What every job of a batch plays on: the model's bottle, the actuator's response.
#[derive(Clone, Copy)]
struct JobInputs<'a> {
    model: Option<&'a ModelFile>,
    actuator: Option<&'a ActuatorProfile>,
}

fn render_job(
    job: &Job,
    args: &RenderArgs,
    JobInputs { model, actuator }: JobInputs,
    options: &OutputOptions,
    stop: &Stop,
    mut progress: impl FnMut(f64),
) -> Result<JobDone, JobError> {
    let preset = args.preset.as_deref().and_then(Preset::find);
    let mut scene = match (&job.scene, preset, model) {
        (Some(path), _, None) => Scene::load(path)?,
        (Some(path), _, Some(model)) => Scene::load_with_model(path, model)?,
        (None, Some(preset), model) => built_in(&Scene::preset_toml(preset), model)?,
        (None, None, model) => built_in(DEFAULT_SCENE, model)?,
    };
    if let Some(take) = &args.midi {
        scene = scene.with_midi_take(take)?;
    }
    if let Some(sample_rate) = args.sample_rate {
        scene = scene.with_sample_rate(sample_rate)?;
    }
    scene.actuator = actuator.map(ActuatorProfile::response);
    if let Some(seed) = args.seed {
        scene.config.seed = seed;
    }
    if let Some((manifest, number)) = &args.take_from {
        let take = read_take(manifest, *number).map_err(JobError::Take)?;
        scene = take.apply(scene).map_err(JobError::Take)?;
    }
    let count = args.variations.or_else(|| {
        args.take_from
            .is_none()
            .then_some(())
            .and(scene.variations.as_ref()?.count)
    });
    let Some(count) = count else {
        let rendered = render_one(
            job.name.clone(),
            &job.name,
            scene,
            &job.outputs,
            args,
            options,
            stop,
            progress,
        )?;
        return Ok(JobDone {
            takes: vec![rendered],
            manifests: Vec::new(),
        });
    };
    // Every take is drawn and checked before the first is rendered.
    let ranges = scene
        .variations
        .as_ref()
        .map_or(Vec::new(), |spec| spec.ranges.clone());
    let master_seed = scene.config.seed;
    let takes = draw_takes(&ranges, count, master_seed);
    let set_name = job
        .outputs
        .first()
        .filter(|_| args.out_dir.is_none())
        .map_or(job.name.clone(), |output| set_name_of(&output.path));
    let scenes = takes
        .iter()
        .map(|take| take.apply(scene.clone()))
        .collect::<Result<Vec<_>, _>>()?;
    // Each take's level is measured on the samples its files are written from, for the
    // manifest (MODEL.md §10.2).
    let options = &OutputOptions {
        measure_loudness: true,
        ..*options
    };
    let mut rendered = Vec::with_capacity(takes.len());
    let mut measured = Vec::with_capacity(takes.len());
    for (index, (take, take_scene)) in takes.iter().zip(scenes).enumerate() {
        let name = take.name(&set_name, count);
        let outputs = take_outputs(&job.outputs, take, count);
        let share = |fraction: f64| (index as f64 + fraction) / count as f64;
        let take_rendered = render_one(
            name,
            &job.name,
            take_scene,
            &outputs,
            args,
            options,
            stop,
            |fraction| progress(share(fraction)),
        )?;
        let level = take_rendered
            .report
            .levelled
            .expect("a take's level is measured");
        measured.push((take.clone(), level.after));
        rendered.push(take_rendered);
    }
    let folder = match (&args.out_dir, job.outputs.first()) {
        (Some(directory), _) => directory.clone(),
        (None, Some(output)) => output
            .path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default(),
        (None, None) => PathBuf::new(),
    };
    let manifests = write_manifests(
        &folder,
        &set_name,
        job.scene.as_deref(),
        master_seed,
        &ranges,
        &args.take_options(),
        &measured,
    )?;
    Ok(JobDone {
        takes: rendered,
        manifests,
    })
}

/// The files of `take`: each of the job's, its own name followed by the take's number
/// (`pour.wav` → `pour_07.wav`, `pad.wav` → `pad_07.wav`), so that two outputs of one extension
/// stay two files.
fn take_outputs(outputs: &[Output], take: &Take, count: u32) -> Vec<Output> {
    outputs
        .iter()
        .map(|output| Output {
            format: output.format,
            path: take_path(&output.path, &take.name(&set_name_of(&output.path), count)),
        })
        .collect()
}

/// Writes a set's manifests (CSV and JSON) together, all or nothing.
fn write_manifests(
    folder: &Path,
    set_name: &str,
    scene_file: Option<&Path>,
    master_seed: u64,
    ranges: &[(sake_glug_render::variations::Varied, [f64; 2])],
    options: &TakeOptions,
    takes: &[(Take, Loudness)],
) -> Result<Vec<(PathBuf, u64)>, JobError> {
    let [csv_path, json_path] = manifest_paths(folder, set_name);
    let texts = [
        (csv_path, manifest_csv(set_name, options, takes)),
        (
            json_path,
            manifest_json(set_name, scene_file, master_seed, ranges, options, takes),
        ),
    ];
    let mut files = Vec::new();
    for (path, text) in texts {
        let file = sake_glug_io::PendingFile::beside(&path, ".tmp")
            .map_err(sake_glug_io::WriteError::at(&path))?;
        let mut writer = file.writer().map_err(sake_glug_io::WriteError::at(&path))?;
        writer
            .write_all(text.as_bytes())
            .and_then(|()| writer.flush())
            .map_err(sake_glug_io::WriteError::at(&path))?;
        drop(writer);
        files.push(file);
    }
    Ok(sake_glug_io::PendingFile::commit_all(files)?)
}

/// Renders one scene (a take's, or the job's own) to `outputs`, trimmed if asked.
#[allow(clippy::too_many_arguments)]
fn render_one(
    name: String,
    clip_name: &str,
    scene: Scene,
    outputs: &[Output],
    args: &RenderArgs,
    options: &OutputOptions,
    stop: &Stop,
    progress: impl FnMut(f64),
) -> Result<Rendered, JobError> {
    let scene = match args.trim {
        Some(level) => trimmed(scene, level.unwrap_or(DEFAULT_TRIM_DB))?,
        None => scene,
    };
    let observer = JobObserver {
        total: scene.duration_samples(),
        progress,
        stop,
    };
    // A clip's metadata names the scene, so that a take rendered again from its row (under
    // any file name) is the set's take byte for byte.
    let report = render_to_files(&scene, clip_name, outputs, options, observer)?;
    let outside = scene
        .inputs
        .iter()
        .filter(|input| input.outside_folder)
        .map(|input| input.path.clone())
        .collect();
    let fidelity = if args.fidelity {
        Some(fidelity::measure(&scene, clip_name, options)?)
    } else {
        None
    };
    let silent = why_silent(&scene, &report.summary);
    let beyond_fit = beyond_fit(&scene, &report.summary);
    Ok(Rendered {
        name,
        report,
        outside,
        fidelity,
        silent,
        beyond_fit,
    })
}

/// What a job's render reports to: the progress bar, and whether a signal came.
struct JobObserver<'a, P> {
    /// Samples of the scene, if it has a duration.
    total: Option<u64>,
    progress: P,
    stop: &'a Stop,
}

impl<P: FnMut(f64)> RenderObserver for JobObserver<'_, P> {
    fn progress(&mut self, done: u64) {
        // A scene without a duration ends where it falls silent: its share is unknown.
        if let Some(total) = self.total {
            (self.progress)(done as f64 / total.max(1) as f64);
        }
    }

    fn interrupted(&self) -> bool {
        self.stop.signal().is_some()
    }
}

/// The line printed for a finished scene.
/// The line a finished scene prints; files the scene read from outside its own folder are named
/// at its end, so a scene from elsewhere cannot read one unseen.
fn summary(
    name: &str,
    report: &RenderReport,
    outside: &[PathBuf],
    haptic_peak: Option<HapticPeak>,
) -> String {
    let summary = &report.summary;
    let files: Vec<String> = report
        .files
        .iter()
        .map(|(path, bytes)| format!("{} ({})", path.display(), human_bytes(*bytes)))
        .collect();
    format!(
        "{}: {:.2} s at {} Hz, {} glug units, {} audible, peak {:.1} dBFS{}, {:.0}× faster than \
         real time → {}",
        name,
        summary.duration_s(),
        summary.sample_rate,
        summary.units,
        report.audible_units,
        20.0 * (summary.peak.max(1e-12) as f64).log10(),
        level_note(report, haptic_peak),
        summary.realtime_factor(),
        if files.is_empty() {
            "no file written (a report alone)".to_owned()
        } else {
            files.join(", ")
        }
    ) + &outside_note(outside)
}

/// What the level stage did (MODEL.md §19): the waveform's gain and loudness, the clips' drive.
fn level_note(report: &RenderReport, haptic_peak: Option<HapticPeak>) -> String {
    let mut note = String::new();
    if let Some(levelled) = &report.levelled {
        note += &format!(
            " before a gain of {:+.2} dB; the waveform files: {}",
            levelled.gain_db, levelled.after
        );
        if levelled.held_by_peak {
            note += &format!(
                " (held by the true-peak ceiling: {:.1} LU quieter than the loudness asked)",
                levelled.quieter_than_asked_lu
            );
        }
    }
    if let Some(peak) = haptic_peak {
        note += &format!("; haptic clips and haptic channels at {peak} peak drive");
    }
    note
}

fn outside_note(outside: &[PathBuf]) -> String {
    if outside.is_empty() {
        return String::new();
    }
    let paths: Vec<String> = outside
        .iter()
        .map(|path| printable(&path.display().to_string()).into_owned())
        .collect();
    format!(
        "; read from outside the scene's folder: {}",
        paths.join(", ")
    )
}

/// Where a batch reports: the summary lines on stdout, whatever stderr is; errors and the
/// progress bar (on a terminal only) on stderr. Output that cannot be written ends the printing,
/// never the batch: a reader that has gone (`| head -1`) is no error, any other (a full disk)
/// fails the command once every scene is written.
struct Console {
    progress: BatchProgress,
    /// Stdout can no longer be written.
    stdout_closed: bool,
    /// Why, unless its reader had gone.
    stdout_error: Option<io::Error>,
}

impl Console {
    fn new(scenes: usize) -> Self {
        Self {
            progress: BatchProgress::new(scenes),
            stdout_closed: false,
            stdout_error: None,
        }
    }

    /// Prints a scene's summary line on stdout (above the bar, if there is one).
    fn summary(&mut self, line: &str) {
        if self.stdout_closed {
            return;
        }
        let written = self
            .progress
            .bar
            .suspend(|| writeln!(io::stdout().lock(), "{line}"));
        if let Err(error) = written {
            self.stdout_closed = true;
            if error.kind() != io::ErrorKind::BrokenPipe {
                self.stdout_error = Some(error);
            }
        }
    }

    /// Prints a line on stderr (above the bar, if there is one); one that cannot be written is
    /// lost, as there is nowhere else to say so.
    fn error(&self, line: &str) {
        self.progress.bar.suspend(|| {
            let _ = writeln!(io::stderr().lock(), "{line}");
        });
    }
}

/// One progress bar over the whole batch on stderr when it is a terminal; nothing otherwise.
struct BatchProgress {
    bar: ProgressBar,
}

/// Steps of the bar per scene.
const STEPS_PER_SCENE: u64 = 1000;

impl BatchProgress {
    fn new(scenes: usize) -> Self {
        if !io::stderr().is_terminal() {
            return Self {
                bar: ProgressBar::hidden(),
            };
        }
        let bar = ProgressBar::new(scenes as u64 * STEPS_PER_SCENE);
        bar.set_draw_target(ProgressDrawTarget::stderr());
        if let Ok(style) = ProgressStyle::with_template("{bar:40} {percent:>3}% {msg}") {
            bar.set_style(style);
        }
        Self { bar }
    }

    /// Scene `index` is `fraction` done.
    fn set(&self, index: usize, fraction: f64) {
        let within = (fraction.clamp(0.0, 1.0) * STEPS_PER_SCENE as f64) as u64;
        self.bar
            .set_position(index as u64 * STEPS_PER_SCENE + within);
    }

    fn finish(&self) {
        self.bar.finish_and_clear();
    }
}
