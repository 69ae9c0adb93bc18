//! `sake-glug analyze plan constant`: the paper's §4.4 design simulated. Its intervals must
//! cover the observers' true points about as often as they claim, its figures must agree with
//! each other (the spread of the estimates and the widths of the intervals), shrink as the
//! design grows, repeat for a seed, and a bad argument is refused by its option's name.

use std::process::Output;

use statrs::distribution::{Binomial, DiscreteCDF};

use crate::{analyze, json_of};

/// The paper's §4.4: nine comparison levels, ten repetitions, three participants; observers
/// with its 25 % and 75 % points.
const PAPER_LEVELS: &str = "0.18,0.22,0.26,0.29,0.33,0.37,0.41,0.45,0.49";

/// `analyze plan constant` of the paper's design, each option of `options` given in place of
/// its default here, and `--json`.
fn plan(options: &[&str]) -> Output {
    let mut args = vec!["plan", "constant", "--json"];
    let defaults = [
        ("--levels", PAPER_LEVELS),
        ("--participants", "3"),
        ("--p25", "0.29"),
        ("--p75", "0.42"),
    ];
    for (name, value) in defaults {
        if !options.contains(&name) {
            args.extend([name, value]);
        }
    }
    args.extend(options);
    analyze(&std::env::temp_dir(), &args)
}

fn plan_json(extra: &[&str]) -> serde_json::Value {
    json_of(&plan(extra))
}

fn point(json: &serde_json::Value, percent: &str, field: &str) -> f64 {
    json["points"][percent][field].as_f64().unwrap()
}

#[test]
fn the_intervals_of_the_papers_design_cover_the_truth_about_as_often_as_they_claim() {
    let json = plan_json(&[
        "--repetitions",
        "10",
        "--studies",
        "400",
        "--resamples",
        "500",
    ]);
    let fitted = json["fitted"].as_u64().unwrap();
    assert!(fitted >= 398, "{fitted} of 400 studies fitted");
    // Counts a true 95 % coverage gives with probability 99.9 %.
    let binomial = Binomial::new(0.95, fitted).unwrap();
    let (low, high) = (binomial.inverse_cdf(0.0005), binomial.inverse_cdf(0.9995));
    for (percent, truth) in [("25", 0.29), ("50", 0.355), ("75", 0.42)] {
        assert!((point(&json, percent, "truth") - truth).abs() < 1e-12);
        let covered = json["points"][percent]["covered"].as_u64().unwrap();
        assert!(
            (low..=high).contains(&covered),
            "the {percent} % point: {covered} of {fitted} intervals hold the truth (expected \
             {low}..={high})"
        );
        let (coverage_low, coverage_high) = (
            point(&json, percent, "coverage_low"),
            point(&json, percent, "coverage_high"),
        );
        let coverage = covered as f64 / fitted as f64;
        assert!(coverage_low < coverage && coverage < coverage_high);
    }
}

/// Where the estimates of many studies fall is what an interval of one study claims to know:
/// the central 95 % of the estimates is about as wide as the median interval, and centred on
/// the truth (the maximum-likelihood points are nearly unbiased at 270 trials).
#[test]
fn the_spread_of_the_estimates_agrees_with_the_widths_of_the_intervals() {
    let json = plan_json(&[
        "--repetitions",
        "10",
        "--studies",
        "400",
        "--resamples",
        "300",
    ]);
    for percent in ["25", "50", "75"] {
        let spread = point(&json, percent, "estimate_high") - point(&json, percent, "estimate_low");
        let width = point(&json, percent, "median_width");
        assert!(
            (0.8..1.25).contains(&(spread / width)),
            "the {percent} % point: estimates spread over {spread}, intervals {width} wide"
        );
        let bias = point(&json, percent, "median_estimate") - point(&json, percent, "truth");
        assert!(
            bias.abs() < 0.1 * width,
            "the {percent} % point: bias {bias}"
        );
    }
}

#[test]
fn four_times_the_repetitions_halve_the_intervals() {
    let args = |repetitions| {
        plan_json(&[
            "--repetitions",
            repetitions,
            "--studies",
            "200",
            "--resamples",
            "300",
        ])
    };
    let (ten, forty) = (args("10"), args("40"));
    assert_eq!(ten["trials_a_study"], 270);
    assert_eq!(forty["trials_a_study"], 1080);
    for percent in ["25", "50", "75"] {
        let ratio = point(&forty, percent, "median_width") / point(&ten, percent, "median_width");
        assert!(
            (0.42..0.58).contains(&ratio),
            "the {percent} % point: widths shrink by {ratio}"
        );
    }
}

#[test]
fn a_seed_gives_the_same_figures_and_another_seed_others() {
    let args = |seed| {
        plan_json(&[
            "--repetitions",
            "10",
            "--studies",
            "30",
            "--resamples",
            "200",
            "--seed",
            seed,
        ])
    };
    let first = args("7");
    assert_eq!(first, args("7"));
    assert_ne!(
        first["points"]["50"]["median_width"],
        args("8")["points"]["50"]["median_width"]
    );
    // The same on one core (`taskset`, which the analysis's count of cores follows) as on all.
    let one_core = std::process::Command::new("taskset")
        .args(["--cpu-list", "0", env!("CARGO_BIN_EXE_sake-glug")])
        .args(["analyze", "plan", "constant", "--levels", PAPER_LEVELS])
        .args(["--participants", "3", "--p25", "0.29", "--p75", "0.42"])
        .args([
            "--repetitions",
            "10",
            "--studies",
            "30",
            "--resamples",
            "200",
        ])
        .args(["--seed", "7", "--json"])
        .output();
    match one_core {
        Ok(one_core) => assert_eq!(json_of(&one_core), first),
        Err(_) => eprintln!("skipped the one-core run: no taskset here"),
    }
}

#[test]
fn the_text_report_names_the_design_and_each_point() {
    let output = analyze(
        &std::env::temp_dir(),
        &[
            "plan",
            "constant",
            "--levels",
            PAPER_LEVELS,
            "--repetitions",
            "10",
            "--participants",
            "3",
            "--p25",
            "0.29",
            "--p75",
            "0.42",
            "--studies",
            "20",
            "--resamples",
            "100",
        ],
    );
    assert!(output.status.success());
    let text = String::from_utf8(output.stdout).unwrap();
    assert!(text.contains("= 270 trials a study"), "{text}");
    assert!(text.contains("20 studies simulated"), "{text}");
    for point in ["25 %   0.2900", "50 %   0.3550", "75 %   0.4200"] {
        assert!(text.contains(point), "{point} in {text}");
    }
}

#[test]
fn bad_arguments_are_refused_by_name() {
    let too_many_levels = (1..=1001)
        .map(|level| level.to_string())
        .collect::<Vec<_>>()
        .join(",");
    let cases: [(&[&str], &str); 19] = [
        (
            &["--levels", &too_many_levels, "--repetitions", "10"],
            "--levels",
        ),
        (&["--repetitions", "10001"], "--repetitions"),
        (
            &["--repetitions", "10", "--participants", "1001"],
            "--participants",
        ),
        (&["--repetitions", "10", "--studies", "100001"], "--studies"),
        (&["--repetitions", "10", "--p25", "nan"], "--p25"),
        (&["--repetitions", "10", "--p25", "-inf"], "--p25"),
        (&["--repetitions", "10", "--p75", "inf"], "--p75"),
        (&["--levels", "0.3", "--repetitions", "10"], "--levels"),
        (&["--levels", "0.2,x", "--repetitions", "10"], "--levels"),
        (&["--levels", "0.3,0.2", "--repetitions", "10"], "--levels"),
        (&["--levels", "0.2,0.2", "--repetitions", "10"], "--levels"),
        (&["--levels", "0.2,inf", "--repetitions", "10"], "--levels"),
        (&["--repetitions", "0"], "--repetitions"),
        (
            &["--repetitions", "10", "--participants", "0"],
            "--participants",
        ),
        (&["--repetitions", "10", "--studies", "0"], "--studies"),
        (&["--repetitions", "10", "--resamples", "0"], "--resamples"),
        (
            &["--repetitions", "10", "--resamples", "100001"],
            "--resamples",
        ),
        (&["--repetitions", "10", "--p25", "0.5"], "--p75"),
        (
            &[
                "--repetitions",
                "10",
                "--studies",
                "100000",
                "--resamples",
                "100000",
            ],
            "--studies",
        ),
    ];
    for (extra, named) in cases {
        let output = plan(extra);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{extra:?}: {stderr}");
        assert!(output.stdout.is_empty(), "{extra:?}");
        assert!(stderr.contains(named), "{extra:?}: {stderr}");
    }
}
