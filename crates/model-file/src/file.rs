//! Reading and validating a model file: the keys of a scene that describe the bottle and the
//! liquid, nothing else (MODEL.md §12.1).

use std::path::Path;

use super::fitted::{FittedVolumes, FITTED_VOLUMES_KEY};
use sake_glug_engine::{Constant, Control, Curve, ModelConfig, PerControl, Quantity, ValueError};
use sake_glug_io::keys;
use sake_glug_io::read::{self, InputKind, ReadError};
use sake_glug_io::text::printable;

/// The largest model file read ([`InputKind::MODEL`]): a model is a few dozen lines.
pub const MAX_MODEL_BYTES: u64 = InputKind::MODEL.max_bytes;

/// Why a model was refused. Text from the file is shown with its control characters escaped.
#[derive(Debug, thiserror::Error)]
pub enum ModelFileError {
    /// The file could not be read: missing, not a regular file, over [`MAX_MODEL_BYTES`], not
    /// UTF-8.
    #[error(transparent)]
    Read(#[from] ReadError),
    /// Not valid TOML, or a value of the wrong type: the parser's message, escaped.
    #[error("invalid model: {0}")]
    Syntax(String),
    /// A key a scene may have but a model may not: automation, a take, render settings.
    #[error(
        "`{key}` does not belong in a model: a model gives the bottle and the liquid (the \
         constants, the [curves] and each control as one number); {what} belong in the scene"
    )]
    NotAModelKey {
        /// The key, as written.
        key: String,
        /// What such keys are.
        what: &'static str,
    },
    /// A model key written in the wrong section (or in none): the key it names elsewhere.
    #[error("`{key}` is not a model key here: did you mean `[{section}] {name}`?")]
    Misplaced {
        /// The key, as written.
        key: String,
        /// The section it belongs in…
        section: String,
        /// …and its name there.
        name: String,
    },
    /// A value the model cannot take: out of range, V0 not below the capacity, or no curve.
    #[error(transparent)]
    Value(#[from] ValueError),
}

/// A validated model file: its name and text (what the plugin saves), its keys as written (what
/// a scene is layered over), and what they set.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelFile {
    name: String,
    text: String,
    keys: Vec<(String, toml::Value)>,
    config: ModelConfig,
    controls: PerControl<Option<f64>>,
    fitted_volumes: Option<FittedVolumes>,
}

impl ModelFile {
    /// Reads the model file at `path`, named after the file (its stem).
    pub fn load(path: &Path) -> Result<Self, ModelFileError> {
        let text = read::read_text(path, InputKind::MODEL)?;
        let name = path
            .file_stem()
            .map_or("model".into(), |stem| stem.to_string_lossy().into_owned());
        Self::parse(&name, &text)
    }

    /// Parses and validates the model `text`, called `name`.
    pub fn parse(name: &str, text: &str) -> Result<Self, ModelFileError> {
        let table: toml::Table = toml::from_str(text)
            .map_err(|error| ModelFileError::Syntax(keys::syntax_message(&error, text)))?;
        let keys = flatten(&table);
        let mut config = ModelConfig::default();
        let mut controls = PerControl::from_fn(|_| None);
        let mut fitted_volumes = None;
        for (key, value) in &keys {
            match model_key(key) {
                Some(ModelKey::FittedVolumes) => {
                    fitted_volumes =
                        Some(FittedVolumes::from_value(value).map_err(|e| syntax(&e))?);
                }
                Some(ModelKey::Control(control)) => {
                    let quantity = control.quantity();
                    let value = as_number(value).ok_or_else(|| ModelFileError::NotAModelKey {
                        key: printable(key).into_owned(),
                        what: "automation lanes and recorded takes",
                    })?;
                    controls[control] = Some(check(quantity, value)?);
                }
                Some(ModelKey::Constant(constant)) => {
                    let quantity = constant.quantity();
                    let value = as_number(value).ok_or_else(|| {
                        syntax(&format!("`{key}`: invalid type: expected a number"))
                    })?;
                    constant.set(&mut config, check(quantity, value)?);
                }
                Some(ModelKey::Curve(curve)) => {
                    let key = curve.scene_key();
                    let points = value
                        .as_array()
                        .ok_or_else(|| syntax(&format!("`{key}`: expected a list of points")))?;
                    let points = curve_points(points).ok_or_else(|| {
                        syntax(&format!(
                            "`{key}`: each point must be a [tilt_deg, value] pair of numbers"
                        ))
                    })?;
                    *curve.of_mut(&mut config.curves) = curve
                        .from_points(&points)
                        .map_err(|source| ValueError::Curve { key, source })?;
                }
                None => {
                    return Err(match misplaced(key) {
                        Some((section, name)) => ModelFileError::Misplaced {
                            key: printable(key).into_owned(),
                            section: section.to_owned(),
                            name: name.to_owned(),
                        },
                        None => ModelFileError::NotAModelKey {
                            key: printable(key).into_owned(),
                            what: "automation, takes, [midi] and the render's settings",
                        },
                    })
                }
            }
        }
        config.check_silent_below()?;
        Ok(Self {
            name: name.to_owned(),
            text: text.to_owned(),
            keys,
            config,
            controls,
            fitted_volumes,
        })
    }

    /// Its name: the file's stem, or the name it was saved with.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The file's text, as read.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// Every key it gives (`section.name` inside a table), with its value as written.
    pub fn keys(&self) -> &[(String, toml::Value)] {
        &self.keys
    }

    /// The default constants with the model's (its constants, V0, spread and curves).
    pub fn config(&self) -> &ModelConfig {
        &self.config
    }

    /// The value it gives each control, if it gives one.
    pub fn controls(&self) -> &PerControl<Option<f64>> {
        &self.controls
    }

    /// The volumes its fit saw glugs at, if a fit wrote them (MODEL.md §13).
    pub fn fitted_volumes(&self) -> Option<FittedVolumes> {
        self.fitted_volumes
    }
}

/// What a model key sets.
enum ModelKey {
    Control(Control),
    Constant(Constant),
    Curve(Curve),
    /// What the fit saw ([`FITTED_VOLUMES_KEY`]): plays nothing, read by the renderer's warning.
    FittedVolumes,
}

/// The model key `key` (`section.name` inside a table), if it is one.
fn model_key(key: &str) -> Option<ModelKey> {
    let controls = Control::ALL
        .iter()
        .find(|control| control.quantity().scene_key == key)
        .map(|&control| ModelKey::Control(control));
    let constants = || {
        Constant::ALL
            .iter()
            .find(|constant| constant.quantity().scene_key == key)
            .map(|&constant| ModelKey::Constant(constant))
    };
    let curves = || {
        Curve::ALL
            .iter()
            .find(|curve| curve.scene_key() == key)
            .map(|&curve| ModelKey::Curve(curve))
    };
    let fitted = || (key == FITTED_VOLUMES_KEY).then_some(ModelKey::FittedVolumes);
    controls.or_else(constants).or_else(curves).or_else(fitted)
}

/// The section and name of the model key that `key` names in another of the model's sections or
/// in none (`capacity_ml` for `[bottle] capacity_ml`), if one does. A key of a scene's own
/// sections (`[output] drain`) is a scene's, not a misplaced model key.
fn misplaced(key: &str) -> Option<(&'static str, &'static str)> {
    let model_keys = || {
        Constant::ALL
            .iter()
            .map(|constant| constant.quantity().scene_key)
            .chain(Curve::ALL.iter().map(|curve| curve.scene_key()))
            .filter_map(|scene_key| scene_key.split_once('.'))
    };
    let name = match key.split_once('.') {
        None => key,
        Some((section, name)) if model_keys().any(|(model, _)| model == section) => name,
        Some(_) => return None,
    };
    model_keys().find(|&(_, scene_name)| scene_name == name)
}

/// Every key of `table`, a section's keys as `section.name` (scene files nest no deeper), in the
/// file's order. A control's table (a CSV lane) is one key, the control's.
fn flatten(table: &toml::Table) -> Vec<(String, toml::Value)> {
    let mut keys = Vec::new();
    for (name, value) in table {
        let lane = matches!(model_key(name), Some(ModelKey::Control(_)));
        match value {
            toml::Value::Table(section) if !lane => {
                for (inner, value) in section {
                    keys.push((keys::join(name, inner), value.clone()));
                }
            }
            value => keys.push((name.clone(), value.clone())),
        }
    }
    keys
}

/// A number as a scene writes it: a float or an integer.
fn as_number(value: &toml::Value) -> Option<f64> {
    value
        .as_float()
        .or_else(|| value.as_integer().map(|integer| integer as f64))
}

/// A curve's points as a scene writes them: `[tilt_deg, value]` pairs of numbers, integer or
/// float; `None` if any point is not.
pub fn curve_points(points: &[toml::Value]) -> Option<Vec<(f64, f64)>> {
    let pair = |point: &toml::Value| match point.as_array()?.as_slice() {
        [tilt_deg, value] => Some((as_number(tilt_deg)?, as_number(value)?)),
        _ => None,
    };
    points.iter().map(pair).collect()
}

fn check(quantity: &Quantity, value: f64) -> Result<f64, ModelFileError> {
    Ok(quantity.range.check(quantity.scene_key, value)?)
}

fn syntax(message: &str) -> ModelFileError {
    ModelFileError::Syntax(printable(message).into_owned())
}
