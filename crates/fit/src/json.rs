//! The fit as one JSON object (`sake-glug fit --json`, and what Python's `fit()` returns): the
//! same numbers from the same function.
//!
//! `{"units": {"detected": N, "used": M}, "explained": {RECORDING: share}, "estimates": {KEY:
//! {"value", "low", "high", "n", "in_model", "note"}}, "liquids": {NAME: {"estimates", "units",
//! "detected", "kept_default", "model"}}, "warnings": [...]}`: a value, low or high is null where
//! there is none (an estimate that could not be made or lies outside the data has no value; one
//! from fewer than 5 units no interval), `n` the units it comes from (null for a rate). The
//! top-level "estimates" are the only liquid's (null for a session of several, whose liquids
//! each have their own).

use serde_json::{json, Map, Value};

use super::estimate::Estimate;
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
    json!({
        "units": {"detected": detected, "used": used},
        "explained": explained,
        "estimates": estimates,
        "liquids": liquids,
        "warnings": fit.warnings,
    })
}
