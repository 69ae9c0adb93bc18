//! A scene file as written: its TOML, from which each key is taken as it is read and checked
//! (every key optional, nothing unknown), into a [`Scene`].

use std::path::{Path, PathBuf};

use super::error::syntax;
use super::lanes::{automation, resolve};
use super::variations_table::VariationSpec;
use super::{InputFile, MidiTake, Scene, SceneError, MAX_DURATION_S};
use crate::automation::LaneSpec;
use sake_glug_device::midi::{MidiMap, MidiSetting};
use sake_glug_engine::config;
use sake_glug_engine::{
    Constant, Control, Curve, DrainMode, ModelConfig, PerControl, Quantity, Range, ValueError,
};
use sake_glug_io::keys::{self, KeyedTable};
use sake_glug_model_file::{curve_points, FittedVolumes, ModelFile, FITTED_VOLUMES_KEY};

/// The keys a scene has besides the controls' and the constants' (theirs come from their tables).
const SAMPLE_RATE: &str = "sample_rate";
const DURATION: &str = "duration_s";
const SEED: &str = config::SEED.scene_key;
const DETERMINISTIC: &str = "deterministic";
pub(super) const MIDI_TAKE: &str = "midi_take";
const DRAIN: &str = config::DRAIN.scene_key;
/// The table of what a set of takes draws (MODEL.md §10.2).
const VARIATIONS: &str = super::variations_table::VARIATIONS_KEY;
/// The table of the plugin's saved MIDI settings, by their names in the state.
const MIDI_SECTION: &str = "midi";

/// A scene file's TOML, from which each key is taken as it is read: what is left at the end is
/// unknown, and refused.
pub(super) struct SceneFile {
    keys: KeyedTable,
}

impl SceneFile {
    pub(super) fn parse(text: &str) -> Result<Self, SceneError> {
        Ok(Self {
            keys: KeyedTable::parse(text).map_err(SceneError::Syntax)?,
        })
    }

    /// Adds each key of `model` that the scene does not set (a model gives nothing but bottle
    /// and liquid keys, so it adds no file, lane or setting). A section the scene writes as
    /// something other than a table is left for validation to refuse.
    pub(super) fn layer_over(&mut self, model: &ModelFile) {
        for (key, value) in model.keys() {
            keys::insert_if_absent(self.keys.table_mut(), key, value);
        }
    }

    /// The value at `key` (`section.name` inside a table), taken out of the file.
    fn take<T: serde::de::DeserializeOwned>(&mut self, key: &str) -> Result<Option<T>, SceneError> {
        self.keys.take(key).map_err(SceneError::Syntax)
    }

    /// Refuses whatever key is left: none of the scene's.
    fn refuse_unknown(self) -> Result<(), SceneError> {
        self.keys.refuse_unknown().map_err(SceneError::Syntax)
    }

    /// The `[midi]` table, each setting checked: a CC above 127 or a channel above 15 that is
    /// not [`OFF`](sake_glug_device::midi::OFF) is refused rather than silently unmapped.
    fn midi_map(&mut self) -> Result<MidiMap, SceneError> {
        let mut map = MidiMap::default();
        for setting in MidiSetting::all() {
            let key = format!("{MIDI_SECTION}.{}", setting.key());
            let Some(byte) = self.take::<u8>(&key)? else {
                continue;
            };
            if byte > setting.max() && byte != sake_glug_device::midi::OFF {
                return Err(ValueError::OutOfRange {
                    key: setting.key(),
                    value: byte as f64,
                    min: 0.0,
                    max: setting.max() as f64,
                }
                .into());
            }
            map.set_raw(setting, byte);
        }
        Ok(map)
    }

    pub(super) fn validate(mut self, folder: &Path) -> Result<Scene, SceneError> {
        let sample_rate = match self.take::<f64>(SAMPLE_RATE)? {
            Some(rate) => check_sample_rate(rate)?,
            None => config::SAMPLE_RATE_HZ.default as u32,
        };
        let duration_s = self
            .take::<f64>(DURATION)?
            .map(|seconds| {
                let allowed = Range {
                    min: 1.0 / sample_rate as f64,
                    max: MAX_DURATION_S,
                    default: 0.0,
                };
                check(DURATION, seconds, allowed)
            })
            .transpose()?;
        let mut config = ModelConfig {
            seed: self
                .take::<u64>(SEED)?
                .unwrap_or(ModelConfig::default().seed),
            ..ModelConfig::default()
        };
        let mut lanes = PerControl::from_fn(|_| None);
        let mut inputs = Vec::new();
        for &control in Control::ALL {
            let key = control.quantity().scene_key;
            let spec = self.take::<LaneSpec>(key)?;
            lanes[control] = Some(automation(
                key,
                resolve(key, spec, folder, &mut inputs)?,
                control.range(),
            )?);
        }
        for &constant in Constant::ALL {
            let Quantity {
                scene_key, range, ..
            } = *constant.quantity();
            if let Some(value) = self.take::<f64>(scene_key)? {
                constant.set(&mut config, check(scene_key, value, range)?);
            }
        }
        config.check_silent_below()?;
        for curve in Curve::ALL {
            let key = curve.scene_key();
            if let Some(points) = self.take::<Vec<toml::Value>>(key)? {
                *curve.of_mut(&mut config.curves) = curve
                    .from_points(&curve_points_of(key, &points)?)
                    .map_err(|source| ValueError::Curve { key, source })?;
            }
        }
        config.drain = self.take::<DrainMode>(DRAIN)?.unwrap_or_default();
        if self.take::<bool>(DETERMINISTIC)?.unwrap_or(false) {
            config = config.deterministic();
        }
        let take = match self.take::<PathBuf>(MIDI_TAKE)? {
            None => None,
            Some(name) => {
                let path = folder.join(name);
                let take = MidiTake::load(&path, sample_rate)?;
                inputs.push(InputFile::new(MIDI_TAKE, path, folder));
                Some(take)
            }
        };
        let midi = self.midi_map()?;
        let variations = match self.take::<toml::Table>(VARIATIONS)? {
            Some(table) => Some(VariationSpec::from_table(table)?),
            None => None,
        };
        let fitted_volumes = self
            .take::<toml::Value>(FITTED_VOLUMES_KEY)?
            .map(|value| FittedVolumes::from_value(&value).map_err(|e| syntax(&e)))
            .transpose()?;
        self.refuse_unknown()?;
        Ok(Scene {
            sample_rate,
            duration_s,
            lanes: lanes.into_map(|_, lane| lane.expect("every control was read above")),
            config,
            take,
            midi,
            inputs,
            actuator: None,
            fade_out: None,
            variations,
            fitted_volumes,
        })
    }
}

/// A curve's points as a scene writes them ([`curve_points`]).
fn curve_points_of(key: &str, points: &[toml::Value]) -> Result<Vec<(f64, f64)>, SceneError> {
    curve_points(points).ok_or_else(|| {
        syntax(&format!(
            "`{key}`: each point must be a [tilt_deg, value] pair of numbers"
        ))
    })
}

pub(super) fn check(key: &'static str, value: f64, range: Range) -> Result<f64, SceneError> {
    Ok(range.check(key, value)?)
}

/// A sample rate in range and a whole number of Hz.
pub(super) fn check_sample_rate(sample_rate: f64) -> Result<u32, SceneError> {
    let sample_rate = check("sample_rate", sample_rate, config::SAMPLE_RATE_HZ)?;
    if sample_rate.fract() != 0.0 {
        return Err(SceneError::NotWhole {
            key: "sample_rate",
            value: sample_rate,
            what: "a sample rate counts whole samples per second",
        });
    }
    Ok(sample_rate as u32)
}
