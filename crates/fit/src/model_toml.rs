//! The model file of one liquid (MODEL.md §12.1, §13): every estimate written into the model at
//! its model key (dotted keys through `sake_glug_io::keys`), the bottle held at the reference
//! tilt, the volumes its units came at, and a header naming every key kept at its default and
//! why.

use super::curves::{round, FittedCurves};
use super::estimate::Estimate;
use sake_glug_engine::curves::REFERENCE_TILT_DEG;
use sake_glug_engine::{Control, Curve};
use sake_glug_io::keys;
use sake_glug_io::text::printable;
use sake_glug_model_file::{FittedVolumes, FITTED_VOLUMES_KEY};

/// The model of one liquid: every key estimated, each at the scene key its table declares, and
/// the bottle held at the reference tilt (one number, as a model file's controls are: MODEL.md
/// §12.1), so that `sake-glug render MODEL.toml` pours it as it is and `--model` takes it; with
/// the volumes its units came at, if they have volumes, so that a render beyond them warns.
pub(crate) fn model_toml(
    liquid: &str,
    estimates: &[Estimate],
    curves: &FittedCurves,
    volumes: Option<FittedVolumes>,
    kept_default: &[(String, String)],
    cautions: &[String],
) -> String {
    let mut table = toml::Table::new();
    keys::insert(
        &mut table,
        Control::Tilt.quantity().scene_key,
        toml::Value::Float(REFERENCE_TILT_DEG),
    );
    for estimate in estimates.iter().filter(|e| e.in_model) {
        keys::insert(
            &mut table,
            &estimate.key,
            toml::Value::Float(round(estimate.value)),
        );
    }
    for (curve, points) in [(Curve::Drain, &curves.drain), (Curve::Rest, &curves.rest)] {
        if let Some(points) = points {
            let points = points
                .iter()
                .map(|&(t, v)| {
                    toml::Value::Array(vec![toml::Value::Float(t), toml::Value::Float(v)])
                })
                .collect();
            keys::insert(&mut table, curve.scene_key(), toml::Value::Array(points));
        }
    }
    if let Some(volumes) = volumes {
        let rounded = FittedVolumes {
            lowest_ml: round(volumes.lowest_ml),
            highest_ml: round(volumes.highest_ml),
        };
        keys::insert(&mut table, FITTED_VOLUMES_KEY, rounded.to_value());
    }
    let mut text = format!(
        "# The model of `{liquid}`, fitted by `sake-glug fit` (MODEL.md §13): a scene file that \
         plays the fitted bottle.\n"
    );
    for caution in cautions {
        text.push_str(&format!("# Caution: {}.\n", printable(caution)));
    }
    for (key, why) in kept_default {
        // A comment line ends at a newline: a reason never carries one raw.
        text.push_str(&format!(
            "# `{key}` kept at its default: {}.\n",
            printable(why)
        ));
    }
    text.push_str(&toml::to_string(&table).expect("a table of numbers is valid TOML"));
    text
}
