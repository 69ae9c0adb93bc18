//! The analyses as JSON values (`sake-glug analyze --json`, and the Python package's
//! `analyze_paired`/`analyze_constant`): one shape, declared here once.

use serde_json::{json, Map, Value};

use super::{
    ChiSquareTest, ConstantAnalysis, PairedAnalysis, Placement, PlanOutcome, PointEstimate,
    PsychometricFit, POINT_PERCENTS,
};

fn test_json(test: Option<ChiSquareTest>) -> Value {
    test.map_or(Value::Null, |test| json!(test))
}

/// `sake-glug analyze paired --json`: one object with the scale by name, the counts, the
/// proportions, the predicted proportions and the two χ² tests (statistic, df, p).
pub fn paired_json(analysis: &PairedAnalysis) -> Value {
    let scale: Map<String, Value> = analysis
        .stimuli
        .iter()
        .zip(&analysis.scale)
        .map(|(name, value)| (name.clone(), json!(value)))
        .collect();
    json!({
        "design": "paired",
        "stimuli": analysis.stimuli,
        "participants": analysis.participants.len(),
        "trials": analysis.trials,
        "counts": analysis.counts,
        "proportions": analysis.proportions,
        "z": analysis.z,
        "scale": scale,
        "predicted": analysis.predicted,
        "fit": test_json(analysis.fit),
        "agreement": test_json(analysis.agreement),
    })
}

/// A point as an estimate only within the levels tested: outside them its value and interval
/// are `null`; an end of its interval outside them is `null` too (beyond the lowest level for
/// `low`, the highest for `high`).
fn point_json(point: &PointEstimate, lowest: f64, highest: f64) -> Value {
    let within = |level: f64| {
        (point.placement == Placement::Within && (lowest..=highest).contains(&level))
            .then_some(level)
    };
    json!({
        "value": within(point.value),
        "low": within(point.low),
        "high": within(point.high),
        "placement": point.placement,
    })
}

fn fit_json(fit: &PsychometricFit) -> Value {
    let (lowest, highest) = fit.level_range();
    let points: Map<String, Value> = POINT_PERCENTS
        .iter()
        .zip(&fit.points)
        .map(|(percent, point)| (percent.to_string(), point_json(point, lowest, highest)))
        .collect();
    json!({
        "levels": fit.levels.iter().map(|level| json!({
            "level": level.level,
            "trials": level.trials,
            "chosen": level.chosen,
            "proportion": level.proportion(),
        })).collect::<Vec<_>>(),
        "curve": fit.curve,
        "points": points,
        "resamples": fit.resamples,
        "failed_resamples": fit.failed_resamples,
    })
}

/// `sake-glug analyze constant --json`: the pooled fit (levels, curve, points 25/50/75 with
/// their 95 % intervals, `null` outside the levels tested) and each participant's.
pub fn constant_json(analysis: &ConstantAnalysis) -> Value {
    let participants: Map<String, Value> = analysis
        .participants
        .iter()
        .map(|(name, fit)| {
            let value = match fit {
                Ok(fit) => fit_json(fit),
                Err(error) => json!({ "error": error.to_string() }),
            };
            (name.clone(), value)
        })
        .collect();
    let mut object = fit_json(&analysis.pooled);
    object["design"] = json!("constant");
    object["participants"] = Value::Object(participants);
    object
}

/// `sake-glug analyze plan constant --json`: the plan as given, the observers' curve, the
/// studies fitted and not, and for each point (`"25"`, `"50"`, `"75"`) its truth, coverage (with
/// its 95 % interval), the median width of the intervals and where the estimates fell.
pub fn plan_json(outcome: &PlanOutcome) -> Value {
    let points: Map<String, Value> = outcome
        .points
        .iter()
        .map(|point| {
            let value = json!({
                "truth": point.truth,
                "covered": point.covered,
                "coverage": point.coverage,
                "coverage_low": point.coverage_low,
                "coverage_high": point.coverage_high,
                "median_width": point.median_width,
                "median_estimate": point.median_estimate,
                "estimate_low": point.estimate_low,
                "estimate_high": point.estimate_high,
            });
            (point.percent.to_string(), value)
        })
        .collect();
    json!({
        "design": "plan constant",
        "plan": outcome.plan,
        "observer": outcome.observer,
        "trials_a_study": outcome.trials_a_study,
        "fitted": outcome.fitted,
        "unfitted": outcome.unfitted,
        "points": points,
    })
}
