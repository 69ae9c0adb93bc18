//! A model fitted by listening (MODEL.md §13, "Fitted by listening"). Where the units' model does
//! not sound like its recordings (a measure a listener hears lies beyond its tolerance), its
//! constants are fitted again by rendering candidates as each recording was made and minimising
//! how far what a listener hears of them lies from what they hear of the recording: the glug rate,
//! the median glug pitch, the pitch's fall, the share of the energy above 700 Hz and the
//! log-spectral distance ([`super::listen`], [`super::compare`]). Where the units explain at
//! least half of every recording and set some of its constants, their model is kept; elsewhere it
//! is one of the search's starts.

use argmin::core::{CostFunction, Error as ArgminError, Executor};
use argmin::solver::neldermead::NelderMead;

use sake_glug_engine::{Constant, Control};
use sake_glug_io::keys;

use super::compare::{log_spectral_distance, render_table, AsRecorded, ONE_MODE_SPLIT_HZ};
use super::estimate::{range_of, Estimate};
use super::listen::{hear, Heard};
use super::recording::{RecordingFit, LOW_EXPLAINED};
use super::spectrum::Spectrum;
use super::stats::median;

/// The glug rate a listener takes for the same: within 25 %.
pub const RATE_TOLERANCE: f64 = 0.25;
/// The median glug pitch: within 15 %.
pub const PITCH_TOLERANCE: f64 = 0.15;
/// The pitch's fall over the recording's glugs: within 15 %.
pub const FALL_TOLERANCE: f64 = 0.15;
/// The share of the energy above [`ONE_MODE_SPLIT_HZ`]: within 10 points.
pub const BRIGHT_TOLERANCE: f64 = 0.10;
/// A log-spectral distance (dB) below which a model is as near as can be told: the distance
/// misses in units of the default bottle's distance, but never of less than this (a recording
/// of the default bottle itself is no reason to fit again).
pub const NEAR_DISTANCE_DB: f64 = 4.0;
/// The units' model sounds like a recording if its log-spectral distance is no more than this
/// many times the default bottle's (or [`NEAR_DISTANCE_DB`]): a recording of a bottle near the
/// default, under noise, is as far from either, and that is no reason to fit again.
const NO_FARTHER: f64 = 1.05;
/// Each search is run this many times in turn, each from where the last ended.
const SEARCH_ROUNDS: usize = 2;
/// The fewest glugs a recording's pitch fall is listened for over.
const MIN_GLUGS_FOR_FALL: usize = 4;
/// What a measure the recording has and a candidate lacks costs: as far as twice its tolerance.
const MISSING: f64 = 4.0;
/// Nelder–Mead iterations in one search (each renders one to a few candidates).
const MAX_ITERATIONS: u64 = 160;
/// c is matched to the bright share in this many halvings of its span.
const BALANCE_STEPS: usize = 7;
/// The pour time is matched to the heard rate in at most this many steps.
const RATE_STEPS: usize = 4;
/// The pour times searched (s).
const POUR_SPAN_S: (f64, f64) = (0.2, 600.0);

/// What a listener hears of one pour, as the listening fit compares it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Listened {
    /// Glugs a second (NaN with fewer than 2 glugs).
    pub rate_per_s: f64,
    /// The median of the glugs' low pitch (Hz; NaN where none is heard).
    pub pitch_hz: f64,
    /// The first glug's pitch over the last's, over the recording's glugs (NaN where not heard).
    pub fall: f64,
    /// The share of the energy above [`ONE_MODE_SPLIT_HZ`].
    pub bright: f64,
    /// The log-spectral distance from the recording (dB; 0 for the recording itself).
    pub distance_db: f64,
    /// The glugs heard.
    pub glugs: usize,
}

impl Listened {
    /// What a listener hears of `samples`, its pitch fall read over `glugs` glugs, its spectrum
    /// against the recording's `reference`.
    pub fn of(samples: &[f32], sample_rate: f64, glugs: usize, reference: &Spectrum) -> Self {
        let heard = hear(samples, sample_rate, ONE_MODE_SPLIT_HZ);
        let spectrum = Spectrum::of(samples, sample_rate);
        Self::from_heard(
            &heard,
            glugs,
            log_spectral_distance(reference, &spectrum, sample_rate),
        )
    }

    fn from_heard(heard: &Heard, glugs: usize, distance_db: f64) -> Self {
        let pitches: Vec<f64> = heard
            .pitch_hz
            .iter()
            .copied()
            .filter(|p| p.is_finite())
            .collect();
        Self {
            rate_per_s: heard.rate_per_s,
            pitch_hz: if pitches.is_empty() {
                f64::NAN
            } else {
                median(&pitches)
            },
            fall: if glugs >= MIN_GLUGS_FOR_FALL {
                heard.fall_over(glugs)
            } else {
                f64::NAN
            },
            bright: heard.high_share,
            distance_db,
            glugs: heard.onsets_s.len(),
        }
    }

    /// As a candidate is judged: with fewer than 2 glugs heard in `duration_s`, a rate of half a
    /// glug over it, so that a search that went too slow is led back rather than lost on a flat.
    fn as_candidate(mut self, duration_s: f64) -> Self {
        if !self.rate_per_s.is_finite() && duration_s > 0.0 {
            self.rate_per_s = 0.5 / duration_s;
        }
        self
    }
}

/// How far each measure of `candidate` lies from the recording's, in tolerances (squared): the
/// rate, the pitch, the fall, the bright share, and the distance over the default bottle's.
pub fn misses(recording: &Listened, candidate: &Listened, default_distance_db: f64) -> [f64; 5] {
    let ratio = |ours: f64, theirs: f64, tolerance: f64| {
        if !theirs.is_finite() {
            0.0
        } else if !ours.is_finite() || ours <= 0.0 {
            MISSING
        } else {
            ((ours / theirs).ln() / (1.0 + tolerance).ln()).powi(2)
        }
    };
    let difference = |ours: f64, theirs: f64, tolerance: f64| {
        if !theirs.is_finite() {
            0.0
        } else if !ours.is_finite() {
            MISSING
        } else {
            ((ours - theirs) / tolerance).powi(2)
        }
    };
    [
        ratio(candidate.rate_per_s, recording.rate_per_s, RATE_TOLERANCE),
        ratio(candidate.pitch_hz, recording.pitch_hz, PITCH_TOLERANCE),
        // A real recording's glug-by-glug pitch is noisy: its fall counts, but never for more
        // than a miss at its tolerance.
        ratio(candidate.fall, recording.fall, FALL_TOLERANCE).min(1.0),
        difference(candidate.bright, recording.bright, BRIGHT_TOLERANCE),
        if candidate.distance_db.is_finite() {
            (candidate.distance_db / default_distance_db.max(NEAR_DISTANCE_DB)).powi(2)
        } else {
            MISSING
        },
    ]
}

/// A measure on which a listener is asked whether a model sounds nearer a recording than the
/// default bottle: the rate, the pitch, the bright share and the spectral distance, as
/// docs/fit.md's tables report them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Measure {
    /// The glug rate, within [`RATE_TOLERANCE`].
    Rate,
    /// The median glug pitch, within [`PITCH_TOLERANCE`].
    Pitch,
    /// The share of the energy above [`ONE_MODE_SPLIT_HZ`], within [`BRIGHT_TOLERANCE`].
    Bright,
    /// The log-spectral distance, below the default bottle's.
    Distance,
}

impl Measure {
    /// Its name, as the tables give it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Rate => "rate",
            Self::Pitch => "pitch",
            Self::Bright => "bright share",
            Self::Distance => "spectral distance",
        }
    }
}

/// The measures on which `model` is not nearer `recording` than `default` is, each heard of the
/// recording as it is (its noise in it) and of the renders as they are: the judge of whether a
/// fit's model is written (MODEL.md §13, *Kept*), and of docs/fit.md's tables. Empty: nearer on
/// every one.
pub fn not_nearer(recording: &Listened, model: &Listened, default: &Listened) -> Vec<Measure> {
    let within = |ours: f64, theirs: f64, tolerance: f64| {
        !theirs.is_finite() || (ours / theirs - 1.0).abs() <= tolerance
    };
    let mut missed = Vec::new();
    if !within(model.rate_per_s, recording.rate_per_s, RATE_TOLERANCE) {
        missed.push(Measure::Rate);
    }
    if !within(model.pitch_hz, recording.pitch_hz, PITCH_TOLERANCE) {
        missed.push(Measure::Pitch);
    }
    if model.bright.is_nan() || (model.bright - recording.bright).abs() > BRIGHT_TOLERANCE {
        missed.push(Measure::Bright);
    }
    if model.distance_db.partial_cmp(&default.distance_db) != Some(std::cmp::Ordering::Less) {
        missed.push(Measure::Distance);
    }
    missed
}

/// How a constant is searched: its scale and the widest span tried.
#[derive(Debug, Clone, Copy)]
enum Scale {
    /// ln of the value.
    Log,
    /// The logit of a share.
    Share,
}

/// One constant the listening fit sets.
#[derive(Debug, Clone, Copy)]
struct Knob {
    /// Its model key.
    key: &'static str,
    scale: Scale,
    /// The widest span searched (the recording's Nyquist limit bounds a frequency further).
    span: (f64, f64),
    /// A frequency (bounded by the recording's rate).
    frequency: bool,
    /// Which of the bottle's modes it belongs to (None: the pour, not a mode).
    mode: Option<usize>,
}

impl Knob {
    fn search_at(self, value: f64) -> f64 {
        match self.scale {
            Scale::Log => value.ln(),
            Scale::Share => {
                let share = value.clamp(1e-3, 1.0 - 1e-3);
                (share / (1.0 - share)).ln()
            }
        }
    }

    fn value_at(self, x: f64) -> f64 {
        match self.scale {
            Scale::Log => x.exp(),
            Scale::Share => 1.0 / (1.0 + (-x).exp()),
        }
    }
}

/// The constants the listening fit sets, and the widest span each is searched over.
fn knobs() -> [Knob; 6] {
    let constant = |c: Constant| c.quantity().scene_key;
    [
        Knob {
            key: constant(Constant::F1),
            scale: Scale::Log,
            span: (30.0, 4000.0),
            frequency: true,
            mode: Some(0),
        },
        Knob {
            key: constant(Constant::F2),
            scale: Scale::Log,
            span: (30.0, 4000.0),
            frequency: true,
            mode: Some(1),
        },
        Knob {
            key: constant(Constant::B1),
            scale: Scale::Log,
            span: (3.0, 2000.0),
            frequency: false,
            mode: Some(0),
        },
        Knob {
            key: constant(Constant::B2),
            scale: Scale::Log,
            span: (3.0, 2000.0),
            frequency: false,
            mode: Some(1),
        },
        Knob {
            key: Control::Viscosity.quantity().scene_key,
            scale: Scale::Share,
            span: (0.01, 0.99),
            frequency: false,
            mode: None,
        },
        Knob {
            key: constant(Constant::FreqJitter),
            scale: Scale::Share,
            span: (0.002, 0.5),
            frequency: false,
            mode: None,
        },
    ]
}

/// One recording as the listening fit hears it.
struct Target {
    /// The recording's name, as its error messages give it.
    name: String,
    made: AsRecorded,
    /// Its glugs (the pitch fall is read over as many).
    glugs: usize,
    /// Its spectrum with its noise out, which the searches match.
    spectrum: Spectrum,
    /// What is heard of it with its noise out (the bright share), which the searches match.
    listened: Listened,
    /// The default bottle's log-spectral distance from [`Target::spectrum`] (dB).
    default_distance_db: f64,
    /// Its spectrum as it is, which a listener hears.
    as_is_spectrum: Spectrum,
    /// What is heard of it as it is, by which a model is judged nearer than the default.
    as_is: Listened,
    /// What is heard of the default bottle rendered as it was made, against it as it is.
    default_as_is: Listened,
}

/// The search: candidates rendered and listened to.
#[derive(Clone, Copy)]
struct Search<'a> {
    base: &'a toml::Table,
    knobs: &'a [Knob],
    bounds: &'a [(f64, f64)],
    targets: &'a [Target],
}

impl Search<'_> {
    /// The model file of the point `x` of the search space (brought within its bounds).
    fn model(&self, x: &[f64]) -> toml::Table {
        let mut table = self.base.clone();
        for ((knob, &(low, high)), &xi) in self.knobs.iter().zip(self.bounds).zip(x) {
            let value = knob.value_at(xi.clamp(low, high));
            keys::insert(&mut table, knob.key, toml::Value::Float(value));
        }
        table
    }

    /// The summed misses of the model `table` over every recording (None: it does not render).
    fn cost_of(&self, table: &toml::Table) -> Option<f64> {
        let mut total = 0.0;
        for target in self.targets {
            let listened = listened_in(table, target)?.as_candidate(target.made.duration_s);
            total += misses(&target.listened, &listened, target.default_distance_db)
                .iter()
                .sum::<f64>();
        }
        Some(total)
    }

    /// How far `x` lies outside its bounds (in the search space's units).
    fn outside(&self, x: &[f64]) -> f64 {
        x.iter()
            .zip(self.bounds)
            .map(|(&xi, &(low, high))| (low - xi).max(0.0) + (xi - high).max(0.0))
            .sum()
    }
}

impl CostFunction for Search<'_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, x: &Self::Param) -> Result<Self::Output, ArgminError> {
        // A point beyond the bounds costs what its nearest point within costs, and more the
        // further out it lies, so the simplex comes back.
        let outside = self.outside(x);
        let cost = self.cost_of(&self.model(x)).unwrap_or(1e6);
        Ok(cost + 100.0 * outside * outside)
    }
}

/// `table` (a model file) rendered as a recording was made; None if the renderer refuses it.
fn render_as_recorded(table: &toml::Table, made: &AsRecorded) -> Option<Vec<f32>> {
    render_table(table.clone(), made).ok()
}

/// Whether the units' `estimates` set any constant the listening fit fits: where they set none
/// (too few units for any), their model is the default bottle.
pub(crate) fn units_set_some(estimates: &[Estimate]) -> bool {
    knobs().iter().any(|knob| {
        estimates
            .iter()
            .any(|e| e.key == knob.key && e.in_model && e.value.is_finite())
    })
}

/// What listening came to for one liquid.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ByEar {
    /// The units' model stands: it sounds like every recording, the units explain enough of
    /// them, or too little of them is heard to judge it by.
    UnitsKept,
    /// Constants fitted by listening, the model they make nearer than the default bottle on every
    /// measure.
    Fitted(ListeningFit),
    /// Neither the units' model nor any the searches ended at sounds nearer the recordings than
    /// the default bottle on every measure: what the nearest of them missed, recording by
    /// recording.
    NoModelNearer { missed: String },
}

/// What the listening fit did for one liquid.
#[derive(Debug, Clone, PartialEq)]
pub struct ListeningFit {
    /// The summed misses of the units' model, and of the model kept.
    pub cost: [f64; 2],
    /// The keys it set.
    pub set: Vec<String>,
}

/// Fits the constants of [`knobs`] by listening, where the units' model (`model_toml`, with its
/// `estimates`) does not sound like `recordings`: the estimates it sets are marked as its own.
pub(crate) fn fit_by_listening(
    model_toml: &str,
    estimates: &mut Vec<Estimate>,
    recordings: &[&RecordingFit],
    capacity_ml: f64,
) -> ByEar {
    // Where the units explain at least half of every recording, the model is theirs: the
    // listening fit is for the recordings the paper's units describe poorly. Unless the units
    // set none of the constants it fits (too few units for any): their model is then the default
    // bottle, which describes no recording.
    if units_set_some(estimates) && recordings.iter().all(|r| r.explained >= LOW_EXPLAINED) {
        return ByEar::UnitsKept;
    }
    let (Ok(base), Some(targets)) = (
        toml::from_str::<toml::Table>(model_toml),
        targets_of(recordings, capacity_ml),
    ) else {
        return ByEar::UnitsKept;
    };
    if targets.iter().all(|t| t.glugs < 2) {
        return ByEar::UnitsKept;
    }
    fit_to_targets(&base, estimates, &targets)
}

/// [`fit_by_listening`] once the recordings are heard (`targets`) and the units' model (`base`)
/// is parsed.
fn fit_to_targets(base: &toml::Table, estimates: &mut Vec<Estimate>, targets: &[Target]) -> ByEar {
    let knobs = knobs();
    let units_value = |key: &str| value_in(base, key).unwrap_or_else(|| default_of(key));
    let bounds = search_bounds(&knobs, targets);
    let search = Search {
        base,
        knobs: &knobs,
        bounds: &bounds,
        targets,
    };
    if sounds_like_every_recording(base, targets) {
        return ByEar::UnitsKept;
    }
    let Some(units_cost) = search.cost_of(base) else {
        return ByEar::NoModelNearer {
            missed: "the units' model does not render".to_owned(),
        };
    };
    let starts = starting_points(&knobs, &bounds, targets, &units_value);
    let pour_key = Control::PourTime.quantity().scene_key;
    let units_pour_s = units_value(pour_key);
    // The units' model missed at least one measure on some recording (above), so a search's end
    // that a listener takes for nearer on every one is kept whatever its cost; where none is but
    // the units' model is (its misses above are heard with the noise out), it stands; where
    // neither is, no model of these recordings was found, and writing the nearest would be a
    // made-up result.
    let best = best_of_searches(&search, starts, units_pour_s);
    let Some((true, pour_s, x, cost)) = best else {
        if nearer_than_the_default(base, targets) {
            return ByEar::UnitsKept;
        }
        let nearest = match &best {
            Some((_, pour_s, x, cost)) if *cost < units_cost => {
                let mut end = search.model(x);
                keys::insert(&mut end, pour_key, toml::Value::Float(*pour_s));
                end
            }
            _ => base.clone(),
        };
        return ByEar::NoModelNearer {
            missed: what_it_misses(&nearest, targets),
        };
    };
    let mut set = Vec::new();
    for ((knob, &(low, high)), &xi) in knobs.iter().zip(&bounds).zip(&x) {
        let note = "fitted by listening: the units' model did not sound like the recordings";
        set_by_listening(
            estimates,
            knob.key,
            knob.value_at(xi.clamp(low, high)),
            note,
        );
        set.push(knob.key.to_owned());
    }
    if (pour_s / units_pour_s - 1.0).abs() > 0.01 {
        let note = "fitted by listening: the pour time that glugs at the recordings' heard rate";
        set_by_listening(estimates, pour_key, pour_s, note);
        set.push(pour_key.to_owned());
    }
    ByEar::Fitted(ListeningFit {
        cost: [units_cost, cost],
        set,
    })
}

/// What a listener hears in each recording, and how far the default bottle, rendered as it was
/// made, lies from it.
fn targets_of(recordings: &[&RecordingFit], capacity_ml: f64) -> Option<Vec<Target>> {
    let default: toml::Table = toml::from_str("tilt_deg = 135.0\n").ok()?;
    recordings
        .iter()
        .map(|recording| {
            let made = AsRecorded::of(recording, capacity_ml);
            let fs = f64::from(made.sample_rate);
            let length = ((made.duration_s * fs) as usize).min(recording.excerpt.len());
            let samples = &recording.excerpt[..length];
            // The glugs are heard without the recording's noise, which no model plays: a noisy
            // clip's hiss would otherwise be matched by a brighter, shorter bottle.
            let spectrum = Spectrum::of(samples, fs).less(&Spectrum::noise_of(samples, fs));
            let heard = hear(samples, fs, ONE_MODE_SPLIT_HZ);
            let glugs = heard.onsets_s.len();
            let listened = Listened {
                bright: spectrum.share_above(ONE_MODE_SPLIT_HZ),
                ..Listened::from_heard(&heard, glugs, 0.0)
            };
            let default_render = render_as_recorded(&default, &made)?;
            let default_distance_db =
                log_spectral_distance(&spectrum, &Spectrum::of(&default_render, fs), fs);
            // As docs/fit.md hears them: the recording's excerpt and its spectrum as they are.
            let as_is = Listened::of(samples, fs, 0, &recording.spectrum);
            let default_as_is = Listened::of(&default_render, fs, glugs, &recording.spectrum);
            Some(Target {
                // The file's name alone, so that the message reads alike wherever the file lies.
                name: recording
                    .spec
                    .audio
                    .file_name()
                    .map_or_else(|| recording.name(), |n| n.to_string_lossy().into_owned()),
                made,
                glugs,
                spectrum,
                listened,
                default_distance_db,
                as_is_spectrum: recording.spectrum.clone(),
                as_is,
                default_as_is,
            })
        })
        .collect()
}

/// The value of scene key `key` in `table`, if it is set there.
fn value_in(table: &toml::Table, key: &str) -> Option<f64> {
    let (section, name) = keys::split(key);
    let holder = match section {
        Some(section) => table.get(section)?.as_table()?,
        None => table,
    };
    let value = holder.get(name)?;
    value.as_float().or(value.as_integer().map(|i| i as f64))
}

/// Each constant's bounds (in the search space): its widest span, narrowed to what the
/// recordings can hold.
fn search_bounds(knobs: &[Knob], targets: &[Target]) -> Vec<(f64, f64)> {
    let nyquist = targets
        .iter()
        .map(|t| 0.45 * f64::from(t.made.sample_rate))
        .fold(f64::INFINITY, f64::min);
    let bright_heard = targets
        .iter()
        .any(|t| t.listened.bright >= BRIGHT_TOLERANCE);
    knobs
        .iter()
        .map(|knob| {
            let (mut low, mut high) = knob.span;
            if knob.frequency {
                high = high.min(nyquist);
            }
            // The glugs' pitch is heard below the split, so f1 stays there; where a tenth of a
            // recording's energy or more lies above it, only a mode above it can play that share.
            if knob.mode == Some(0) {
                high = high.min(ONE_MODE_SPLIT_HZ);
            } else if knob.mode == Some(1) && knob.frequency && bright_heard {
                low = low.max(ONE_MODE_SPLIT_HZ);
            }
            let (low, high) = if low < high { (low, high) } else { (high, low) };
            (knob.search_at(low), knob.search_at(high))
        })
        .collect()
}

/// Whether `model`, rendered as each recording was made, passes on the four measures a listener
/// is asked about, heard as the searches hear them (the recordings' noise out; the fall is the
/// headspace law's, which the units give and the search leaves alone), its distance at most
/// [`NO_FARTHER`] times the default bottle's (or [`NEAR_DISTANCE_DB`]): so near that the searches
/// are not run.
fn sounds_like_every_recording(model: &toml::Table, targets: &[Target]) -> bool {
    targets.iter().all(|target| {
        heard_in(model, target).is_some_and(|(_, misses)| {
            let [rate, pitch, _, bright, distance] = misses;
            [rate, pitch, bright].iter().all(|&m| m < 1.0) && distance < NO_FARTHER * NO_FARTHER
        })
    })
}

/// Whether `model`, rendered as each recording was made, is nearer every recording than the
/// default bottle on every measure, as [`not_nearer`] judges it.
fn nearer_than_the_default(model: &toml::Table, targets: &[Target]) -> bool {
    targets
        .iter()
        .all(|target| judged_in(model, target).is_some_and(|(_, missed)| missed.is_empty()))
}

/// What a listener hears of `model` rendered as `target` was made, against the recording as it
/// is, and the measures on which it is not nearer than the default bottle; None if it does not
/// render.
fn judged_in(model: &toml::Table, target: &Target) -> Option<(Listened, Vec<Measure>)> {
    let samples = render_as_recorded(model, &target.made)?;
    let heard = Listened::of(
        &samples,
        f64::from(target.made.sample_rate),
        target.glugs,
        &target.as_is_spectrum,
    );
    let missed = not_nearer(&target.as_is, &heard, &target.default_as_is);
    Some((heard, missed))
}

/// What a listener hears of `model` rendered as `target` was made; None if it does not render.
fn listened_in(model: &toml::Table, target: &Target) -> Option<Listened> {
    let samples = render_as_recorded(model, &target.made)?;
    Some(Listened::of(
        &samples,
        f64::from(target.made.sample_rate),
        target.glugs,
        &target.spectrum,
    ))
}

/// [`listened_in`], and its misses from `target`.
fn heard_in(model: &toml::Table, target: &Target) -> Option<(Listened, [f64; 5])> {
    let listened = listened_in(model, target)?;
    let misses = misses(&target.listened, &listened, target.default_distance_db);
    Some((listened, misses))
}

/// The measures on which `model` is not nearer `targets` than the default bottle, recording by
/// recording, with what was heard of each (as [`nearer_than_the_default`] judges them).
fn what_it_misses(model: &toml::Table, targets: &[Target]) -> String {
    let mut said = Vec::new();
    for target in targets {
        let Some((heard, missed)) = judged_in(model, target) else {
            said.push(format!("{}: the model does not render", target.name));
            continue;
        };
        let (wanted, default) = (&target.as_is, &target.default_as_is);
        let missed: Vec<String> = missed
            .iter()
            .map(|measure| match measure {
                Measure::Rate => format!(
                    "{:.3} glugs a second for its {:.3}",
                    heard.rate_per_s, wanted.rate_per_s
                ),
                Measure::Pitch => format!(
                    "a median pitch of {:.0} Hz for its {:.0}",
                    heard.pitch_hz, wanted.pitch_hz
                ),
                Measure::Bright => format!(
                    "{:.0} % of the energy above {ONE_MODE_SPLIT_HZ} Hz for its {:.0} %",
                    100.0 * heard.bright,
                    100.0 * wanted.bright
                ),
                Measure::Distance => format!(
                    "a spectral distance of {:.2} dB against the default bottle's {:.2}",
                    heard.distance_db, default.distance_db
                ),
            })
            .collect();
        if !missed.is_empty() {
            said.push(format!("{}: {}", target.name, missed.join(", ")));
        }
    }
    said.join("; ")
}

/// The best of the searches from `starts`: (whether a listener takes it for nearer than the
/// default bottle on every measure, its pour time, its point, its cost). An end that is nearer
/// beats one that is not, whatever their costs (the cost weighs the measures against each other;
/// a listener asks each in turn).
fn best_of_searches(
    search: &Search,
    starts: Vec<Vec<f64>>,
    units_pour_s: f64,
) -> Option<(bool, f64, Vec<f64>, f64)> {
    let pour_key = Control::PourTime.quantity().scene_key;
    let mut best: Option<(bool, f64, Vec<f64>, f64)> = None;
    for start in starts {
        let (mut x, mut pour_s) = (start, units_pour_s);
        // Each round ends where the next starts, with a fresh simplex (Nelder–Mead's shrunken
        // simplex stalls in a valley; a restart walks on).
        for _ in 0..SEARCH_ROUNDS {
            // Each start glugs at the recordings' rate before the search, and its end again
            // after: the rate is the pour time's alone, and a search that set both would wander
            // off where too few glugs are heard to tell.
            balance(search, &mut x, search.targets);
            pour_s = matched_pour_time(&search.model(&x), pour_s, search.targets);
            let mut start_base = search.base.clone();
            keys::insert(&mut start_base, pour_key, toml::Value::Float(pour_s));
            let here = Search {
                base: &start_base,
                ..*search
            };
            let Some((end_x, _)) = minimise(&here, x.clone()) else {
                break;
            };
            x = end_x;
            balance(&here, &mut x, search.targets);
            pour_s = matched_pour_time(&here.model(&x), pour_s, search.targets);
            let mut end = here.model(&x);
            keys::insert(&mut end, pour_key, toml::Value::Float(pour_s));
            let Some(cost) = search.cost_of(&end) else {
                break;
            };
            let nearer = nearer_than_the_default(&end, search.targets);
            if best
                .as_ref()
                .is_none_or(|&(was_nearer, _, _, c)| (nearer, -cost) > (was_nearer, -c))
            {
                best = Some((nearer, pour_s, x.clone(), cost));
            }
        }
    }
    best
}

/// Marks the estimate of `key` as fitted by listening, at `value` (added if the units gave none).
fn set_by_listening(estimates: &mut Vec<Estimate>, key: &'static str, value: f64, note: &str) {
    match estimates.iter_mut().find(|e| e.key == key) {
        Some(estimate) => estimate.by_listening(value, note.to_owned()),
        None => {
            let mut estimate = Estimate::measured(key, value, None, true);
            estimate.by_listening(value, note.to_owned());
            estimates.push(estimate);
        }
    }
}

/// The default of the constant or control whose scene key is `key` (NaN for none).
fn default_of(key: &str) -> f64 {
    range_of(key).map_or(f64::NAN, |range| range.default)
}

/// Where the searches start (in the search space): the units' model, the default bottle, and the
/// recordings' own spectral peaks and rate.
fn starting_points(
    knobs: &[Knob],
    bounds: &[(f64, f64)],
    targets: &[Target],
    units_value: &dyn Fn(&str) -> f64,
) -> Vec<Vec<f64>> {
    let at = |values: &dyn Fn(&Knob) -> f64| -> Vec<f64> {
        knobs
            .iter()
            .zip(bounds)
            .map(|(knob, &(low, high))| {
                let value = values(knob);
                let x = knob.search_at(if value.is_finite() {
                    value
                } else {
                    units_value(knob.key)
                });
                if x.is_finite() {
                    x.clamp(low, high)
                } else {
                    0.5 * (low + high)
                }
            })
            .collect()
    };
    let units = at(&|knob| units_value(knob.key));
    let defaults = at(&|knob| default_of(knob.key));
    // The recordings' own: the strongest peak below the split and above it, and the share of the
    // energy below it as c.
    let first = &targets[0];
    let (low_peak, high_peak) = strongest_peaks(&first.spectrum, first.made.sample_rate);
    let heard = at(&|knob| match knob.key {
        k if k == Constant::F1.quantity().scene_key => low_peak,
        k if k == Constant::F2.quantity().scene_key => high_peak,
        k if k == Control::Viscosity.quantity().scene_key => 1.0 - first.listened.bright,
        _ => f64::NAN,
    });
    vec![units, heard, defaults]
}

/// The frequencies (Hz) of the strongest bins of `spectrum` below [`ONE_MODE_SPLIT_HZ`] (from
/// 50 Hz) and above it (up to 4 kHz and 45 % of the rate).
fn strongest_peaks(spectrum: &Spectrum, sample_rate: u32) -> (f64, f64) {
    let strongest = |low: f64, high: f64| {
        (0..spectrum.power.len())
            .filter(|&bin| (low..high).contains(&spectrum.hz(bin)))
            .max_by(|&a, &b| spectrum.power[a].total_cmp(&spectrum.power[b]))
            .map_or(f64::NAN, |bin| spectrum.hz(bin))
    };
    (
        strongest(50.0, ONE_MODE_SPLIT_HZ),
        strongest(
            ONE_MODE_SPLIT_HZ,
            4000.0f64.min(0.45 * f64::from(sample_rate)),
        ),
    )
}

/// The pour time (s) at which the model `table` glugs at the recordings' heard rate, from
/// `pour_s`: the pour time scaled by the median ratio of the rate heard in its renders to the
/// recordings', at most [`RATE_STEPS`] times (the rate is the outflow over the pocket, so it scales
/// as 1/T but for glugs a listener hears as one).
fn matched_pour_time(table: &toml::Table, pour_s: f64, targets: &[Target]) -> f64 {
    let key = Control::PourTime.quantity().scene_key;
    // The median ratio of the heard rate to the recordings' at a pour time.
    let ratio_at = |pour_s: f64| {
        let mut table = table.clone();
        keys::insert(&mut table, key, toml::Value::Float(pour_s));
        let ratios: Vec<f64> = targets
            .iter()
            .filter(|t| t.listened.rate_per_s.is_finite())
            .filter_map(|target| {
                let samples = render_as_recorded(&table, &target.made)?;
                let heard = hear(
                    &samples,
                    f64::from(target.made.sample_rate),
                    ONE_MODE_SPLIT_HZ,
                );
                let listened =
                    Listened::from_heard(&heard, 0, 0.0).as_candidate(target.made.duration_s);
                Some(listened.rate_per_s / target.listened.rate_per_s)
            })
            .filter(|r| r.is_finite() && *r > 0.0)
            .collect();
        (!ratios.is_empty()).then(|| median(&ratios))
    };
    let (mut best_s, Some(mut best_ratio)) = (pour_s, ratio_at(pour_s)) else {
        return pour_s;
    };
    for _ in 0..RATE_STEPS {
        if (best_ratio - 1.0).abs() < 0.03 {
            break;
        }
        // The rate goes as 1/T until glugs run together: a step at most halves or doubles T,
        // and is taken only where it brings the rate nearer.
        let next_s = (best_s * best_ratio.clamp(0.5, 2.0)).clamp(POUR_SPAN_S.0, POUR_SPAN_S.1);
        match ratio_at(next_s) {
            Some(ratio) if ratio.ln().abs() < best_ratio.ln().abs() => {
                (best_s, best_ratio) = (next_s, ratio);
            }
            _ => break,
        }
    }
    best_s
}

/// c set at `x` (a point of `search`) so that its renders' share of the energy above the split
/// is the recordings' (the median of their differences, by bisection over c in [`BALANCE_STEPS`]
/// halvings), where one mode lies above the split and the other below: the balance of the two
/// modes is c's alone there, and a search over everything at once loses it on a steep slope.
fn balance(search: &Search, x: &mut [f64], targets: &[Target]) {
    let index = |key: &str| search.knobs.iter().position(|k| k.key == key);
    let (Some(c), Some(f1), Some(f2)) = (
        index(Control::Viscosity.quantity().scene_key),
        index(Constant::F1.quantity().scene_key),
        index(Constant::F2.quantity().scene_key),
    ) else {
        return;
    };
    let hz = |i: usize| search.knobs[i].value_at(x[i]);
    // c is the low mode's share: more c, less above the split where f2 is the bright one.
    let brighter_with_less_c = match (hz(f1) < ONE_MODE_SPLIT_HZ, hz(f2) < ONE_MODE_SPLIT_HZ) {
        (true, false) => true,
        (false, true) => false,
        _ => return,
    };
    let (mut low, mut high) = search.bounds[c];
    for _ in 0..BALANCE_STEPS {
        let middle = 0.5 * (low + high);
        x[c] = middle;
        let table = search.model(x);
        let excess: Vec<f64> = targets
            .iter()
            .filter(|t| t.listened.bright.is_finite())
            .filter_map(|target| {
                let samples = render_as_recorded(&table, &target.made)?;
                let fs = f64::from(target.made.sample_rate);
                Some(
                    super::listen::high_share(&samples, fs, ONE_MODE_SPLIT_HZ)
                        - target.listened.bright,
                )
            })
            .filter(|e| e.is_finite())
            .collect();
        if excess.is_empty() {
            return;
        }
        // Too bright: more of the low mode (more c where f1 is the low one).
        if (median(&excess) > 0.0) == brighter_with_less_c {
            low = middle;
        } else {
            high = middle;
        }
    }
    x[c] = 0.5 * (low + high);
}

/// Nelder–Mead from `start`: the best point and its cost.
fn minimise(search: &Search, start: Vec<f64>) -> Option<(Vec<f64>, f64)> {
    // The first simplex: a step of a fifth of each bound's width (at least 0.1 in the search
    // space: 10 % of a frequency).
    let mut simplex = vec![start.clone()];
    for (i, &(low, high)) in search.bounds.iter().enumerate() {
        let step = (0.2 * (high - low)).max(0.1);
        let mut vertex = start.clone();
        vertex[i] = if start[i] + step <= high {
            start[i] + step
        } else {
            start[i] - step
        };
        simplex.push(vertex);
    }
    let solver = NelderMead::new(simplex).with_sd_tolerance(1e-3).ok()?;
    let result = Executor::new(*search, solver)
        .configure(|state| state.max_iters(MAX_ITERATIONS))
        .run()
        .ok()?;
    let state = result.state;
    let x = state.best_param?;
    Some((x, state.best_cost))
}
