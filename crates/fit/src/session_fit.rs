//! A whole session fitted (MODEL.md §13): every recording fitted one at a time, each liquid's
//! units put in the bottle's two modes, the volumes completed where no weight log gives them,
//! the shared curves, and each liquid's model.

use std::collections::BTreeMap;

use super::curves::{fit_curves, FittedCurves};
use super::error::FitError;
use super::liquid::{fit_liquid, LiquidFit, LiquidInputs};
use super::pour::{complete_without_weight, pockets, tilt_rates};
use super::recording::{fit_recording, RecordingFit};
use super::session::FitSession;
use super::stats::median;
use super::units::{local_split, Modes};
use sake_glug_engine::Constant;

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
    /// What the user should know: clipping, a recording the model describes poorly, a curve
    /// left at its default.
    pub warnings: Vec<String>,
}

impl SessionFit {
    /// Units detected and used, over every recording.
    pub fn unit_counts(&self) -> (usize, usize) {
        self.recordings.iter().fold((0, 0), |(detected, used), r| {
            (detected + r.detected.len(), used + r.units.len())
        })
    }
}

/// Fits the model of every liquid of `session` (MODEL.md §13).
pub fn fit_session(session: &FitSession) -> Result<SessionFit, FitError> {
    let mut warnings = Vec::new();
    let mut recordings = Vec::with_capacity(session.recordings.len());
    for spec in &session.recordings {
        recordings.push(fit_recording(spec, session.capacity_ml, &mut warnings)?);
    }
    let mut rates: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
    let mut modes: BTreeMap<String, Modes> = BTreeMap::new();
    for liquid in session.liquids() {
        let members: Vec<usize> = (0..recordings.len())
            .filter(|&i| recordings[i].spec.liquid == liquid)
            .collect();
        if members.iter().all(|&i| recordings[i].detected.is_empty()) {
            return Err(FitError::NoGlugs {
                what: format!("the recordings of liquid `{liquid}`"),
            });
        }
        if members.iter().all(|&i| recordings[i].units.is_empty()) {
            return Err(no_unit_described(liquid, &recordings, &members));
        }
        let liquid_modes = assign_modes(&mut recordings, &members);
        modes.insert(liquid.to_owned(), liquid_modes);
        let logged: Vec<&RecordingFit> = members.iter().map(|&i| &recordings[i]).collect();
        let pockets = pockets(&logged);
        if pockets.is_empty() {
            warnings.push(format!(
                "liquid `{liquid}`: no weight log, so the pocket volume stays at its default and \
                 the volumes come from the glug count × that pocket (the model glugs at the \
                 recordings' rate through its pour time)"
            ));
        }
        let pocket_ml = if pockets.is_empty() {
            Constant::Pocket.range().default
        } else {
            median(&pockets)
        };
        for &i in &members {
            complete_without_weight(&mut recordings[i], pocket_ml, &mut warnings);
        }
        let members: Vec<&RecordingFit> = members.iter().map(|&i| &recordings[i]).collect();
        rates.insert(liquid.to_owned(), tilt_rates(&members));
    }
    let (curves, rate_at_135) = fit_curves(session, &recordings, &rates, &mut warnings);
    let mut liquids = Vec::new();
    for liquid in session.liquids() {
        let inputs = LiquidInputs {
            liquid,
            recordings: recordings
                .iter()
                .filter(|r| r.spec.liquid == liquid)
                .collect(),
            capacity_ml: session.capacity_ml,
            curves: &curves,
            rate_at_135: rate_at_135[liquid],
            rates: &rates[liquid],
            modes: modes[liquid],
        };
        liquids.push(fit_liquid(&inputs, &mut warnings)?);
    }
    Ok(SessionFit {
        session: session.clone(),
        recordings,
        liquids,
        curves,
        warnings,
    })
}

/// Puts the components of every unit of `members` in the modes the pitches they are heard at
/// show: the pitch `UnitFit::assign` then puts each in a mode by, where a glide slower than
/// its ring leaves a component's own f a guess (MODEL.md §13, the bottle's two modes).
fn assign_modes(recordings: &mut [RecordingFit], members: &[usize]) -> Modes {
    let pitches: Vec<f64> = members
        .iter()
        .flat_map(|&i| recordings[i].units.iter())
        .flat_map(|u| u.fit.fitted().map(|c| c.heard_hz))
        .collect();
    let modes = Modes::of(&pitches);
    for &i in members {
        let recording = &mut recordings[i];
        for unit in &mut recording.units {
            unit.fit.assign(&modes);
        }
        for detected in &mut recording.detected {
            if let Some(fit) = &mut detected.fit {
                fit.assign(&modes);
            }
        }
        if matches!(modes, Modes::Split(_)) {
            place_lone_modes(recording);
        }
    }
    modes
}

/// Puts the component of each unit of `recording` that rings one mode in the mode its neighbours
/// in time ring there (MODEL.md §13).
fn place_lone_modes(recording: &mut RecordingFit) {
    let both: Vec<(f64, [f64; 2])> = recording
        .units
        .iter()
        .filter(|u| u.fit.amplitude.iter().all(|&a| a > 0.0))
        .map(|u| (u.fit.onset_s, u.fit.frequency_hz))
        .collect();
    let fits = recording
        .units
        .iter_mut()
        .map(|unit| &mut unit.fit)
        .chain(recording.detected.iter_mut().filter_map(|d| d.fit.as_mut()));
    for fit in fits.filter(|fit| fit.rings_one_mode()) {
        if let Some(split) = local_split(fit.onset_s, &both) {
            fit.assign_by_neighbours(&split);
        }
    }
}

/// The error of a liquid none of whose detected units the model describes, with the reasons.
fn no_unit_described(liquid: &str, recordings: &[RecordingFit], members: &[usize]) -> FitError {
    let mut reasons: BTreeMap<String, usize> = BTreeMap::new();
    let mut detected = 0;
    for &i in members {
        for unit in &recordings[i].detected {
            detected += 1;
            if let Some(rejection) = unit.rejection {
                *reasons.entry(rejection.kind().to_owned()).or_default() += 1;
            }
        }
    }
    let reasons = reasons
        .iter()
        .map(|(reason, count)| format!("{count}× {reason}"))
        .collect::<Vec<_>>()
        .join("; ");
    FitError::NoUnitDescribed {
        what: format!("liquid `{liquid}`"),
        detected,
        reasons,
    }
}
