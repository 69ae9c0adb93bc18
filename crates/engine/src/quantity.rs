//! How the product names, bounds and shows a number the model takes: its [`Range`] and
//! default, its plugin [`Knob`], the [`Quantity`] that holds both with its names, and the
//! [`ValueError`] a scene or a model file gets for a value outside them. The tables of controls
//! and constants are made of these.

use super::curves::CurveError;

/// An input's allowed closed range and its default (MODEL.md).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Range {
    /// Lowest allowed value.
    pub min: f64,
    /// Highest allowed value.
    pub max: f64,
    /// Value of a left-out input, and what NaN becomes.
    pub default: f64,
}

impl Range {
    /// The range `[min, max]` with its `default`.
    pub const fn new(min: f64, max: f64, default: f64) -> Self {
        Self { min, max, default }
    }

    /// Whether `value` lies in the closed range `[min, max]` (false for NaN).
    pub fn contains(&self, value: f64) -> bool {
        value >= self.min && value <= self.max
    }

    /// `value` if it lies in the range, else the error that names `key` and the range: the
    /// one check of a scene's and a model file's values.
    pub fn check(&self, key: &'static str, value: f64) -> Result<f64, ValueError> {
        if self.contains(value) {
            Ok(value)
        } else {
            Err(ValueError::OutOfRange {
                key,
                value,
                min: self.min,
                max: self.max,
            })
        }
    }

    /// Brings any f64 into range: NaN becomes the default, ±∞ and outliers the nearest bound.
    #[inline]
    pub fn sanitize(&self, value: f64) -> f64 {
        if value.is_nan() {
            self.default
        } else {
            value.clamp(self.min, self.max)
        }
    }
}

/// How a quantity is shown on a plugin knob: the part of its range the knob spans, the decimals
/// shown (the value snaps to steps of 10^−decimals) and the skew. Plain data: the plugin turns it
/// into a parameter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Knob {
    /// Lowest value on the knob; `None`: the range's minimum.
    pub min: Option<f64>,
    /// Highest value on the knob; `None`: the range's maximum.
    pub max: Option<f64>,
    /// Decimals shown; the value snaps to steps of 10^−decimals.
    pub decimals: i32,
    /// `None` for a linear knob, else nice-plug's skew exponent (negative: finer at the bottom).
    pub skew: Option<f32>,
}

impl Knob {
    /// A linear knob over the whole range, with `decimals` decimals.
    pub const fn full(decimals: i32) -> Self {
        Self {
            min: None,
            max: None,
            decimals,
            skew: None,
        }
    }

    /// A knob narrower than the engine's range, where the full range is absurd on a knob.
    pub const fn within(self, min: f64, max: f64) -> Self {
        Self {
            min: Some(min),
            max: Some(max),
            ..self
        }
    }

    /// The same knob with a skew.
    pub const fn skewed(self, factor: f32) -> Self {
        Self {
            skew: Some(factor),
            ..self
        }
    }

    /// The step the value snaps to: 10^−decimals.
    pub fn step(&self) -> f64 {
        10f64.powi(-self.decimals)
    }

    /// The step as its decimal text (`0.01`, `1`): what `sake-glug parameters` shows.
    pub fn step_text(&self) -> String {
        format!("{:.*}", self.decimals.max(0) as usize, self.step())
    }
}

/// A value of a scene or a model file that the model cannot take, named by its key.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ValueError {
    /// Outside its allowed range.
    #[error("`{key}` = {value} is out of range: allowed {min} to {max}")]
    OutOfRange {
        /// The key.
        key: &'static str,
        /// The value given.
        value: f64,
        /// Lowest allowed value.
        min: f64,
        /// Highest allowed value.
        max: f64,
    },
    /// Not below another value it must lie below (V0 below the capacity).
    #[error("`{key}` = {value} is out of range: it must lie below `{limit_key}` ({limit})")]
    NotBelow {
        /// The key.
        key: &'static str,
        /// The value given.
        value: f64,
        /// The key of the value it must lie below.
        limit_key: &'static str,
        /// That value.
        limit: f64,
    },
    /// A list of points that is no curve of the bottle (MODEL.md §12).
    #[error("`{key}`: {source}")]
    Curve {
        /// The key.
        key: &'static str,
        /// What was wrong.
        source: CurveError,
    },
}

/// A number the model takes, as every part of the product names and bounds it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quantity {
    /// The name a host and the editor show.
    pub name: &'static str,
    /// The unit shown after the value (with its leading space, if any).
    pub unit: &'static str,
    /// Its key in a scene file (`section.key` inside a table); empty if scenes have none.
    pub scene_key: &'static str,
    /// The plugin parameter's stable id (saved states and automation depend on it); empty for a
    /// constant that scenes set but the plugin has no parameter for.
    pub param_id: &'static str,
    /// What it is, in a few words (the guide's table of parameters).
    pub note: &'static str,
    /// The allowed range and the default.
    pub range: Range,
    /// How the plugin shows it.
    pub knob: Knob,
}

impl Quantity {
    /// The knob's lowest and highest value.
    pub fn knob_bounds(&self) -> (f64, f64) {
        (
            self.knob.min.unwrap_or(self.range.min),
            self.knob.max.unwrap_or(self.range.max),
        )
    }
}
