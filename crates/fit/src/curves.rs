//! The bottle's curves (MODEL.md §13), shared by every liquid: h(θ) from each tilt's outflow
//! rate over the rate at 135°, r(θ) from the rest levels; each a curve only with 2 tilts or more.

use std::collections::BTreeMap;

use super::pour::SAME_TILT_DEG;
use super::recording::RecordingFit;
use super::session::FitSession;
use sake_glug_engine::curves::REFERENCE_TILT_DEG;
use sake_glug_engine::{Curve, ModelConfig};

/// The bottle's curves as fitted: `(tilt, value)` points (defaults outside the measured tilts).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FittedCurves {
    /// h(θ), if several tilts were measured.
    pub drain: Option<Vec<(f64, f64)>>,
    /// r(θ), if several tilts showed their rest level.
    pub rest: Option<Vec<(f64, f64)>>,
}

/// The rate at 135° from measured `rates`: measured there, else linear between the tilts around
/// it, else the nearest tilt's through the default h.
pub(crate) fn rate_at_reference(
    rates: &[(f64, f64)],
    default_h: &sake_glug_engine::curves::TiltCurve,
) -> Option<f64> {
    if let Some(&(_, k)) = rates
        .iter()
        .find(|r| (r.0 - REFERENCE_TILT_DEG).abs() < SAME_TILT_DEG)
    {
        return Some(k);
    }
    let below = rates.iter().rev().find(|r| r.0 < REFERENCE_TILT_DEG);
    let above = rates.iter().find(|r| r.0 > REFERENCE_TILT_DEG);
    match (below, above) {
        (Some(&(t0, k0)), Some(&(t1, k1))) => {
            Some(k0 + (k1 - k0) * (REFERENCE_TILT_DEG - t0) / (t1 - t0))
        }
        (Some(&(tilt, k)), None) | (None, Some(&(tilt, k))) => {
            let h = default_h.at(tilt);
            (h > 0.0).then(|| k / h)
        }
        (None, None) => None,
    }
}

/// The drain and rest curves (shared) and each liquid's rate at 135°.
pub(crate) fn fit_curves(
    session: &FitSession,
    recordings: &[RecordingFit],
    rates: &BTreeMap<String, Vec<(f64, f64)>>,
    warnings: &mut Vec<String>,
) -> (FittedCurves, BTreeMap<String, Option<f64>>) {
    let defaults = ModelConfig::default().curves;
    let mut at_135 = BTreeMap::new();
    // h at each tilt: the mean over the liquids of k/k(135°).
    let mut relative: Vec<(f64, Vec<f64>)> = Vec::new();
    for (liquid, tilts) in rates {
        let reference = rate_at_reference(tilts, Curve::Drain.of(&defaults));
        at_135.insert(liquid.clone(), reference);
        let Some(reference) = reference else { continue };
        for &(tilt, k) in tilts {
            match relative
                .iter_mut()
                .find(|g| (g.0 - tilt).abs() < SAME_TILT_DEG)
            {
                Some(group) => group.1.push(k / reference),
                None => relative.push((tilt, vec![k / reference])),
            }
        }
    }
    let mut drain: Vec<(f64, f64)> = relative
        .iter()
        .map(|(tilt, hs)| (*tilt, hs.iter().sum::<f64>() / hs.len() as f64))
        .collect();
    if !drain
        .iter()
        .any(|p| (p.0 - REFERENCE_TILT_DEG).abs() < SAME_TILT_DEG)
        && !drain.is_empty()
    {
        drain.push((REFERENCE_TILT_DEG, 1.0));
    }
    for point in &mut drain {
        if point.1 > 1.0 {
            warnings.push(format!(
                "the outflow at {}° is {:.3} times that at 135°; h is held to 1 there (a curve's \
                 values lie within 0 and 1)",
                point.0, point.1
            ));
            point.1 = 1.0;
        }
    }
    let measured_drain = relative.len();
    let drain = curve_or_default(Curve::Drain, drain, measured_drain, &defaults, warnings);

    let mut rests: Vec<(f64, Vec<f64>)> = Vec::new();
    for recording in recordings {
        let Some(rest_ml) = recording.rest_ml else {
            continue;
        };
        let tilt = recording.spec.tilt_deg;
        let share = (rest_ml / session.capacity_ml).clamp(0.0, 1.0);
        match rests
            .iter_mut()
            .find(|g| (g.0 - tilt).abs() < SAME_TILT_DEG)
        {
            Some(group) => group.1.push(share),
            None => rests.push((tilt, vec![share])),
        }
    }
    let measured_rest = rests.len();
    let rest = rests
        .iter()
        .map(|(tilt, shares)| (*tilt, shares.iter().sum::<f64>() / shares.len() as f64))
        .collect();
    let rest = curve_or_default(Curve::Rest, rest, measured_rest, &defaults, warnings);
    (FittedCurves { drain, rest }, at_135)
}

/// `measured` points completed by the default's outside their tilts, checked as a scene's; the
/// default (with a warning) if fewer than 2 tilts were measured or the points are refused.
fn curve_or_default(
    curve: Curve,
    mut measured: Vec<(f64, f64)>,
    tilts: usize,
    defaults: &sake_glug_engine::curves::BottleCurves,
    warnings: &mut Vec<String>,
) -> Option<Vec<(f64, f64)>> {
    let key = curve.scene_key();
    if tilts < 2 {
        // What each curve is read from, so that two counts from one clip do not look at odds.
        let what = match curve {
            Curve::Drain => "an outflow rate (a weight log, or the glug count)",
            Curve::Rest => "a rest level (a weight log that shows where the pour stopped)",
            Curve::Submerged => "a submerged level",
        };
        warnings.push(format!(
            "`{key}` needs recordings at several tilts, each with {what}: {tilts} tilt(s) have \
             one, so it is kept at its default"
        ));
        return None;
    }
    measured.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (low, high) = (measured[0].0, measured[measured.len() - 1].0);
    let outside = curve
        .of(defaults)
        .points()
        .iter()
        .copied()
        .filter(|p| p.0 < low - SAME_TILT_DEG || p.0 > high + SAME_TILT_DEG);
    measured.extend(outside);
    measured.sort_by(|a, b| a.0.total_cmp(&b.0));
    let measured: Vec<(f64, f64)> = measured
        .iter()
        .map(|&(t, v)| (round(t), round(v)))
        .collect();
    match curve.from_points(&measured) {
        Ok(_) => Some(measured),
        Err(error) => {
            warnings.push(format!(
                "`{key}` as fitted is no curve ({error}): kept at its default"
            ));
            None
        }
    }
}

/// Six significant digits: what a model file needs, and readable.
pub(crate) fn round(value: f64) -> f64 {
    format!("{value:.5e}").parse().unwrap_or(value)
}
