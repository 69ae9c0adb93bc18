//! The volumes a fitted model's glugs were recorded at (MODEL.md §12.1, §13): written by the fit,
//! carried by the model file and the scene it is layered under, and read back by the renderer,
//! which warns when a pour's glugs come far beyond them.

/// The key of a model file (and of a scene) that gives the volumes the fit saw: `[fit]
/// volumes_ml = [lowest, highest]`.
pub const FITTED_VOLUMES_KEY: &str = "fit.volumes_ml";

/// How far beyond the volumes the fit saw a glug may come before a render warns: this share of
/// the bottle's capacity (a tenth: 30 ml of the paper's 300 ml bottle, six glugs of its pocket).
pub const FITTED_VOLUMES_MARGIN: f64 = 0.1;

/// The lowest and highest V_i of the units a model was fitted from (ml).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FittedVolumes {
    pub lowest_ml: f64,
    pub highest_ml: f64,
}

impl FittedVolumes {
    /// The range `value` gives: a pair of numbers in ml, 0 ≤ lowest ≤ highest; the reason
    /// otherwise, naming the key.
    pub fn from_value(value: &toml::Value) -> Result<Self, String> {
        let number = |value: &toml::Value| {
            value
                .as_float()
                .or_else(|| value.as_integer().map(|integer| integer as f64))
        };
        let pair = match value.as_array().map(Vec::as_slice) {
            Some([lowest, highest]) => number(lowest).zip(number(highest)),
            _ => None,
        };
        match pair {
            Some((lowest_ml, highest_ml))
                if lowest_ml.is_finite() && 0.0 <= lowest_ml && lowest_ml <= highest_ml =>
            {
                Ok(Self {
                    lowest_ml,
                    highest_ml,
                })
            }
            _ => Err(format!(
                "`{FITTED_VOLUMES_KEY}`: expected [lowest, highest] in ml, with 0 ≤ lowest ≤ \
                 highest"
            )),
        }
    }

    /// The value written at [`FITTED_VOLUMES_KEY`].
    pub fn to_value(&self) -> toml::Value {
        toml::Value::Array(vec![
            toml::Value::Float(self.lowest_ml),
            toml::Value::Float(self.highest_ml),
        ])
    }

    /// Why a pour whose glugs came at `lowest_ml` to `highest_ml` in a bottle of `capacity_ml`
    /// plays the model beyond what was recorded (more than [`FITTED_VOLUMES_MARGIN`] of the
    /// capacity below or above the fit's volumes), or `None` if it stays within.
    pub fn exceeded_by(&self, lowest_ml: f64, highest_ml: f64, capacity_ml: f64) -> Option<String> {
        let margin_ml = FITTED_VOLUMES_MARGIN * capacity_ml;
        let below = lowest_ml < self.lowest_ml - margin_ml;
        let above = highest_ml > self.highest_ml + margin_ml;
        (below || above).then(|| {
            format!(
                "its glugs come at {lowest_ml:.0}–{highest_ml:.0} ml, but the model was fitted \
                 from glugs at {:.0}–{:.0} ml (`{FITTED_VOLUMES_KEY}`): beyond them its laws of \
                 V (the headspace law's pitch, the amplitude law) are carried past what was \
                 recorded, and may not sound like the bottle (a mode carried below 20 Hz is not \
                 sounded; MODEL.md §6, §13)",
                self.lowest_ml, self.highest_ml
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_range_is_read_back_as_written_and_a_bad_one_is_refused() {
        let range = FittedVolumes {
            lowest_ml: 275.0,
            highest_ml: 295.5,
        };
        assert_eq!(FittedVolumes::from_value(&range.to_value()), Ok(range));
        for bad in [
            "[295.0, 275.0]",
            "[-1.0, 3.0]",
            "[1.0]",
            "\"275\"",
            "[nan, 3.0]",
        ] {
            let value: toml::Value = toml::from_str::<toml::Table>(&format!("v = {bad}"))
                .unwrap()
                .remove("v")
                .unwrap();
            assert!(FittedVolumes::from_value(&value).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_pour_warns_only_beyond_the_margin() {
        let range = FittedVolumes {
            lowest_ml: 275.0,
            highest_ml: 295.0,
        };
        // A tenth of 300 ml: 30 ml either side.
        assert_eq!(range.exceeded_by(246.0, 300.0, 300.0), None);
        assert!(range.exceeded_by(244.0, 300.0, 300.0).is_some());
        assert!(range.exceeded_by(280.0, 326.0, 300.0).is_some());
        let full_pour = range.exceeded_by(2.0, 295.0, 300.0).unwrap();
        assert!(
            full_pour.contains("2–295 ml") && full_pour.contains("275–295 ml"),
            "{full_pour}"
        );
    }
}
