//! Paired comparison: the count matrix back from the trials, Case V by hand, the tests' degrees
//! of freedom.

use std::fmt::Write;

use sake_glug_analysis::{scale_paired, PairedTrial};
use statrs::distribution::{ContinuousCDF, Normal};

use crate::{analyze, json_of};

/// The stimuli of the paper's §3: the two-sinusoid model, the high-frequency wave alone, the
/// low-frequency wave alone (the names of experiments/paired-waves.toml).
const STIMULI: [&str; 3] = ["model", "high", "low"];

/// The paper's Table 1 (§3), read as its scale needs: `[row][column]` is how often the row's
/// wave was chosen over the column's (the caption says the reverse, but only this reading puts
/// the modeled wave first, as fig. 2 and the text do). Six participants, each judging every
/// ordered pair 3 times: 36 answers a pair.
const TABLE_1: [[u32; 3]; 3] = [[0, 29, 34], [7, 0, 31], [2, 5, 0]];
const PARTICIPANTS: usize = 6;

/// The Thurstone scale of Table 1 to 3 decimals, as computed from the table in the paper's data
/// (the paper shows it only as fig. 2): modeled, high-frequency, low-frequency.
const TABLE_1_SCALE: [f64; 3] = [1.711, 0.967, 0.0];

/// Table 1 entered as trials, shared with the docs.
const TABLE_1_LOG: &str = "tests/fixtures/studies/table-1.csv";

fn fixture(path: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// The table as a runner's log: each participant's trials, every ordered pair 3 times (18), the
/// choices of each pair dealt out to the participants in turn, so every participant has some of
/// each answer, and the order of presentation alternating.
fn log_of_table(table: &[[u32; 3]; 3], participants: usize) -> String {
    let mut log = String::from("participant,trial,design,first,second,answer\n");
    let mut trial = vec![0; participants];
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        let answers = std::iter::repeat_n(i, table[i][j] as usize)
            .chain(std::iter::repeat_n(j, table[j][i] as usize));
        for (index, chosen) in answers.enumerate() {
            let participant = index % participants;
            // Alternate the order of presentation: both ordered pairs.
            let (first, second) = if (index / participants).is_multiple_of(2) {
                (i, j)
            } else {
                (j, i)
            };
            trial[participant] += 1;
            writeln!(
                log,
                "P{},{},paired,{},{},{}",
                participant + 1,
                trial[participant],
                STIMULI[first],
                STIMULI[second],
                STIMULI[chosen]
            )
            .unwrap();
        }
    }
    log
}

/// The fixture is the table dealt out by the code above (so the docs that read it read Table 1),
/// in the paper's design: 6 participants, each every ordered pair 3 times.
#[test]
fn the_table_1_log_is_the_papers_design() {
    let log = std::fs::read_to_string(fixture(TABLE_1_LOG)).unwrap();
    assert_eq!(
        log,
        log_of_table(&TABLE_1, PARTICIPANTS),
        "{TABLE_1_LOG} is not Table 1 entered as trials: write it from `log_of_table`"
    );
    let mut reader = csv::Reader::from_reader(log.as_bytes());
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    assert_eq!(rows.len(), PARTICIPANTS * 18);
    for participant in 1..=PARTICIPANTS {
        let name = format!("P{participant}");
        for first in STIMULI {
            for second in STIMULI.iter().filter(|&&second| second != first) {
                let presented = rows
                    .iter()
                    .filter(|row| row[0] == name && &row[3] == first && &row[4] == *second)
                    .count();
                assert_eq!(presented, 3, "{name}: {first} then {second}");
            }
        }
    }
}

#[test]
fn table_1_entered_as_trials_gives_back_its_counts_and_the_papers_scale() {
    let json = json_of(&analyze(&fixture(""), &["paired", TABLE_1_LOG, "--json"]));
    let stimuli: Vec<&str> = json["stimuli"]
        .as_array()
        .unwrap()
        .iter()
        .map(|name| name.as_str().unwrap())
        .collect();
    assert_eq!(stimuli, STIMULI);
    let counts: Vec<Vec<u32>> = serde_json::from_value(json["counts"].clone()).unwrap();
    assert_eq!(counts, TABLE_1.map(Vec::from).to_vec());
    let scale = json["scale"].as_object().unwrap();
    for (name, paper) in STIMULI.iter().zip(TABLE_1_SCALE) {
        let value = scale[*name].as_f64().unwrap();
        assert_eq!(
            format!("{value:.3}"),
            format!("{paper:.3}"),
            "{name}: {scale:?}"
        );
    }
    assert_eq!(json["participants"], PARTICIPANTS);
    assert_eq!(json["trials"], 108);
}

/// The scale as Thurstone's Case V has it, computed here from the table directly.
#[test]
fn the_scale_is_case_v_by_hand() {
    let trials = trials_of_table(&TABLE_1);
    let analysis = scale_paired(&trials).unwrap();
    let normal = Normal::standard();
    let z = |i: usize, j: usize| {
        let (a, b) = (TABLE_1[i][j], TABLE_1[j][i]);
        if i == j {
            0.0
        } else {
            normal.inverse_cdf(f64::from(a) / f64::from(a + b))
        }
    };
    let means: Vec<f64> = (0..3)
        .map(|i| (0..3).map(|j| z(i, j)).sum::<f64>() / 3.0)
        .collect();
    let lowest = means.iter().copied().fold(f64::INFINITY, f64::min);
    for (computed, mean) in analysis.scale.iter().zip(&means) {
        assert!(
            (computed - (mean - lowest)).abs() < 1e-12,
            "{:?} vs {means:?}",
            analysis.scale
        );
    }
    let fit = analysis.fit.expect("three stimuli: one degree of freedom");
    assert_eq!(fit.df, 1);
    assert!(fit.p > 0.0 && fit.p <= 1.0);
}

/// A unanimous pair (p = 1) is clipped to 1 − 1/(2n), not scaled at infinity.
#[test]
fn a_unanimous_pair_is_clipped_by_the_one_over_2n_rule() {
    let trials = trials_of_table(&[[0, 6, 6], [0, 0, 3], [0, 3, 0]]);
    let analysis = scale_paired(&trials).unwrap();
    let expected = Normal::standard().inverse_cdf(1.0 - 1.0 / 12.0);
    assert!(
        (analysis.z[0][1] - expected).abs() < 1e-12,
        "{:?}",
        analysis.z
    );
    assert!(analysis.scale.iter().all(|value| value.is_finite()));
}

fn trials_of_table(table: &[[u32; 3]; 3]) -> Vec<PairedTrial> {
    let mut trials = Vec::new();
    for i in 0..3 {
        for j in 0..3 {
            for _ in 0..table[i][j] {
                trials.push(PairedTrial {
                    participant: "p".into(),
                    first: STIMULI[i.min(j)].into(),
                    second: STIMULI[i.max(j)].into(),
                    answer: STIMULI[i].into(),
                });
            }
        }
    }
    trials
}

/// 21 participants, 3 stimuli: the agreement test has (21 − 1)(3 − 1) = 40 degrees of freedom,
/// the paper's χ²(40). Participants who all answer alike agree (p near 1); two camps do not.
#[test]
fn the_agreement_test_has_the_papers_40_degrees_of_freedom_for_21_participants() {
    let camp = |participant: usize, reversed: bool| {
        let mut trials = Vec::new();
        for (i, j) in [(0, 1), (0, 2), (1, 2)] {
            for repetition in 0..6 {
                let (winner, loser) = if reversed { (j, i) } else { (i, j) };
                let (first, second) = if repetition % 2 == 0 { (i, j) } else { (j, i) };
                // One answer in six goes the other way, so no pair is unanimous.
                let chosen = if repetition == 5 { loser } else { winner };
                trials.push(PairedTrial {
                    participant: format!("p{participant}"),
                    first: STIMULI[first].into(),
                    second: STIMULI[second].into(),
                    answer: STIMULI[chosen].into(),
                });
            }
        }
        trials
    };
    let alike: Vec<PairedTrial> = (0..21).flat_map(|p| camp(p, false)).collect();
    let agreement = scale_paired(&alike).unwrap().agreement.unwrap();
    assert_eq!(agreement.df, 40);
    assert!(
        agreement.chi2.abs() < 1e-9 && agreement.p > 0.999,
        "{agreement:?}"
    );
    let split: Vec<PairedTrial> = (0..21).flat_map(|p| camp(p, p % 2 == 1)).collect();
    let agreement = scale_paired(&split).unwrap().agreement.unwrap();
    assert_eq!(agreement.df, 40);
    assert!(agreement.p < 1e-6, "{agreement:?}");
}

#[test]
fn the_text_report_shows_the_matrix_the_scale_and_both_tests() {
    let folder = tempfile::tempdir().unwrap();
    std::fs::copy(fixture(TABLE_1_LOG), folder.path().join("log.csv")).unwrap();
    let output = analyze(folder.path(), &["paired", "log.csv", "--plot", "scale.png"]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = String::from_utf8(output.stdout).unwrap();
    // Agreement: (6 participants − 1)(3 stimuli − 1) = 10 degrees of freedom.
    for expected in ["chosen over", "scale", "Mosteller", "χ²(1)", "χ²(10)"] {
        assert!(text.contains(expected), "no `{expected}` in\n{text}");
    }
    let png = std::fs::read(folder.path().join("scale.png")).unwrap();
    assert!(png.starts_with(b"\x89PNG"));
    let left: Vec<_> = std::fs::read_dir(folder.path()).unwrap().collect();
    assert_eq!(left.len(), 2, "the log and the plot, no temporary file");
}

/// Determinism: the same trials give the same bits in every run. Each HashMap iterates in an
/// order of its own, so a sum over one (the participants' χ² did) changes its last bits from
/// map to map, which Python saw as the package and the command line disagreeing.
#[test]
fn the_same_trials_give_the_same_bits_every_time() {
    let mut trials = Vec::new();
    // Many participants and stimuli, so that the cells have many orders to be summed in.
    let stimuli: Vec<String> = (0..12).map(|s| format!("s{s}")).collect();
    for participant in 0..30 {
        for (i, first) in stimuli.iter().enumerate() {
            for (j, second) in stimuli.iter().enumerate().skip(i + 1) {
                let answer = if (participant * 7 + i * 3 + j) % 5 < 3 {
                    first
                } else {
                    second
                };
                trials.push(PairedTrial {
                    participant: format!("P{participant}"),
                    first: first.clone(),
                    second: second.clone(),
                    answer: answer.clone(),
                });
            }
        }
    }
    let bits = |analysis: &sake_glug_analysis::PairedAnalysis| {
        let agreement = analysis.agreement.expect("a homogeneity test");
        (agreement.chi2.to_bits(), agreement.p.to_bits())
    };
    let first = bits(&scale_paired(&trials).unwrap());
    for _ in 0..20 {
        assert_eq!(bits(&scale_paired(&trials).unwrap()), first);
    }
}
