//! One liquid's model (MODEL.md §13): its glug constants and amplitude law from the units of its
//! recordings, its pocket and timing from their intervals, its pour time from the rate at 135°,
//! each estimate checked by the honesty rules of [`Estimate`].

use super::by_ear::{fit_by_listening, units_set_some, ByEar, ListeningFit};
use super::curves::FittedCurves;
use super::error::FitError;
use super::estimate::MIN_UNITS_FOR_MODEL;
use super::estimate::{range_of, Estimate};
use super::headspace::{fit_law, HeadspaceLaw};
use super::model_toml::model_toml;
use super::pour::{fitted_intervals, pockets, rate_error};
use super::recording::{FittedUnit, RecordingFit, LOW_EXPLAINED};
use super::stats::{bootstrap, iqr, median, Line, NORMAL_IQR};
use super::units::{Modes, UnitGlide};
use sake_glug_engine::curves::REFERENCE_TILT_DEG;
use sake_glug_engine::{Constant, Control, Curve, Headspace};
use sake_glug_model_file::FittedVolumes;

/// A mode's glide is written only where its median ρ lies this far from 1 (MODEL.md §13).
const GLIDE_HEARD: f64 = 0.05;
/// The z of a two-sided 95 % normal interval (a line's rate).
const Z_95: f64 = 1.959_963_984_540_054;
/// A fitted V0 further below the lowest unit's volume than this share of the volumes' span lies
/// outside the data.
const V0_BEYOND_DATA: f64 = 0.25;
/// A mode's spread is estimated from at least this many units of it.
const MIN_UNITS_FOR_SPREAD: usize = 3;
/// A mode's decay is taken from the units that fitted it gliding where at least this many did
/// (as few as a short mode's agreement asks for).
const MIN_SWEPT_UNITS: usize = 3;
/// A glide fewer than half a mode's units show is its bottle's only where at least this many
/// agree on it (MODEL.md §13).
const MIN_AGREEING_GLIDES: usize = 3;

/// One liquid's model.
#[derive(Debug, Clone)]
pub struct LiquidFit {
    /// Its name.
    pub liquid: String,
    /// Every estimate, model keys first.
    pub estimates: Vec<Estimate>,
    /// The model's keys left at their defaults, and why.
    pub kept_default: Vec<(String, String)>,
    /// Units used.
    pub units: usize,
    /// Units detected.
    pub detected: usize,
    /// How its units' components were put in the bottle's two modes.
    pub modes: Modes,
    /// The amplitude law Asum = slope·V + intercept, if fitted.
    pub amplitude_law: Option<Line>,
    /// The model: a scene file.
    pub model_toml: String,
    /// What the listening fit did, where the units' model did not sound like the recordings.
    pub listening: Option<ListeningFit>,
}

impl LiquidFit {
    /// A constant as the model file has it: its estimate where written, else its default.
    fn model_value(&self, constant: Constant) -> f64 {
        let key = constant.quantity().scene_key;
        self.estimates
            .iter()
            .find(|e| e.key == key && e.in_model)
            .map_or(constant.range().default, |e| e.value)
    }

    /// The frequencies f1, f2 the model plays for a unit at `volume_ml` in a bottle of
    /// `capacity_ml`: the headspace law (MODEL.md §5.1) with the model's values, before the spread.
    pub fn model_hz(&self, volume_ml: f64, capacity_ml: f64) -> [f64; 2] {
        let law = Headspace {
            headspace_ml: self.model_value(Constant::Headspace),
            exponent: [
                self.model_value(Constant::F1Exponent),
                self.model_value(Constant::F2Exponent),
            ],
        };
        let quoted = [
            self.model_value(Constant::F1),
            self.model_value(Constant::F2),
        ];
        let factors = law.factors(volume_ml, capacity_ml, self.model_value(Constant::Pocket));
        [quoted[0] * factors[0], quoted[1] * factors[1]]
    }
}

/// What one liquid's model is made of.
pub(crate) struct LiquidInputs<'a> {
    /// Its name.
    pub liquid: &'a str,
    /// Its recordings.
    pub recordings: Vec<&'a RecordingFit>,
    /// The bottle's capacity (ml).
    pub capacity_ml: f64,
    /// The bottle's curves.
    pub curves: &'a FittedCurves,
    /// Its outflow rate at 135°, if known (ml/s).
    pub rate_at_135: Option<f64>,
    /// Its outflow rate at each tilt measured (°, ml/s).
    pub rates: &'a [(f64, f64)],
    /// How its units' components were put in modes.
    pub modes: Modes,
}

/// The unit estimates, in this order: each one's model key (or name), and whether it is one.
fn unit_keys() -> [(String, bool); 18] {
    let key = |constant: Constant| (constant.quantity().scene_key.to_owned(), true);
    [
        key(Constant::F1),
        key(Constant::F2),
        key(Constant::F1Exponent),
        key(Constant::F2Exponent),
        key(Constant::F1GlideRatio),
        key(Constant::F2GlideRatio),
        key(Constant::F1GlideTime),
        key(Constant::F2GlideTime),
        key(Constant::Headspace),
        key(Constant::FreqJitter),
        key(Constant::B1),
        key(Constant::B2),
        key(Constant::DecaySigma),
        (Control::Viscosity.quantity().scene_key.to_owned(), true),
        key(Constant::SilentBelow),
        key(Constant::AmplitudeSpread),
        (Control::Gain.quantity().scene_key.to_owned(), true),
        ("R² of Asum against V".to_owned(), false),
    ]
}

/// The units each of [`unit_keys`]' estimates comes from.
fn unit_counts(units: &[FittedUnit]) -> [usize; 18] {
    let in_mode = |mode: usize| {
        units
            .iter()
            .filter(|u| u.fit.frequency_hz[mode].is_finite())
            .count()
    };
    let in_mode_with_volume = |mode: usize| {
        units
            .iter()
            .filter(|u| u.fit.frequency_hz[mode].is_finite() && u.volume_ml.is_finite())
            .count()
    };
    let (low, high) = (in_mode(0), in_mode(1));
    let spread = [low, high]
        .into_iter()
        .filter(|&n| n >= MIN_UNITS_FOR_SPREAD)
        .max()
        .unwrap_or(low.max(high));
    let with_volume = units.iter().filter(|u| u.volume_ml.is_finite()).count();
    let gliding = |mode: usize| units.iter().filter(|u| u.fit.glide[mode].is_some()).count();
    [
        low,
        high,
        in_mode_with_volume(0),
        in_mode_with_volume(1),
        low,
        high,
        gliding(0),
        gliding(1),
        in_mode_with_volume(0).max(in_mode_with_volume(1)),
        spread,
        low,
        high,
        spread,
        units.len(),
        with_volume,
        with_volume,
        units.len(),
        with_volume,
    ]
}

/// Each mode's (C − V_i, f_i) of the units whose volume is known, f_i as the model would have to
/// ring to be heard where unit i is (`own`, [`own_hz`]).
fn pitch_points(
    units: &[FittedUnit],
    capacity_ml: f64,
    own: &impl Fn(&FittedUnit, usize) -> f64,
) -> [Vec<(f64, f64)>; 2] {
    [0, 1].map(|k| {
        units
            .iter()
            .filter(|u| u.volume_ml.is_finite() && u.fit.frequency_hz[k].is_finite())
            .map(|u| (capacity_ml - u.volume_ml, own(u, k)))
            .filter(|(_, hz)| hz.is_finite())
            .collect()
    })
}

/// Unit k's mode as heard: its own f moved by its glide 1/(2B) after the onset, where its ring's
/// energy is centred (MODEL.md §5.2).
fn heard_hz(unit: &FittedUnit, k: usize) -> f64 {
    let glide = unit.fit.glide[k];
    let centre_s = 0.5 / unit.fit.decay_per_s[k];
    unit.fit.frequency_hz[k] * glide.map_or(1.0, |g| g.factor(centre_s))
}

/// A unit's mode k as the model's own f. Where the model's mode glides, the pitch the unit is heard
/// at, over the model's glide factor where its ring's energy is centred (MODEL.md §13): a glide's
/// ρ, τ_g and f trade against each other in one unit's fit, while the pitch heard is what its
/// samples fix, and the model, gliding by the units' median glide, is then heard where the units
/// are. Where the model's mode is steady, the unit's own f: a glide a few units show is no
/// bottle's, and a steady model is played at the f its units' fits end at. Where the units'
/// glides are not the recordings' (`glides_heard` false: they explain under half of one), the
/// units' own f too: the model is then fitted by listening, which hears the pitch itself, and the
/// glides the units' fits traded for it would only move where that search starts. `glide` and
/// `decay_per_s` are the model's ([`glides`], [`unit_decays`]' medians).
fn own_hz(
    units: &[FittedUnit],
    glide: [(f64, f64); 2],
    decay_per_s: [f64; 2],
    glides_heard: bool,
) -> impl Fn(&FittedUnit, usize) -> f64 {
    let decay = decay_per_s;
    let enough_gliding = [0, 1]
        .map(|k| units.iter().filter(|u| u.fit.glide[k].is_some()).count() >= MIN_AGREEING_GLIDES);
    let factor = [0, 1].map(|k| {
        let (ratio, time_ms) = glide[k];
        (glides_heard
            && (ratio - 1.0).abs() >= GLIDE_HEARD
            && time_ms.is_finite()
            && decay[k].is_finite())
        .then(|| {
            UnitGlide {
                ratio,
                time_s: 1e-3 * time_ms,
            }
            .factor(0.5 / decay[k])
        })
    });
    move |unit, k| match factor[k] {
        // A unit fitted steady in a gliding mode read a pitch between the glide's start and its
        // own f, wherever its window began (a development draw's 177 Hz between gliding
        // neighbours heard at 223 and 189): where enough units glide, it places no f.
        Some(_) if enough_gliding[k] && unit.fit.glide[k].is_none() && !unit.fit.swept[k] => {
            f64::NAN
        }
        Some(factor) => heard_hz(unit, k) / factor,
        None => unit.fit.frequency_hz[k],
    }
}

/// Each mode's B (1/s) as the model writes it: the median over the units. A mode rising into its
/// pitch, fitted steady, decays up to three times as fast as it rings; where enough units fitted
/// the mode gliding, its decay is theirs (MODEL.md §13).
fn unit_decays(units: &[FittedUnit]) -> [Vec<f64>; 2] {
    [0, 1].map(|k| {
        let of = |swept_only: bool| -> Vec<f64> {
            units
                .iter()
                .filter(|u| !swept_only || u.fit.swept[k])
                .map(|u| u.fit.decay_per_s[k])
                .filter(|v| v.is_finite())
                .collect()
        };
        let swept = of(true);
        if swept.len() >= MIN_SWEPT_UNITS {
            swept
        } else {
            of(false)
        }
    })
}

/// The headspace law of a liquid's units (MODEL.md §5.1, §13) in a bottle whose pocket is
/// `pocket_ml`.
fn headspace_law(
    units: &[FittedUnit],
    capacity_ml: f64,
    pocket_ml: f64,
    glides_heard: bool,
) -> HeadspaceLaw {
    let decay = unit_decays(units).map(|b| median(&b));
    let own = own_hz(units, glides(units, glides_heard), decay, glides_heard);
    let points = pitch_points(units, capacity_ml, &own);
    fit_law([&points[0], &points[1]], pocket_ml)
}

/// The pocket the model is written with: the logged recordings' (MODEL.md §13), else the
/// default.
fn model_pocket_ml(recordings: &[&RecordingFit]) -> f64 {
    let pockets = pockets(recordings);
    if pockets.is_empty() {
        Constant::Pocket.range().default
    } else {
        median(&pockets)
    }
}

/// The unit-based estimates of a liquid, in [`unit_keys`] order (NaN where unknown).
fn unit_estimates(
    units: &[FittedUnit],
    capacity_ml: f64,
    pocket_ml: f64,
    glides_heard: bool,
) -> Vec<f64> {
    let of = |get: &dyn Fn(&FittedUnit) -> f64| {
        units
            .iter()
            .map(get)
            .filter(|v| v.is_finite())
            .collect::<Vec<_>>()
    };
    // The model's glides and decays, worked out once: the own f of every unit depends on them.
    let glide = glides(units, glides_heard);
    let b = unit_decays(units);
    let own = own_hz(units, glide, [median(&b[0]), median(&b[1])], glides_heard);
    let points = pitch_points(units, capacity_ml, &own);
    let law = fit_law([&points[0], &points[1]], pocket_ml);
    // Where a mode follows the headspace, its spread is the scatter around the law (as the
    // engine reads it), over the units whose volume places them on it.
    let model = law.model();
    let f = [0, 1].map(|k| {
        if law.heard() {
            points[k]
                .iter()
                .map(|&(added_ml, hz)| {
                    hz / model.factors(capacity_ml - added_ml, capacity_ml, pocket_ml)[k]
                })
                .collect()
        } else {
            of(&|u| own(u, k))
        }
    });
    let quoted_hz = [0, 1].map(|k| match law.modes[k] {
        Some(mode) if mode.follows() => mode.full_hz,
        _ => median(&of(&|u| own(u, k))),
    });
    let exponent = law.modes.map(|mode| mode.map_or(f64::NAN, |m| m.exponent));
    // A spread over the modes with enough units to show one.
    let mean_over_modes = |values: &[Vec<f64>; 2], spread: &dyn Fn(&[f64]) -> f64| {
        let spreads: Vec<f64> = values
            .iter()
            .filter(|v| v.len() >= MIN_UNITS_FOR_SPREAD)
            .map(|v| spread(v))
            .collect();
        spreads.iter().sum::<f64>() / spreads.len() as f64
    };
    let relative = |values: &[f64]| iqr(values) / median(values);
    let log_sigma =
        |values: &[f64]| iqr(&values.iter().map(|v| v.ln()).collect::<Vec<_>>()) / NORMAL_IQR;
    let amplitude = amplitude_law(units);
    let (silent_below, amplitude_spread, r_squared) = match amplitude {
        Some(line) if line.slope > 0.0 => {
            let residuals: Vec<f64> = units
                .iter()
                .filter(|u| u.volume_ml.is_finite() && line.at(u.volume_ml) > 0.0)
                .map(|u| (u.fit.amplitude_sum() / line.at(u.volume_ml)).ln())
                .collect();
            (
                -line.intercept / line.slope,
                iqr(&residuals) / NORMAL_IQR,
                line.r_squared,
            )
        }
        _ => (f64::NAN, f64::NAN, f64::NAN),
    };
    // The full bottle's Asum: the law at C where Asum falls with V, else the units' median (a
    // recording near full, whose law has no slope).
    let full = match amplitude {
        Some(line) if line.slope > 0.0 => line.at(capacity_ml),
        _ => median(&of(&|u| u.fit.amplitude_sum())),
    };
    vec![
        quoted_hz[0],
        quoted_hz[1],
        exponent[0],
        exponent[1],
        glide[0].0,
        glide[1].0,
        glide[0].1,
        glide[1].1,
        law.headspace_ml,
        // j_f: f(1 + j·u), u uniform in [−1, 1], has its quartiles at f(1 ± j/2).
        mean_over_modes(&f, &relative),
        median(&b[0]),
        median(&b[1]),
        mean_over_modes(&b, &log_sigma),
        viscosity(units),
        silent_below,
        amplitude_spread,
        20.0 * full.log10(),
        r_squared,
    ]
}

/// Each mode's glide (MODEL.md §5.2, §13): ρ and τ_g the medians over the units whose component
/// in the mode glides, where those are at least half of the units ringing it, or, where the units'
/// glides are the recordings' (`glides_heard`), at least [`MIN_AGREEING_GLIDES`] and a quarter of
/// them that agree (their ln ρ's IQR under half its median's size); else no glide (ρ = 1), as a
/// glide a few units show, each its own, is no bottle's. A unit whose glide is slower than its
/// ring is fitted steady, so a gliding bottle's units that glide are its ρ; counted as 1 they
/// pulled its ρ towards 1 (a development draw's 1.41 to 1.31, with 18 of its 47 units steady),
/// and where most of its units are steady, a glide its gliding units agree on is still its own
/// (development draws 3009 and 1033: 7 of 22 units at ρ 1.17–1.20, 6–9 of 13 at 1.38–1.48).
fn glides(units: &[FittedUnit], glides_heard: bool) -> [(f64, f64); 2] {
    [0, 1].map(|k| {
        let ringing = units
            .iter()
            .filter(|u| u.fit.frequency_hz[k].is_finite())
            .count();
        let gliding: Vec<UnitGlide> = units
            .iter()
            .filter(|u| u.fit.frequency_hz[k].is_finite())
            .filter_map(|u| u.fit.glide[k])
            .collect();
        let times_ms: Vec<f64> = gliding.iter().map(|g| 1e3 * g.time_s).collect();
        let ratios: Vec<f64> = gliding.iter().map(|g| g.ratio).collect();
        let log_ratios: Vec<f64> = ratios.iter().map(|r| r.ln()).collect();
        // Steady draws' stray glides scatter (ρ 0.54–1.03 over a development draw's units); a
        // bottle's cluster within a few per cent.
        let agree = glides_heard
            && gliding.len() >= MIN_AGREEING_GLIDES
            && 4 * gliding.len() >= ringing
            && iqr(&log_ratios) < 0.5 * median(&log_ratios).abs();
        if (2 * gliding.len() >= ringing || agree) && !gliding.is_empty() {
            (median(&ratios), median(&times_ms))
        } else {
            (1.0, median(&times_ms))
        }
    })
}

/// A glide is written only where its mode's median ρ lies at least [`GLIDE_HEARD`] from 1 (a
/// smaller one moves the pitch less than the units' own scatter); else ρ and τ_g keep their
/// defaults, with the reason.
fn check_glides(estimates: &mut [Estimate]) {
    let modes = [
        (Constant::F1GlideRatio, Constant::F1GlideTime),
        (Constant::F2GlideRatio, Constant::F2GlideTime),
    ];
    for (k, (ratio, time)) in modes.into_iter().enumerate() {
        let find = |estimates: &[Estimate], c: Constant| {
            estimates
                .iter()
                .position(|e| e.key == c.quantity().scene_key)
        };
        let (Some(r), Some(t)) = (find(estimates, ratio), find(estimates, time)) else {
            continue;
        };
        let value = estimates[r].value;
        if estimates[r].in_model && (value - 1.0).abs() >= GLIDE_HEARD {
            continue;
        }
        for (index, what) in [(r, "ρ"), (t, "τ_g")] {
            let estimate = &mut estimates[index];
            if estimate.in_model || estimate.has_value() {
                estimate.in_model = false;
                estimate.note = Some(format!(
                    "f{} does not glide measurably (median ρ = {value:.3} over its units): {what} \
                     kept at its default",
                    k + 1
                ));
            }
        }
    }
}

/// c: the median of A1/(A1 + A2) over the units that ring both modes, where at least
/// [`MIN_UNITS_FOR_SPREAD`] do; else over every unit. A unit ringing one mode beside units that
/// ring both has lost the other in noise or in the last glug's ring (its short bright mode, tens
/// of milliseconds long, is the first to go), and would pull c to 0 or 1 (MODEL.md §13).
fn viscosity(units: &[FittedUnit]) -> f64 {
    let both: Vec<f64> = units
        .iter()
        .filter(|u| u.fit.amplitude.iter().all(|&a| a > 0.0))
        .map(|u| u.fit.viscosity())
        .filter(|c| c.is_finite())
        .collect();
    if both.len() >= MIN_UNITS_FOR_SPREAD {
        median(&both)
    } else {
        median(
            &units
                .iter()
                .map(|u| u.fit.viscosity())
                .filter(|c| c.is_finite())
                .collect::<Vec<_>>(),
        )
    }
}

/// The line Asum = α·V + β through the units whose volume is known.
fn amplitude_law(units: &[FittedUnit]) -> Option<Line> {
    let points: Vec<(f64, f64)> = units
        .iter()
        .filter(|u| u.volume_ml.is_finite())
        .map(|u| (u.volume_ml, u.fit.amplitude_sum()))
        .collect();
    Line::through(&points)
}

/// Fits the model of one liquid.
pub(crate) fn fit_liquid(
    inputs: &LiquidInputs,
    warnings: &mut Vec<String>,
) -> Result<LiquidFit, FitError> {
    let LiquidInputs {
        liquid,
        capacity_ml,
        ..
    } = *inputs;
    let recordings = &inputs.recordings;
    let units: Vec<FittedUnit> = recordings
        .iter()
        .flat_map(|r| r.units.iter().copied())
        .collect();
    let detected = recordings.iter().map(|r| r.detected.len()).sum();
    let pocket_ml = model_pocket_ml(recordings);
    // The units' glides are the recordings' where the units explain at least half of each (as
    // where the listening fit keeps their model).
    let glides_heard = recordings.iter().all(|r| r.explained >= LOW_EXPLAINED);
    let values = unit_estimates(&units, capacity_ml, pocket_ml, glides_heard);
    let intervals = bootstrap(&units, |sample| {
        unit_estimates(sample, capacity_ml, pocket_ml, glides_heard)
    });
    let mut estimates: Vec<Estimate> = unit_keys()
        .into_iter()
        .zip(values.iter().zip(intervals).zip(unit_counts(&units)))
        .map(|((key, in_model), ((&value, interval), n))| {
            Estimate::from_units(key, value, interval, n, in_model)
        })
        .collect();
    if units.len() < MIN_UNITS_FOR_MODEL {
        warnings.push(format!(
            "liquid `{liquid}`: the paper's model describes {} of its {detected} detected \
             unit(s): too few for a model of its glugs, whose constants keep their defaults",
            units.len()
        ));
    }
    if inputs.modes == Modes::One && !units.is_empty() {
        let f2 = Constant::F2.quantity().scene_key;
        if let Some(estimate) = estimates.iter_mut().find(|e| e.key == f2) {
            estimate.note = Some(
                "every unit rings one mode (f1), so c = 1 and f2 is not heard: kept at its \
                 default"
                    .to_owned(),
            );
        }
    }
    check_silent_below(&mut estimates, &units, capacity_ml);
    check_glides(&mut estimates);
    check_headspace(
        &mut estimates,
        &headspace_law(&units, capacity_ml, pocket_ml, glides_heard),
    );
    estimates.extend(timing_estimates(inputs));
    estimates.push(Estimate::measured(
        Constant::Capacity.quantity().scene_key,
        capacity_ml,
        None,
        true,
    ));
    for estimate in estimates.iter_mut().filter(|e| e.in_model) {
        if let Some(range) = range_of(&estimate.key).filter(|r| !r.contains(estimate.value)) {
            warnings.push(format!(
                "liquid `{liquid}`: `{}` = {} lies outside {}…{}: brought into range",
                estimate.key, estimate.value, range.min, range.max
            ));
            estimate.value = range.sanitize(estimate.value);
        }
    }
    let kept_default = kept_at_default(&estimates, inputs.curves);
    let law = amplitude_law(&units);
    // Where the model describes a recording poorly, its file says so before anything else.
    let cautions: Vec<String> = recordings
        .iter()
        .filter(|r| r.explained < LOW_EXPLAINED)
        .map(|r| {
            format!(
                "the units fitted explain only {:.0} % of {}: the paper's model describes it \
                 poorly, and this model may not sound like it",
                100.0 * r.explained,
                r.name()
            )
        })
        .chain((units.len() < MIN_UNITS_FOR_MODEL).then(|| {
            format!(
                "only {} unit(s) are described by the paper's model: the glug's constants keep \
                 their defaults",
                units.len()
            )
        }))
        .collect();
    let mut kept_default = kept_default;
    let volumes = fitted_volumes(&units);
    let model_toml = |estimates: &[Estimate], kept_default: &[(String, String)]| {
        model_toml(
            liquid,
            estimates,
            inputs.curves,
            volumes,
            kept_default,
            &cautions,
        )
    };
    let mut model = model_toml(&estimates, &kept_default);
    let units_set = units_set_some(&estimates);
    let by_ear = if !units.is_empty() {
        fit_by_listening(&model, &mut estimates, recordings, capacity_ml)
    } else {
        ByEar::UnitsKept
    };
    let listening = match by_ear {
        ByEar::Fitted(listening) => Some(listening),
        // With no constant from the units and none by listening, the model would be the default
        // bottle: a model of no recording, which is refused as one of none would be.
        ByEar::UnitsKept | ByEar::NoModelNearer { .. } if !units_set => {
            return Err(FitError::NothingNearer {
                what: format!("liquid `{liquid}`"),
                used: units.len(),
                detected,
            })
        }
        ByEar::UnitsKept => None,
        ByEar::NoModelNearer { missed } => {
            return Err(FitError::NoModelNearer {
                what: format!("liquid `{liquid}`"),
                used: units.len(),
                detected,
                missed,
            })
        }
    };
    if let Some(listening) = &listening {
        warnings.push(format!(
            "liquid `{liquid}`: the units' model did not sound like its recordings, so {} were \
             fitted by listening (MODEL.md §13)",
            listening.set.join(", ")
        ));
        kept_default = kept_at_default(&estimates, inputs.curves);
        model = model_toml(&estimates, &kept_default);
    }
    Ok(LiquidFit {
        listening,
        liquid: liquid.to_owned(),
        units: units.len(),
        detected,
        modes: inputs.modes,
        estimates,
        kept_default,
        model_toml: model,
        amplitude_law: law,
    })
}

/// The lowest and highest V_i of the units the model was fitted from, if any has a volume: what
/// the model file records, so that a render far beyond them warns (MODEL.md §13).
fn fitted_volumes(units: &[FittedUnit]) -> Option<FittedVolumes> {
    let volumes = units.iter().map(|u| u.volume_ml).filter(|v| v.is_finite());
    volumes.fold(None, |range, v| {
        Some(range.map_or(
            FittedVolumes {
                lowest_ml: v,
                highest_ml: v,
            },
            |FittedVolumes {
                 lowest_ml,
                 highest_ml,
             }| FittedVolumes {
                lowest_ml: lowest_ml.min(v),
                highest_ml: highest_ml.max(v),
            },
        ))
    })
}

/// An exponent is written only where its mode follows the headspace measurably, and H only where
/// the units reject the default H; otherwise each keeps its default, with the reason.
fn check_headspace(estimates: &mut [Estimate], law: &HeadspaceLaw) {
    for (k, constant) in [Constant::F1Exponent, Constant::F2Exponent]
        .into_iter()
        .enumerate()
    {
        let key = constant.quantity().scene_key;
        let (Some(estimate), Some(mode)) =
            (estimates.iter_mut().find(|e| e.key == key), law.modes[k])
        else {
            continue;
        };
        if estimate.has_value() && !mode.follows() {
            estimate.in_model = false;
            estimate.note = Some(format!(
                "f{} does not move measurably with the headspace (γ = {:.3} ± {:.3}, {:.1} % \
                 over the units' volumes): kept at 0, the paper's constant frequency",
                k + 1,
                mode.exponent,
                Z_95 * mode.exponent_error,
                100.0 * mode.pitch_change()
            ));
        }
    }
    let key = Constant::Headspace.quantity().scene_key;
    let Some(estimate) = estimates.iter_mut().find(|e| e.key == key) else {
        return;
    };
    if !law.heard() {
        estimate.in_model = false;
        estimate.note = Some("no mode follows the headspace: not needed".to_owned());
    } else if !law.headspace_heard {
        estimate.in_model = false;
        estimate.note = Some(match law.allowed_ml {
            Some((low, high)) => format!(
                "the units allow any H from {low:.3} to {high:.3} ml, the default among them: \
                 kept at its default"
            ),
            None => "the units do not tell H: kept at its default".to_owned(),
        });
    }
}

/// V0 is not written where the law has no measurable slope, where it lies at or above the
/// capacity, or where it lies outside the units' volumes: reported as such, without a number.
fn check_silent_below(estimates: &mut [Estimate], units: &[FittedUnit], capacity_ml: f64) {
    let silent_key = Constant::SilentBelow.quantity().scene_key;
    let Some(estimate) = estimates.iter_mut().find(|e| e.key == silent_key) else {
        return;
    };
    let law = amplitude_law(units);
    let volumes: Vec<f64> = units
        .iter()
        .map(|u| u.volume_ml)
        .filter(|v| v.is_finite())
        .collect();
    let (lowest, highest) = volumes
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| {
            (l.min(v), h.max(v))
        });
    // A line whose slope its own error cannot tell from 0 has no zero worth a number.
    if let Some(line) = law.filter(|line| line.slope <= Z_95 * line.slope_error) {
        estimate.fail(format!(
            "Asum does not fall measurably with V (slope {:.3e} ± {:.3e} per ml)",
            line.slope,
            Z_95 * line.slope_error
        ));
    } else if estimate.has_value() && estimate.value >= capacity_ml {
        estimate.fail("the fitted zero lies above the capacity".to_owned());
    } else if estimate.has_value() && estimate.value < lowest - V0_BEYOND_DATA * (highest - lowest)
    {
        estimate.fail(format!(
            "outside the data: the line reaches 0 at {:.1} ml, far below the units' volumes \
             ({lowest:.1} … {highest:.1} ml)",
            estimate.value
        ));
    }
}

/// The pocket, the timing spread, the pour time and each tilt's rate.
fn timing_estimates(inputs: &LiquidInputs) -> Vec<Estimate> {
    let mut estimates = Vec::new();
    let recordings = &inputs.recordings;
    let pockets = pockets(recordings);
    if !pockets.is_empty() {
        let interval = bootstrap(&pockets, |s| vec![median(s)])[0];
        estimates.push(Estimate::from_units(
            Constant::Pocket.quantity().scene_key,
            median(&pockets),
            interval,
            pockets.len(),
            true,
        ));
    }
    let relative_intervals: Vec<f64> = recordings
        .iter()
        .flat_map(|r| {
            let all = fitted_intervals(r);
            let typical = median(&all);
            all.into_iter().map(move |dt| dt / typical)
        })
        .collect();
    if !relative_intervals.is_empty() {
        // j_t: b(1 + j·u) has its quartiles at b(1 ± j/2).
        let interval = bootstrap(&relative_intervals, |s| vec![iqr(s) / median(s)])[0];
        estimates.push(Estimate::from_units(
            Constant::TimingJitter.quantity().scene_key,
            iqr(&relative_intervals) / median(&relative_intervals),
            interval,
            relative_intervals.len(),
            true,
        ));
    }
    if let Some(rate) = inputs.rate_at_135 {
        let interval = rate_error(recordings, REFERENCE_TILT_DEG)
            .map(|e| (rate - Z_95 * e, rate + Z_95 * e))
            .filter(|(low, _)| *low > 0.0);
        estimates.push(Estimate::measured(
            Control::PourTime.quantity().scene_key,
            inputs.capacity_ml / rate,
            interval.map(|(low, high)| (inputs.capacity_ml / high, inputs.capacity_ml / low)),
            true,
        ));
    }
    for &(tilt, rate) in inputs.rates {
        let interval = rate_error(recordings, tilt).map(|e| (rate - Z_95 * e, rate + Z_95 * e));
        estimates.push(Estimate::measured(
            format!("outflow rate at {tilt}° (ml/s)"),
            rate,
            interval,
            false,
        ));
    }
    estimates
}

/// Every model key left at its default, and why.
fn kept_at_default(estimates: &[Estimate], curves: &FittedCurves) -> Vec<(String, String)> {
    let model_keys: Vec<String> = unit_keys()
        .into_iter()
        .filter(|(_, in_model)| *in_model)
        .map(|(key, _)| key)
        .collect();
    let mut kept: Vec<(String, String)> = estimates
        .iter()
        .filter(|e| !e.in_model && model_keys.contains(&e.key))
        .map(|e| {
            (
                e.key.clone(),
                e.note.clone().unwrap_or_else(|| "not estimated".into()),
            )
        })
        .collect();
    for (key, why) in [
        (
            Constant::Pocket.quantity().scene_key,
            "no weight log gave the outflow",
        ),
        (
            Constant::TimingJitter.quantity().scene_key,
            "too few intervals between units",
        ),
        (
            Control::PourTime.quantity().scene_key,
            "no drain rate was measured",
        ),
    ] {
        match estimates.iter().find(|e| e.key == key) {
            None => kept.push((key.to_owned(), why.to_owned())),
            Some(e) if !e.in_model => kept.push((
                key.to_owned(),
                e.note.clone().unwrap_or_else(|| why.to_owned()),
            )),
            Some(_) => {}
        }
    }
    for curve in Curve::ALL {
        let fitted = match curve {
            Curve::Drain => curves.drain.is_some(),
            Curve::Rest => curves.rest.is_some(),
            Curve::Submerged => false,
        };
        if !fitted {
            let why = match curve {
                Curve::Submerged => {
                    "the last glug shows where the mouth surfaces only above the silent volume; \
                     not estimated"
                }
                _ => "needs several tilts",
            };
            kept.push((curve.scene_key().to_owned(), why.to_owned()));
        }
    }
    kept
}
