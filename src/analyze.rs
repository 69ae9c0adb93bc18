//! `sake-glug analyze paired|constant LOG.csv…`: the paper's two studies from their trial logs,
//! as tables on stdout or one JSON object (`--json`), and their figure (`--plot FILE.png`).
//! `sake-glug analyze discrimination LOG.csv…`: d′ of a triangle, 2AFC or ABX study.
//! `sake-glug analyze plan constant|discrimination …`: a design simulated before it is run.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Subcommand};
use sake_glug_io::text::{printable, quoted};
use sake_glug_study::{Discriminate, DISCRIMINATE_DESIGNS};

use sake_glug_analysis::{
    analyze_constant_logs, analyze_discrimination_logs, analyze_paired_logs, constant_json,
    discrimination_json, discrimination_plan_json, draw_constant_plot, draw_paired_plot,
    paired_json, plan_constant, plan_discrimination, plan_json, AnalysisError, ChiSquareTest,
    ConstantAnalysis, ConstantPlan, DiscriminationAnalysis, DiscriminationDesign,
    DiscriminationEstimate, DiscriminationGoal, DiscriminationPlan, DiscriminationPlanOutcome,
    DryRuns, PairedAnalysis, Placement, PlanOutcome, PsychometricFit, PsychometricOptions,
    MAX_RESAMPLES, POINT_PERCENTS,
};

#[derive(Args, Debug)]
pub struct AnalyzeArgs {
    #[command(subcommand)]
    design: Design,
}

#[derive(Subcommand, Debug)]
enum Design {
    /// Paired comparison: count matrix, Thurstone Case V scale, Mosteller's fit, agreement.
    Paired {
        #[command(flatten)]
        common: Common,
    },
    /// Constant stimuli: logistic psychometric function, 25/50/75 % points with 95 % intervals.
    Constant {
        #[command(flatten)]
        common: Common,
        /// Bootstrap resamples for the intervals (too many is refused with the limit).
        #[arg(long, default_value_t = PsychometricOptions::default().resamples as u64,
              value_parser = clap::value_parser!(u64).range(1..=MAX_RESAMPLES as u64))]
        resamples: u64,
        /// Seed of the resamples (the same seed gives the same intervals).
        #[arg(long, default_value_t = PsychometricOptions::default().seed)]
        seed: u64,
        /// Fits a lapse rate λ within 0..=MAX (the curve runs from λ to 1 − λ); 0 for none.
        #[arg(long, default_value_t = PsychometricOptions::default().max_lapse, value_name = "MAX")]
        lapse: f64,
    },
    /// Discrimination (triangle, 2AFC, ABX): proportion correct, the test against chance, d′
    /// under the design's decision model with its 95 % interval, pooled and per participant.
    Discrimination {
        /// The trial logs (CSV with a header), read together.
        #[arg(required = true, value_name = "LOG.csv")]
        logs: Vec<PathBuf>,
        /// Prints one JSON object instead of tables.
        #[arg(long)]
        json: bool,
        #[command(flatten)]
        dry_runs: DryRunLogs,
    },
    /// Plans a study: simulates its design with observers of a known curve or d′, and says how
    /// wide its intervals would be and how often they would hold the truth, or how many
    /// participants it needs.
    Plan {
        #[command(subcommand)]
        design: PlanDesign,
    },
}

#[derive(Subcommand, Debug)]
enum PlanDesign {
    /// Constant stimuli: each simulated study fitted as `analyze constant` fits a log.
    Constant(PlanConstantArgs),
    /// Discrimination: the participants a study needs to show d′ above zero, or below a bound,
    /// with a given power; each simulated study analysed as `analyze discrimination` does.
    Discrimination(PlanDiscriminationArgs),
}

#[derive(Args, Debug)]
struct PlanDiscriminationArgs {
    /// The design: triangle, 2afc or abx.
    #[arg(long, default_value = "triangle", value_parser = design_of)]
    design: DiscriminationDesign,
    /// The goal: show d′ below this bound (equivalence: the 95 % interval's upper end below
    /// it). Without it, the goal is to show d′ above zero (the test against chance).
    #[arg(long, allow_hyphen_values = true, value_name = "D")]
    below: Option<f64>,
    /// The simulated observers' d′ (default 0 with --below: people who cannot tell them apart).
    #[arg(long = "d-prime", allow_hyphen_values = true, value_name = "D")]
    d_prime: Option<f64>,
    /// The standard deviation of the participants' d′ around --d-prime.
    #[arg(
        long,
        default_value_t = 0.0,
        allow_hyphen_values = true,
        value_name = "D"
    )]
    spread: f64,
    /// Trials each participant answers (default: as many as the session `experiment
    /// --discriminate` runs of the design).
    #[arg(long = "trials-each", value_name = "N")]
    trials_each: Option<u32>,
    /// The power wanted (0.8 is 80 %).
    #[arg(long, default_value_t = 0.8, allow_hyphen_values = true)]
    power: f64,
    /// Studies simulated at each size tried.
    #[arg(long, default_value_t = 1000, value_name = "N")]
    studies: u32,
    /// Seed of the simulation (the same seed gives the same figures).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Prints one JSON object instead of the table.
    #[arg(long)]
    json: bool,
}

fn design_of(name: &str) -> Result<DiscriminationDesign, String> {
    DiscriminationDesign::from_name(name).ok_or_else(|| {
        format!(
            "`{}` is not a discrimination design: one of {}",
            quoted(name),
            DiscriminationDesign::names()
        )
    })
}

#[derive(Args, Debug)]
struct PlanConstantArgs {
    /// The comparison levels, rising, comma-separated (e.g. 0.18,0.22,0.26).
    #[arg(
        long,
        required = true,
        value_delimiter = ',',
        allow_hyphen_values = true,
        value_name = "L1,L2,…"
    )]
    levels: Vec<f64>,
    /// Presentations of each level to each participant.
    #[arg(long, value_name = "N")]
    repetitions: u32,
    /// Participants, their answers pooled into one fit.
    #[arg(long, default_value_t = 1, value_name = "N")]
    participants: u32,
    /// The simulated observers' 25 % point (a logistic through it and --p75).
    #[arg(long, allow_hyphen_values = true, value_name = "LEVEL")]
    p25: f64,
    /// Their 75 % point.
    #[arg(long, allow_hyphen_values = true, value_name = "LEVEL")]
    p75: f64,
    /// Studies simulated.
    #[arg(long, default_value_t = 1000, value_name = "N")]
    studies: u32,
    /// Bootstrap resamples of each study's intervals.
    #[arg(long, default_value_t = 1000, value_name = "N")]
    resamples: usize,
    /// Seed of the simulation (the same seed gives the same figures).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Prints one JSON object instead of the table.
    #[arg(long)]
    json: bool,
}

/// Whether a dry run's trials are analysed.
#[derive(Args, Debug)]
struct DryRunLogs {
    /// Analyses a dry run's trials too (`experiment --dry-run` marks them: answered while
    /// nothing played), saying how many; without it they are refused.
    #[arg(long = "dry-run-logs")]
    read: bool,
}

impl DryRunLogs {
    fn dry_runs(&self) -> DryRuns {
        match self.read {
            true => DryRuns::Read,
            false => DryRuns::Refused,
        }
    }
}

/// Says on stderr that `count` of the trials analysed were a dry run's.
fn warn_dry_run(count: usize) {
    if count > 0 {
        eprintln!(
            "warning: {count} of these trials were answered in a dry run (nothing played): \
             the figures are no listening result"
        );
    }
}

#[derive(Args, Debug)]
struct Common {
    /// The trial logs (CSV with a header), read together.
    #[arg(required = true, value_name = "LOG.csv")]
    logs: Vec<PathBuf>,
    /// Draws the figure into this PNG file.
    #[arg(long, value_name = "FILE.png")]
    plot: Option<PathBuf>,
    /// Prints one JSON object instead of tables.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    dry_runs: DryRunLogs,
}

/// Exit status 0 when analysed (and plotted), 1 for a bad log or an unwritable plot, 2 for a
/// bad option.
pub fn run(args: AnalyzeArgs) -> ExitCode {
    let outcome = match args.design {
        Design::Plan {
            design: PlanDesign::Constant(args),
        } => return plan(args),
        Design::Plan {
            design: PlanDesign::Discrimination(args),
        } => return plan_discrimination_run(args),
        Design::Discrimination {
            logs,
            json,
            dry_runs,
        } => analyze_discrimination_logs(&logs, dry_runs.dry_runs()).map(|analysis| {
            warn_dry_run(analysis.dry_run_trials);
            match json {
                true => discrimination_json(&analysis).to_string(),
                false => discrimination_text(&analysis),
            }
        }),
        Design::Paired { common } => analyze_paired_logs(&common.logs, common.dry_runs.dry_runs())
            .and_then(|analysis| {
                warn_dry_run(analysis.dry_run_trials);
                if let Some(path) = &common.plot {
                    draw_paired_plot(&analysis, path)?;
                }
                Ok(match common.json {
                    true => paired_json(&analysis).to_string(),
                    false => paired_text(&analysis),
                })
            }),
        Design::Constant {
            common,
            resamples,
            seed,
            lapse,
        } => {
            let options = PsychometricOptions {
                resamples: resamples as usize,
                seed,
                max_lapse: lapse,
            };
            analyze_constant_logs(&common.logs, &options, common.dry_runs.dry_runs()).and_then(
                |analysis| {
                    warn_dry_run(analysis.dry_run_trials);
                    if let Some(path) = &common.plot {
                        draw_constant_plot(&analysis, path)?;
                    }
                    Ok(match common.json {
                        true => constant_json(&analysis).to_string(),
                        false => constant_text(&analysis),
                    })
                },
            )
        }
    };
    match outcome {
        Ok(report) => {
            println!("{report}");
            ExitCode::SUCCESS
        }
        Err(error) => {
            eprintln!("error: {error}");
            match error {
                AnalysisError::Option(_) => ExitCode::from(2),
                _ => ExitCode::FAILURE,
            }
        }
    }
}

/// Exit status 0 when simulated, 2 for an argument refused (named as its option).
fn plan(args: PlanConstantArgs) -> ExitCode {
    let plan = ConstantPlan {
        levels: args.levels,
        repetitions: args.repetitions,
        participants: args.participants,
        p25: args.p25,
        p75: args.p75,
        studies: args.studies,
        resamples: args.resamples,
        seed: args.seed,
    };
    match plan_constant(&plan) {
        Ok(outcome) => {
            match args.json {
                true => println!("{}", plan_json(&outcome)),
                false => println!("{}", plan_text(&outcome)),
            }
            ExitCode::SUCCESS
        }
        Err(error) => {
            eprintln!("error: --{}: {}", error.argument, error.message);
            ExitCode::from(2)
        }
    }
}

/// The trials of the session `experiment --discriminate` runs of `design` unless told: what a
/// plan assumes unless told, so that it plans the study that is run.
fn session_trials(design: DiscriminationDesign) -> u32 {
    let design = DISCRIMINATE_DESIGNS
        .into_iter()
        .find(|study| study.discrimination() == Some(design))
        .expect("every discrimination design can be run");
    Discriminate::default_trials(design)
}

/// Exit status 0 when simulated, 2 for an argument refused (named as its option).
fn plan_discrimination_run(args: PlanDiscriminationArgs) -> ExitCode {
    let goal = match args.below {
        Some(bound) => DiscriminationGoal::Below(bound),
        None => DiscriminationGoal::AboveZero,
    };
    let plan = DiscriminationPlan {
        design: args.design,
        goal,
        d_prime: args.d_prime.unwrap_or(0.0),
        spread: args.spread,
        trials_each: args
            .trials_each
            .unwrap_or_else(|| session_trials(args.design)),
        power: args.power,
        studies: args.studies,
        seed: args.seed,
    };
    match plan_discrimination(&plan) {
        Ok(outcome) => {
            match args.json {
                true => println!("{}", discrimination_plan_json(&outcome)),
                false => println!("{}", discrimination_plan_text(&outcome)),
            }
            ExitCode::SUCCESS
        }
        Err(error) => {
            eprintln!("error: --{}: {}", error.argument, error.message);
            ExitCode::from(2)
        }
    }
}

fn discrimination_plan_text(outcome: &DiscriminationPlanOutcome) -> String {
    let plan = &outcome.plan;
    let goal = match plan.goal {
        DiscriminationGoal::AboveZero => {
            "show d′ above zero (the one-sided exact test against chance at 5 %)".to_owned()
        }
        DiscriminationGoal::Below(bound) => {
            format!("show d′ < {bound} (the 95 % interval's upper end below it)")
        }
    };
    let mut text = format!(
        "{}\nobservers: d′ = {} (spread {}), proportion correct {:.4}\ngoal: {goal} with \
         {:.0} % power\n{} trials a participant; {} studies a size, seed {}\n\n\
         participants  trials  power (95 % interval)\n",
        plan.design.decision_model(),
        plan.d_prime,
        plan.spread,
        outcome.proportion_correct,
        100.0 * plan.power,
        plan.trials_each,
        plan.studies,
        plan.seed,
    );
    for size in &outcome.tried {
        text += &format!(
            "{:>12}  {:>6}  {:.1} % ({:.1} … {:.1} %)\n",
            size.participants,
            size.trials,
            100.0 * size.power,
            100.0 * size.power_low,
            100.0 * size.power_high
        );
    }
    text += &match outcome.needed {
        Some(size) => format!(
            "\nneeded: {} participants × {} trials = {} trials (power {:.1} %)",
            size.participants,
            plan.trials_each,
            size.trials,
            100.0 * size.power
        ),
        None => format!(
            "\nnot reached with {} participants: more trials each, or a larger bound",
            outcome.tried.last().map_or(0, |size| size.participants)
        ),
    };
    text
}

fn estimate_text(estimate: &DiscriminationEstimate, design: DiscriminationDesign) -> String {
    let d_prime = |d: f64| match d.is_finite() {
        true => format!("{d:.3}"),
        false => "∞".into(),
    };
    let interval = match estimate.d_prime_interval {
        Some((low, high)) => format!("[{}, {}]", d_prime(low), d_prime(high)),
        None => "empty (below chance)".into(),
    };
    format!(
        "  {} of {} right: {:.3} (exact 95 % [{:.3}, {:.3}]); against chance {}\n  d′ = {} \
         {interval}\n  {}\n",
        estimate.correct,
        estimate.trials,
        estimate.proportion,
        estimate.proportion_low,
        estimate.proportion_high,
        match estimate.p_value < 1e-4 {
            true => "p < 0.0001".to_owned(),
            false => format!("p = {:.4}", estimate.p_value),
        },
        d_prime(estimate.d_prime),
        estimate.sentence(design),
    )
}

fn discrimination_text(analysis: &DiscriminationAnalysis) -> String {
    let design = analysis.design;
    let mut text = format!(
        "{}; chance {:.3}; d′ intervals: profile likelihood, 95 %\n\nall participants\n",
        design.decision_model(),
        design.chance()
    );
    text += &estimate_text(&analysis.pooled, design);
    for (name, estimate) in &analysis.participants {
        text += &format!("\n{}\n", printable(name));
        text += &estimate_text(estimate, design);
    }
    text.trim_end().to_owned()
}

fn plan_text(outcome: &PlanOutcome) -> String {
    let plan = &outcome.plan;
    let (first, last) = (plan.levels[0], plan.levels[plan.levels.len() - 1]);
    let mut text = format!(
        "{} levels ({first} … {last}) × {} repetitions × {} participant(s) = {} trials a \
         study, pooled\nobservers: a logistic with its 25 % point at {} and its 75 % at {}\n\
         {} studies simulated, {} fitted, {} without a fit; {} resamples each, seed {}\n\n",
        plan.levels.len(),
        plan.repetitions,
        plan.participants,
        outcome.trials_a_study,
        plan.p25,
        plan.p75,
        plan.studies,
        outcome.fitted,
        outcome.unfitted,
        plan.resamples,
        plan.seed,
    );
    text += "point  truth    median estimate  95 % of estimates  median interval width  \
             coverage\n";
    for point in &outcome.points {
        text += &format!(
            "{:>2} %   {:<7.4}  {:<15.4}  {:.4} … {:.4}    {:<21.4}  {:.1} % ({:.1} … {:.1} %)\n",
            point.percent,
            point.truth,
            point.median_estimate,
            point.estimate_low,
            point.estimate_high,
            point.median_width,
            100.0 * point.coverage,
            100.0 * point.coverage_low,
            100.0 * point.coverage_high,
        );
    }
    text += "\ninterval: each study's 95 % BCa interval; coverage: the share of the fitted \
             studies whose interval holds the truth (in brackets, its 95 % Clopper-Pearson \
             interval)\n";
    text.trim_end().to_owned()
}

fn test_text(name: &str, test: Option<ChiSquareTest>, absent: &str) -> String {
    match test {
        Some(test) => format!(
            "{name}: χ²({}) = {:.2}, p = {:.4}\n",
            test.df, test.chi2, test.p
        ),
        None => format!("{name}: {absent}\n"),
    }
}

fn matrix_text(title: &str, names: &[String], cell: impl Fn(usize, usize) -> String) -> String {
    let width = names
        .iter()
        .map(|name| name.chars().count())
        .max()
        .unwrap_or(0)
        .max(8);
    let mut text = format!("{title}\n{:width$}", "");
    for name in names {
        text += &format!(" {name:>width$}");
    }
    text.push('\n');
    for (i, name) in names.iter().enumerate() {
        text += &format!("{name:width$}");
        for j in 0..names.len() {
            text += &format!(" {:>width$}", cell(i, j));
        }
        text.push('\n');
    }
    text
}

fn paired_text(analysis: &PairedAnalysis) -> String {
    // The names come from the logs: shown with their control characters escaped, and cut short
    // (every cell of the matrices is as wide as the widest name).
    let names: Vec<String> = analysis.stimuli.iter().map(|name| quoted(name)).collect();
    let mut text = format!(
        "{} trials, {} participant(s), {} stimuli\n\n",
        analysis.trials,
        analysis.participants.len(),
        names.len()
    );
    let diagonal = |i: usize, j: usize, value: String| if i == j { "-".into() } else { value };
    text += &matrix_text(
        "times the row was chosen over the column",
        &names,
        |i, j| diagonal(i, j, analysis.counts[i][j].to_string()),
    );
    text += &matrix_text("\nproportions", &names, |i, j| {
        diagonal(i, j, format!("{:.3}", analysis.proportions[i][j]))
    });
    text += &matrix_text(
        "\nz (proportions clipped to [1/2n, 1 − 1/2n])",
        &names,
        |i, j| format!("{:.3}", analysis.z[i][j]),
    );
    text += &matrix_text(
        "\npredicted proportions Φ(Sᵢ − Sⱼ)",
        &names,
        |i, j| diagonal(i, j, format!("{:.3}", analysis.predicted[i][j])),
    );
    text += "\nscale (Case V, lowest 0)\n";
    let mut order: Vec<usize> = (0..names.len()).collect();
    order.sort_by(|&a, &b| analysis.scale[b].total_cmp(&analysis.scale[a]));
    for index in order {
        text += &format!("  {:>8.3}  {}\n", analysis.scale[index], names[index]);
    }
    text.push('\n');
    text += &test_text(
        "fit (Mosteller)",
        analysis.fit,
        "none with two stimuli (no degree of freedom)",
    );
    text += &test_text(
        "agreement of participants (homogeneity of choices)",
        analysis.agreement,
        "needs two or more participants",
    );
    text.trim_end().to_owned()
}

fn fit_text(fit: &PsychometricFit) -> String {
    let curve = fit.curve;
    let mut text = format!(
        "  ψ(x) = {:.3} + {:.3}·σ({:.3} + {:.3}·x)\n",
        curve.lapse,
        1.0 - 2.0 * curve.lapse,
        curve.intercept,
        curve.slope
    );
    let (lowest, highest) = fit.level_range();
    let tested = format!("{lowest}–{highest}");
    // An estimate only within the levels tested; beyond them the curve is the logistic's shape.
    let end = |level: f64| match Placement::of(level, lowest, highest) {
        Placement::Within => format!("{level:.4}"),
        Placement::BelowLevels => format!("below {lowest}"),
        Placement::AboveLevels => format!("above {highest}"),
    };
    for (percent, point) in POINT_PERCENTS.iter().zip(&fit.points) {
        text += &match point.placement {
            Placement::Within => format!(
                "  {percent:>2} %: {:.4}  95 % [{}, {}]\n",
                point.value,
                end(point.low),
                end(point.high)
            ),
            Placement::BelowLevels => {
                format!("  {percent:>2} %: below the levels tested ({tested}): no estimate\n")
            }
            Placement::AboveLevels => {
                format!("  {percent:>2} %: above the levels tested ({tested}): no estimate\n")
            }
        };
    }
    if fit.failed_resamples > 0 {
        text += &format!(
            "  ({} of {} resamples had no finite fit and are left out)\n",
            fit.failed_resamples, fit.resamples
        );
    }
    text
}

fn constant_text(analysis: &ConstantAnalysis) -> String {
    let pooled = &analysis.pooled;
    let mut text = String::from("level     trials  chosen  proportion\n");
    for level in &pooled.levels {
        text += &format!(
            "{:<9} {:>6}  {:>6}  {:>10.3}\n",
            level.level,
            level.trials,
            level.chosen,
            level.proportion()
        );
    }
    text += &format!("\nall participants ({} resamples)\n", pooled.resamples);
    text += &fit_text(pooled);
    for (name, fit) in &analysis.participants {
        text += &format!("\n{}\n", printable(name));
        text += &match fit {
            Ok(fit) => fit_text(fit),
            Err(error) => format!("  {error}\n"),
        };
    }
    text.trim_end().to_owned()
}
