//! The analyses as JSON values (`sake-glug analyze --json`, and the Python package's
//! `analyze_paired`/`analyze_constant`): one shape, declared here once.

use serde_json::{json, Map, Value};

use super::{
    ChiSquareTest, ConstantAnalysis, DiscriminationAnalysis, DiscriminationDesign,
    DiscriminationEstimate, DiscriminationPlanOutcome, PairedAnalysis, Placement, PlanOutcome,
    PointEstimate, PsychometricFit, POINT_PERCENTS,
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
        "dry_run_trials": analysis.dry_run_trials,
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
    object["dry_run_trials"] = json!(analysis.dry_run_trials);
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

/// A d′ as JSON: a number, or `null` when infinite (every answer right).
fn d_prime_json(d_prime: f64) -> Value {
    match d_prime.is_finite() {
        true => json!(d_prime),
        false => Value::Null,
    }
}

fn estimate_json(estimate: &DiscriminationEstimate, design: DiscriminationDesign) -> Value {
    let (low, high) = match estimate.d_prime_interval {
        Some((low, high)) => (d_prime_json(low), d_prime_json(high)),
        None => (Value::Null, Value::Null),
    };
    json!({
        "trials": estimate.trials,
        "correct": estimate.correct,
        "proportion": estimate.proportion,
        "proportion_low": estimate.proportion_low,
        "proportion_high": estimate.proportion_high,
        "p_value": estimate.p_value,
        "told_apart": estimate.told_apart(),
        "d_prime": d_prime_json(estimate.d_prime),
        "d_prime_low": low,
        "d_prime_high": high,
        "interval_empty": estimate.d_prime_interval.is_none(),
        "sentence": estimate.sentence(design),
    })
}

/// `sake-glug analyze discrimination --json` (and Python's `analyze_discrimination`): the
/// design, its chance and decision model, the pooled estimate (trials, correct, proportion with
/// its exact interval, the one-sided p value, d′ with its profile-likelihood interval, `null`
/// where infinite or empty, the sentence) and each participant's.
pub fn discrimination_json(analysis: &DiscriminationAnalysis) -> Value {
    let design = analysis.design;
    let participants: Map<String, Value> = analysis
        .participants
        .iter()
        .map(|(name, estimate)| (name.clone(), estimate_json(estimate, design)))
        .collect();
    let mut object = estimate_json(&analysis.pooled, design);
    object["design"] = json!(design.name());
    object["chance"] = json!(design.chance());
    object["decision_model"] = json!(design.decision_model());
    object["interval"] = json!("profile likelihood, 95 %");
    object["participants"] = Value::Object(participants);
    object["dry_run_trials"] = json!(analysis.dry_run_trials);
    object
}

/// `sake-glug analyze plan discrimination --json`: the plan as given, the observers'
/// proportion correct, every size tried (participants, trials, studies that showed the goal,
/// the power with its 95 % interval) and the size needed (`null` if none within the bound).
pub fn discrimination_plan_json(outcome: &DiscriminationPlanOutcome) -> Value {
    json!({
        "design": "plan discrimination",
        "plan": outcome.plan,
        "proportion_correct": outcome.proportion_correct,
        "tried": outcome.tried,
        "needed": outcome.needed,
    })
}
