//! One number of the report, and the rules that keep it honest (MODEL.md §13): an estimate from
//! fewer than [`MIN_UNITS_FOR_INTERVAL`] units has no interval ("too few units (n)"); one from
//! fewer than [`MIN_UNITS_FOR_MODEL`] is not written into the model (its default is kept, with the
//! reason); one that could not be made, or that lies outside the data, has no value and says why.

use sake_glug_engine::{Constant, Control, Range};

/// The fewest units an interval is given from.
pub const MIN_UNITS_FOR_INTERVAL: usize = 5;
/// The fewest units an estimate written into the model comes from.
pub const MIN_UNITS_FOR_MODEL: usize = 3;

/// Which path of the fit gave an estimate (MODEL.md §13).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// The units' fits (or the drain: a rate, the capacity).
    Units,
    /// The listening fit: candidates rendered and heard against the recordings.
    Listening,
}

impl Source {
    /// Its name in the report and the JSON.
    pub fn name(self) -> &'static str {
        match self {
            Self::Units => "units",
            Self::Listening => "listening",
        }
    }
}

/// One estimate of the report, written to the model under `key` if it is a model key.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// The model's key it is written to, or what it is (`outflow rate at 135° (ml/s)`).
    pub key: String,
    /// Its value (NaN: none; see `note`).
    pub value: f64,
    /// The 95 % interval (bootstrap over units, or a line's standard error), if it has one.
    pub interval: Option<(f64, f64)>,
    /// The units (or intervals between units) it comes from, where it comes from units.
    pub units: Option<usize>,
    /// Whether it is written into the model.
    pub in_model: bool,
    /// Why it has no value, no interval, or is not in the model.
    pub note: Option<String>,
    /// The path that gave it.
    pub source: Source,
}

impl Estimate {
    /// An estimate from `units` units (or intervals), with its bootstrap interval, checked by the
    /// honesty rules; `in_model` if it is a model key.
    pub fn from_units(
        key: impl Into<String>,
        value: f64,
        interval: (f64, f64),
        units: usize,
        in_model: bool,
    ) -> Self {
        let mut estimate = Self {
            key: key.into(),
            value,
            interval: Some(interval),
            units: Some(units),
            in_model,
            note: None,
            source: Source::Units,
        };
        if !value.is_finite() {
            estimate.fail(if units == 0 {
                "no unit gives it".to_owned()
            } else {
                format!("could not be estimated from {units} unit(s)")
            });
        } else if units < MIN_UNITS_FOR_INTERVAL {
            estimate.interval = None;
            estimate.note = Some(format!("too few units ({units})"));
            if units < MIN_UNITS_FOR_MODEL {
                estimate.in_model = false;
                estimate.note = Some(format!(
                    "too few units ({units}): an estimate needs {MIN_UNITS_FOR_MODEL}"
                ));
            }
        } else if !(interval.0.is_finite() && interval.1.is_finite()) {
            estimate.interval = None;
            estimate.note = Some("the bootstrap gave no interval".to_owned());
        }
        estimate
    }

    /// An estimate that is not made from units (a rate, the capacity), with its interval if any.
    pub fn measured(
        key: impl Into<String>,
        value: f64,
        interval: Option<(f64, f64)>,
        in_model: bool,
    ) -> Self {
        let mut estimate = Self {
            key: key.into(),
            value,
            interval,
            units: None,
            in_model,
            note: None,
            source: Source::Units,
        };
        if !value.is_finite() {
            estimate.fail("could not be estimated".to_owned());
        }
        estimate
    }

    /// Marks it as having no value, for `why`: no number, no interval, not in the model.
    pub fn fail(&mut self, why: String) {
        self.value = f64::NAN;
        self.interval = None;
        self.in_model = false;
        self.note = Some(why);
    }

    /// Set by the listening fit to `value`, for `why`: in the model, with no interval (a search
    /// over renders gives none).
    pub fn by_listening(&mut self, value: f64, why: String) {
        self.value = value;
        self.interval = None;
        self.in_model = true;
        self.note = Some(why);
        self.source = Source::Listening;
    }

    /// Whether it has a value.
    pub fn has_value(&self) -> bool {
        self.value.is_finite()
    }
}

/// The range of the constant or control whose scene key is `key`.
pub(crate) fn range_of(key: &str) -> Option<Range> {
    Constant::ALL
        .iter()
        .map(|c| c.quantity())
        .chain(Control::ALL.iter().map(|c| c.quantity()))
        .find(|q| q.scene_key == key)
        .map(|q| q.range)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn few_units_give_no_interval_and_fewer_no_model_key() {
        let four = Estimate::from_units("glug.f1_hz", 100.0, (90.0, 110.0), 4, true);
        assert_eq!(four.interval, None);
        assert!(four.in_model);
        assert_eq!(four.note.as_deref(), Some("too few units (4)"));
        let two = Estimate::from_units("glug.f1_hz", 100.0, (90.0, 110.0), 2, true);
        assert!(!two.in_model && two.interval.is_none());
        let five = Estimate::from_units("glug.f1_hz", 100.0, (90.0, 110.0), 5, true);
        assert_eq!(five.interval, Some((90.0, 110.0)));
        let none = Estimate::from_units("glug.f2_hz", f64::NAN, (1.0, 2.0), 0, true);
        assert!(!none.has_value() && !none.in_model && none.interval.is_none());
    }
}
