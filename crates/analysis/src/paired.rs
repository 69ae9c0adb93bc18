//! The paired-comparison study (the paper's §3): every ordered pair of stimuli, the participant
//! names the one that is more so. Scaled by Thurstone's Case V (docs/studies.md).

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use sake_glug_io::text::quoted;
use serde::Serialize;
use statrs::distribution::{ChiSquared, ContinuousCDF, Normal};

use super::error::AnalysisError;
use super::log::{read_rows, DryRuns, Rows};

/// The columns the paired analysis reads, in the order of [`PairedTrial`]'s fields.
pub const PAIRED_COLUMNS: [&str; 4] = ["participant", "first", "second", "answer"];

/// One answered trial: two stimuli in the order presented, and the one chosen.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PairedTrial {
    /// Who answered.
    pub participant: String,
    /// The stimulus presented first.
    pub first: String,
    /// The stimulus presented second.
    pub second: String,
    /// The stimulus chosen: `first` or `second`.
    pub answer: String,
}

/// A χ² test: the statistic, its degrees of freedom and the probability of a statistic at least
/// as large under the null hypothesis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ChiSquareTest {
    /// The statistic.
    pub chi2: f64,
    /// Degrees of freedom.
    pub df: u32,
    /// P(χ²(df) ≥ chi2).
    pub p: f64,
}

impl ChiSquareTest {
    fn of(chi2: f64, df: u32) -> Option<Self> {
        let distribution = ChiSquared::new(f64::from(df)).ok()?;
        Some(Self {
            chi2,
            df,
            p: distribution.sf(chi2),
        })
    }
}

/// Thurstone's Case V scale of a paired-comparison study and its tests.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PairedAnalysis {
    /// The stimuli, in the order they first appear in the logs.
    pub stimuli: Vec<String>,
    /// `counts[i][j]`: how often stimulus i was chosen over stimulus j (the paper's Table 1).
    pub counts: Vec<Vec<u32>>,
    /// `proportions[i][j]`: counts[i][j] over the trials comparing i and j (½ on the diagonal).
    pub proportions: Vec<Vec<f64>>,
    /// The unit-normal deviates of the proportions, each first clipped to
    /// [1/(2n), 1 − 1/(2n)] with n the pair's trials.
    pub z: Vec<Vec<f64>>,
    /// Each stimulus's scale value: the mean of its row of `z`, the lowest shifted to 0.
    pub scale: Vec<f64>,
    /// `predicted[i][j]` = Φ(scale[i] − scale[j]), the proportions the scale predicts.
    pub predicted: Vec<Vec<f64>>,
    /// Mosteller's goodness of fit of the scale; `None` with two stimuli (no degree of freedom).
    pub fit: Option<ChiSquareTest>,
    /// The agreement of the participants: a χ² test of homogeneity of the participants ×
    /// chosen-stimulus table; `None` with fewer than two participants.
    pub agreement: Option<ChiSquareTest>,
    /// The participants, in the order they first appear.
    pub participants: Vec<String>,
    /// Trials read.
    pub trials: usize,
    /// How many of them a dry run answered (nothing played): read only with [`DryRuns::Read`].
    pub dry_run_trials: usize,
}

/// Reads paired-comparison logs (columns [`PAIRED_COLUMNS`], others ignored) and scales them;
/// a dry run's trials as `dry_runs` says.
pub fn analyze_paired_logs(
    files: &[impl AsRef<Path>],
    dry_runs: DryRuns,
) -> Result<PairedAnalysis, AnalysisError> {
    let Rows {
        rows,
        dry_run_trials,
    } = read_rows(files, PAIRED_COLUMNS, dry_runs)?;
    let mut trials = Vec::with_capacity(rows.len());
    for row in &rows {
        for (index, column) in PAIRED_COLUMNS.iter().enumerate() {
            if row.fields[index].is_empty() {
                return Err(row.error(column, "empty"));
            }
        }
        let [participant, first, second, answer] = row.fields.clone();
        if first == second {
            return Err(row.error(
                PAIRED_COLUMNS[2],
                format!("{} is also the first stimulus", row.quoted(2)),
            ));
        }
        if answer != first && answer != second {
            return Err(row.error(
                PAIRED_COLUMNS[3],
                format!(
                    "{} is neither stimulus of this trial ({} or {})",
                    row.quoted(3),
                    row.quoted(1),
                    row.quoted(2)
                ),
            ));
        }
        trials.push(PairedTrial {
            participant,
            first,
            second,
            answer,
        });
    }
    let analysis =
        scale_paired(&trials).map_err(|message| AnalysisError::design(files, message))?;
    Ok(PairedAnalysis {
        dry_run_trials,
        ..analysis
    })
}

/// The most stimuli a paired analysis scales: its matrices grow with the square of the count
/// (256² cells each), and Case V needs every pair compared (32,640 pairs), far past any study
/// of people (the paper's has 3).
pub const MAX_PAIRED_STIMULI: usize = 256;

/// The Case V scale of `trials`, or what keeps them from being scaled: fewer than two stimuli,
/// more than [`MAX_PAIRED_STIMULI`], or a pair of stimuli never compared.
pub fn scale_paired(trials: &[PairedTrial]) -> Result<PairedAnalysis, String> {
    let mut stimuli: Vec<String> = Vec::new();
    let mut participants: Vec<String> = Vec::new();
    let mut stimulus_index: HashMap<&str, usize> = HashMap::new();
    let mut participant_index: HashMap<&str, usize> = HashMap::new();
    let index_in = |names: &mut Vec<String>, index: &mut HashMap<_, usize>, name| {
        *index.entry(name).or_insert_with(|| {
            names.push(String::from(name));
            names.len() - 1
        })
    };
    let mut choices = Vec::with_capacity(trials.len());
    for trial in trials {
        let first = index_in(&mut stimuli, &mut stimulus_index, trial.first.as_str());
        let second = index_in(&mut stimuli, &mut stimulus_index, trial.second.as_str());
        if stimuli.len() > MAX_PAIRED_STIMULI {
            return Err(format!(
                "more than {MAX_PAIRED_STIMULI} stimuli (the {}th is `{}`): a paired analysis \
                 scales at most {MAX_PAIRED_STIMULI}, whose every pair must be compared",
                stimuli.len(),
                quoted(&stimuli[stimuli.len() - 1])
            ));
        }
        let participant = index_in(
            &mut participants,
            &mut participant_index,
            trial.participant.as_str(),
        );
        let (chosen, other) = if trial.answer == trial.first {
            (first, second)
        } else {
            (second, first)
        };
        choices.push((participant, chosen, other));
    }
    let n = stimuli.len();
    if n < 2 {
        return Err(match stimuli.first() {
            None => "no trials".into(),
            Some(only) => format!(
                "one stimulus only (`{}`): scaling needs two or more",
                quoted(only)
            ),
        });
    }
    let pairs = n * (n - 1) / 2;
    if pairs > trials.len() {
        return Err(format!(
            "{n} stimuli make {pairs} pairs, and there are {} trials: some pair is never \
             compared, and Case V needs every pair",
            trials.len()
        ));
    }
    let mut counts = vec![vec![0u32; n]; n];
    // Who chose what, kept sparse: a participant chooses few of many stimuli. Ordered, so that
    // the χ² sums its cells in one order in every process (a HashMap's order is random per map,
    // and so were the last bits of the sum).
    let mut wins: BTreeMap<(usize, usize), u32> = BTreeMap::new();
    for &(participant, chosen, other) in &choices {
        counts[chosen][other] += 1;
        *wins.entry((participant, chosen)).or_default() += 1;
    }
    for i in 0..n {
        for j in i + 1..n {
            if counts[i][j] + counts[j][i] == 0 {
                return Err(format!(
                    "`{}` and `{}` are never compared: Case V needs every pair",
                    quoted(&stimuli[i]),
                    quoted(&stimuli[j])
                ));
            }
        }
    }
    let normal = Normal::standard();
    let trials_of = |i: usize, j: usize| f64::from(counts[i][j] + counts[j][i]);
    let proportions: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| match i == j {
                    true => 0.5,
                    false => f64::from(counts[i][j]) / trials_of(i, j),
                })
                .collect()
        })
        .collect();
    let z: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| match i == j {
                    true => 0.0,
                    false => {
                        // A proportion of 0 or 1 has no finite deviate: the 1/(2n) rule.
                        let bound = 1.0 / (2.0 * trials_of(i, j));
                        normal.inverse_cdf(proportions[i][j].clamp(bound, 1.0 - bound))
                    }
                })
                .collect()
        })
        .collect();
    let means: Vec<f64> = z
        .iter()
        .map(|row| row.iter().sum::<f64>() / n as f64)
        .collect();
    let lowest = means.iter().copied().fold(f64::INFINITY, f64::min);
    let scale: Vec<f64> = means.iter().map(|mean| mean - lowest).collect();
    let predicted: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| normal.cdf(scale[i] - scale[j])).collect())
        .collect();
    let fit = mosteller_fit(&proportions, &predicted, trials_of);
    let agreement = homogeneity(&wins, participants.len(), n);
    Ok(PairedAnalysis {
        stimuli,
        counts,
        proportions,
        z,
        scale,
        predicted,
        fit,
        agreement,
        participants,
        trials: trials.len(),
        // Trials handed in are data; the log reader counts a dry run's.
        dry_run_trials: 0,
    })
}

/// Mosteller (1951): the observed and predicted proportions of each pair through the
/// variance-stabilising arcsine, whose variance is 1/(4n) for n trials; the sum of the squared
/// differences over their variance is χ² with (k − 1)(k − 2)/2 degrees of freedom for k stimuli.
fn mosteller_fit(
    observed: &[Vec<f64>],
    predicted: &[Vec<f64>],
    trials_of: impl Fn(usize, usize) -> f64,
) -> Option<ChiSquareTest> {
    let k = observed.len();
    let arcsine = |p: f64| p.sqrt().asin();
    let mut chi2 = 0.0;
    for i in 0..k {
        for j in i + 1..k {
            let difference = arcsine(observed[i][j]) - arcsine(predicted[i][j]);
            chi2 += 4.0 * trials_of(i, j) * difference * difference;
        }
    }
    let df = ((k - 1) * (k - 2) / 2) as u32;
    (df > 0).then(|| ChiSquareTest::of(chi2, df)).flatten()
}

/// Pearson's χ² test of homogeneity of a participants × stimuli table of how often each
/// participant chose each stimulus (`wins`, its cells that are not 0): do the participants share
/// one order? A stimulus nobody chose carries no information and is left out. (P − 1)(k − 1)
/// degrees of freedom. χ² = Σ (O − E)²/E = Σ O²/E − N over every cell, the second form summed
/// over the cells that are not 0 alone.
fn homogeneity(
    wins: &BTreeMap<(usize, usize), u32>,
    participants: usize,
    stimuli: usize,
) -> Option<ChiSquareTest> {
    let mut row_totals = vec![0.0; participants];
    let mut column_totals = vec![0.0; stimuli];
    for (&(participant, stimulus), &count) in wins {
        row_totals[participant] += f64::from(count);
        column_totals[stimulus] += f64::from(count);
    }
    let columns = column_totals.iter().filter(|&&total| total > 0.0).count();
    if participants < 2 || columns < 2 {
        return None;
    }
    let total: f64 = row_totals.iter().sum();
    let mut sum = 0.0;
    for (&(participant, stimulus), &count) in wins {
        let expected = row_totals[participant] * column_totals[stimulus] / total;
        sum += f64::from(count) * f64::from(count) / expected;
    }
    let df = ((participants - 1) * (columns - 1)) as u32;
    ChiSquareTest::of((sum - total).max(0.0), df)
}
