//! Discrimination (`sake-glug analyze discrimination`, `analyze plan discrimination`): the
//! decision models against observers who answer by them, the triangle's table against another
//! computation of it, and the analysis by simulation: simulated observers of known d′ answer
//! thousands of studies; the estimates must be median-unbiased, the 95 % intervals must cover
//! the truth about as often as they claim, and the test against chance must hold its level at
//! d′ = 0. `cargo test --test analysis -- --ignored discrimination_figures` runs the long
//! simulation and writes its figures into docs/studies.md.

use std::fmt::Write;
use std::path::Path;

use rand::{Rng, RngExt, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;
use sake_glug_analysis::{estimate_discrimination, DiscriminationDesign};
use sake_glug_study::{plan_trials, Design, Discriminate, Spec, DISCRIMINATE_DESIGNS};
use statrs::distribution::{Binomial, Discrete, DiscreteCDF};

use crate::{analyze, json_of};

/// The d′ of the simulated observers.
const D_PRIMES: [f64; 5] = [0.0, 0.5, 1.0, 2.0, 3.0];

/// One trial answered by an observer of sensitivity `d_prime` who decides as the design's model
/// says: each stimulus a unit-variance normal draw, the odd one's (or B's) mean `d_prime`.
/// Written from the decision rules, not from the formulas under test.
fn observer_is_right(design: DiscriminationDesign, d_prime: f64, rng: &mut impl Rng) -> bool {
    match design {
        // Two alike, one odd: the two closest are taken for the alike pair.
        DiscriminationDesign::Triangle => {
            let (alike, also_alike, odd) = (draw(0.0, rng), draw(0.0, rng), draw(d_prime, rng));
            let alike_gap = (alike - also_alike).abs();
            alike_gap < (alike - odd).abs() && alike_gap < (also_alike - odd).abs()
        }
        // The one that is more so is named.
        DiscriminationDesign::TwoAfc => draw(d_prime, rng) > draw(0.0, rng),
        // X is A or B at random; the observer says the one X is nearer.
        DiscriminationDesign::Abx => {
            let (a, b) = (draw(0.0, rng), draw(d_prime, rng));
            let x_is_a = rng.random::<bool>();
            let x = if x_is_a {
                draw(0.0, rng)
            } else {
                draw(d_prime, rng)
            };
            let says_a = (x - a).abs() < (x - b).abs();
            says_a == x_is_a
        }
    }
}

/// A percept: `mean` plus unit-variance normal noise.
fn draw(mean: f64, rng: &mut impl Rng) -> f64 {
    let noise: f64 = StandardNormal.sample(rng);
    mean + noise
}

#[test]
fn each_designs_proportion_correct_is_what_its_observers_answer() {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(38);
    const TRIALS: u32 = 200_000;
    for design in DiscriminationDesign::ALL {
        for d_prime in D_PRIMES {
            let right: u32 = (0..TRIALS)
                .map(|_| u32::from(observer_is_right(design, d_prime, &mut rng)))
                .sum();
            let expected = design.proportion_correct(d_prime);
            let observed = f64::from(right) / f64::from(TRIALS);
            let error = (expected * (1.0 - expected) / f64::from(TRIALS)).sqrt();
            assert!(
                (observed - expected).abs() < 4.5 * error,
                "{} at d′ = {d_prime}: the model says {expected:.4}, its observers answered \
                 {observed:.4} right (±{error:.4})",
                design.name()
            );
        }
    }
}

/// The triangle's proportion correct against d′: at d′ = 0 a guess, 1/3; elsewhere the
/// differencing model's values computed another way, as the probability that a noncentral F
/// with 1 and 1 degrees of freedom and noncentrality 2d′²/3 exceeds 3 (Brockhoff & Christensen
/// 2010, Food Quality and Preference 21:330, the form sensR uses), by
/// `scipy.stats.ncf.sf(3, 1, 1, 2*d*d/3)` with SciPy 1.17.1. This is the function the published
/// tables give (Frijters, Kooistra & Vereijken 1980, Perception & Psychophysics 27:176, eq. 1;
/// Ennis 1993, J. Sensory Studies 8:353); their printed values could not be had here, so the
/// reference is this second computation of it, independent of the quadrature under test.
#[test]
fn the_triangle_table_is_reproduced() {
    let triangle = DiscriminationDesign::Triangle;
    assert!((triangle.proportion_correct(0.0) - 1.0 / 3.0).abs() < 1e-10);
    let table = [
        (0.5, 0.355_834_649_628_560_7),
        (1.0, 0.418_046_674_714_639_2),
        (1.5, 0.506_456_097_259_189_8),
        (2.0, 0.604_806_932_772_188_6),
        (3.0, 0.781_427_598_596_483_7),
    ];
    for (d_prime, expected) in table {
        let computed = triangle.proportion_correct(d_prime);
        assert!(
            (computed - expected).abs() < 1e-9,
            "d′ = {d_prime}: {computed} where the table has {expected}"
        );
        assert!((triangle.d_prime(expected) - d_prime).abs() < 1e-7);
    }
    // 2AFC: d′ = √2·z(p); z(0.76) = 0.706303, so p = 0.76 is d′ = 0.998862.
    let two_afc = DiscriminationDesign::TwoAfc;
    assert!((two_afc.d_prime(0.76) - 0.998_862).abs() < 1e-5);
    assert_eq!(two_afc.d_prime(0.5), 0.0);
}

/// What a simulated series of studies gave at one d′.
struct Figures {
    studies: u32,
    /// Estimates below the truth, and above it.
    below: u32,
    above: u32,
    /// Intervals holding the truth.
    covered: u32,
    /// Tests against chance that rejected at 5 %.
    rejected: u32,
    /// The mean and standard deviation of the finite estimates, and how many were finite.
    mean: f64,
    sd: f64,
    finite: u32,
    /// The greatest probability of one count of right answers (how far from ½ the median of a
    /// discrete estimate may fall).
    largest_mass: f64,
    /// The intervals' exact coverage at this d′: the probability, over the binomial counts of
    /// right answers, of an interval that holds the truth. A count is discrete, so it is not
    /// 95 % exactly (the likelihood-ratio interval's swings about it).
    exact_coverage: f64,
}

/// `studies` studies of `participants` × `trials` trials each, pooled, answered by observers of
/// `d_prime`.
fn simulate(
    design: DiscriminationDesign,
    d_prime: f64,
    studies: u32,
    participants: u32,
    trials: u32,
    seed: u64,
) -> Figures {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let (mut below, mut above, mut covered, mut rejected) = (0, 0, 0, 0);
    let mut finite = Vec::new();
    let total = participants * trials;
    for _ in 0..studies {
        let right: u32 = (0..total)
            .map(|_| u32::from(observer_is_right(design, d_prime, &mut rng)))
            .sum();
        let estimate = estimate_discrimination(design, right, total);
        below += u32::from(estimate.d_prime < d_prime);
        above += u32::from(estimate.d_prime > d_prime);
        covered += u32::from(
            estimate
                .d_prime_interval
                .is_some_and(|(low, high)| low <= d_prime && d_prime <= high),
        );
        rejected += u32::from(estimate.told_apart());
        if estimate.d_prime.is_finite() {
            finite.push(estimate.d_prime);
        }
    }
    let count = finite.len() as f64;
    let mean = finite.iter().sum::<f64>() / count;
    let sd = (finite.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / (count - 1.0)).sqrt();
    let binomial = Binomial::new(design.proportion_correct(d_prime), u64::from(total)).unwrap();
    let largest_mass = (0..=u64::from(total))
        .map(|k| binomial.pmf(k))
        .fold(0.0, f64::max);
    let exact_coverage = exact_coverage(design, d_prime, total);
    Figures {
        studies,
        below,
        above,
        covered,
        rejected,
        mean,
        sd,
        finite: finite.len() as u32,
        largest_mass,
        exact_coverage,
    }
}

/// The probability, over the binomial counts of right answers in `trials` trials of observers of
/// `d_prime`, of an interval that holds `d_prime`.
fn exact_coverage(design: DiscriminationDesign, d_prime: f64, trials: u32) -> f64 {
    let binomial = Binomial::new(design.proportion_correct(d_prime), u64::from(trials)).unwrap();
    (0..=trials)
        .filter(|&right| {
            estimate_discrimination(design, right, trials)
                .d_prime_interval
                .is_some_and(|(low, high)| low <= d_prime && d_prime <= high)
        })
        .map(|right| binomial.pmf(u64::from(right)))
        .sum()
}

/// The counts in `studies` that a true rate `rate` gives with probability 99.9 %.
fn plausible(rate: f64, studies: u32) -> std::ops::RangeInclusive<u64> {
    let binomial = Binomial::new(rate, u64::from(studies)).unwrap();
    binomial.inverse_cdf(0.0005)..=binomial.inverse_cdf(0.9995)
}

/// The checks on one d′'s figures: the estimate median-unbiased (as many below the truth as
/// above it, but for one count's probability, which a discrete estimate may sit on); the
/// intervals' exact coverage from 94 to 96 %, and the simulated studies' coverage where it puts
/// it; at d′ = 0, the test's level.
fn check(design: DiscriminationDesign, d_prime: f64, figures: &Figures) {
    let name = design.name();
    let studies = figures.studies;
    let most = *plausible(0.5 + figures.largest_mass, studies).end();
    for (side, count) in [("below", figures.below), ("above", figures.above)] {
        assert!(
            u64::from(count) <= most,
            "{name} at d′ = {d_prime}: {count} of {studies} estimates {side} the truth (at \
             most {most} for a median-unbiased estimate)"
        );
    }
    assert!(
        (0.94..=0.96).contains(&figures.exact_coverage),
        "{name} at d′ = {d_prime}: the intervals' exact coverage is {}",
        figures.exact_coverage
    );
    let coverage = plausible(figures.exact_coverage, studies);
    assert!(
        coverage.contains(&u64::from(figures.covered)),
        "{name} at d′ = {d_prime}: {} of {studies} intervals hold the truth (expected \
         {coverage:?}, the exact coverage being {:.4})",
        figures.covered,
        figures.exact_coverage
    );
    if d_prime == 0.0 {
        let most = *plausible(0.05, studies).end();
        assert!(
            u64::from(figures.rejected) <= most,
            "{name} at d′ = 0: the test rejected {} of {studies} times at 5 % (at most {most})",
            figures.rejected
        );
    }
}

/// The pooled study of the checks: 10 participants × 30 trials.
const PARTICIPANTS: u32 = 10;
const TRIALS_EACH: u32 = 30;

#[test]
fn the_triangle_analysis_is_unbiased_covers_and_holds_its_level_by_simulation() {
    let design = DiscriminationDesign::Triangle;
    for (index, d_prime) in D_PRIMES.into_iter().enumerate() {
        let figures = simulate(
            design,
            d_prime,
            2000,
            PARTICIPANTS,
            TRIALS_EACH,
            index as u64,
        );
        check(design, d_prime, &figures);
    }
}

#[test]
fn the_2afc_and_abx_analyses_are_unbiased_cover_and_hold_their_level_by_simulation() {
    for design in [DiscriminationDesign::TwoAfc, DiscriminationDesign::Abx] {
        for (index, d_prime) in D_PRIMES.into_iter().enumerate() {
            let figures = simulate(
                design,
                d_prime,
                1000,
                PARTICIPANTS,
                TRIALS_EACH,
                100 + index as u64,
            );
            check(design, d_prime, &figures);
        }
    }
}

/// One participant's 30 trials: the test against chance holds its level on a small count too,
/// where a count off by one would show (P(X ≥ k) taken as P(X > k) rejects about twice as
/// often).
#[test]
fn the_test_against_chance_holds_its_level_for_one_participant() {
    for design in DiscriminationDesign::ALL {
        let figures = simulate(design, 0.0, 4000, 1, TRIALS_EACH, 7);
        let most = *plausible(0.05, figures.studies).end();
        assert!(
            u64::from(figures.rejected) <= most,
            "{} at d′ = 0, 30 trials: rejected {} of {} times (at most {most})",
            design.name(),
            figures.rejected,
            figures.studies
        );
    }
}

/// The long simulation: 20,000 studies of 10 × 30 trials at each d′ and design; its figures go
/// into docs/studies.md between the markers, written by this test and never by hand.
#[test]
#[ignore = "minutes: the figures of docs/studies.md; run with --ignored"]
fn discrimination_figures() {
    const STUDIES: u32 = 20_000;
    let mut table = format!(
        "{STUDIES} simulated studies a row, each {PARTICIPANTS} participants × {TRIALS_EACH} \
         trials pooled; observers answering by the design's decision model \
         (`tests/analysis/discrimination.rs`, `discrimination_figures`).\n\n\
         | design | d′ | estimates below / above the truth | mean estimate (± its Monte Carlo \
         error) | bias of the mean | coverage of the 95 % interval | its exact coverage | \
         rejections at 5 % |\n\
         |---|---|---|---|---|---|---|---|\n"
    );
    for design in DiscriminationDesign::ALL {
        for (index, d_prime) in D_PRIMES.into_iter().enumerate() {
            let figures = simulate(
                design,
                d_prime,
                STUDIES,
                PARTICIPANTS,
                TRIALS_EACH,
                1000 + index as u64,
            );
            check(design, d_prime, &figures);
            let coverage = f64::from(figures.covered) / f64::from(STUDIES);
            let error = figures.sd / f64::from(figures.finite).sqrt();
            let infinite = STUDIES - figures.finite;
            let mean = match infinite {
                0 => format!("{:.4} ± {error:.4}", figures.mean),
                _ => format!(
                    "{:.4} ± {error:.4} ({infinite} infinite left out)",
                    figures.mean
                ),
            };
            writeln!(
                table,
                "| {} | {d_prime} | {:.1} % / {:.1} % | {mean} | {:+.4} | {:.2} % | {:.2} % | \
                 {:.2} % |",
                design.name(),
                100.0 * f64::from(figures.below) / f64::from(STUDIES),
                100.0 * f64::from(figures.above) / f64::from(STUDIES),
                figures.mean - d_prime,
                100.0 * coverage,
                100.0 * figures.exact_coverage,
                100.0 * f64::from(figures.rejected) / f64::from(STUDIES),
            )
            .unwrap();
        }
    }
    table += "\nOne participant's interval is the same computation on fewer trials, where the \
              count moves in coarse steps, so its exact coverage swings further about 95 %:\n\n\
              | design | d′ | exact coverage, 12 trials | 30 trials |\n|---|---|---|---|\n";
    for design in DiscriminationDesign::ALL {
        for d_prime in D_PRIMES {
            writeln!(
                table,
                "| {} | {d_prime} | {:.2} % | {:.2} % |",
                design.name(),
                100.0 * exact_coverage(design, d_prime, 12),
                100.0 * exact_coverage(design, d_prime, TRIALS_EACH),
            )
            .unwrap();
        }
    }
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/studies.md");
    let text = std::fs::read_to_string(&docs).unwrap();
    let (start, end) = (FIGURES_START, FIGURES_END);
    let before = &text[..text.find(start).expect("the start marker") + start.len()];
    let after = &text[text.find(end).expect("the end marker")..];
    std::fs::write(&docs, format!("{before}\n{table}{after}")).unwrap();
}

const FIGURES_START: &str =
    "<!-- discrimination figures: written by tests/analysis/discrimination.rs -->";
const FIGURES_END: &str = "<!-- end of discrimination figures -->";

/// The figures in docs/studies.md are the long simulation's: a row for each design and d′,
/// every coverage, simulated and exact, from 94 to 96 %.
#[test]
fn the_documented_figures_are_the_long_simulations() {
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/studies.md");
    let text = std::fs::read_to_string(docs).unwrap();
    let start = text.find(FIGURES_START).expect("the start marker") + FIGURES_START.len();
    let end = text.find(FIGURES_END).expect("the end marker");
    // The pooled table's rows (eight cells); the one-participant table has four.
    let rows: Vec<&str> = text[start..end]
        .lines()
        .filter(|line| line.starts_with("| ") && !line.starts_with("| design"))
        .filter(|line| line.matches('|').count() == 9)
        .collect();
    assert_eq!(rows.len(), DiscriminationDesign::ALL.len() * D_PRIMES.len());
    for row in rows {
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        for cell in [cells[6], cells[7]] {
            let coverage: f64 = cell.trim_end_matches(" %").parse().unwrap();
            assert!((94.0..=96.0).contains(&coverage), "{row}");
        }
    }
}

/// A log's row: participant, design, correct.
type LogLine<'a> = (&'a str, &'a str, u32);

fn write_log(folder: &Path, name: &str, rows: &[LogLine]) -> String {
    let mut text = String::from("participant,trial,design,correct\n");
    for (index, (participant, design, correct)) in rows.iter().enumerate() {
        writeln!(text, "{participant},{},{design},{correct}", index + 1).unwrap();
    }
    std::fs::write(folder.join(name), text).unwrap();
    name.to_owned()
}

#[test]
fn a_triangle_log_is_analysed_pooled_and_per_participant_with_its_sentence() {
    let folder = tempfile::tempdir().unwrap();
    // P1: 10 of 12 right, P2: 9 of 12.
    let mut rows = Vec::new();
    for trial in 0..12 {
        rows.push(("P1", "triangle", u32::from(trial < 10)));
    }
    for trial in 0..12 {
        rows.push(("P2", "triangle", u32::from(trial < 9)));
    }
    let log = write_log(folder.path(), "triangle.csv", &rows);
    let json = json_of(&analyze(folder.path(), &["discrimination", "--json", &log]));
    assert_eq!(json["design"], "triangle");
    assert_eq!(json["trials"], 24);
    assert_eq!(json["correct"], 19);
    let expected = estimate_discrimination(DiscriminationDesign::Triangle, 19, 24);
    assert!((json["d_prime"].as_f64().unwrap() - expected.d_prime).abs() < 1e-12);
    assert!(json["told_apart"].as_bool().unwrap());
    let sentence = json["sentence"].as_str().unwrap();
    assert!(
        sentence.starts_with("people told them apart (d′ = "),
        "{sentence}"
    );
    assert_eq!(json["participants"]["P1"]["correct"], 10);
    assert_eq!(json["participants"]["P2"]["trials"], 12);
    let text = analyze(folder.path(), &["discrimination", &log]);
    assert!(text.status.success());
    let text = String::from_utf8(text.stdout).unwrap();
    assert!(
        text.contains("profile likelihood") && text.contains(sentence),
        "{text}"
    );
}

#[test]
fn answers_at_chance_say_not_distinguishable_with_a_bound() {
    let folder = tempfile::tempdir().unwrap();
    // 100 of 300 right: exactly chance.
    let rows: Vec<_> = (0..300)
        .map(|trial| ("P1", "triangle", u32::from(trial % 3 == 0)))
        .collect();
    let log = write_log(folder.path(), "chance.csv", &rows);
    let json = json_of(&analyze(folder.path(), &["discrimination", "--json", &log]));
    assert_eq!(json["d_prime"], 0.0);
    assert_eq!(json["d_prime_low"], 0.0);
    let high = json["d_prime_high"].as_f64().unwrap();
    assert!(0.5 < high && high < 1.2, "{high}");
    assert_eq!(
        json["sentence"],
        format!("not distinguishable at this sample size (d′ < {high:.2} with 95 % confidence)")
    );
}

#[test]
fn bad_discrimination_logs_are_refused_with_file_line_and_column() {
    let folder = tempfile::tempdir().unwrap();
    let cases: [(&str, &[LogLine], &str); 3] = [
        (
            "design.csv",
            &[("P1", "duo-trio", 1)],
            "line 2, column `design`: `duo-trio` is not a discrimination design",
        ),
        (
            "mixed.csv",
            &[("P1", "triangle", 1), ("P1", "2afc", 0)],
            "line 3, column `design`: `2afc`, where",
        ),
        (
            "correct.csv",
            &[("P1", "abx", 2)],
            "line 2, column `correct`: `2`: 1 if the answer was right",
        ),
    ];
    for (name, rows, message) in cases {
        let log = write_log(folder.path(), name, rows);
        let output = analyze(folder.path(), &["discrimination", &log]);
        assert_eq!(output.status.code(), Some(1), "{name}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(
            stderr.contains(name) && stderr.contains(message),
            "{stderr}"
        );
        assert!(output.stdout.is_empty());
    }
}

/// The trials of the session `experiment --discriminate` runs of `design` unless told, as the
/// session plans them.
fn session_trials(design: Design) -> u64 {
    // The files the spec names are read as it is parsed: an empty model (the default bottle) and
    // three seconds of a tone.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("model.toml"), "").unwrap();
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: 48_000,
        bits_per_sample: 32,
        sample_format: hound::SampleFormat::Float,
    };
    let mut take = hound::WavWriter::create(dir.path().join("take.wav"), spec).unwrap();
    for n in 0..144_000 {
        take.write_sample((n as f32 * 0.05).sin() * 0.5).unwrap();
    }
    take.finalize().unwrap();
    let study = Discriminate {
        design,
        recording: dir.path().join("take.wav"),
        model: dir.path().join("model.toml"),
        start_s: 0.0,
        duration_s: 2.0,
        repetitions: Discriminate::default_repetitions(design),
    };
    let spec = Spec::parse(&study.spec_text(), Path::new("--discriminate")).unwrap();
    plan_trials(&spec, 1).len() as u64
}

/// The planner plans the study that is run: unless told, each participant answers as many
/// trials as the session `experiment --discriminate` runs of the design (the guide's "23
/// participants" assumed 12 trials, the session ran 24: issue 49).
#[test]
fn the_planner_assumes_the_session_that_is_run() {
    for design in DISCRIMINATE_DESIGNS {
        let name = design.discrimination().unwrap().name();
        let output = analyze(
            &std::env::temp_dir(),
            &[
                "plan",
                "discrimination",
                "--design",
                name,
                "--below",
                "1",
                "--studies",
                "20",
                "--json",
            ],
        );
        let json = json_of(&output);
        assert_eq!(
            json["plan"]["trials_each"].as_u64(),
            Some(session_trials(design)),
            "{name}: {json}"
        );
    }
}

#[test]
fn the_planner_sizes_a_triangle_study_to_show_d_prime_below_one() {
    let output = analyze(
        &std::env::temp_dir(),
        &[
            "plan",
            "discrimination",
            "--below",
            "1",
            "--studies",
            "400",
            "--json",
        ],
    );
    let json = json_of(&output);
    let needed = &json["needed"];
    let participants = needed["participants"].as_u64().unwrap();
    let trials = needed["trials"].as_u64().unwrap();
    assert_eq!(trials, participants * session_trials(Design::Triangle));
    // A normal approximation: 1/3 + (z₀.₈ + z₀.₉₇₅)·√(pq/n) = P_c(1) needs n ≈ 240 trials.
    assert!((150..=350).contains(&trials), "{trials} trials");
    assert!(needed["power"].as_f64().unwrap() >= 0.8);
    // The size just short of it did not reach the power.
    let tried = json["tried"].as_array().unwrap();
    let short = tried
        .iter()
        .find(|size| size["participants"].as_u64() == Some(participants - 1))
        .expect("the size below was tried");
    assert!(short["power"].as_f64().unwrap() < 0.8);
}

#[test]
fn the_planner_refuses_a_goal_its_observers_cannot_show() {
    for (args, option) in [
        (&["--below", "1", "--d-prime", "1.5"][..], "--d-prime"),
        (&["--d-prime", "0"][..], "--d-prime"),
        (&["--below", "-1"][..], "--below"),
        (&["--below", "1", "--power", "1"][..], "--power"),
        (&["--below", "1", "--trials-each", "0"][..], "--trials-each"),
    ] {
        let mut full = vec!["plan", "discrimination"];
        full.extend(args);
        let output = analyze(&std::env::temp_dir(), &full);
        assert_eq!(output.status.code(), Some(2), "{args:?}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains(option), "{args:?}: {stderr}");
    }
}
