//! Constant stimuli: simulated observers with a known logistic answer 9 levels × 10 trials; the
//! fitted points' 95 % intervals must cover the truth in about 95 % of the studies.

use std::fmt::Write;

use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use sake_glug_analysis::{count_levels, fit_psychometric, PsychometricOptions, POINT_PERCENTS};
use statrs::distribution::{Binomial, DiscreteCDF};

use crate::{analyze, json_of};

/// The paper's §4.4: nine comparison levels from c = 0.18 to 0.49, ten trials each.
fn paper_levels() -> Vec<f64> {
    vec![0.18, 0.22, 0.26, 0.29, 0.33, 0.37, 0.41, 0.45, 0.49]
}
const TRIALS_PER_LEVEL: usize = 10;

/// The simulated observer: a logistic through the paper's thresholds, 25 % at c = 0.29 and
/// 75 % at 0.42 (so 50 % at 0.355).
const TRUE_25: f64 = 0.29;
const TRUE_75: f64 = 0.42;

fn true_points() -> [f64; 3] {
    [TRUE_25, (TRUE_25 + TRUE_75) / 2.0, TRUE_75]
}

fn observer(level: f64) -> f64 {
    let slope = 2.0 * 3f64.ln() / (TRUE_75 - TRUE_25);
    1.0 / (1.0 + (-slope * (level - (TRUE_25 + TRUE_75) / 2.0)).exp())
}

/// One study's answers: (level, chose the comparison).
fn simulated_study(seed: u64) -> Vec<(f64, bool)> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut answers = Vec::new();
    for level in paper_levels() {
        for _ in 0..TRIALS_PER_LEVEL {
            answers.push((level, rng.random::<f64>() < observer(level)));
        }
    }
    answers
}

/// How many of `studies` seeded studies' intervals cover each true point, and how many studies
/// had a fit.
fn coverage(studies: u64, resamples: usize) -> ([u64; 3], u64) {
    let mut covered = [0; 3];
    let mut fitted = 0;
    for study in 0..studies {
        let options = PsychometricOptions {
            resamples,
            seed: 1_000_000 + study,
            max_lapse: 0.0,
        };
        let Ok(fit) = fit_psychometric(&count_levels(&simulated_study(study)), &options) else {
            continue;
        };
        fitted += 1;
        for ((count, point), truth) in covered.iter_mut().zip(&fit.points).zip(true_points()) {
            *count += u64::from(point.low <= truth && truth <= point.high);
        }
    }
    (covered, fitted)
}

/// Counts of covered studies that a true 95 % coverage gives with probability 99.9 %.
fn binomial_bounds(studies: u64) -> (u64, u64) {
    let binomial = Binomial::new(0.95, studies).unwrap();
    (binomial.inverse_cdf(0.0005), binomial.inverse_cdf(0.9995))
}

#[test]
fn simulated_observers_intervals_cover_the_truth_in_about_95_percent_of_studies() {
    const STUDIES: u64 = 200;
    let (covered, fitted) = coverage(STUDIES, 500);
    assert!(
        fitted >= STUDIES - 2,
        "{fitted} of {STUDIES} studies fitted"
    );
    let (low, high) = binomial_bounds(fitted);
    for (percent, count) in POINT_PERCENTS.iter().zip(covered) {
        assert!(
            (low..=high).contains(&count),
            "the {percent} % point: {count} of {fitted} intervals cover the truth (expected {low}..={high})"
        );
    }
}

/// The coverage over many more studies, for docs/studies.md: `cargo test --all-features --test
/// analysis -- --ignored --nocapture coverage_of_many`.
#[test]
#[ignore = "minutes: the figure for docs/studies.md"]
fn coverage_of_many_simulated_studies() {
    const STUDIES: u64 = 2000;
    let (covered, fitted) = coverage(STUDIES, 2000);
    for (percent, count) in POINT_PERCENTS.iter().zip(covered) {
        println!(
            "{percent} % point: {count} of {fitted} intervals cover the truth ({:.1} %)",
            100.0 * count as f64 / fitted as f64
        );
    }
    let (low, high) = binomial_bounds(fitted);
    assert!(covered.iter().all(|count| (low..=high).contains(count)));
}

/// A study's answers as a runner's log, two participants.
fn log_of(answers: &[(f64, bool)]) -> String {
    let mut log = String::from("participant,trial,design,level,chose_comparison,rt_s\n");
    for (trial, (level, chosen)) in answers.iter().enumerate() {
        writeln!(
            log,
            "{},{trial},constant,{level},{},0.9",
            ["ann", "bo"][trial % 2],
            u8::from(*chosen)
        )
        .unwrap();
    }
    log
}

#[test]
fn the_json_holds_the_pooled_points_with_intervals_and_each_participant() {
    let folder = tempfile::tempdir().unwrap();
    std::fs::write(folder.path().join("log.csv"), log_of(&simulated_study(7))).unwrap();
    let args = [
        "constant",
        "log.csv",
        "--json",
        "--resamples",
        "300",
        "--seed",
        "5",
    ];
    let json = json_of(&analyze(folder.path(), &args));
    for percent in ["25", "50", "75"] {
        let point = &json["points"][percent];
        let (value, low, high) = (
            point["value"].as_f64().unwrap(),
            point["low"].as_f64().unwrap(),
            point["high"].as_f64().unwrap(),
        );
        assert!(low < value && value < high, "{percent}: {point}");
    }
    assert_eq!(json["levels"].as_array().unwrap().len(), 9);
    assert_eq!(json["levels"][0]["trials"], 10);
    let participants = json["participants"].as_object().unwrap();
    assert_eq!(participants.len(), 2);
    // The same seed, the same intervals.
    assert_eq!(json, json_of(&analyze(folder.path(), &args)));
    let other = json_of(&analyze(
        folder.path(),
        &[
            "constant",
            "log.csv",
            "--json",
            "--resamples",
            "300",
            "--seed",
            "6",
        ],
    ));
    assert_eq!(
        json["points"]["50"]["value"],
        other["points"]["50"]["value"]
    );
    assert_ne!(json["points"]["50"]["low"], other["points"]["50"]["low"]);
}

#[test]
fn a_fitted_lapse_stays_within_its_bound_and_the_plot_is_written() {
    let folder = tempfile::tempdir().unwrap();
    // An observer who slips: one answer in ten at the extremes goes the other way.
    let mut answers = simulated_study(3);
    for (index, answer) in answers.iter_mut().enumerate() {
        if index % 10 == 0 {
            answer.1 = answer.0 < 0.3;
        }
    }
    std::fs::write(folder.path().join("log.csv"), log_of(&answers)).unwrap();
    let args = [
        "constant",
        "log.csv",
        "--json",
        "--resamples",
        "200",
        "--lapse",
        "0.1",
        "--plot",
        "fit.png",
    ];
    let json = json_of(&analyze(folder.path(), &args));
    let lapse = json["curve"]["lapse"].as_f64().unwrap();
    assert!((0.0..=0.1).contains(&lapse), "{lapse}");
    assert!(std::fs::read(folder.path().join("fit.png"))
        .unwrap()
        .starts_with(b"\x89PNG"));
}

/// The resamples are drawn on every core; the intervals are the same on one core (`taskset`,
/// which the count of cores the analysis sees follows) as on all of them.
#[test]
fn the_intervals_are_the_same_on_one_core_and_on_all() {
    let folder = tempfile::tempdir().unwrap();
    std::fs::write(folder.path().join("log.csv"), log_of(&simulated_study(11))).unwrap();
    let args = [
        "analyze",
        "constant",
        "log.csv",
        "--json",
        "--resamples",
        "300",
    ];
    let one_core = std::process::Command::new("taskset")
        .current_dir(folder.path())
        .args(["--cpu-list", "0", env!("CARGO_BIN_EXE_sake-glug")])
        .args(args)
        .output();
    let Ok(one_core) = one_core else {
        eprintln!("skipped: no taskset here");
        return;
    };
    let all = analyze(folder.path(), &args[1..]);
    assert_eq!(json_of(&one_core), json_of(&all));
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get);
    if cores < 2 {
        eprintln!("this machine has one core: both runs drew on one");
    }
}
