//! The fit as one JSON object (`sake-glug fit --json`, and what Python's `fit()` returns): the
//! same numbers from the same function.
//!
//! `{"units": {"detected": N, "used": M}, "explained": {RECORDING: share}, "estimates": {KEY:
//! {"value", "low", "high", "n", "in_model", "note"}}, "liquids": {NAME: {"estimates", "units",
//! "detected", "kept_default", "model"}}, "compared": {RECORDING: {"rendered", "glugs",
//! "rate_per_s", "pitch_fall", "pitch_hz", "high_share", "spectral_correlation",
//! "log_spectral_distance_db"}}, "warnings": [...]}`: a value, low or high is null where
//! there is none (an estimate that could not be made or lies outside the data has no value; one
//! from fewer than 5 units no interval), `n` the units it comes from (null for a rate). The
//! top-level "estimates" are the only liquid's (null for a session of several, whose liquids
//! each have their own).

use serde_json::{json, Map, Value};

use super::compare::Comparison;
use super::comparisons::compare;
use super::estimate::Estimate;
use super::listen::Heard;
use super::session_fit::SessionFit;

/// A number, or null where it is not finite.
fn number(value: f64) -> Value {
    if value.is_finite() {
        json!(value)
    } else {
        Value::Null
    }
}

fn estimate_json(estimate: &Estimate) -> Value {
    let (low, high) = estimate.interval.unzip();
    json!({
        "value": number(estimate.value),
        "low": low.map_or(Value::Null, number),
        "high": high.map_or(Value::Null, number),
        "n": estimate.units,
        "in_model": estimate.in_model,
        "note": estimate.note,
        "from": estimate.source.name(),
    })
}

fn estimates_json(estimates: &[Estimate]) -> Value {
    Value::Object(
        estimates
            .iter()
            .map(|e| (e.key.clone(), estimate_json(e)))
            .collect(),
    )
}

/// One measure of a comparison: the recording's value (where it has one), the fitted model's and
/// the default bottle's.
fn measure(of: impl Fn(&Heard) -> f64, comparison: &Comparison) -> Value {
    let [recording, model, default] = comparison.heard.each_ref().map(&of).map(number);
    json!({"recording": recording, "model": model, "default": default})
}

/// A recording against its model and the default bottle, rendered as it was made.
fn comparison_json(comparison: &Comparison) -> Value {
    let glugs = comparison.glugs();
    let pitches = comparison
        .heard
        .each_ref()
        .map(|heard| Value::Array(heard.pitch_hz.iter().map(|&hz| number(hz)).collect()));
    let [recording_pitch, model_pitch, default_pitch] = pitches;
    json!({
        "rendered": comparison.rendered,
        "glugs": measure(|h| h.onsets_s.len() as f64, comparison),
        "rate_per_s": measure(|h| h.rate_per_s, comparison),
        "pitch_fall": {
            "over_glugs": glugs,
            "recording": number(comparison.heard[0].fall_over(glugs)),
            "model": number(comparison.heard[1].fall_over(glugs)),
            "default": number(comparison.heard[2].fall_over(glugs)),
        },
        "pitch_hz": {"recording": recording_pitch, "model": model_pitch, "default": default_pitch},
        "high_share": {
            "split_hz": number(comparison.split_hz),
            "recording": number(comparison.heard[0].high_share),
            "model": number(comparison.heard[1].high_share),
            "default": number(comparison.heard[2].high_share),
        },
        "spectral_correlation": {
            "model": number(comparison.fitted),
            "default": number(comparison.default),
        },
        "log_spectral_distance_db": {
            "model": number(comparison.distance[0]),
            "default": number(comparison.distance[1]),
        },
    })
}

/// The fit as the JSON object of `sake-glug fit --json`.
pub fn fit_json(fit: &SessionFit) -> Value {
    let (detected, used) = fit.unit_counts();
    let explained: Map<String, Value> = fit
        .recordings
        .iter()
        .map(|r| (r.name(), number(r.explained)))
        .collect();
    let liquids: Map<String, Value> = fit
        .liquids
        .iter()
        .map(|liquid| {
            let kept: Map<String, Value> = liquid
                .kept_default
                .iter()
                .map(|(key, why)| (key.clone(), why.clone().into()))
                .collect();
            let value = json!({
                "estimates": estimates_json(&liquid.estimates),
                "units": liquid.units,
                "detected": liquid.detected,
                "kept_default": kept,
                "model": liquid.model_toml,
            });
            (liquid.liquid.clone(), value)
        })
        .collect();
    let estimates = match fit.liquids.as_slice() {
        [only] => estimates_json(&only.estimates),
        _ => Value::Null,
    };
    let compared = match compare(fit) {
        Ok(comparisons) => Value::Object(
            comparisons
                .iter()
                .map(|c| (c.recording.clone(), comparison_json(c)))
                .collect(),
        ),
        Err(error) => json!({"error": error}),
    };
    json!({
        "units": {"detected": detected, "used": used},
        "explained": explained,
        "estimates": estimates,
        "liquids": liquids,
        "compared": compared,
        "warnings": fit.warnings,
    })
}
