//! `sake-glug experiment`: runs a listening study's session for one participant.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, ValueEnum};
use sake_glug_io::text::{printable, quoted};

use sake_glug_study::{
    check_dry_run_folder, order_seed, plan_trials, render_stimuli, write_dry_run, Design,
    Discriminate, DryRun, DryRunFiles, Equalize, Spec, StudyError, StudySession, TrialLog,
    DISCRIMINATE_DESIGNS,
};
#[cfg(feature = "audio")]
use sake_glug_study::{AlsaOutput, Channels, JackOutput, Presenter};

/// `experiment`'s summary and `--design`'s help, written from the designs' own lists
/// ([`Design::ALL`], [`DISCRIMINATE_DESIGNS`]) so that a design added shows in `--help`, with
/// the command that plans a discrimination study.
pub fn with_designs(command: clap::Command) -> clap::Command {
    let names = |designs: &[Design]| {
        let names: Vec<&str> = designs.iter().map(|design| design.name()).collect();
        names.join(", ")
    };
    let about = format!(
        "Runs a listening study's session for one participant: a spec file's design ({}), or \
         with --discriminate a recording against its fitted model ({}; plan the participants it \
         needs with `sake-glug analyze plan discrimination`)",
        names(&Design::ALL),
        names(&DISCRIMINATE_DESIGNS)
    );
    let designs: Vec<String> = DISCRIMINATE_DESIGNS
        .iter()
        .map(|&design| {
            let arrangements = design.arrangements().unwrap_or(1);
            let repetitions = Discriminate::default_repetitions(design);
            format!(
                "`{}`: {} ({arrangements} arrangements; by default each {repetitions} times, {} \
                 trials)",
                design.name(),
                design.task(),
                Discriminate::default_trials(design)
            )
        })
        .collect();
    let design_help = format!(
        "With --discriminate: the design, one of: {} [default: {}]. `sake-glug analyze plan \
         discrimination --design DESIGN` says how many participants such a session needs",
        designs.join("; "),
        DISCRIMINATE_DESIGNS[0].name()
    );
    command
        .about(about)
        .mut_arg("design", |arg| arg.help(design_help))
}

/// The JACK client's name unless `--client-name` gives one.
const CLIENT_NAME: &str = "sake-glug-experiment";
/// The ALSA device unless `--alsa-device` names one.
const ALSA_DEVICE: &str = "default";

#[derive(Args, Debug)]
pub struct ExperimentArgs {
    /// The study's spec file: its keys in experiments/README.md, installed with the two studies
    /// of the paper in /usr/share/doc/sake-glug/experiments (the .deb) or
    /// ~/.local/share/doc/sake-glug/experiments (the tarball).
    #[arg(required_unless_present = "discriminate")]
    spec: Option<PathBuf>,
    /// Without a spec file: a discrimination study of a recording against the model fitted to
    /// it (by default a triangle test: "two are alike: which one is different?"), the
    /// recording's excerpt and the model's render level-matched by RMS, each arrangement
    /// --repetitions times.
    #[arg(
        long,
        num_args = 2,
        value_names = ["RECORDING.wav", "MODEL.toml"],
        conflicts_with = "spec"
    )]
    discriminate: Option<Vec<PathBuf>>,
    /// With --discriminate: the design (its help is written from the designs' list:
    /// [`with_designs`]).
    #[arg(long, requires = "discriminate", value_name = "DESIGN")]
    design: Option<String>,
    /// With --discriminate: each stimulus's length (s) [default: 2].
    #[arg(long = "duration-s", requires = "discriminate", value_name = "S")]
    duration_s: Option<f64>,
    /// With --discriminate: where the recording's excerpt starts (s) [default: 0].
    #[arg(long = "start-s", requires = "discriminate", value_name = "S")]
    start_s: Option<f64>,
    /// With --discriminate: presentations of each arrangement (the triangle's 6, 2AFC's 2,
    /// ABX's 4) [default: 4 for the triangle (24 trials), 10 for 2AFC, 6 for ABX].
    #[arg(long, requires = "discriminate", value_name = "N")]
    repetitions: Option<u32>,
    /// The participant's ID: with the spec's seed it fixes the trial order.
    #[arg(long)]
    participant: String,
    /// The trial log (CSV), one row appended per answer.
    #[arg(long, required_unless_present = "no_answers")]
    log: Option<PathBuf>,
    /// Writes every trial's stimuli as WAV files and the trial list into this new (or empty)
    /// folder, and runs the session without playing anything. If the answers (stdin) end
    /// before the first one, the dry run ends there as --no-answers does (exit status 0).
    #[arg(long, value_name = "DIR")]
    dry_run: Option<PathBuf>,
    /// With --dry-run: writes the folder and ends there, asking for no answers and keeping no
    /// log (a scripted dry run).
    #[arg(long, requires = "dry_run", conflicts_with_all = ["log", "resume"])]
    no_answers: bool,
    /// Continues the session of an existing log after its last trial (same order).
    #[arg(long)]
    resume: bool,
    /// The actuator's output channels, from 1 (e.g. `1` or `1,2`): overrides the spec's.
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    actuator: Option<Vec<u16>>,
    /// The headphones' output channels, which carry the masking noise: overrides the spec's.
    #[arg(long, value_delimiter = ',', value_name = "LIST")]
    headphones: Option<Vec<u16>>,
    /// Where the trials play: a running JACK server, or an ALSA device (`--alsa-device`).
    #[arg(long, value_enum, default_value_t = Audio::Jack)]
    audio: Audio,
    /// With `--audio jack`: the JACK client's name [default: sake-glug-experiment].
    #[arg(long, value_name = "NAME")]
    client_name: Option<String>,
    /// With `--audio alsa`: the ALSA device (a PCM name: `default`, `hw:1`, `plughw:CARD=USB`,
    /// …) [default: default].
    #[arg(long, value_name = "NAME")]
    alsa_device: Option<String>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Audio {
    /// A running JACK server.
    Jack,
    /// An ALSA device.
    Alsa,
}

/// The audio interface the options name.
#[derive(Debug)]
#[cfg_attr(
    not(feature = "audio"),
    expect(
        dead_code,
        reason = "checked, so that a build without audio refuses the same options"
    )
)]
enum Interface {
    Jack { client_name: String },
    Alsa { device: String },
}

impl ExperimentArgs {
    /// Refuses an option of the other interface's (`--client-name` is JACK's, `--alsa-device`
    /// ALSA's), so that neither is silently ignored.
    fn interface(&self) -> Result<Interface, StudyError> {
        match (self.audio, &self.client_name, &self.alsa_device) {
            (Audio::Jack, _, Some(_)) => Err(StudyError::Audio(
                "--alsa-device names an ALSA device: add `--audio alsa` (without it the session \
                 plays on JACK)"
                    .into(),
            )),
            (Audio::Alsa, Some(_), _) => Err(StudyError::Audio(
                "--client-name names a JACK client, and `--audio alsa` plays on an ALSA device: \
                 name it with --alsa-device"
                    .into(),
            )),
            (Audio::Jack, client_name, None) => Ok(Interface::Jack {
                client_name: client_name.as_deref().unwrap_or(CLIENT_NAME).to_owned(),
            }),
            (Audio::Alsa, None, device) => Ok(Interface::Alsa {
                device: device.as_deref().unwrap_or(ALSA_DEVICE).to_owned(),
            }),
        }
    }
}

/// The audio interface opened, not yet playing: its sample rate is the stimuli's.
#[cfg(feature = "audio")]
enum Output {
    Jack(JackOutput),
    Alsa(AlsaOutput),
}

#[cfg(feature = "audio")]
impl Output {
    /// Reaches the interface; an ALSA device is asked for the scenes' sample rate and the
    /// spec's channel count.
    fn open(interface: &Interface, spec: &Spec) -> Result<Self, StudyError> {
        match interface {
            Interface::Jack { client_name } => JackOutput::open(client_name).map(Self::Jack),
            Interface::Alsa { device } => {
                AlsaOutput::open(device, spec.channels.count(), spec.sample_rate()).map(Self::Alsa)
            }
        }
    }

    fn sample_rate(&self) -> u32 {
        match self {
            Self::Jack(output) => output.sample_rate(),
            Self::Alsa(output) => output.sample_rate(),
        }
    }

    fn start(
        self,
        stimuli: Vec<Vec<f32>>,
        gap_samples: u64,
        channels: &Channels,
        noise_dbfs: Option<f64>,
    ) -> Result<Box<dyn Presenter>, StudyError> {
        Ok(match self {
            Self::Jack(output) => {
                Box::new(output.start(stimuli, gap_samples, channels, noise_dbfs)?)
            }
            Self::Alsa(output) => {
                Box::new(output.start(stimuli, gap_samples, channels, noise_dbfs)?)
            }
        })
    }
}

pub fn run(args: ExperimentArgs) -> ExitCode {
    match session(args) {
        Ok(()) => ExitCode::SUCCESS,
        Err((status, error)) => {
            eprintln!("error: {error}");
            ExitCode::from(status)
        }
    }
}

/// A usage error (exit status 2): nothing was presented.
fn usage(error: StudyError) -> (u8, StudyError) {
    (2, error)
}

/// The study's spec: its file, or the one --discriminate makes; and the path messages name.
fn load_spec(args: &ExperimentArgs) -> Result<(PathBuf, Spec), StudyError> {
    let Some(files) = &args.discriminate else {
        let path = args
            .spec
            .clone()
            .expect("clap requires a spec or --discriminate");
        return Spec::load(&path).map(|spec| (path, spec));
    };
    let path = PathBuf::from("--discriminate");
    let design = match args.design.as_deref() {
        None => DISCRIMINATE_DESIGNS[0],
        Some(name) => Design::from_name(name)
            .filter(|design| DISCRIMINATE_DESIGNS.contains(design))
            .ok_or_else(|| {
                let names: Vec<String> = DISCRIMINATE_DESIGNS
                    .iter()
                    .map(|design| format!("`{}`", design.name()))
                    .collect();
                StudyError::Spec {
                    path: path.clone(),
                    message: format!("--design `{}`: one of {}", quoted(name), names.join(", ")),
                }
            })?,
    };
    let repetitions = Discriminate::default_repetitions(design);
    let study = Discriminate {
        design,
        recording: files[0].clone(),
        model: files[1].clone(),
        start_s: args.start_s.unwrap_or(0.0),
        duration_s: args.duration_s.unwrap_or(2.0),
        repetitions: args.repetitions.unwrap_or(repetitions),
    };
    Spec::parse(&study.spec_text(), &path).map(|spec| (path, spec))
}

fn session(args: ExperimentArgs) -> Result<(), (u8, StudyError)> {
    let (spec_path, mut spec) = load_spec(&args).map_err(usage)?;
    if args.participant.trim().is_empty() || args.participant.chars().any(char::is_control) {
        return Err(usage(StudyError::Spec {
            path: spec_path.clone(),
            message: "--participant: give a non-empty ID without control characters".into(),
        }));
    }
    let interface = args.interface().map_err(usage)?;
    if let Some(actuator) = args.actuator {
        spec.channels.actuator = actuator;
    }
    if let Some(headphones) = args.headphones {
        spec.channels.headphones = headphones;
    }
    spec.channels.check(spec.noise_dbfs).map_err(|message| {
        usage(StudyError::Spec {
            path: spec_path.clone(),
            message,
        })
    })?;
    // Refused before the audio and the renders: the log is created or reopened after them.
    if let Some(log) = &args.log {
        TrialLog::check_path(log, args.resume).map_err(usage)?;
    }
    // So is a dry run's folder that holds anything (a resumed one keeps the folder it wrote).
    if let Some(dir) = &args.dry_run {
        if !(args.resume && dir.join(sake_glug_study::TRIAL_LIST).exists()) {
            check_dry_run_folder(dir).map_err(usage)?;
        }
    }
    let seed = order_seed(spec.seed, &args.participant);
    let trials = plan_trials(&spec, seed);

    // The audio interface first: its sample rate is the stimuli's.
    #[cfg(feature = "audio")]
    let output = match args.dry_run {
        Some(_) => None,
        None => Some(Output::open(&interface, &spec).map_err(|e| (1, e))?),
    };
    #[cfg(feature = "audio")]
    let sample_rate = output
        .as_ref()
        .map_or(spec.sample_rate(), |output| output.sample_rate());
    #[cfg(not(feature = "audio"))]
    let sample_rate = {
        if args.dry_run.is_none() {
            return Err((
                2,
                StudyError::Audio(
                    "this build plays no audio: build it with `--features audio` (JACK and \
                     ALSA), or run the session without it with `--dry-run DIR`"
                        .into(),
                ),
            ));
        }
        // The interface means nothing without audio.
        let _ = interface;
        spec.sample_rate()
    };

    #[cfg_attr(
        not(feature = "audio"),
        expect(unused_mut, reason = "the player takes the samples")
    )]
    let mut rendered = render_stimuli(&spec, sample_rate).map_err(usage)?;
    let practice = match spec.practice {
        0 => String::new(),
        count => format!(" after {count} practice trials"),
    };
    println!(
        "{} design, {} trials{practice}, order seed {seed}, equalize {} ({} Hz):",
        spec.design.name(),
        trials.len(),
        spec.equalize.name(),
        sample_rate
    );
    // What was matched: `none` shows the peaks.
    let kind = match spec.equalize {
        Equalize::Rms => "rms ",
        Equalize::Peak | Equalize::None => "peak",
    };
    for (stimulus, rendered) in spec.stimuli.iter().zip(&rendered) {
        println!(
            "  {:<24} {} {:>8.2} dBFS  gain {:>+7.3} dB",
            quoted(&stimulus.name),
            kind,
            20.0 * rendered.level.log10(),
            rendered.gain_db
        );
    }
    let session = StudySession {
        spec: &spec,
        participant: &args.participant,
        seed,
        trials: &trials,
        rendered: &rendered,
        dry_run: args.dry_run.is_some(),
    };
    // Locked and checked whole before anything is written, its own rows or the dry run's.
    let resumed = match (&args.log, args.resume) {
        (Some(log), true) => {
            let (log, done) = session.resume_log(log).map_err(usage)?;
            // Counted with the practice trials, which come first.
            println!(
                "Resuming after trial {done} of {}.",
                trials.len() + spec.practice as usize
            );
            Some((log, done))
        }
        _ => None,
    };
    let dry_run_files = match &args.dry_run {
        // A resumed dry run keeps the folder its first run wrote.
        Some(dir) if args.resume && dir.join(sake_glug_study::TRIAL_LIST).exists() => {
            Some(DryRunFiles::planned(&session, dir))
        }
        Some(dir) => {
            let written = write_dry_run(dir, &session, sample_rate).map_err(usage)?;
            println!(
                "Wrote {} files into {}.",
                written.count(),
                printable(&dir.to_string_lossy())
            );
            Some(written)
        }
        None => None,
    };
    let Some(log_path) = &args.log else {
        // --no-answers: the folder was the whole job.
        return Ok(());
    };
    // Created last, so that a refused folder or spec leaves no log behind.
    let (mut log, done) = match resumed {
        Some(resumed) => resumed,
        None => (TrialLog::create(log_path).map_err(usage)?, 0),
    };
    let _ = std::io::stdout().flush();

    let mut input = std::io::stdin().lock();
    let mut prompt = std::io::stdout();
    let result = match &dry_run_files {
        Some(files) => session.run(done, &mut DryRun(files), &mut log, &mut input, &mut prompt),
        #[cfg(feature = "audio")]
        None => {
            // The player takes the samples; the session keeps the gains for the log.
            let stimuli = rendered
                .iter_mut()
                .map(|r| std::mem::take(&mut r.samples))
                .collect();
            let session = StudySession {
                spec: &spec,
                participant: &args.participant,
                seed,
                trials: &trials,
                rendered: &rendered,
                dry_run: false,
            };
            let gap = (spec.gap_s * sample_rate as f64).round() as u64;
            let output = output.expect("opened above without --dry-run");
            let mut player = output
                .start(stimuli, gap, &spec.channels, spec.noise_dbfs)
                .map_err(|e| (1, e))?;
            session.run(done, player.as_mut(), &mut log, &mut input, &mut prompt)
        }
        #[cfg(not(feature = "audio"))]
        None => unreachable!("refused above without --dry-run"),
    };
    match result {
        // A dry run whose answers end before the first one (stdin closed, or /dev/null) is a
        // scripted dry run, as --no-answers is: its folder is the job, done.
        Err(StudyError::InputClosed { answered, total })
            if args.dry_run.is_some() && answered == done =>
        {
            eprintln!(
                "The answers (stdin) ended before the first one: the dry run's folder is \
                 written, and no trial was answered in this run ({answered} of {total} in the \
                 log; --resume continues). `--no-answers` (without --log) does this without a log."
            );
            Ok(())
        }
        result => result.map_err(|error| (1, error)),
    }
}
