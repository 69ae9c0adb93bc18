//! The independent emptying simulator (`emptying.rs`) drawn at random over a wide family of
//! bottles (issue 45, item 2), each draw fitted as a bare clip of its bottle (its capacity given,
//! full at the first sample) and judged per constant against its truth: the simulators as a
//! family, not a point.
//!
//! Two disjoint sets of seeds: the **development** set, run while the fit is tuned, and the
//! **held-out** set, run once, at the end. Each prints its table (per draw the truth, the model's
//! value and a pass or a miss per constant; per constant the share within tolerance and the
//! draws that miss) and holds docs/fit.md's block to it; the development set is also held to the
//! goal, each constant within its tolerance in at least 90 % of the draws. Its 300 fits take
//! 45–75 minutes on 2 cores and the held-out set's 60 take 8–15, so both are `#[ignore]`d,
//! outside CI; `cargo xtask docs family` writes the development block:
//!
//! ```sh
//! cargo test --all-features --test fit the_development_family -- --ignored --nocapture
//! ```
//!
//! While tuning, `SAKE_GLUG_FAMILY_SEEDS=37,43` fits only those draws of the set, and
//! `SAKE_GLUG_FAMILY_CLIPS=folder` keeps each draw's clip there (`draw-37.wav`) to look at with
//! `sake-glug fit`; the goal is held only over the whole set.

use std::f64::consts::{PI, TAU};
use std::fmt::Write as _;
use std::ops::Range;

use sake_glug_engine::Constant;
use sake_glug_fit::comparisons::compare;
use sake_glug_fit::{fit_session, FitSession, SessionFit, Source};
use sake_glug_render::Scene;

use super::bubbles::{minnaert_hz, minnaert_radius, SOUND_M_PER_S};
use super::emptying::{
    helmholtz_hz, neck_length_m, simulate, Draws, Glide, Params, Simulated, END_CORRECTION,
    LEAD_IN_S,
};
use super::{add_noise, glug_rms, write_wav};

/// The development set: tune the fit on these draws only. 1001–1060 were the first held-out set,
/// run once at e092597d (docs/fit.md at 480fbdd5), 3001–3060 the third, run once at 3c3e0c43
/// (docs/fit.md there), 4001–4060 the fourth, run once at 544a2369 (docs/fit.md there), and
/// 5001–5060 the fifth, run once at a1c7e5be (docs/fit.md there), 6001–6060 the sixth, run
/// once at 33c05163 (docs/fit.md at 13b7d332), and 7001–7060 the seventh, run once at 3535e54d
/// (docs/fit.md at fd06c7a7); each has been seen since.
pub const DEVELOPMENT_SEEDS: [Range<u64>; 7] = [
    1..61,
    1001..1061,
    3001..3061,
    4001..4061,
    5001..5061,
    6001..6061,
    7001..7061,
];
/// The held-out set: run once, at the end, when the development set meets the goal, and reported
/// whatever it shows. Seeds 2001–2060, a set before the others, were run once with a candidate
/// fit kept off main (docs/fit.md) and are seen.
pub const HELD_OUT_SEEDS: Range<u64> = 8001..8061;
/// The issue's goal: each constant within its tolerance in this share of the draws.
const GOAL_SHARE: f64 = 0.9;

/// The family's ranges (issue 45).
const CAVITY_HZ: (f64, f64) = (80.0, 600.0);
const CAVITY_DECAY: (f64, f64) = (8.0, 60.0);
const BUBBLE_HZ: (f64, f64) = (600.0, 2500.0);
const BUBBLE_DECAY: (f64, f64) = (60.0, 400.0);
/// c, the cavity's (the lower mode's) share of each glug's amplitude.
const LOW_SHARE: (f64, f64) = (0.2, 0.9);
/// The bubble mode lies at least this far above the cavity's own frequency: two modes a fit can
/// tell apart (MODEL.md §13 splits modes at least 1.4× apart).
const MODES_APART: f64 = 1.5;
/// ρ of a cavity gliding down into its resonance, and of a bubble gliding up to its own.
const CAVITY_GLIDE_RATIO: (f64, f64) = (1.1, 2.0);
const BUBBLE_GLIDE_RATIO: (f64, f64) = (0.5, 0.9);
/// τ_g (s).
const GLIDE_TIME_S: (f64, f64) = (0.005, 0.06);
/// The noise below the glugs' RMS (`glug_rms`, as the round trips measure it).
const SNR_DB: (f64, f64) = (10.0, 40.0);
/// Each mode below 0.45·fs at every rate: the bubble's 2.5 kHz is below 0.45 · 8 kHz.
const SAMPLE_RATES_HZ: [f64; 8] = [
    8_000.0, 11_025.0, 16_000.0, 22_050.0, 24_000.0, 32_000.0, 44_100.0, 48_000.0,
];
const HIGHEST_MODE_OF_FS: f64 = 0.45;
/// A real bottle's glugs a second.
const GLUG_RATE: (f64, f64) = (4.0, 14.0);
/// The clip's nominal length (s): the lead-in, the glugs at their mean interval, the tail; the
/// clip ends with the last whole glug that fits in the length drawn.
const DURATION_S: (f64, f64) = (1.5, 6.0);
const TAIL_S: f64 = 0.3;
/// The bottle: its capacity (ml), the share of it the clip pours, its full headspace H as a
/// share of the capacity (how far the cavity falls), the neck's radius (m).
const CAPACITY_ML: (f64, f64) = (180.0, 1000.0);
const POURED_SHARE: (f64, f64) = (0.3, 0.8);
const HEADSPACE_SHARE: (f64, f64) = (0.03, 0.3);
/// A falling cavity's last glug rings no lower than this (Hz): a bottle's glug, not a rumble.
const LOWEST_CAVITY_HZ: f64 = 50.0;
const NECK_RADIUS_M: (f64, f64) = (0.005, 0.012);
/// The simulator's other draws, as its presets have them (see `emptying::Params`).
const POCKET_JITTER: (f64, f64) = (0.0, 0.15);
const TIMING_JITTER: (f64, f64) = (0.05, 0.2);
const BUBBLE_DECAY_SPREAD: (f64, f64) = (1.0, 1.5);
const AMPLITUDE_FALL: (f64, f64) = (0.0, 0.4);
const LEVEL_JITTER: (f64, f64) = (0.0, 0.15);
const REVERB_LEVEL: (f64, f64) = (0.0, 0.15);
const REVERB_S: (f64, f64) = (0.1, 0.5);
const HUM: (f64, f64) = (0.0, 0.02);
/// The family's own salt for a seed (the simulator has its own).
const FAMILY_SALT: u64 = 0xD1B5_4A32_D192_ED03;

/// One bottle of the family.
#[derive(Debug, Clone, Copy)]
pub struct Draw {
    pub seed: u64,
    pub params: Params,
    /// The noise below the glugs' RMS (dB).
    pub snr_db: f64,
    /// Whether the cavity falls with the air above the liquid (else a fixed low mode).
    pub falls: bool,
    /// Whether the modes glide within each glug.
    pub glides: bool,
    /// The nominal length (s).
    pub duration_s: f64,
}

fn between(draws: &mut Draws, (low, high): (f64, f64)) -> f64 {
    low + (high - low) * draws.uniform()
}

fn log_between(draws: &mut Draws, (low, high): (f64, f64)) -> f64 {
    (low.ln() + (high.ln() - low.ln()) * draws.uniform()).exp()
}

/// The bottle of `seed`.
pub fn draw(seed: u64) -> Draw {
    let mut draws = Draws::new(seed, FAMILY_SALT);
    let sample_rate = SAMPLE_RATES_HZ[(draws.uniform() * SAMPLE_RATES_HZ.len() as f64) as usize];
    let cavity_hz = log_between(&mut draws, CAVITY_HZ);
    let cavity_decay = log_between(&mut draws, CAVITY_DECAY);
    let bubble_low = BUBBLE_HZ.0.max(MODES_APART * cavity_hz);
    let bubble_hz = log_between(&mut draws, (bubble_low, BUBBLE_HZ.1));
    let bubble_decay = log_between(&mut draws, BUBBLE_DECAY);
    let low_share = between(&mut draws, LOW_SHARE);
    let falls = draws.uniform() < 0.5;
    let glides = draws.uniform() < 0.5;
    let (cavity_glide, bubble_glide) = if glides {
        (
            Glide {
                ratio: between(&mut draws, CAVITY_GLIDE_RATIO),
                time_s: log_between(&mut draws, GLIDE_TIME_S),
            },
            Glide {
                ratio: between(&mut draws, BUBBLE_GLIDE_RATIO),
                time_s: log_between(&mut draws, GLIDE_TIME_S),
            },
        )
    } else {
        (Glide::NONE, Glide::NONE)
    };
    let snr_db = between(&mut draws, SNR_DB);
    let rate_per_s = between(&mut draws, GLUG_RATE);
    let duration_s = between(&mut draws, DURATION_S);
    let glugs = 1 + ((duration_s - LEAD_IN_S - TAIL_S) * rate_per_s) as usize;
    let capacity_ml = log_between(&mut draws, CAPACITY_ML);
    let poured_ml = between(&mut draws, POURED_SHARE) * capacity_ml;
    let pocket_ml = poured_ml / glugs as f64;
    // A falling cavity's last glug rings no lower than LOWEST_CAVITY_HZ: its air, H + poured,
    // at most (f/f_lowest)² times the first glug's, H + b; H is raised where the draw is lower.
    let widest_fall = (cavity_hz / LOWEST_CAVITY_HZ).powi(2);
    let headspace_ml = (log_between(&mut draws, HEADSPACE_SHARE) * capacity_ml)
        .max((poured_ml - widest_fall * pocket_ml) / (widest_fall - 1.0));
    // The neck that makes the first glug's air (H and its pocket) ring at the cavity's f; wide
    // enough that its length less the end correction stays positive (L > 0 needs
    // r > END_CORRECTION·V·k²/π; twice that).
    let first_air_ml = headspace_ml + pocket_ml;
    let wavenumber = TAU * cavity_hz / SOUND_M_PER_S;
    let narrowest_m = 2.0 * END_CORRECTION * first_air_ml * 1e-6 * wavenumber * wavenumber / PI;
    let neck_radius_m = log_between(&mut draws, NECK_RADIUS_M).max(narrowest_m);
    let params = Params {
        sample_rate,
        capacity_ml,
        start_ml: capacity_ml,
        headspace_ml,
        neck_radius_m,
        neck_length_m: neck_length_m(cavity_hz, first_air_ml, neck_radius_m),
        glugs,
        pocket_ml,
        pocket_jitter: between(&mut draws, POCKET_JITTER),
        rate_per_s,
        timing_jitter: between(&mut draws, TIMING_JITTER),
        cavity_decay,
        fixed_cavity_hz: (!falls).then_some(cavity_hz),
        cavity_glide,
        bubble_glide,
        bubble_radius_m: minnaert_radius(bubble_hz),
        bubble_rise: 0.0,
        bubble_decay,
        bubble_decay_spread: between(&mut draws, BUBBLE_DECAY_SPREAD),
        bubble_share: 1.0 - low_share,
        amplitude_fall: between(&mut draws, AMPLITUDE_FALL),
        level_jitter: between(&mut draws, LEVEL_JITTER),
        reverb: (
            between(&mut draws, REVERB_LEVEL),
            between(&mut draws, REVERB_S),
        ),
        // Added after the simulation, at the draw's SNR against the glugs' RMS.
        noise: 0.0,
        hum: between(&mut draws, HUM),
        tail_s: TAIL_S,
        log_hz: 0.0,
        seed,
    };
    Draw {
        seed,
        params,
        snr_db,
        falls,
        glides,
        duration_s,
    }
}

/// How near an estimate must come to its truth.
#[derive(Debug, Clone, Copy)]
enum Within {
    /// Within this share of the truth.
    Share(f64),
    /// Within this much of the truth.
    Plus(f64),
}

impl Within {
    fn holds(self, truth: f64, got: f64) -> bool {
        got.is_finite()
            && match self {
                Within::Share(share) => (got / truth - 1.0).abs() <= share,
                Within::Plus(plus) => (got - truth).abs() <= plus,
            }
    }

    fn describe(self) -> String {
        match self {
            Within::Share(share) => format!("{:.0} %", share * 100.0),
            Within::Plus(plus) => format!("± {plus}"),
        }
    }
}

/// What the fit gave, as its model plays it.
struct Fitted {
    /// The model file, parsed as the renderer reads it.
    scene: Scene,
    /// The model's glugs a second, rendered as the clip was made and heard
    /// (`sake_glug_fit::listen`).
    rate_per_s: f64,
}

impl Fitted {
    fn constant(&self, constant: Constant) -> f64 {
        (constant.spec().get)(&self.scene.config)
    }
}

/// One constant judged: its truth in the simulator, its value in the fitted model, its tolerance
/// and why.
struct Measure {
    name: &'static str,
    decimals: usize,
    within: Within,
    why: &'static str,
    truth: fn(&Simulated) -> f64,
    model: fn(&Fitted) -> f64,
}

fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let middle = sorted.len() / 2;
    if sorted.len() % 2 == 1 {
        sorted[middle]
    } else {
        (sorted[middle - 1] + sorted[middle]) / 2.0
    }
}

/// The tolerances, declared once: the test, its table and docs/testing.md read them.
const MEASURES: [Measure; 9] = [
    Measure {
        name: "f1 (Hz)",
        decimals: 0,
        within: Within::Share(0.05),
        why: "a pitch heard as the bottle's: the truth is the cavity at a full bottle's first \
              glug, where MODEL.md §5.1 quotes f1 (a fixed low mode's own f); a gliding mode's \
              pitch is heard where its ring's energy is centred, 1/(2B) after the onset, in the \
              truth and in the model alike (a glide slower than the ring never reaches the mode's \
              own f: no listener, and no fit, hears that)",
        truth: |s| s.cavity_hz[0] * s.cavity_glide.factor(0.5 / s.cavity_decay),
        model: |m| super::heard_hz(&m.scene, 0),
    },
    Measure {
        name: "f2 (Hz)",
        decimals: 0,
        within: Within::Share(0.05),
        why: "the bubble mode's pitch, heard as f1's (the truth's decay the median of the \
              glugs' drawn decays)",
        truth: |s| s.bubble_hz[0] * s.bubble_glide.factor(0.5 / median(&s.bubble_decay)),
        model: |m| super::heard_hz(&m.scene, 1),
    },
    Measure {
        name: "B1 (/s)",
        decimals: 1,
        within: Within::Share(0.3),
        why: "a ring's length: units' decays scatter by tens of per cent in noise, a room and \
              overlap (the bubbles test holds 30 %)",
        truth: |s| s.cavity_decay,
        model: |m| m.constant(Constant::B1),
    },
    Measure {
        name: "B2 (/s)",
        decimals: 0,
        within: Within::Share(0.3),
        why: "as B1; the truth is the median of the glugs' drawn decays, as the fit takes the \
              median of its units'",
        truth: |s| median(&s.bubble_decay),
        model: |m| m.constant(Constant::B2),
    },
    Measure {
        name: "c",
        decimals: 2,
        within: Within::Plus(0.12),
        why: "the cavity's share of the amplitude, c = A1/(A1 + A2) (MODEL.md §5), as the \
              bubbles test holds it",
        truth: |s| s.low_mode_share,
        model: |m| m.scene.lanes.viscosity.value_at(0.0),
    },
    Measure {
        name: "γ1",
        decimals: 2,
        within: Within::Plus(0.1),
        why: "½ for a Helmholtz cavity, 0 for a fixed low mode: 0.1 tells a falling pitch from \
              a constant one",
        truth: |s| s.cavity_exponent,
        model: |m| m.constant(Constant::F1Exponent),
    },
    Measure {
        name: "γ2",
        decimals: 2,
        within: Within::Plus(0.1),
        why: "0: in this family the bubble's own pitch does not follow the air",
        truth: |_| 0.0,
        model: |m| m.constant(Constant::F2Exponent),
    },
    Measure {
        name: "rate (/s)",
        decimals: 2,
        within: Within::Share(0.1),
        why: "the model, rendered as the clip was made, glugs at the clip's pace: (glugs − 1) \
              over the first to the last onset",
        truth: |s| {
            let glugs = s.onsets.len();
            (glugs - 1) as f64 / (s.onsets[glugs - 1] - s.onsets[0])
        },
        model: |m| m.rate_per_s,
    },
    Measure {
        name: "ρ1",
        decimals: 2,
        within: Within::Plus(0.1),
        why: "the cavity's glide (MODEL.md §5.2): where it starts over where it ends, 1 for a \
              steady cavity; a glide slower than its ring is not heard, and is missed",
        truth: |s| s.cavity_glide.ratio,
        model: |m| m.constant(Constant::F1GlideRatio),
    },
];

/// One draw fitted.
struct Outcome {
    draw: Draw,
    /// The clip's length (s) and its glugs.
    clip_s: f64,
    glugs: usize,
    truth: [f64; MEASURES.len()],
    /// The model's values, or why the fit gave none.
    got: Result<[f64; MEASURES.len()], String>,
    /// Units used and detected.
    units: (usize, usize),
}

impl Outcome {
    fn passes(&self, measure: usize) -> bool {
        self.got.as_ref().is_ok_and(|got| {
            MEASURES[measure]
                .within
                .holds(self.truth[measure], got[measure])
        })
    }
}

fn fitted(fit: &SessionFit) -> Result<Fitted, String> {
    let liquid = &fit.liquids[0];
    let scene = Scene::parse(&liquid.model_toml).map_err(|e| format!("its model: {e}"))?;
    let comparison = compare(fit)?;
    let rate_per_s = comparison
        .first()
        .map_or(f64::NAN, |compared| compared.heard[1].rate_per_s);
    Ok(Fitted { scene, rate_per_s })
}

/// Simulates `draw`, adds its noise, writes it as a clip and fits it as a user would.
fn fit_draw(draw: &Draw) -> Outcome {
    let mut simulated = simulate(&draw.params);
    let sigma = glug_rms(&simulated.samples) * 10f64.powf(-draw.snr_db / 20.0);
    add_noise(&mut simulated.samples, sigma, draw.seed);
    let folder = tempfile::tempdir().unwrap();
    let wav = folder.path().join("clip.wav");
    write_wav(&wav, &simulated.samples, draw.params.sample_rate as u32);
    if let Some(folder) = std::env::var_os("SAKE_GLUG_FAMILY_CLIPS") {
        let kept = std::path::Path::new(&folder).join(format!("draw-{}.wav", draw.seed));
        std::fs::copy(&wav, kept).unwrap();
    }
    let truth = MEASURES.map(|measure| (measure.truth)(&simulated));
    let fit = FitSession::of_clips(&[wav], Some(draw.params.capacity_ml), None)
        .and_then(|session| fit_session(&session))
        .map_err(|e| e.to_string());
    let units = fit.as_ref().map_or((0, 0), |fit| {
        (fit.liquids[0].units, fit.liquids[0].detected)
    });
    let got = fit
        .and_then(|fit| fitted(&fit))
        .map(|model| MEASURES.map(|measure| (measure.model)(&model)));
    Outcome {
        draw: *draw,
        clip_s: simulated.samples.len() as f64 / draw.params.sample_rate,
        glugs: simulated.onsets.len(),
        truth,
        got,
        units,
    }
}

/// Fits the draws of `seeds` on every core (each fit is single-threaded and depends on its seed
/// alone), their outcomes in the order of `seeds`.
fn fit_draws(seeds: &[u64]) -> Vec<Outcome> {
    let workers = std::thread::available_parallelism().map_or(1, usize::from);
    let next = std::sync::atomic::AtomicUsize::new(0);
    let mut outcomes: Vec<(usize, Outcome)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..workers)
            .map(|_| {
                scope.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(&seed) = seeds.get(i) else {
                            return done;
                        };
                        done.push((i, fit_draw(&draw(seed))));
                    }
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|handle| handle.join().expect("a draw's fit panicked"))
            .collect()
    });
    outcomes.sort_by_key(|&(i, _)| i);
    outcomes.into_iter().map(|(_, outcome)| outcome).collect()
}

/// The share of `outcomes` within tolerance for each measure, and the seeds that miss.
fn summary(outcomes: &[Outcome]) -> Vec<(f64, Vec<u64>)> {
    (0..MEASURES.len())
        .map(|measure| {
            let misses: Vec<u64> = outcomes
                .iter()
                .filter(|outcome| !outcome.passes(measure))
                .map(|outcome| outcome.draw.seed)
                .collect();
            let share = 1.0 - misses.len() as f64 / outcomes.len().max(1) as f64;
            (share, misses)
        })
        .collect()
}

/// The set's table in markdown: per constant the share within tolerance and the draws that miss,
/// then per draw the truth → the model's value, ✓ or ✗.
fn markdown(set: &str, outcomes: &[Outcome]) -> String {
    let mut text = format!(
        "#### The emptying family: the {set} set ({} draws)\n\n\
         | constant | tolerance | within | draws missing it | why |\n|---|---|---|---|---|\n",
        outcomes.len()
    );
    for (measure, (share, misses)) in MEASURES.iter().zip(summary(outcomes)) {
        let misses: Vec<String> = misses.iter().map(u64::to_string).collect();
        writeln!(
            text,
            "| {} | {} | {:.0} % | {} | {} |",
            measure.name,
            measure.within.describe(),
            share * 100.0,
            misses.join(", "),
            measure.why
        )
        .unwrap();
    }
    text.push_str(
        "\n| draw | fs (Hz) | s | glugs | falls | glides | SNR (dB) | units used/detected |",
    );
    for measure in &MEASURES {
        write!(text, " {} |", measure.name).unwrap();
    }
    text.push_str("\n|---|---|---|---|---|---|---|---|");
    text.push_str(&"---|".repeat(MEASURES.len()));
    text.push('\n');
    for outcome in outcomes {
        let draw = &outcome.draw;
        let yes = |flag: bool| if flag { "yes" } else { "no" };
        write!(
            text,
            "| {} | {} | {:.2} | {} | {} | {} | {:.1} | {}/{} |",
            draw.seed,
            draw.params.sample_rate,
            outcome.clip_s,
            outcome.glugs,
            yes(draw.falls),
            yes(draw.glides),
            draw.snr_db,
            outcome.units.0,
            outcome.units.1
        )
        .unwrap();
        for (index, measure) in MEASURES.iter().enumerate() {
            let digits = measure.decimals;
            let truth = outcome.truth[index];
            let cell = match &outcome.got {
                Ok(got) => format!(
                    "{truth:.digits$} → {:.digits$} {}",
                    got[index],
                    if outcome.passes(index) { "✓" } else { "✗" }
                ),
                Err(_) => format!("{truth:.digits$} → — ✗"),
            };
            write!(text, " {cell} |").unwrap();
        }
        text.push('\n');
    }
    let refused: Vec<String> = outcomes
        .iter()
        .filter_map(|o| {
            o.got
                .as_ref()
                .err()
                .map(|e| format!("- draw {}: {e}", o.draw.seed))
        })
        .collect();
    if !refused.is_empty() {
        text.push_str("\nNo model:\n\n");
        text.push_str(&refused.join("\n"));
        text.push('\n');
    }
    text
}

/// Fits every draw of `seeds`, prints the table and holds docs/fit.md's block `block` to it (or
/// writes it there, with `SAKE_GLUG_WRITE_FIT_TABLES`); the outcomes, or none when
/// `SAKE_GLUG_FAMILY_SEEDS` picks some draws while tuning.
fn run_family(set: &str, seeds: &[Range<u64>], block: &str, command: &str) -> Option<Vec<Outcome>> {
    let only: Option<Vec<u64>> = std::env::var("SAKE_GLUG_FAMILY_SEEDS").ok().map(|list| {
        list.split(',')
            .map(|seed| {
                seed.trim()
                    .parse()
                    .expect("SAKE_GLUG_FAMILY_SEEDS: seeds, by commas")
            })
            .collect()
    });
    let picked: Vec<u64> = seeds
        .iter()
        .flat_map(Range::clone)
        .filter(|seed| only.as_ref().is_none_or(|only| only.contains(seed)))
        .collect();
    let outcomes = fit_draws(&picked);
    let table = markdown(set, &outcomes);
    println!("{table}");
    if only.is_some() {
        return None;
    }
    super::documented(block, &table, command);
    Some(outcomes)
}

/// The constants within tolerance in fewer than [`GOAL_SHARE`] of `outcomes`, with their shares.
fn short_of_goal(outcomes: &[Outcome]) -> Vec<String> {
    MEASURES
        .iter()
        .zip(summary(outcomes))
        .filter(|(_, (share, _))| *share < GOAL_SHARE)
        .map(|(measure, (share, _))| format!("{} {:.0} %", measure.name, share * 100.0))
        .collect()
}

/// The development set meets the goal, and docs/fit.md reports it as the fit gives it.
#[test]
#[ignore = "300 fits, 45–75 minutes on 2 cores: run outside CI, by `cargo xtask docs family`"]
fn the_development_family_is_fitted_within_tolerance() {
    let command = "cargo xtask docs family";
    if let Some(outcomes) = run_family(
        "development",
        &DEVELOPMENT_SEEDS,
        "family-development",
        command,
    ) {
        let short = short_of_goal(&outcomes);
        assert!(
            short.is_empty(),
            "the development set: within tolerance in fewer than {:.0} % of the draws: {}",
            GOAL_SHARE * 100.0,
            short.join(", ")
        );
    }
}

/// The held-out set, fitted once when the fit was tuned on the development set: docs/fit.md
/// reports it as it came out, whatever it shows, and this test holds the report (a change to the
/// fit that moves a held-out draw shows here).
#[test]
#[ignore = "60 fits, 8–15 minutes on 2 cores: run outside CI"]
fn the_held_out_family_is_reported_as_fitted() {
    run_family(
        "held-out",
        std::slice::from_ref(&HELD_OUT_SEEDS),
        "family-held-out",
        "SAKE_GLUG_WRITE_FIT_TABLES=1 cargo test --all-features --test fit the_held_out_family -- --ignored",
    );
}

/// Every draw of both sets lies in the family the issue names, the sets are disjoint and each
/// holds both kinds of cavity and both kinds of glug (gliding or not).
#[test]
fn the_family_is_drawn_as_stated() {
    let inside = |value: f64, (low, high): (f64, f64)| (low..=high).contains(&value);
    for set in [
        &DEVELOPMENT_SEEDS[..],
        std::slice::from_ref(&HELD_OUT_SEEDS),
    ] {
        let draws: Vec<Draw> = set.iter().flat_map(Range::clone).map(draw).collect();
        assert!(draws.len() >= 50);
        for (what, count) in [
            ("falling", draws.iter().filter(|d| d.falls).count()),
            ("gliding", draws.iter().filter(|d| d.glides).count()),
        ] {
            let share = count as f64 / draws.len() as f64;
            assert!(
                (0.25..=0.75).contains(&share),
                "{share} of the draws {what}"
            );
        }
        for d in &draws {
            let p = &d.params;
            let cavity_hz = p.fixed_cavity_hz.unwrap_or_else(|| {
                helmholtz_hz(
                    p.headspace_ml + p.pocket_ml,
                    p.neck_radius_m,
                    p.neck_length_m,
                )
            });
            let bubble_hz = minnaert_hz(p.bubble_radius_m);
            let last_air_ml = p.headspace_ml + p.pocket_ml * p.glugs as f64;
            let last_hz = p
                .fixed_cavity_hz
                .unwrap_or_else(|| helmholtz_hz(last_air_ml, p.neck_radius_m, p.neck_length_m));
            let nominal_s = LEAD_IN_S + (p.glugs - 1) as f64 / p.rate_per_s + p.tail_s;
            let ok = inside(cavity_hz, CAVITY_HZ)
                && last_hz >= LOWEST_CAVITY_HZ * (1.0 - 1e-9)
                && inside(p.cavity_decay, CAVITY_DECAY)
                && inside(bubble_hz, BUBBLE_HZ)
                && bubble_hz >= MODES_APART * cavity_hz * (1.0 - 1e-9)
                && bubble_hz < HIGHEST_MODE_OF_FS * p.sample_rate
                && inside(p.bubble_decay, BUBBLE_DECAY)
                && inside(1.0 - p.bubble_share, LOW_SHARE)
                && inside(d.snr_db, SNR_DB)
                && inside(p.rate_per_s, GLUG_RATE)
                && inside(d.duration_s, DURATION_S)
                && nominal_s <= d.duration_s
                && nominal_s > d.duration_s - 1.0 / p.rate_per_s
                && p.glugs >= 5
                && p.neck_length_m > 0.0
                && p.pocket_ml * p.glugs as f64 * (1.0 + p.pocket_jitter) < p.capacity_ml
                && (d.falls == p.fixed_cavity_hz.is_none())
                && (d.glides || (p.cavity_glide == Glide::NONE && p.bubble_glide == Glide::NONE))
                && (!d.glides
                    || (inside(p.cavity_glide.ratio, CAVITY_GLIDE_RATIO)
                        && inside(p.bubble_glide.ratio, BUBBLE_GLIDE_RATIO)
                        && inside(p.cavity_glide.time_s, GLIDE_TIME_S)
                        && inside(p.bubble_glide.time_s, GLIDE_TIME_S)));
            assert!(
                ok,
                "draw {}: cavity {cavity_hz} Hz, bubble {bubble_hz} Hz, {nominal_s} s: {d:?}",
                d.seed
            );
        }
    }
    for development in &DEVELOPMENT_SEEDS {
        assert!(development.end <= HELD_OUT_SEEDS.start || HELD_OUT_SEEDS.end <= development.start);
    }
}

/// A glide follows its law, f(τ) = f·(1 + (ρ − 1)·e^(−τ/τ_g)), and a fixed low mode stays put
/// while the air grows: one mode of a quiet, dry bottle against the closed form.
#[test]
fn a_glide_and_a_fixed_low_mode_are_as_their_laws_say() {
    let fs = 16_000.0;
    let (hz, decay) = (200.0, 20.0);
    let glide = Glide {
        ratio: 1.8,
        time_s: 0.02,
    };
    let mut params = Params::short_clip(fs);
    params.glugs = 3;
    params.fixed_cavity_hz = Some(hz);
    params.cavity_decay = decay;
    params.cavity_glide = glide;
    params.bubble_share = 0.0;
    (params.reverb, params.noise, params.hum, params.level_jitter) = ((0.0, 0.3), 0.0, 0.0, 0.0);
    let simulated = simulate(&params);
    assert!(simulated.cavity_hz.iter().all(|&f| f == hz));
    assert_eq!(simulated.cavity_exponent, 0.0);
    // The first glug alone, until the second starts: e^(−Bτ)·sin(2π·f·(τ + (ρ − 1)·τ_g·(1 −
    // e^(−τ/τ_g)))), at the simulator's own scale (its peak at 0.5).
    let onset = simulated.onsets[0];
    let first = (onset * fs).ceil() as usize;
    let last = (simulated.onsets[1] * fs) as usize;
    let scale = simulated.amplitude[0];
    let worst = (first..last)
        .map(|n| {
            let tau = n as f64 / fs - onset;
            let phase = TAU
                * hz
                * (tau + (glide.ratio - 1.0) * glide.time_s * (1.0 - (-tau / glide.time_s).exp()));
            (simulated.samples[n] as f64 - scale * (-decay * tau).exp() * phase.sin()).abs()
        })
        .fold(0.0, f64::max);
    assert!(worst < 1e-5, "the glide's samples are {worst} off its law");
}

/// The judge passes the truth, misses a value just beyond a tolerance and a fit that gave no
/// model, and counts the misses per constant.
#[test]
fn a_miss_is_counted_as_a_miss() {
    let truth = [300.0, 1500.0, 20.0, 150.0, 0.5, 0.5, 0.0, 8.0, 1.0];
    let outcome = |seed, got| Outcome {
        draw: draw(seed),
        clip_s: 2.0,
        glugs: 16,
        truth,
        got,
        units: (16, 16),
    };
    let mut off = truth;
    off[0] *= 1.051; // f1 5.1 % off
    off[4] += 0.121; // c 0.121 off
    let mut near = truth;
    near[0] *= 1.049;
    near[4] -= 0.119;
    let outcomes = [
        outcome(1, Ok(truth)),
        outcome(2, Ok(off)),
        outcome(3, Ok(near)),
        outcome(4, Err("refused".to_owned())),
    ];
    let summary = summary(&outcomes);
    for (index, (share, misses)) in summary.iter().enumerate() {
        let expected: &[u64] = if index == 0 || index == 4 {
            &[2, 4]
        } else {
            &[4]
        };
        assert_eq!(misses, expected, "{}", MEASURES[index].name);
        assert_eq!(*share, 1.0 - expected.len() as f64 / 4.0);
    }
    let table = markdown("test", &outcomes);
    assert!(table.contains("| f1 (Hz) | 5 % | 50 % | 2, 4 |"), "{table}");
    assert!(table.contains("- draw 4: refused"), "{table}");
}

/// The harness end to end on one draw of the development set: every truth finite, the model's
/// values finite where the fit gave one, a row in the table.
#[test]
fn one_draw_runs_through_the_harness() {
    let outcome = fit_draw(&draw(DEVELOPMENT_SEEDS[0].start));
    assert!(
        outcome.truth.iter().all(|v| v.is_finite()),
        "{:?}",
        outcome.truth
    );
    if let Ok(got) = &outcome.got {
        assert!(got.iter().all(|v| v.is_finite()), "{got:?}");
    }
    assert!(outcome.truth[0] > 0.0 && outcome.glugs >= 5);
    let table = markdown("development", std::slice::from_ref(&outcome));
    assert!(
        table.contains(&format!("\n| {} |", DEVELOPMENT_SEEDS[0].start)),
        "{table}"
    );
}

/// Development draws whose weak, short bright mode the fit once missed: beside a long cavity, in
/// a room, with hum that an eq. 1 fit took for the second mode (draws 4 and 44), and in a
/// cavity falling from 590 Hz, whose full bottle's f1 the liquid's split put in f2's mode (draw
/// 43). Their f2 and c come within tolerance (MODEL.md §13, "A short bright mode").
#[test]
fn weak_short_bright_modes_of_the_development_set_are_found() {
    assert_draws_pass(&[4, 43, 44], &[1, 4]);
}

/// Development draws whose modes glide (MODEL.md §13, "A glug that glides"): a cavity sweeping
/// down into 101, 204 and 326 Hz beside a bubble sweeping up. Their f1 and f2 as heard, and the
/// cavity's glide ρ1, come within tolerance: the fit hears the sweep, not a steady pitch
/// somewhere along it (before it did: ρ1 1 for 1.13, 1.64 and 1.18; f2 500 Hz for 541, f1 221 Hz
/// for 204, f2 1328 Hz for 1491).
#[test]
fn gliding_draws_of_the_development_set_are_heard() {
    assert_draws_pass(&[38, 56, 60], &[0, 1, 8]);
}

/// Draws 7006 and 7023 (the seventh held-out set, seen): a cavity gliding down into 203 Hz, and
/// one falling from 446 Hz as it glides, beside a bubble mode at 823 and 726 Hz carrying half the
/// amplitude and more. Every unit's eq. 1 fit took the glide in as a second component just above
/// the cavity (195 and 218 Hz), so no unit was looked at again for a short mode and the bubble
/// mode was lost (f2 kept at 300 Hz, c = 1). Its pitch, its decay, c and the cavity's glide come
/// within tolerance: a component within a mode's width above the unit's own is that mode's
/// glide, not a second mode (MODEL.md §13, "A short bright mode").
#[test]
fn a_cavitys_glide_fitted_as_two_components_does_not_hide_the_bubble_mode() {
    assert_draws_pass(&[7006, 7023], &[1, 3, 4, 8]);
}

/// Draws 31 and 41 of the development set: a cavity gliding down into 466 and 324 Hz beside a
/// short bubble (1/B of 3 ms) sweeping up more slowly than it rings. Its pitch as heard, its
/// decay and c come within tolerance: the pair is fitted with the cavity gliding and the bubble
/// at the pitch it is heard at (before, the bubble mode was lost: f2 kept at 300 Hz, c = 1).
#[test]
fn a_bright_mode_beside_a_gliding_cavity_is_heard() {
    assert_draws_pass(&[31, 41], &[1, 3, 4]);
}

/// Draws 22, 29 and 56 of the development set: a cavity gliding down into 88, 114 and 204 Hz
/// beside a short bubble rising into 1011, 1968 and 870 Hz. The bubble's pitch as heard, its
/// decay, c and the cavity's glide come within tolerance. Before: draw 29's cavity glide was lost
/// to a weak second component whose own glide ran out of range, and with it the bubble (c = 1);
/// draw 22's bubble, fitted steady, decayed at 185 /s for 88; draw 56's glide ran into a free
/// phase at τ_g = 0.5 ms, and its bubble decayed at 166 /s for 70 (MODEL.md §13: the glide refit
/// with its stronger component gliding, the short mode gliding beside a steady cavity, and the
/// glide started again where Levenberg-Marquardt held it at a bound).
#[test]
fn a_short_mode_rising_into_its_pitch_keeps_its_decay() {
    assert_draws_pass(&[22, 29, 56], &[1, 3, 4, 8]);
}

/// Draws 24 and 43 of the development set: a cavity falling from 197 and 590 Hz whose first glug
/// no fit described (the fit explains 49 % of draw 43's). Its full bottle's f1 and the fall's γ1
/// come within tolerance: the drain is dated from the first glug detected, kept or rejected
/// (MODEL.md §13, "Drain and volumes"); dated from the first kept, the law put the full bottle a
/// glug too low (f1 151 Hz for 197 and 521 for 590; γ1 0.63 for 0.5).
#[test]
fn a_pour_is_dated_from_its_first_glug_even_one_no_fit_described() {
    assert_draws_pass(&[24, 43], &[0, 5]);
}

/// Draw 30 of the development set: a cavity gliding down 1.59-fold, heard at 440 Hz, beside a
/// bubble at 679 Hz. Its bubble's decay, c and the cavity's glide come within tolerance:
/// a gliding mode may peak anywhere along its sweep (MODEL.md §13, a unit kept), and its span's
/// peak, 378 Hz, lies below the 442 Hz it is heard at. Before: 50 of 60 units were rejected as
/// off their peak, and c was 0.26 for 0.65.
#[test]
fn a_gliding_cavity_peaks_along_its_sweep() {
    assert_draws_pass(&[30], &[3, 4, 8]);
}

/// Draw 32 of the development set, at 11 kHz with 50 Hz mains hum, where a weak glug's span
/// peaks at the hum. The cavity's decay, the bubble's and c come within tolerance: no start and
/// no span's peak is taken at a line the recording holds throughout (MODEL.md §13, held lines).
/// Before: a component spent on the hum glided out of range and cost 18 of 22 units; B1 was 3
/// /s for 59.
#[test]
fn mains_hum_is_no_glugs_mode() {
    assert_draws_pass(&[32], &[2, 3, 4]);
}

/// Draw 32 again: 12 of its 22 glugs are kept. The model glugs at the clip's pace: a bare clip
/// drains at a pocket per median interval between the units detected, kept or rejected (MODEL.md
/// §13, "Drain and volumes"). Between the kept units alone it glugged 2.8 times a second for 4.3.
#[test]
fn a_glug_no_fit_described_still_sets_the_pace() {
    assert_draws_pass(&[32], &[7]);
}

/// Draws 11 and 53 of the development set: a cavity gliding down into its f, falling with the
/// headspace from 503 and 686 Hz, beside a steady bubble at 759 and 749 Hz. The bubble's pitch and
/// its law (none) come within tolerance: a full bottle's lone cavity is placed by its own f, as its
/// neighbours' modes record theirs (MODEL.md §13, "The bottle's two modes"). Placed by the pitch
/// it is heard at, near the bubble, it rang f2: γ2 −0.19 and −0.27, f2 583 and 526 Hz.
#[test]
fn a_full_bottles_lone_cavity_is_placed_by_its_own_frequency() {
    assert_draws_pass(&[11, 53], &[1, 6]);
}

/// Draw 45 of the development set: a Helmholtz cavity falling from 102 Hz beside a bubble at
/// 704 Hz. The bubble's pitch and its law (none) come within tolerance: a component whose
/// amplitude the fit held at 0 is no mode (MODEL.md §13, "Each unit"). Kept, four early units'
/// such components at 859–953 Hz wrote a law of γ2 0.07 and, from it, f2 770 Hz.
#[test]
fn a_component_that_rings_nothing_is_no_mode() {
    assert_draws_pass(&[45], &[1, 6]);
}

/// Development draw 2 (a cavity at 185 Hz beside a bubble at 2.04 kHz, 40 dB above its noise)
/// cut before its third glug: two units, each explained, but too few for any unit estimate, so
/// the units' model is the default bottle. It is fitted by listening, and its f1 comes nearer
/// the cavity than the default's 80 Hz (MODEL.md §13, "Fitted by listening", *When*). Before,
/// the units explaining more than half the clip kept the default bottle as its model (f1 not
/// written: the units' 181 Hz from 2 units, the model's 80).
#[test]
fn a_clip_too_short_for_any_unit_estimate_is_fitted_by_listening() {
    let draw = draw(2);
    let mut simulated = simulate(&draw.params);
    let sigma = glug_rms(&simulated.samples) * 10f64.powf(-draw.snr_db / 20.0);
    add_noise(&mut simulated.samples, sigma, draw.seed);
    let third_s = simulated.onsets[2];
    simulated
        .samples
        .truncate((third_s * draw.params.sample_rate) as usize);
    let folder = tempfile::tempdir().unwrap();
    let wav = folder.path().join("clip.wav");
    write_wav(&wav, &simulated.samples, draw.params.sample_rate as u32);
    let fit = FitSession::of_clips(&[wav], Some(draw.params.capacity_ml), None)
        .and_then(|session| fit_session(&session))
        .unwrap();
    let liquid = &fit.liquids[0];
    assert!(liquid.units < 3, "{} units", liquid.units);
    assert!(
        fit.recordings[0].explained >= 0.5,
        "{}",
        fit.recordings[0].explained
    );
    let f1_key = Constant::F1.quantity().scene_key;
    let f1 = liquid
        .estimates
        .iter()
        .find(|e| e.key == f1_key)
        .expect("an f1 estimate");
    let truth_hz = (MEASURES[0].truth)(&simulated);
    let default_hz = Constant::F1.quantity().range.default;
    assert!(
        f1.in_model
            && f1.source == Source::Listening
            && (f1.value / truth_hz).ln().abs() < (default_hz / truth_hz).ln().abs(),
        "f1 {} Hz ({:?}, in the model: {}) for a cavity at {truth_hz} Hz; the default is \
         {default_hz} Hz",
        f1.value,
        f1.source,
        f1.in_model
    );
}

/// Draws 1030 and 1048 of the development set: a steady cavity ringing 85–100 ms (B1 9.6 and
/// 11.7 /s) at 12 glugs a second, so that its rings overlap and the clip is quiet only before its
/// first glug. Their pitches, decays and c come within tolerance: the onsets' noise is the
/// quietest hundredth of the clip, not a tenth that is all rings (MODEL.md §13, "Onsets"; before,
/// draw 1048 found no unit above the noise and 1030 kept 2 of 57 glugs: B1 39 /s for 9.6).
#[test]
fn a_pour_whose_rings_overlap_is_heard() {
    assert_draws_pass(&[1030, 1048], &[0, 1, 2, 3, 4]);
}

/// Draws 1049 and 1057 of the development set: a cavity gliding down 1.5–1.8-fold into a pitch
/// that falls as the bottle empties. Its pitch as heard comes within tolerance: the model's own f
/// is the units' pitch as heard over the model's own glide factor (MODEL.md §13, Estimates),
/// where it was the units' own f, which one unit's fit trades against its ρ and τ_g (before, with
/// ρ also the median over every unit: f1 108 and 183 Hz for 101 and 212; with the units' own f
/// alone put back, the same). Draw 1004, of the same kind, was held here too, just within 5 %
/// (186 Hz); since a component just above a unit's own is taken for its glide (MODEL.md §13, "A
/// short bright mode"), two late units of it are fitted gliding beside its bubble mode, lower,
/// and its f1 is 173 Hz, a miss the development table lists.
#[test]
fn a_gliding_cavity_is_heard_where_its_units_are() {
    assert_draws_pass(&[1049, 1057], &[0]);
}

/// Draw 48 of the development set: a cavity gliding 1.41-fold, whose glide 18 of its 47 units
/// fitted steady (a glide slower than its ring is not heard in one unit). Its ρ1 is the median
/// over the units that glide (MODEL.md §13, Estimates), where it was the median over every unit
/// with a steady one counted as 1, which gave 1.31.
#[test]
fn a_gliding_bottles_steady_units_do_not_flatten_its_glide() {
    assert_draws_pass(&[48], &[8]);
}

/// Draws 3009 and 1033 of the development set: a cavity gliding 1.19- and 1.45-fold, whose glide
/// most of its units fitted steady (7 of 22 and 6–9 of 13 glide, at ρ 1.17–1.20 and 1.38–1.48).
/// A glide its gliding units agree on is the bottle's though fewer than half show it (MODEL.md
/// §13, Estimates): ρ1 and the pitch as heard come within tolerance, where the model was written
/// steady (ρ1 1.00 for both; f1 81 Hz for 1033's 90).
#[test]
fn a_glide_its_gliding_units_agree_on_is_the_bottles() {
    assert_draws_pass(&[3009, 1033], &[0, 8]);
}

/// Draws 3049 and 3058 of the development set: a cavity gliding 1.8-fold into a pitch that falls as
/// the bottle empties, 18 of 46 and 5 of 20 units fitted steady. A steady unit's pitch lies
/// between where the glide starts and its own f, so only the units fitted gliding place the
/// model's f (MODEL.md §13, Estimates): f1 comes within tolerance, where the steady units, taken
/// as heard, pulled it low (232 Hz for 249, 88 for 93).
#[test]
fn a_gliding_cavitys_pitch_is_placed_by_its_units_that_glide() {
    assert_draws_pass(&[3049, 3058], &[0]);
}

/// Draw 3042 of the development set: a steady cavity at 322 Hz and a bubble mode at 825 Hz, both
/// in each of its 27 units, and hum at 50 Hz in two units' fits. The two modes are the liquid's
/// (MODEL.md §13, the bottle's two modes), where the hum, left in the split, widened f1's group
/// until the two no longer stood apart: f2 was then kept at its default 300 Hz and c at 1.
#[test]
fn a_bright_mode_beside_two_units_hum_is_kept() {
    assert_draws_pass(&[3042], &[1, 3, 4]);
}

/// Draw 3038 of the development set: a cavity gliding 1.9-fold into 280 Hz that carries 89 % of
/// the amplitude, and a bubble mode heard at 754 Hz decaying at 226 /s, 25 dB under it in each of
/// the 45 units and in none found by a unit's own fit. The residues every unit's fit left early,
/// summed, show it (MODEL.md §13, the short mode), where f2 was kept at its default 300 Hz.
#[test]
fn a_bubble_mode_under_each_units_noise_is_found_in_their_sum() {
    assert_draws_pass(&[3038], &[1, 3, 4]);
}

/// Draw 5038 of the development set: a bubble mode heard at 1.3 kHz in 54 of its 73 units, most
/// of which fit it rising more slowly than it rings, so that their own f is a guess scattered
/// from 1.3 to 4.6 kHz. Its pitch, its decay and c come within tolerance: the liquid's modes are
/// split by the pitch each component is heard at (MODEL.md §13, the bottle's two modes), where
/// split by their own f the two modes made one and f2 was written at 300 Hz for 1315.
#[test]
fn a_bubble_mode_that_rises_slower_than_it_rings_is_split_by_its_heard_pitch() {
    assert_draws_pass(&[5038], &[1, 3, 4]);
}

/// Fits each development draw of `seeds` and fails with the rows of those that miss any of
/// `measures` (indices into [`MEASURES`]).
fn assert_draws_pass(seeds: &[u64], measures: &[usize]) {
    let missed: Vec<String> = seeds
        .iter()
        .map(|&seed| fit_draw(&draw(seed)))
        .filter(|outcome| !measures.iter().all(|&measure| outcome.passes(measure)))
        .map(|outcome| markdown("development", std::slice::from_ref(&outcome)))
        .collect();
    assert!(missed.is_empty(), "{}", missed.join("\n"));
}
