//! Study spec files: TOML in, a validated [`Spec`] out, every stimulus a [`Scene`] ready to
//! render. A stimulus is a scene file, a preset or a model file with scene keys over it; the
//! keys are the scene's own (checked by the scene parser), so none is restated here.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::recording::Recording;
use super::StudyError;
use sake_glug_analysis::DiscriminationDesign;
use sake_glug_engine::{Constant, Control, Preset};
use sake_glug_io::keys::{self, KeyedTable};
use sake_glug_io::read::{self, InputKind};
use sake_glug_io::text::{cut_quotes, quoted};
use sake_glug_render::{Scene, DEFAULT_SCENE, MAX_DURATION_S};

/// The designs: the paper's two studies, and three of discrimination. The names of the
/// discrimination designs are the analysis's ([`DiscriminationDesign::name`]), which reads
/// their logs: one declaration for the spec, the log, the runner and `analyze`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(try_from = "String")]
pub enum Design {
    /// Every ordered pair of named stimuli (§3).
    Paired,
    /// A standard against comparison levels of one control or constant (§4.4).
    Constant,
    /// Two stimuli, the `target` first in half the trials: which one is the target?
    /// (two-alternative forced choice; `sake-glug analyze discrimination` reads its log).
    TwoAfc,
    /// Two stimuli, three intervals, two alike: which one is different? (oddity; either
    /// stimulus the odd one, at each place).
    Triangle,
    /// Two stimuli as A and B, then X, one of them: is X A or B?
    Abx,
}

impl Design {
    /// Its name in the spec and the log.
    pub fn name(self) -> &'static str {
        match self.discrimination() {
            Some(design) => design.name(),
            None if self == Design::Paired => "paired",
            None => "constant",
        }
    }

    /// The discrimination design it is, as `sake-glug analyze discrimination` reads its log;
    /// `None` for the paper's two.
    pub fn discrimination(self) -> Option<DiscriminationDesign> {
        match self {
            Design::Paired | Design::Constant => None,
            Design::TwoAfc => Some(DiscriminationDesign::TwoAfc),
            Design::Triangle => Some(DiscriminationDesign::Triangle),
            Design::Abx => Some(DiscriminationDesign::Abx),
        }
    }

    /// Every design, in the order `--help` and the messages list them.
    pub const ALL: [Design; 5] = [
        Design::Paired,
        Design::Constant,
        Design::TwoAfc,
        Design::Triangle,
        Design::Abx,
    ];

    /// The design of `name` (as the spec and the log write it).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|design| design.name() == name)
    }

    /// The stimuli a trial plays: 3 in the triangle and ABX, else 2.
    pub fn intervals(self) -> u8 {
        match self {
            Design::Triangle | Design::Abx => 3,
            Design::Paired | Design::Constant | Design::TwoAfc => 2,
        }
    }

    /// The answers a trial takes (keys 1 to this): the triangle's three places, else two.
    pub fn answers(self) -> u8 {
        match self {
            Design::Triangle => 3,
            _ => 2,
        }
    }

    /// Whether its log rows say if the answer was right (the discrimination designs).
    pub fn discriminates(self) -> bool {
        self.discrimination().is_some()
    }

    /// What a session of it presents, as `--help` says it.
    pub fn task(self) -> &'static str {
        match self {
            Design::Paired => "every ordered pair of named stimuli (the paper's §3)",
            Design::Constant => {
                "a standard against comparison levels of one control or constant (the paper's §4.4)"
            }
            Design::TwoAfc => "two stimuli: which one is the target (the recording)?",
            Design::Triangle => "three stimuli, two alike: which one is different?",
            Design::Abx => "A, B, then X: is X A or B?",
        }
    }

    /// The arrangements of two stimuli one repetition of a discrimination design presents
    /// (its orders, or which stimulus is the odd one where); `None` for the paper's two.
    pub fn arrangements(self) -> Option<u32> {
        match self {
            Design::Paired | Design::Constant => None,
            Design::TwoAfc => Some(2),
            Design::Triangle => Some(6),
            Design::Abx => Some(4),
        }
    }
}

impl TryFrom<String> for Design {
    type Error = String;

    /// A spec's `design`, by name; else the names it could be.
    fn try_from(name: String) -> Result<Self, String> {
        Self::from_name(&name).ok_or_else(|| {
            let names: Vec<String> = Self::ALL
                .iter()
                .map(|design| format!("`{}`", design.name()))
                .collect();
            format!(
                "`{}`: not a design; expected one of {}",
                quoted(&name),
                names.join(", ")
            )
        })
    }
}

/// Which level is made equal across a spec's stimuli (MODEL.md §15).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Equalize {
    /// The largest |sample|.
    Peak,
    /// The root mean square over the whole stimulus.
    Rms,
    /// As rendered.
    #[default]
    None,
}

impl Equalize {
    /// Its name in the spec.
    pub fn name(self) -> &'static str {
        match self {
            Equalize::Peak => "peak",
            Equalize::Rms => "rms",
            Equalize::None => "none",
        }
    }
}

/// Which of the player's output channels (from 1) carry what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Channels {
    /// The stimuli (the actuator's amplifier): channel 1 unless the spec names others.
    pub actuator: Vec<u16>,
    /// The masking noise (the headphones): none unless the spec names them.
    pub headphones: Vec<u16>,
}

impl Channels {
    fn default_actuator() -> Vec<u16> {
        vec![1]
    }

    /// How many output channels the player needs.
    pub fn count(&self) -> u16 {
        self.actuator
            .iter()
            .chain(&self.headphones)
            .copied()
            .max()
            .unwrap_or(0)
    }

    /// Refuses channel 0, a channel with both roles (the noise must stay off the actuator), and
    /// masking noise (`noise_dbfs`) with no headphone channel to play it on.
    pub fn check(&self, noise_dbfs: Option<f64>) -> Result<(), String> {
        if noise_dbfs.is_some() && self.headphones.is_empty() {
            return Err(
                "`noise_dbfs` needs headphone channels (`channels.headphones` or --headphones)"
                    .into(),
            );
        }
        if self.actuator.is_empty() {
            return Err("`channels.actuator` names no channel".into());
        }
        if let Some(zero) = self
            .actuator
            .iter()
            .chain(&self.headphones)
            .find(|&&c| c == 0)
        {
            return Err(format!("channel {zero}: channels are numbered from 1"));
        }
        if let Some(both) = self.actuator.iter().find(|c| self.headphones.contains(c)) {
            return Err(format!(
                "channel {both} is both an actuator and a headphone channel"
            ));
        }
        Ok(())
    }
}

impl Default for Channels {
    fn default() -> Self {
        Self {
            actuator: Self::default_actuator(),
            headphones: Vec::new(),
        }
    }
}

/// One stimulus: its name in the log, its definition as written (for the log) and its scene.
#[derive(Debug, Clone)]
pub struct Stimulus {
    /// Its name (`first`, `second` and `answer` in the log).
    pub name: String,
    /// The stimulus as the spec defines it, one line of inline TOML.
    pub params: String,
    /// The comparison level, for the constant design's comparisons.
    pub level: Option<f64>,
    /// What it is played from.
    pub source: Source,
}

/// What a stimulus is played from.
#[derive(Debug, Clone)]
pub enum Source {
    /// A scene to render, lasting the spec's `duration_s`.
    Scene(Box<Scene>),
    /// A recording's excerpt of the spec's `duration_s` (`audio = "FILE.wav"`, `start_s`).
    Recording(Recording),
}

/// A validated study spec.
#[derive(Debug, Clone)]
pub struct Spec {
    /// The file it was read from.
    pub path: PathBuf,
    /// Paired or constant.
    pub design: Design,
    /// The question asked after each trial.
    pub question: String,
    /// Length of each stimulus (s).
    pub duration_s: f64,
    /// Silence between the two stimuli of a trial (s).
    pub gap_s: f64,
    /// How many times each ordered pair (paired) or each level (constant) is presented.
    pub repetitions: u32,
    /// The seed of the trial order, mixed with the participant's ID.
    pub seed: u64,
    /// The level matching.
    pub equalize: Equalize,
    /// The masking noise's RMS level (dBFS) on the headphone channels, if any.
    pub noise_dbfs: Option<f64>,
    /// The channel layout.
    pub channels: Channels,
    /// The stimuli; for the constant design the standard first, then the comparisons in order;
    /// for 2AFC the target first, then the other.
    pub stimuli: Vec<Stimulus>,
    /// What the participant reads before the first trial.
    pub instructions: Option<String>,
    /// Practice trials played before the study's, logged as practice (not data).
    pub practice: u32,
    /// A pause after every this many of the study's trials, which the participant ends.
    pub break_every: Option<u32>,
}

impl Spec {
    /// The rate a dry run writes, and an ALSA device is asked for: the first recording's, whose
    /// samples are then played as they are; else the first scene's.
    pub fn sample_rate(&self) -> u32 {
        let recording = self
            .stimuli
            .iter()
            .find_map(|stimulus| match &stimulus.source {
                Source::Recording(recording) => Some(recording.sample_rate),
                Source::Scene(_) => None,
            });
        let scene = || {
            self.stimuli
                .iter()
                .find_map(|stimulus| match &stimulus.source {
                    Source::Scene(scene) => Some(scene.sample_rate),
                    Source::Recording(_) => None,
                })
        };
        recording
            .or_else(scene)
            .expect("a spec has two stimuli or more")
    }
}

/// How `sake-glug experiment --discriminate` sets up a discrimination study of a recording
/// against a model.
#[derive(Debug, Clone, PartialEq)]
pub struct Discriminate {
    /// The design: triangle, 2AFC or ABX.
    pub design: Design,
    /// The recording (the target: "which one is the recording?").
    pub recording: PathBuf,
    /// The model file fitted to it.
    pub model: PathBuf,
    /// Where the recording's excerpt starts (s).
    pub start_s: f64,
    /// Each stimulus's length (s).
    pub duration_s: f64,
    /// Presentations of each order.
    pub repetitions: u32,
}

/// The designs `--discriminate` sets up, the default first.
pub const DISCRIMINATE_DESIGNS: [Design; 3] = [Design::Triangle, Design::TwoAfc, Design::Abx];

impl Discriminate {
    /// Presentations of each order `--discriminate` gives `design` unless told: about two dozen
    /// trials whatever the design.
    pub fn default_repetitions(design: Design) -> u32 {
        match design {
            Design::Triangle => 4,
            Design::Abx => 6,
            _ => 10,
        }
    }

    /// The trials of the session `--discriminate` runs of `design` by default (the
    /// recording and the model, [`Discriminate::default_repetitions`] times): what a plan of the
    /// study assumes unless told (`analyze plan discrimination --trials-each`).
    pub fn default_trials(design: Design) -> u32 {
        let trials = trial_count(design, 2, Self::default_repetitions(design));
        u32::try_from(trials).expect("two dozen trials")
    }

    /// The spec file of the study: its design (for 2AFC the recording the target: "which one is
    /// the recording?"), the model with the built-in pour's other keys, levels matched by RMS,
    /// half a second between stimuli.
    pub fn spec_text(&self) -> String {
        let path = |path: &Path| {
            let absolute = std::path::absolute(path).unwrap_or_else(|_| path.to_owned());
            toml::Value::String(absolute.to_string_lossy().into_owned())
        };
        let mut recording = toml::Table::new();
        recording.insert(AUDIO.into(), path(&self.recording));
        recording.insert(START_S.into(), toml::Value::Float(self.start_s));
        // The model poured as the built-in scene pours.
        let mut model = parse_table(DEFAULT_SCENE);
        model.insert(MODEL.into(), path(&self.model));
        let mut stimuli = toml::Table::new();
        stimuli.insert("recording".into(), toml::Value::Table(recording));
        stimuli.insert("model".into(), toml::Value::Table(model));
        let mut spec = toml::Table::new();
        let mut set = |key: &str, value: toml::Value| spec.insert(key.into(), value);
        set("design", toml::Value::String(self.design.name().into()));
        if self.design == Design::TwoAfc {
            set("target", toml::Value::String("recording".into()));
            set(
                "question",
                toml::Value::String("Which one is the recording?".into()),
            );
        }
        set("duration_s", toml::Value::Float(self.duration_s));
        set("gap_s", toml::Value::Float(0.5));
        set("repetitions", toml::Value::Integer(self.repetitions.into()));
        set("equalize", toml::Value::String(Equalize::Rms.name().into()));
        set("stimuli", toml::Value::Table(stimuli));
        toml::to_string(&spec).expect("a table of strings and numbers is TOML")
    }
}

/// The masking noise is uniform white noise: its RMS is its peak over √3, and its peak may
/// not pass full scale, so its RMS level is at most −4.77 dBFS.
pub const MAX_NOISE_DBFS: f64 = -4.771_212_547_196_624;
/// Quieter than this is no masking.
pub const MIN_NOISE_DBFS: f64 = -120.0;

/// The name of the constant design's standard.
pub const STANDARD: &str = "standard";

/// The default question.
const QUESTION: &str = "Which one?";

/// The keys of a stimulus that name what its scene starts from (the rest are scene keys).
const PRESET: &str = "preset";
const SCENE: &str = "scene";
const MODEL: &str = "model";
/// The keys of a recorded stimulus.
const AUDIO: &str = "audio";
const START_S: &str = "start_s";
/// A stimulus table's own keys (its others are scene keys), as experiments/README.md lists
/// them.
pub const STIMULUS_KEYS: [&str; 5] = [PRESET, SCENE, MODEL, AUDIO, START_S];

impl Spec {
    /// Reads and validates the spec at `path`; the scene and model files it names are found
    /// relative to its folder.
    pub fn load(path: &Path) -> Result<Self, StudyError> {
        let text = read::read_text(path, InputKind::STUDY_SPEC)?;
        Self::parse(&text, path)
    }

    /// Parses and validates a spec from `text`, read from `path`.
    pub fn parse(text: &str, path: &Path) -> Result<Self, StudyError> {
        let bad = |message: String| StudyError::Spec {
            path: path.to_owned(),
            message,
        };
        let table: toml::Table =
            toml::from_str(text).map_err(|error| bad(keys::syntax_message(&error, text)))?;
        let mut file = KeyedTable::new(table);
        let mut take = |key: &str| -> Result<Option<toml::Value>, StudyError> {
            file.take(key).map_err(|message| bad(cut_quotes(&message)))
        };
        let design: Design = required(take("design")?, "design").map_err(bad)?;
        let question: Option<String> = optional(take("question")?, "question").map_err(bad)?;
        let target: Option<String> = optional(take("target")?, "target").map_err(bad)?;
        let duration_s: f64 = required(take("duration_s")?, "duration_s").map_err(bad)?;
        let gap_s: f64 = required(take("gap_s")?, "gap_s").map_err(bad)?;
        let repetitions: u32 = required(take("repetitions")?, "repetitions").map_err(bad)?;
        let seed: u64 = optional(take("seed")?, "seed").map_err(bad)?.unwrap_or(0);
        let equalize: Equalize = optional(take("equalize")?, "equalize")
            .map_err(bad)?
            .unwrap_or_default();
        let noise_dbfs: Option<f64> = optional(take("noise_dbfs")?, "noise_dbfs").map_err(bad)?;
        let actuator = optional(take(CHANNELS_ACTUATOR)?, CHANNELS_ACTUATOR).map_err(bad)?;
        let headphones = optional(take(CHANNELS_HEADPHONES)?, CHANNELS_HEADPHONES).map_err(bad)?;
        let instructions: Option<String> =
            optional(take("instructions")?, "instructions").map_err(bad)?;
        let practice: u32 = optional(take("practice")?, "practice")
            .map_err(bad)?
            .unwrap_or(0);
        let break_every: Option<u32> =
            optional(take("break_every")?, "break_every").map_err(bad)?;
        let mut section = |key: &str| -> Result<Option<toml::Table>, StudyError> {
            optional(take(key)?, key).map_err(bad)
        };
        let named_stimuli = section("stimuli")?;
        let shared = section("stimulus")?;
        let standard = section("standard")?;
        let comparisons = section("comparisons")?;
        file.refuse_unknown()
            .map_err(|message| bad(cut_quotes(&message)))?;

        if !(duration_s > 0.0 && duration_s <= MAX_DURATION_S) {
            return Err(bad(format!(
                "`duration_s` = {duration_s}: it must lie above 0 and at most {MAX_DURATION_S} s"
            )));
        }
        if !(0.0..=MAX_DURATION_S).contains(&gap_s) {
            return Err(bad(format!(
                "`gap_s` = {gap_s}: it must lie from 0 to {MAX_DURATION_S} s"
            )));
        }
        if repetitions == 0 {
            return Err(bad("`repetitions` = 0: it must be at least 1".into()));
        }
        if practice > MAX_PRACTICE {
            return Err(bad(format!(
                "`practice` = {practice}: at most {MAX_PRACTICE} practice trials"
            )));
        }
        if break_every == Some(0) {
            return Err(bad(
                "`break_every` = 0: a pause after every 1 or more trials (leave it out for none)"
                    .into(),
            ));
        }
        if instructions
            .as_deref()
            .is_some_and(|text| text.trim().is_empty())
        {
            return Err(bad(
                "`instructions` is empty: give the text, or leave the key out".into(),
            ));
        }
        if let Some(level) = noise_dbfs {
            if !(MIN_NOISE_DBFS..=MAX_NOISE_DBFS).contains(&level) {
                return Err(bad(format!(
                    "`noise_dbfs` = {level} is out of range: allowed {MIN_NOISE_DBFS} to \
                     {MAX_NOISE_DBFS:.2} (the RMS of uniform noise that peaks at full scale)"
                )));
            }
        }
        let channels = Channels {
            actuator: actuator.unwrap_or_else(Channels::default_actuator),
            headphones: headphones.unwrap_or_default(),
        };
        channels.check(noise_dbfs).map_err(bad)?;
        let folder = path.parent().unwrap_or(Path::new(""));
        let stimulus = |name: String, table: toml::Table, level: Option<f64>| {
            build_stimulus(path, folder, name, table, level, duration_s)
        };
        let misplaced = |key: &str| {
            bad(format!(
                "`{key}` does not belong to the {} design",
                design.name()
            ))
        };
        if target.is_some() && design != Design::TwoAfc {
            return Err(misplaced("target"));
        }
        let stimuli = match design {
            Design::TwoAfc | Design::Triangle | Design::Abx => {
                for (key, value) in [
                    ("stimulus", shared.is_some()),
                    ("standard", standard.is_some()),
                    ("comparisons", comparisons.is_some()),
                ] {
                    if value {
                        return Err(misplaced(key));
                    }
                }
                let named = named_stimuli.unwrap_or_default();
                let names = named
                    .keys()
                    .map(|name| format!("`{}`", quoted(name)))
                    .collect::<Vec<_>>()
                    .join(", ");
                if named.len() != 2 {
                    let study = match design {
                        Design::TwoAfc => "2AFC",
                        Design::Abx => "ABX",
                        _ => "triangle",
                    };
                    return Err(bad(format!(
                        "`stimuli` names {} stimulus(es) ({}): a {study} study has two",
                        named.len(),
                        names
                    )));
                }
                let mut ordered: Vec<(String, toml::Value)> = named.into_iter().collect();
                if design == Design::TwoAfc {
                    let target = target.as_deref().ok_or_else(|| {
                        bad(format!(
                            "missing field `target`: the stimulus the question asks for, one of {}",
                            names
                        ))
                    })?;
                    if !ordered.iter().any(|(name, _)| name == target) {
                        return Err(bad(format!(
                            "`target` = \"{}\" is not a stimulus; one of {}",
                            quoted(target),
                            names
                        )));
                    }
                    // The target first, then the other.
                    ordered.sort_by_key(|(name, _)| name != target);
                }
                // The triangle and ABX treat both alike: they stay in the spec's name order.
                check_trials(design, 2, repetitions).map_err(bad)?;
                ordered
                    .into_iter()
                    .map(|(name, value)| match value {
                        toml::Value::Table(table) => stimulus(name, table, None),
                        other => Err(bad(format!(
                            "`{}`: invalid type: {}, expected a table",
                            quoted(&keys::join("stimuli", &name)),
                            other.type_str()
                        ))),
                    })
                    .collect::<Result<Vec<_>, _>>()?
            }
            Design::Paired => {
                for (key, value) in [
                    ("stimulus", shared.is_some()),
                    ("standard", standard.is_some()),
                    ("comparisons", comparisons.is_some()),
                ] {
                    if value {
                        return Err(misplaced(key));
                    }
                }
                let named = named_stimuli.unwrap_or_default();
                if named.len() < 2 {
                    return Err(bad(format!(
                        "`stimuli` names {} stimulus(es): a paired comparison needs at least 2",
                        named.len()
                    )));
                }
                check_trials(design, named.len(), repetitions).map_err(bad)?;
                named
                    .into_iter()
                    .map(|(name, value)| match value {
                        toml::Value::Table(table) => stimulus(name, table, None),
                        other => Err(bad(format!(
                            "`{}`: invalid type: {}, expected a table",
                            quoted(&keys::join("stimuli", &name)),
                            other.type_str()
                        ))),
                    })
                    .collect::<Result<Vec<_>, _>>()?
            }
            Design::Constant => {
                if named_stimuli.is_some() {
                    return Err(misplaced("stimuli"));
                }
                let base = shared.unwrap_or_default();
                let (key, comparisons) = one_level(comparisons, "comparisons").map_err(bad)?;
                let (standard_key, standard) = one_level(standard, "standard").map_err(bad)?;
                if standard_key != key {
                    return Err(bad(format!(
                        "`{}`: the standard must set the compared key `{key}`",
                        keys::join("standard", &standard_key)
                    )));
                }
                let standard = number(&standard).ok_or_else(|| {
                    bad(format!(
                        "`{}`: expected a number",
                        keys::join("standard", &key)
                    ))
                })?;
                let listed = keys::join("comparisons", &key);
                let toml::Value::Array(comparisons) = comparisons else {
                    return Err(bad(format!("`{listed}`: expected a list of numbers")));
                };
                let levels = comparisons
                    .iter()
                    .map(number)
                    .collect::<Option<Vec<f64>>>()
                    .filter(|levels| !levels.is_empty())
                    .ok_or_else(|| {
                        bad(format!("`{listed}`: expected a non-empty list of numbers"))
                    })?;
                check_trials(design, levels.len() + 1, repetitions).map_err(bad)?;
                let with_level = |value: f64| {
                    let mut table = base.clone();
                    keys::insert(&mut table, &key, toml::Value::Float(value));
                    table
                };
                let mut stimuli = vec![stimulus(STANDARD.into(), with_level(standard), None)?];
                for (index, &level) in levels.iter().enumerate() {
                    let name = format!("{key}={level}");
                    if levels[..index].contains(&level) {
                        return Err(bad(format!("`{listed}` lists {level} twice")));
                    }
                    stimuli.push(stimulus(name, with_level(level), Some(level))?);
                }
                stimuli
            }
        };
        let default_question = match design {
            Design::TwoAfc => format!("Which one is `{}`?", stimuli[0].name),
            Design::Triangle => "Two are alike: which one is different?".into(),
            Design::Abx => "The third is one of the first two: which?".into(),
            Design::Paired | Design::Constant => QUESTION.into(),
        };
        Ok(Spec {
            path: path.to_owned(),
            design,
            question: question.unwrap_or(default_question),
            duration_s,
            gap_s,
            repetitions,
            seed,
            equalize,
            noise_dbfs,
            channels,
            stimuli,
            instructions,
            practice,
            break_every,
        })
    }
}

/// The spec's keys of the channel layout.
const CHANNELS_ACTUATOR: &str = "channels.actuator";
const CHANNELS_HEADPHONES: &str = "channels.headphones";

/// The most trials a session may have: a long day of the shortest trials, far more than a study
/// asks of one participant (the paper's are 18 and 90), and a bound on what a session holds in
/// memory and what its dry run writes (two files a trial).
pub const MAX_TRIALS: u64 = 10_000;

/// The most practice trials a session may have: practice is a few trials to learn the task.
pub const MAX_PRACTICE: u32 = 100;

/// Trials in a session of `design` with `stimuli` stimuli (the standard included) presented
/// `repetitions` times: every ordered pair, or every comparison.
fn trial_count(design: Design, stimuli: usize, repetitions: u32) -> u64 {
    let stimuli = stimuli as u64;
    let per_repetition = match design.arrangements() {
        Some(arrangements) => u64::from(arrangements),
        None if design == Design::Paired => stimuli * stimuli.saturating_sub(1),
        None => stimuli.saturating_sub(1),
    };
    per_repetition.saturating_mul(u64::from(repetitions))
}

/// Refuses a session of more than [`MAX_TRIALS`] trials, with the figure.
fn check_trials(design: Design, stimuli: usize, repetitions: u32) -> Result<(), String> {
    let trials = trial_count(design, stimuli, repetitions);
    if trials <= MAX_TRIALS {
        return Ok(());
    }
    let what = match design {
        Design::Paired => format!("{} ordered pairs", trials / u64::from(repetitions)),
        Design::Constant => format!("{} comparisons", trials / u64::from(repetitions)),
        Design::TwoAfc => "2 orders".into(),
        Design::Triangle | Design::Abx => {
            format!("{} arrangements", trials / u64::from(repetitions))
        }
    };
    Err(format!(
        "{what} × `repetitions` = {repetitions} make {trials} trials a session: at most \
         {MAX_TRIALS} (split the study into sessions, or repeat less)"
    ))
}

/// A key's value converted, or a message naming the key.
fn optional<T: serde::de::DeserializeOwned>(
    value: Option<toml::Value>,
    key: &str,
) -> Result<Option<T>, String> {
    value
        .map(|value| {
            value.try_into().map_err(|error: toml::de::Error| {
                format!("`{key}`: {}", cut_quotes(error.message().trim_end()))
            })
        })
        .transpose()
}

/// A key that must be given.
fn required<T: serde::de::DeserializeOwned>(
    value: Option<toml::Value>,
    key: &str,
) -> Result<T, String> {
    optional(value, key)?.ok_or_else(|| format!("missing field `{key}`"))
}

/// The scene keys a constant design may vary: every control's and every constant's, from their
/// tables.
pub fn level_keys() -> impl Iterator<Item = &'static str> {
    Control::ALL
        .iter()
        .map(|control| control.quantity().scene_key)
        .chain(
            Constant::ALL
                .iter()
                .map(|constant| constant.quantity().scene_key),
        )
}

/// The one key (`section.name` for a constant in a section) of `[standard]` or
/// `[comparisons]`, and its value.
fn one_level(table: Option<toml::Table>, place: &str) -> Result<(String, toml::Value), String> {
    let leaves = keys::flatten(&table.unwrap_or_default());
    let known = || {
        let keys: Vec<String> = level_keys().map(|key| format!("`{key}`")).collect();
        keys.join(", ")
    };
    match <[_; 1]>::try_from(leaves) {
        Ok([(key, value)]) => {
            if level_keys().any(|known| known == key) {
                Ok((key, value))
            } else {
                Err(format!(
                    "`{}`: not a control or constant; expected one of {}",
                    quoted(&keys::join(place, &key)),
                    known()
                ))
            }
        }
        Err(leaves) => Err(format!(
            "`[{place}]` must set exactly one key (one of {}), it sets {}",
            known(),
            leaves.len()
        )),
    }
}

/// `over`'s keys laid over `base`, section by section.
fn merge(base: &mut toml::Table, over: toml::Table) {
    for (key, value) in over {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(inner)), toml::Value::Table(over)) => merge(inner, over),
            (_, value) => {
                base.insert(key, value);
            }
        }
    }
}

fn number(value: &toml::Value) -> Option<f64> {
    value
        .as_float()
        .or_else(|| value.as_integer().map(|integer| integer as f64))
}

/// A stimulus from its table: the scene it starts from (`preset`, `scene` or `model`, else the
/// built-in pour) with the table's other keys over it, lasting `duration_s`.
fn build_stimulus(
    spec: &Path,
    folder: &Path,
    name: String,
    mut table: toml::Table,
    level: Option<f64>,
    duration_s: f64,
) -> Result<Stimulus, StudyError> {
    let bad = |message: String| StudyError::Stimulus {
        path: spec.to_owned(),
        name: quoted(&name),
        message,
    };
    let params = toml::Value::Table(table.clone()).to_string();
    if let Some(audio) = table.remove(AUDIO) {
        let toml::Value::String(file) = audio else {
            return Err(bad(format!(
                "`{AUDIO}`: invalid type: {}, expected a file name",
                audio.type_str()
            )));
        };
        let start_s = match table.remove(START_S) {
            None => 0.0,
            Some(value) => number(&value)
                .ok_or_else(|| bad(format!("`{START_S}`: expected a number of seconds")))?,
        };
        if let Some(key) = table.keys().next() {
            return Err(bad(format!(
                "`{}`: a recording (`{AUDIO}`) takes `{START_S}` only, no scene key",
                quoted(key)
            )));
        }
        let recording = Recording::open(folder.join(&file), start_s).map_err(bad)?;
        return Ok(Stimulus {
            name,
            params,
            level,
            source: Source::Recording(recording),
        });
    }
    if table.contains_key(START_S) {
        return Err(bad(format!(
            "`{START_S}` belongs to a recording (`{AUDIO}` = \"FILE.wav\")"
        )));
    }
    let mut sources: Vec<(&str, toml::Value)> = [PRESET, SCENE, MODEL]
        .into_iter()
        .filter_map(|key| Some((key, table.remove(key)?)))
        .collect();
    if sources.len() > 1 {
        return Err(bad(format!(
            "give at most one of `{PRESET}`, `{SCENE}` and `{MODEL}`"
        )));
    }
    let (mut base, scene_folder) = match sources.pop() {
        None => (parse_table(DEFAULT_SCENE), folder.to_owned()),
        Some((key, toml::Value::String(value))) if key == PRESET => {
            let preset = Preset::find(&value).ok_or_else(|| {
                bad(format!(
                    "`{PRESET}` = \"{}\": no such preset; the presets are {}",
                    quoted(&value),
                    Preset::ids()
                ))
            })?;
            (parse_table(&Scene::preset_toml(preset)), folder.to_owned())
        }
        Some((key, toml::Value::String(file))) => {
            let path = folder.join(&file);
            let kind = if key == MODEL {
                InputKind::MODEL
            } else {
                InputKind::SCENE
            };
            let text = read::text_within(&path, kind.max_bytes).map_err(|failure| {
                bad(format!(
                    "`{key}` = \"{}\": cannot read it: {failure}",
                    quoted(&file)
                ))
            })?;
            let table: toml::Table = toml::from_str(&text).map_err(|error| {
                bad(format!(
                    "`{key}` = \"{}\": not TOML: {}",
                    quoted(&file),
                    keys::syntax_message(&error, &text)
                ))
            })?;
            let scene_folder = path.parent().unwrap_or(Path::new("")).to_owned();
            (table, scene_folder)
        }
        Some((key, other)) => {
            return Err(bad(format!(
                "`{key}`: invalid type: {}, expected a string",
                other.type_str()
            )))
        }
    };
    if table.contains_key("duration_s") {
        return Err(bad(
            "`duration_s`: every stimulus lasts the spec's `duration_s`".into(),
        ));
    }
    merge(&mut base, table);
    base.insert("duration_s".into(), toml::Value::Float(duration_s));
    let scene = Scene::parse_in(
        &toml::to_string(&base).expect("a table read from TOML is valid TOML"),
        &scene_folder,
    )
    .map_err(|error| bad(cut_quotes(&error.to_string())))?;
    Ok(Stimulus {
        name,
        params,
        level,
        source: Source::Scene(Box::new(scene)),
    })
}

fn parse_table(text: &str) -> toml::Table {
    toml::from_str(text).expect("the built-in scenes are valid TOML")
}
