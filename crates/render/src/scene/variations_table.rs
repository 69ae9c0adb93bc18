//! A scene's `[variations]` table (MODEL.md §10.2): what a take may vary, within which ranges,
//! and how many takes a set has. Read with the scene, so it depends on nothing of the scene;
//! drawing the takes and applying them to a scene is `crate::variations`'.

use super::duration::MAX_DURATION_S;
use sake_glug_engine::{Constant, Control, Range, ValueError};
use sake_glug_io::keys;
use sake_glug_io::read::ReadError;
use sake_glug_io::text::printable;

/// The scene's table of ranges.
pub const VARIATIONS_KEY: &str = "variations";
/// The key of the table's number of takes.
pub const COUNT_KEY: &str = "count";
/// The most takes a set may have.
pub const MAX_TAKES: u32 = 9999;
/// What a take may draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Varied {
    /// The value the tilt lane ends at: its last point's (a constant tilt is replaced).
    TiltEnd,
    /// The time of the tilt lane's last point: every point's time scaled to it.
    RampTime,
    /// A control other than the tilt, held at the drawn value through the take.
    Control(Control),
    /// A model constant.
    Constant(Constant),
}

impl Varied {
    /// Every varied value, in the order a take draws them and a manifest lists them.
    pub fn all() -> impl Iterator<Item = Varied> {
        [Varied::TiltEnd, Varied::RampTime]
            .into_iter()
            .chain(
                Control::ALL
                    .iter()
                    .filter(|&&control| control != Control::Tilt)
                    .map(|&control| Varied::Control(control)),
            )
            .chain(
                Constant::ALL
                    .iter()
                    .map(|&constant| Varied::Constant(constant)),
            )
    }

    /// Its key in `[variations]` and its column in a manifest: the control's or the constant's
    /// scene key.
    pub fn key(self) -> &'static str {
        match self {
            Varied::TiltEnd => "tilt_end_deg",
            Varied::RampTime => "ramp_s",
            Varied::Control(control) => control.quantity().scene_key,
            Varied::Constant(constant) => constant.quantity().scene_key,
        }
    }

    /// The values it may take.
    pub fn range(self) -> Range {
        match self {
            Varied::TiltEnd => Control::Tilt.range(),
            Varied::RampTime => Range::new(0.0, MAX_DURATION_S, 0.5),
            Varied::Control(control) => control.range(),
            Varied::Constant(constant) => constant.range(),
        }
    }

    /// The varied value of `key`, if any.
    pub fn of_key(key: &str) -> Option<Varied> {
        Varied::all().find(|varied| varied.key() == key)
    }
}

/// Why a `[variations]` table, a take's row or a manifest was refused; each names its key.
#[derive(Debug, thiserror::Error)]
pub enum VariationError {
    /// A key that names nothing a take may vary.
    #[error(
        "unknown key `{}` in [variations]: use `count` or a range for one of {}",
        printable(key),
        known_keys()
    )]
    UnknownKey {
        /// The key as written.
        key: String,
    },
    /// A range that is not `[low, high]` of two finite numbers in order.
    #[error("`variations.{key}` = {written}: {why}")]
    BadRange {
        /// The varied key.
        key: &'static str,
        /// The value as written.
        written: String,
        /// What is wrong with it.
        why: String,
    },
    /// A count out of its range.
    #[error("`variations.count` = {0}: a set has 1 to {MAX_TAKES} takes")]
    Count(String),
    /// A value the model cannot take (out of its range, V0 not below the capacity).
    #[error(transparent)]
    Value(#[from] ValueError),
    /// `ramp_s` on a scene whose tilt lane has no point after 0 s.
    #[error(
        "`{key}`: the scene's tilt_deg has no ramp to time (a constant, or points all at 0 s); \
         give it points such as [[0.0, 90.0], [0.5, 135.0]]"
    )]
    NoRamp {
        /// The key.
        key: &'static str,
    },
    /// A take's row that cannot be read.
    #[error("{0}")]
    Row(String),
    /// A manifest that could not be read.
    #[error(transparent)]
    Read(#[from] ReadError),
}

/// The keys a take may vary, for a message.
pub(crate) fn known_keys() -> String {
    Varied::all()
        .map(|varied| format!("`{}`", varied.key()))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A scene's `[variations]` table: how many takes, and the range of each value drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct VariationSpec {
    /// Takes in the set, unless the command line says.
    pub count: Option<u32>,
    /// Each varied value with its `[low, high]`, in [`Varied::all`]'s order.
    pub ranges: Vec<(Varied, [f64; 2])>,
}

impl VariationSpec {
    /// The table read key by key: `count`, and `[low, high]` ranges at the keys of
    /// [`Varied::all`] (dotted or in sub-tables: `glug.f1_hz = [70, 90]`).
    pub fn from_table(table: toml::Table) -> Result<Self, VariationError> {
        let mut count = None;
        let mut ranges = Vec::new();
        for (key, value) in keys::flatten(&table) {
            if key == COUNT_KEY {
                count = Some(take_count(&value)?);
                continue;
            }
            let varied = Varied::of_key(&key).ok_or(VariationError::UnknownKey { key })?;
            ranges.push((varied, range_of(varied, &value)?));
        }
        ranges.sort_by_key(|(varied, _)| Varied::all().position(|other| other == *varied));
        Ok(Self { count, ranges })
    }
}

fn take_count(value: &toml::Value) -> Result<u32, VariationError> {
    match value.as_integer() {
        Some(count) if (1..=MAX_TAKES as i64).contains(&count) => Ok(count as u32),
        _ => Err(VariationError::Count(value.to_string())),
    }
}

/// `[low, high]` for `varied`: two numbers, in order, within its range.
fn range_of(varied: Varied, value: &toml::Value) -> Result<[f64; 2], VariationError> {
    let key = varied.key();
    let bad = |why: String| VariationError::BadRange {
        key,
        written: printable(&value.to_string()).into_owned(),
        why,
    };
    let numbers: Option<Vec<f64>> = value.as_array().and_then(|items| {
        items
            .iter()
            .map(|item| {
                item.as_float()
                    .or_else(|| item.as_integer().map(|i| i as f64))
            })
            .collect()
    });
    let [low, high] = numbers
        .as_deref()
        .and_then(|numbers| <[f64; 2]>::try_from(numbers).ok())
        .ok_or_else(|| bad("a range is [low, high], two numbers".into()))?;
    if low.is_nan() || high.is_nan() {
        return Err(bad("a range's ends are numbers, not NaN".into()));
    }
    if low > high {
        return Err(bad(format!(
            "its low end {low} is above its high end {high}"
        )));
    }
    let allowed = varied.range();
    for end in [low, high] {
        if !allowed.contains(end) {
            return Err(bad(format!(
                "{end} lies outside `{key}`'s range, {} to {}",
                allowed.min, allowed.max
            )));
        }
    }
    Ok([low, high])
}
