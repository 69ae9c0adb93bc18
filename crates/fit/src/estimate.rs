//! From the units of every recording to the model (MODEL.md §13): each recording's drain line and
//! rest level, each liquid's glug constants and amplitude law, the bottle's curves, and the scene
//! file that plays them.

use std::collections::BTreeMap;

use super::audio::Audio;
use super::error::FitError;
use super::session::{FitSession, RecordingSpec};
use super::spectrum::Spectrum;
use super::stats::{bootstrap, iqr, median, Line, NORMAL_IQR};
use super::unit::{fit_units, UnitFit};
use super::weight::WeightLog;
use sake_glug_engine::curves::REFERENCE_TILT_DEG;
use sake_glug_engine::Range;
use sake_glug_engine::{Constant, Control, Curve, ModelConfig};

/// An interval between units longer than this many times the median counts a missed unit, one
/// shorter than [`SHORT_INTERVAL`] of it a spurious one: neither tells the pocket.
const LONG_INTERVAL: f64 = 1.6;
const SHORT_INTERVAL: f64 = 0.4;
/// A weight log whose last second falls by less than this share of the pour's rate (and less than
/// [`FLAT_ML`]) has stopped pouring: its end is the rest level.
const FLAT_SHARE: f64 = 0.03;
const FLAT_ML: f64 = 0.5;
/// The end of a weight log read for its rest level (s).
const REST_TAIL_S: f64 = 1.0;
/// Two tilts closer than this are one (degrees).
const SAME_TILT_DEG: f64 = 0.5;
/// The z of a two-sided 95 % normal interval (a line's rate).
const Z_95: f64 = 1.959_963_984_540_054;

/// A unit with the volume in the bottle at its onset.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FittedUnit {
    /// Its eq. 1.
    pub fit: UnitFit,
    /// V_i (ml).
    pub volume_ml: f64,
}

/// The straight drain of one recording (paper eq. 3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrainLine {
    /// V(t) = line.at(t) while it pours; −slope is the outflow rate k (ml/s).
    pub line: Line,
    /// From the weight log (else from the glug count × pocket).
    pub from_weight: bool,
    /// The time span it was fitted over (s).
    pub span_s: (f64, f64),
}

impl DrainLine {
    /// The outflow rate k (ml/s).
    pub fn rate_ml_per_s(&self) -> f64 {
        -self.line.slope
    }
}

/// One recording, fitted.
#[derive(Debug, Clone)]
pub struct RecordingFit {
    /// As the session gives it.
    pub spec: RecordingSpec,
    /// The samples.
    pub audio: Audio,
    /// Its units with their volumes.
    pub units: Vec<FittedUnit>,
    /// Onsets whose fit was rejected.
    pub rejected: usize,
    /// Its spectrum, and the peaks that started every unit.
    pub spectrum: Spectrum,
    /// f1, f2 where every unit's fit started (Hz).
    pub start_hz: [f64; 2],
    /// The weight log, as volumes.
    pub weight: Option<WeightLog>,
    /// The drain line, if one could be drawn.
    pub drain: Option<DrainLine>,
    /// What remained once it stopped pouring (ml), if the log shows it.
    pub rest_ml: Option<f64>,
}

/// One estimate of the report, written to the model under `key` if it is a scene key.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// The scene key it is written to, or what it is (`drain rate at 135°`).
    pub key: String,
    /// Its value.
    pub value: f64,
    /// The 95 % interval (bootstrap over units, or a line's standard error).
    pub interval: Option<(f64, f64)>,
    /// Whether it is a key of the model file.
    pub in_model: bool,
}

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
    /// The amplitude law Asum = slope·V + intercept, if fitted.
    pub amplitude_law: Option<Line>,
    /// The model: a scene file.
    pub model_toml: String,
}

/// The bottle's curves as fitted: `(tilt, value)` points (defaults outside the measured tilts).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FittedCurves {
    /// h(θ), if several tilts were measured.
    pub drain: Option<Vec<(f64, f64)>>,
    /// r(θ), if several tilts showed their rest level.
    pub rest: Option<Vec<(f64, f64)>>,
}

/// A whole session, fitted.
#[derive(Debug, Clone)]
pub struct SessionFit {
    /// The session.
    pub session: FitSession,
    /// Each recording.
    pub recordings: Vec<RecordingFit>,
    /// Each liquid, in the order first named.
    pub liquids: Vec<LiquidFit>,
    /// The bottle's curves, shared by every liquid.
    pub curves: FittedCurves,
    /// What the user should know: clipping, a recording without glugs, a curve left at default.
    pub warnings: Vec<String>,
}

/// Fits the model of every liquid of `session` (MODEL.md §13).
pub fn fit_session(session: &FitSession) -> Result<SessionFit, FitError> {
    let mut warnings = Vec::new();
    let mut recordings = Vec::with_capacity(session.recordings.len());
    for spec in &session.recordings {
        recordings.push(fit_recording(spec, session.capacity_ml, &mut warnings)?);
    }
    let mut liquids = Vec::new();
    let mut rates: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
    for liquid in session.liquids() {
        let members: Vec<usize> = (0..recordings.len())
            .filter(|&i| recordings[i].spec.liquid == liquid)
            .collect();
        if members.iter().all(|&i| recordings[i].units.is_empty()) {
            return Err(FitError::NoGlugs {
                what: format!("the recordings of liquid `{liquid}`"),
            });
        }
        let pocket = pocket_of(&recordings, &members);
        if pocket.is_none() {
            warnings.push(format!(
                "liquid `{liquid}`: no weight log, so the pocket volume stays at its default and \
                 the volumes come from the glug count × that pocket"
            ));
        }
        let pocket_ml = pocket.map_or(Constant::Pocket.range().default, |(b, _)| b);
        for &i in &members {
            complete_without_weight(&mut recordings[i], pocket_ml, &mut warnings);
        }
        rates.insert(liquid.to_owned(), tilt_rates(&recordings, &members));
    }
    let (curves, rate_at_135) = fit_curves(session, &recordings, &rates, &mut warnings);
    for liquid in session.liquids() {
        let members: Vec<&RecordingFit> = recordings
            .iter()
            .filter(|r| r.spec.liquid == liquid)
            .collect();
        liquids.push(fit_liquid(
            liquid,
            &members,
            session.capacity_ml,
            &curves,
            rate_at_135[liquid],
            &rates[liquid],
            &mut warnings,
        ));
    }
    Ok(SessionFit {
        session: session.clone(),
        recordings,
        liquids,
        curves,
        warnings,
    })
}

/// Reads, detects and fits one recording, its drain line and rest level from its weight log.
fn fit_recording(
    spec: &RecordingSpec,
    capacity_ml: f64,
    warnings: &mut Vec<String>,
) -> Result<RecordingFit, FitError> {
    let audio_key = format!("{}.audio", spec.key);
    let audio = Audio::read(&spec.audio, &audio_key)?;
    let weight = spec
        .weight
        .as_ref()
        .map(|weight| WeightLog::read(weight, &spec.key, spec.start_ml))
        .transpose()?;
    if audio.clipped > 0 {
        warnings.push(format!(
            "`{audio_key}`: {} samples are clipped (runs at full scale): the amplitudes of the \
             units there are too low",
            audio.clipped
        ));
    }
    let found = fit_units(&audio.samples, audio.sample_rate);
    if found.units.is_empty() {
        warnings.push(format!("`{audio_key}`: no glugs found"));
    }
    if found.one_peak && !found.units.is_empty() {
        warnings.push(format!(
            "`{audio_key}`: the spectrum shows one peak only; the other component's start was \
             guessed at the paper's ratio of f2 to f1"
        ));
    }
    let mut recording = RecordingFit {
        spec: spec.clone(),
        audio,
        units: found
            .units
            .iter()
            .map(|&fit| FittedUnit {
                fit,
                volume_ml: f64::NAN,
            })
            .collect(),
        rejected: found.rejected,
        spectrum: found.spectrum,
        start_hz: found.start_hz,
        weight,
        drain: None,
        rest_ml: None,
    };
    if let Some(log) = &recording.weight {
        let (first, last) = match (recording.units.first(), recording.units.last()) {
            (Some(first), Some(last)) => (first.fit.onset_s, last.fit.onset_s),
            _ => (0.0, recording.audio.duration_s()),
        };
        let during: Vec<(f64, f64)> = log
            .points
            .iter()
            .copied()
            .filter(|&(t, _)| t >= first && t <= last)
            .collect();
        match Line::through(&during).filter(|line| line.slope < 0.0) {
            Some(line) => {
                recording.drain = Some(DrainLine {
                    line,
                    from_weight: true,
                    span_s: (first, last),
                });
                for unit in &mut recording.units {
                    unit.volume_ml = line.at(unit.fit.onset_s).clamp(0.0, capacity_ml);
                }
            }
            None => warnings.push(format!(
                "`{}.weight`: fewer than 3 falling readings while it glugs: no drain line",
                spec.key
            )),
        }
        recording.rest_ml = rest_level(log, recording.drain.as_ref());
        if recording.rest_ml.is_none() {
            warnings.push(format!(
                "`{}.weight`: the log still falls at its end: the rest level at {}° is unknown",
                spec.key, spec.tilt_deg
            ));
        }
    }
    Ok(recording)
}

/// The level the log settles at, if its last second is flat.
fn rest_level(log: &WeightLog, drain: Option<&DrainLine>) -> Option<f64> {
    let end_s = log.points.last()?.0;
    let tail: Vec<f64> = log
        .points
        .iter()
        .filter(|p| p.0 >= end_s - REST_TAIL_S)
        .map(|p| p.1)
        .collect();
    let fall = log.volume_at(end_s - REST_TAIL_S) - log.points.last()?.1;
    let allowed = drain.map_or(FLAT_ML, |d| (FLAT_SHARE * d.rate_ml_per_s()).max(FLAT_ML));
    (tail.len() >= 2 && fall.abs() <= allowed).then(|| median(&tail).max(0.0))
}

/// The intervals between consecutive units of `recording`, those that tell a pocket.
fn intervals(recording: &RecordingFit) -> Vec<f64> {
    let all: Vec<f64> = recording
        .units
        .windows(2)
        .map(|pair| pair[1].fit.onset_s - pair[0].fit.onset_s)
        .collect();
    let typical = median(&all);
    all.into_iter()
        .filter(|&dt| dt < LONG_INTERVAL * typical && dt > SHORT_INTERVAL * typical)
        .collect()
}

/// The pockets b_i = k·Δt_i of the recordings with a weight log: (median, every b_i).
fn pocket_of(recordings: &[RecordingFit], members: &[usize]) -> Option<(f64, Vec<f64>)> {
    let pockets: Vec<f64> = members
        .iter()
        .map(|&i| &recordings[i])
        .filter_map(|r| Some((r.drain?.rate_ml_per_s(), intervals(r))))
        .flat_map(|(rate, intervals)| intervals.into_iter().map(move |dt| rate * dt))
        .collect();
    (!pockets.is_empty()).then(|| (median(&pockets), pockets))
}

/// A recording without a weight log drains at pocket / median interval from its start volume,
/// pouring from a pocket's time before its first unit. Units that count past an empty bottle
/// (the recording is not the pour its session says) are given no volume, and that is warned.
fn complete_without_weight(
    recording: &mut RecordingFit,
    pocket_ml: f64,
    warnings: &mut Vec<String>,
) {
    if recording.weight.is_some() || recording.units.len() < 3 {
        return;
    }
    let Some(start_ml) = recording.spec.start_ml else {
        return;
    };
    let rate = pocket_ml / median(&intervals(recording));
    if !(rate.is_finite() && rate > 0.0) {
        return;
    }
    let poured_from = recording.units[0].fit.onset_s - pocket_ml / rate;
    let line = Line {
        slope: -rate,
        intercept: start_ml + rate * poured_from,
        r_squared: f64::NAN,
        slope_error: f64::NAN,
    };
    let mut past_empty = 0;
    for unit in &mut recording.units {
        let volume_ml = line.at(unit.fit.onset_s);
        unit.volume_ml = if volume_ml >= 0.0 {
            volume_ml
        } else {
            past_empty += 1;
            f64::NAN
        };
    }
    if past_empty > 0 {
        warnings.push(format!(
            "`{}`: its {} units, a {pocket_ml} ml pocket each, pour {:.0} ml, more than its \
             start_ml = {start_ml} ml; the {past_empty} counted past an empty bottle have no \
             volume (a weight log would give the pocket)",
            recording.spec.key,
            recording.units.len(),
            recording.units.len() as f64 * pocket_ml,
        ));
    }
    let span_s = (
        recording.units[0].fit.onset_s,
        recording.units[recording.units.len() - 1].fit.onset_s,
    );
    recording.drain = Some(DrainLine {
        line,
        from_weight: false,
        span_s,
    });
}

/// Each tilt's outflow rate: (tilt, mean k over its recordings), tilts ascending.
fn tilt_rates(recordings: &[RecordingFit], members: &[usize]) -> Vec<(f64, f64)> {
    let mut groups: Vec<(f64, Vec<f64>)> = Vec::new();
    for &i in members {
        let recording = &recordings[i];
        let Some(drain) = recording.drain else {
            continue;
        };
        let tilt = recording.spec.tilt_deg;
        match groups
            .iter_mut()
            .find(|g| (g.0 - tilt).abs() < SAME_TILT_DEG)
        {
            Some(group) => group.1.push(drain.rate_ml_per_s()),
            None => groups.push((tilt, vec![drain.rate_ml_per_s()])),
        }
    }
    let mut rates: Vec<(f64, f64)> = groups
        .into_iter()
        .map(|(tilt, ks)| (tilt, ks.iter().sum::<f64>() / ks.len() as f64))
        .collect();
    rates.sort_by(|a, b| a.0.total_cmp(&b.0));
    rates
}

/// The rate at 135° from measured `rates`: measured there, else linear between the tilts around
/// it, else the nearest tilt's through the default h.
fn rate_at_reference(
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
fn fit_curves(
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
        warnings.push(format!(
            "`{key}` needs recordings at several tilts ({tilts} measured): kept at its default"
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

/// The unit-based estimates of a liquid, in [`UNIT_KEYS`] order (NaN where unknown).
fn unit_estimates(units: &[FittedUnit], capacity_ml: f64) -> Vec<f64> {
    let of = |get: &dyn Fn(&UnitFit) -> f64| units.iter().map(|u| get(&u.fit)).collect::<Vec<_>>();
    let f = [of(&|u| u.frequency_hz[0]), of(&|u| u.frequency_hz[1])];
    let b = [of(&|u| u.decay_per_s[0]), of(&|u| u.decay_per_s[1])];
    let spread = |values: &[f64]| iqr(values) / median(values);
    let log_sigma =
        |values: &[f64]| iqr(&values.iter().map(|v| v.ln()).collect::<Vec<_>>()) / NORMAL_IQR;
    let law = amplitude_law(units);
    let (silent_below, gain_db, amplitude_spread, r_squared) = match law {
        Some(line) if line.slope > 0.0 => {
            let residuals: Vec<f64> = units
                .iter()
                .filter(|u| u.volume_ml.is_finite() && line.at(u.volume_ml) > 0.0)
                .map(|u| (u.fit.amplitude_sum() / line.at(u.volume_ml)).ln())
                .collect();
            (
                -line.intercept / line.slope,
                20.0 * line.at(capacity_ml).log10(),
                iqr(&residuals) / NORMAL_IQR,
                line.r_squared,
            )
        }
        _ => (f64::NAN, f64::NAN, f64::NAN, f64::NAN),
    };
    vec![
        median(&f[0]),
        median(&f[1]),
        // j_f: f(1 + j·u), u uniform in [−1, 1], has its quartiles at f(1 ± j/2).
        0.5 * (spread(&f[0]) + spread(&f[1])),
        median(&b[0]),
        median(&b[1]),
        0.5 * (log_sigma(&b[0]) + log_sigma(&b[1])),
        median(&of(&UnitFit::viscosity)),
        silent_below,
        amplitude_spread,
        gain_db,
        r_squared,
    ]
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

/// What [`unit_estimates`] gives, in order: a model's scene key or a name.
fn unit_keys() -> [(String, bool); 11] {
    let key = |constant: Constant| (constant.quantity().scene_key.to_owned(), true);
    [
        key(Constant::F1),
        key(Constant::F2),
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

#[allow(clippy::too_many_arguments)]
fn fit_liquid(
    liquid: &str,
    recordings: &[&RecordingFit],
    capacity_ml: f64,
    curves: &FittedCurves,
    rate_at_135: Option<f64>,
    rates: &[(f64, f64)],
    warnings: &mut Vec<String>,
) -> LiquidFit {
    let units: Vec<FittedUnit> = recordings
        .iter()
        .flat_map(|r| r.units.iter().copied())
        .collect();
    let values = unit_estimates(&units, capacity_ml);
    let intervals = bootstrap(&units, |sample| unit_estimates(sample, capacity_ml));
    let mut estimates: Vec<Estimate> = unit_keys()
        .into_iter()
        .zip(values.iter().zip(intervals))
        .map(|((key, in_model), (&value, interval))| Estimate {
            key,
            value,
            interval: Some(interval),
            in_model,
        })
        .collect();
    // The pocket and its spread, from the intervals.
    let with_weight: Vec<&RecordingFit> = recordings
        .iter()
        .copied()
        .filter(|r| r.drain.is_some_and(|d| d.from_weight))
        .collect();
    let pockets: Vec<f64> = with_weight
        .iter()
        .flat_map(|r| {
            let rate = r.drain.map_or(0.0, |d| d.rate_ml_per_s());
            intervals_of(r).into_iter().map(move |dt| rate * dt)
        })
        .collect();
    let relative_intervals: Vec<f64> = recordings
        .iter()
        .flat_map(|r| {
            let all = intervals_of(r);
            let typical = median(&all);
            all.into_iter().map(move |dt| dt / typical)
        })
        .collect();
    if !pockets.is_empty() {
        let interval = bootstrap(&pockets, |s| vec![median(s)])[0];
        estimates.push(Estimate {
            key: Constant::Pocket.quantity().scene_key.to_owned(),
            value: median(&pockets),
            interval: Some(interval),
            in_model: true,
        });
    }
    if relative_intervals.len() >= 3 {
        // j_t: b(1 + j·u) has its quartiles at b(1 ± j/2).
        let interval = bootstrap(&relative_intervals, |s| vec![iqr(s) / median(s)])[0];
        estimates.push(Estimate {
            key: Constant::TimingJitter.quantity().scene_key.to_owned(),
            value: iqr(&relative_intervals) / median(&relative_intervals),
            interval: Some(interval),
            in_model: true,
        });
    }
    if let Some(rate) = rate_at_135 {
        let interval = reference_interval(recordings, rate);
        estimates.push(Estimate {
            key: Control::PourTime.quantity().scene_key.to_owned(),
            value: capacity_ml / rate,
            interval: interval.map(|(low, high)| (capacity_ml / high, capacity_ml / low)),
            in_model: true,
        });
    }
    for &(tilt, rate) in rates {
        let errors: Vec<f64> = recordings
            .iter()
            .filter(|r| (r.spec.tilt_deg - tilt).abs() < SAME_TILT_DEG)
            .filter_map(|r| r.drain.map(|d| d.line.slope_error))
            .filter(|e| e.is_finite())
            .collect();
        let error = (!errors.is_empty())
            .then(|| errors.iter().map(|e| e * e).sum::<f64>().sqrt() / errors.len() as f64);
        estimates.push(Estimate {
            key: format!("outflow rate at {tilt}° (ml/s)"),
            value: rate,
            interval: error.map(|e| (rate - Z_95 * e, rate + Z_95 * e)),
            in_model: false,
        });
    }
    estimates.push(Estimate {
        key: Constant::Capacity.quantity().scene_key.to_owned(),
        value: capacity_ml,
        interval: None,
        in_model: true,
    });
    let mut kept_default = Vec::new();
    let silent_key = Constant::SilentBelow.quantity().scene_key;
    let law = amplitude_law(&units);
    if let Some(estimate) = estimates
        .iter_mut()
        .find(|e| e.key == silent_key && e.in_model)
    {
        // A line whose slope its own error cannot tell from 0 has no zero worth a number.
        let flat = law.filter(|line| line.slope <= Z_95 * line.slope_error);
        if let Some(line) = flat {
            kept_default.push((
                silent_key.to_owned(),
                format!(
                    "Asum does not fall measurably with V (slope {:.3e} ± {:.3e} per ml)",
                    line.slope,
                    Z_95 * line.slope_error
                ),
            ));
            estimate.in_model = false;
        } else if estimate.value >= capacity_ml {
            kept_default.push((
                silent_key.to_owned(),
                "the fitted zero lies above the capacity".into(),
            ));
            estimate.in_model = false;
        }
    }
    for estimate in &mut estimates {
        if !estimate.in_model {
            continue;
        }
        let range = range_of(&estimate.key);
        if !estimate.value.is_finite() {
            kept_default.push((estimate.key.clone(), "could not be estimated".to_owned()));
            estimate.in_model = false;
        } else if let Some(range) = range.filter(|r| !r.contains(estimate.value)) {
            warnings.push(format!(
                "liquid `{liquid}`: `{}` = {} lies outside {}…{}: brought into range",
                estimate.key, estimate.value, range.min, range.max
            ));
            estimate.value = range.sanitize(estimate.value);
        }
    }
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
        if !estimates.iter().any(|e| e.key == key) {
            kept_default.push((key.to_owned(), why.to_owned()));
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
                    "the last glug shows where the mouth surfaces only above the \
                                     silent volume; not estimated"
                }
                _ => "needs several tilts",
            };
            kept_default.push((curve.scene_key().to_owned(), why.to_owned()));
        }
    }
    let model_toml = model_toml(liquid, &estimates, curves, &kept_default);
    LiquidFit {
        liquid: liquid.to_owned(),
        units: units.len(),
        estimates,
        kept_default,
        model_toml,
        amplitude_law: law,
    }
}

fn intervals_of(recording: &RecordingFit) -> Vec<f64> {
    intervals(recording)
}

/// The 95 % interval of the rate at 135° from the recordings there (their lines' errors).
fn reference_interval(recordings: &[&RecordingFit], rate: f64) -> Option<(f64, f64)> {
    let errors: Vec<f64> = recordings
        .iter()
        .filter(|r| (r.spec.tilt_deg - REFERENCE_TILT_DEG).abs() < SAME_TILT_DEG)
        .filter_map(|r| r.drain.map(|d| d.line.slope_error))
        .filter(|e| e.is_finite())
        .collect();
    if errors.is_empty() {
        return None;
    }
    let error = errors.iter().map(|e| e * e).sum::<f64>().sqrt() / errors.len() as f64;
    Some((rate - Z_95 * error, rate + Z_95 * error))
}

/// The range of the constant or control whose scene key is `key`.
fn range_of(key: &str) -> Option<Range> {
    Constant::ALL
        .iter()
        .map(|c| c.quantity())
        .chain(Control::ALL.iter().map(|c| c.quantity()))
        .find(|q| q.scene_key == key)
        .map(|q| q.range)
}

/// Six significant digits: what a model file needs, and readable.
fn round(value: f64) -> f64 {
    format!("{value:.5e}").parse().unwrap_or(value)
}

/// The model of one liquid: every key estimated, each at the scene key its table declares, and
/// the bottle held at the reference tilt (one number, as a model file's controls are: MODEL.md
/// §12.1), so that `sake-glug render MODEL.toml` pours it as it is and `--model` takes it.
fn model_toml(
    liquid: &str,
    estimates: &[Estimate],
    curves: &FittedCurves,
    kept_default: &[(String, String)],
) -> String {
    let mut table = toml::Table::new();
    table.insert(
        Control::Tilt.quantity().scene_key.to_owned(),
        toml::Value::Float(REFERENCE_TILT_DEG),
    );
    let mut set = |key: &str, value: toml::Value| match key.split_once('.') {
        Some((section, name)) => {
            table
                .entry(section)
                .or_insert_with(|| toml::Value::Table(toml::Table::new()))
                .as_table_mut()
                .expect("a section is a table")
                .insert(name.to_owned(), value);
        }
        None => {
            table.insert(key.to_owned(), value);
        }
    };
    for estimate in estimates.iter().filter(|e| e.in_model) {
        set(&estimate.key, toml::Value::Float(round(estimate.value)));
    }
    for (curve, points) in [(Curve::Drain, &curves.drain), (Curve::Rest, &curves.rest)] {
        if let Some(points) = points {
            let points = points
                .iter()
                .map(|&(t, v)| {
                    toml::Value::Array(vec![toml::Value::Float(t), toml::Value::Float(v)])
                })
                .collect();
            set(curve.scene_key(), toml::Value::Array(points));
        }
    }
    let mut text = format!(
        "# The model of `{liquid}`, fitted by `sake-glug fit` (MODEL.md §13): a scene file that \
         plays the fitted bottle.\n"
    );
    for (key, why) in kept_default {
        text.push_str(&format!("# `{key}` kept at its default: {why}.\n"));
    }
    text.push_str(&toml::to_string(&table).expect("a table of numbers is valid TOML"));
    text
}
