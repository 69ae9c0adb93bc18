//! Study spec files: TOML in, a validated [`Spec`] out, every stimulus a [`Scene`] ready to
//! render. A stimulus is a scene file, a preset or a model file with scene keys over it; the
//! keys are the scene's own (checked by the scene parser), so none is restated here.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::StudyError;
use sake_glug_engine::{Constant, Control, Preset};
use sake_glug_io::read::{self, InputKind};
use sake_glug_io::text::printable;
use sake_glug_render::{Scene, DEFAULT_SCENE, MAX_DURATION_S};

/// The two designs of the paper's studies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Design {
    /// Every ordered pair of named stimuli (§3).
    Paired,
    /// A standard against comparison levels of one control or constant (§4.4).
    Constant,
}

impl Design {
    /// Its name in the spec and the log.
    pub fn name(self) -> &'static str {
        match self {
            Design::Paired => "paired",
            Design::Constant => "constant",
        }
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
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Channels {
    /// The stimuli (the actuator's amplifier).
    #[serde(default = "Channels::default_actuator")]
    pub actuator: Vec<u16>,
    /// The masking noise (the headphones).
    #[serde(default)]
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
    /// The scene to render, lasting the spec's `duration_s`.
    pub scene: Scene,
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
    /// The stimuli; for the constant design the standard first, then the comparisons in order.
    pub stimuli: Vec<Stimulus>,
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

/// The spec's top level, as written.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SpecFile {
    design: Design,
    question: Option<String>,
    duration_s: f64,
    gap_s: f64,
    repetitions: u32,
    #[serde(default)]
    seed: u64,
    #[serde(default)]
    equalize: Equalize,
    noise_dbfs: Option<f64>,
    #[serde(default)]
    channels: Option<Channels>,
    /// Paired: every stimulus by name.
    stimuli: Option<toml::Table>,
    /// Constant: what the standard and the comparisons share.
    stimulus: Option<toml::Table>,
    standard: Option<toml::Table>,
    comparisons: Option<toml::Table>,
}

/// The keys of a stimulus that name what its scene starts from (the rest are scene keys).
const PRESET: &str = "preset";
const SCENE: &str = "scene";
const MODEL: &str = "model";

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
        let file: SpecFile = toml::from_str(text)
            .map_err(|error| bad(printable(error.to_string().trim_end()).into_owned()))?;
        if !(file.duration_s > 0.0 && file.duration_s <= MAX_DURATION_S) {
            return Err(bad(format!(
                "`duration_s` = {}: it must lie above 0 and at most {MAX_DURATION_S} s",
                file.duration_s
            )));
        }
        if !(file.gap_s >= 0.0 && file.gap_s <= MAX_DURATION_S) {
            return Err(bad(format!(
                "`gap_s` = {}: it must lie from 0 to {MAX_DURATION_S} s",
                file.gap_s
            )));
        }
        if file.repetitions == 0 {
            return Err(bad("`repetitions` = 0: it must be at least 1".into()));
        }
        if let Some(level) = file.noise_dbfs {
            if !(MIN_NOISE_DBFS..=MAX_NOISE_DBFS).contains(&level) {
                return Err(bad(format!(
                    "`noise_dbfs` = {level} is out of range: allowed {MIN_NOISE_DBFS} to \
                     {MAX_NOISE_DBFS:.2} (the RMS of uniform noise that peaks at full scale)"
                )));
            }
        }
        let channels = file.channels.unwrap_or_default();
        channels.check(file.noise_dbfs).map_err(bad)?;
        let folder = path.parent().unwrap_or(Path::new(""));
        let stimulus = |name: String, table: toml::Table, level: Option<f64>| {
            build_stimulus(path, folder, name, table, level, file.duration_s)
        };
        let misplaced = |key: &str| {
            bad(format!(
                "`{key}` does not belong to the {} design",
                file.design.name()
            ))
        };
        let stimuli = match file.design {
            Design::Paired => {
                for (key, value) in [
                    ("stimulus", file.stimulus.is_some()),
                    ("standard", file.standard.is_some()),
                    ("comparisons", file.comparisons.is_some()),
                ] {
                    if value {
                        return Err(misplaced(key));
                    }
                }
                let named = file.stimuli.unwrap_or_default();
                if named.len() < 2 {
                    return Err(bad(format!(
                        "`stimuli` names {} stimulus(es): a paired comparison needs at least 2",
                        named.len()
                    )));
                }
                named
                    .into_iter()
                    .map(|(name, value)| match value {
                        toml::Value::Table(table) => stimulus(name, table, None),
                        other => Err(bad(format!(
                            "`stimuli.{name}`: invalid type: {}, expected a table",
                            other.type_str()
                        ))),
                    })
                    .collect::<Result<Vec<_>, _>>()?
            }
            Design::Constant => {
                if file.stimuli.is_some() {
                    return Err(misplaced("stimuli"));
                }
                let base = file.stimulus.unwrap_or_default();
                let (key, comparisons) = one_level(file.comparisons, "comparisons").map_err(bad)?;
                let (standard_key, standard) = one_level(file.standard, "standard").map_err(bad)?;
                if standard_key != key {
                    return Err(bad(format!(
                        "`standard.{standard_key}`: the standard must set the compared key \
                         `{key}`"
                    )));
                }
                let standard = number(&standard)
                    .ok_or_else(|| bad(format!("`standard.{key}`: expected a number")))?;
                let toml::Value::Array(comparisons) = comparisons else {
                    return Err(bad(format!(
                        "`comparisons.{key}`: expected a list of numbers"
                    )));
                };
                let levels = comparisons
                    .iter()
                    .map(number)
                    .collect::<Option<Vec<f64>>>()
                    .filter(|levels| !levels.is_empty())
                    .ok_or_else(|| {
                        bad(format!(
                            "`comparisons.{key}`: expected a non-empty list of numbers"
                        ))
                    })?;
                let with_level = |value: f64| {
                    let mut table = base.clone();
                    set_key(&mut table, &key, toml::Value::Float(value));
                    table
                };
                let mut stimuli = vec![stimulus(STANDARD.into(), with_level(standard), None)?];
                for (index, &level) in levels.iter().enumerate() {
                    let name = format!("{key}={level}");
                    if levels[..index].contains(&level) {
                        return Err(bad(format!("`comparisons.{key}` lists {level} twice")));
                    }
                    stimuli.push(stimulus(name, with_level(level), Some(level))?);
                }
                stimuli
            }
        };
        Ok(Spec {
            path: path.to_owned(),
            design: file.design,
            question: file.question.unwrap_or_else(|| QUESTION.into()),
            duration_s: file.duration_s,
            gap_s: file.gap_s,
            repetitions: file.repetitions,
            seed: file.seed,
            equalize: file.equalize,
            noise_dbfs: file.noise_dbfs,
            channels,
            stimuli,
        })
    }
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
    let mut leaves = Vec::new();
    flatten("", table.unwrap_or_default(), &mut leaves);
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
                    "`{place}.{key}`: not a control or constant; expected one of {}",
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

/// Every non-table value of `table`, at its dotted key.
fn flatten(prefix: &str, table: toml::Table, leaves: &mut Vec<(String, toml::Value)>) {
    for (name, value) in table {
        let key = if prefix.is_empty() {
            name
        } else {
            format!("{prefix}.{name}")
        };
        match value {
            toml::Value::Table(inner) => flatten(&key, inner, leaves),
            value => leaves.push((key, value)),
        }
    }
}

/// `value` at the dotted `key` of `table`, creating the sections on the way.
fn set_key(table: &mut toml::Table, key: &str, value: toml::Value) {
    match key.split_once('.') {
        None => {
            table.insert(key.to_owned(), value);
        }
        Some((section, rest)) => {
            let inner = table
                .entry(section)
                .or_insert_with(|| toml::Value::Table(toml::Table::new()));
            if !inner.is_table() {
                *inner = toml::Value::Table(toml::Table::new());
            }
            set_key(inner.as_table_mut().expect("made a table"), rest, value);
        }
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
        name: printable(&name).into_owned(),
        message,
    };
    let params = toml::Value::Table(table.clone()).to_string();
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
                    printable(&value),
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
                    printable(&file)
                ))
            })?;
            let table: toml::Table = toml::from_str(&text).map_err(|error| {
                bad(format!(
                    "`{key}` = \"{}\": {}",
                    printable(&file),
                    printable(error.to_string().trim_end())
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
    .map_err(|error| bad(error.to_string()))?;
    Ok(Stimulus {
        name,
        params,
        level,
        scene,
    })
}

fn parse_table(text: &str) -> toml::Table {
    toml::from_str(text).expect("the built-in scenes are valid TOML")
}
