//! docs/paper.md (`cargo xtask docs`, or `cargo xtask docs paper` alone): every number the paper
//! reports (the project's PAPER-DATA.md) beside what the release CLI gives for it, computed each
//! time the page is made, with a verdict and the tolerance it was judged by.
//!
//! The paper's figures are typed here once, each with its section; the product's are never typed:
//! each comes from a run of `sake-glug` (`analyze paired` of Table 1 entered as trials, `analyze
//! plan constant` of the §4.4 design, `fit` of renders at the paper's 25 kHz, `render --state` of
//! the 5 s pour, `parameters` for the defaults). The page is written all or nothing.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use anyhow::{anyhow, Context};
use serde_json::Value;

use super::{cli, output, stamp, target_dir};

/// The page this module writes.
pub const PAGE: &str = "docs/paper.md";

/// Table 1 (§3) entered as trials, written and checked by tests/analysis/paired.rs.
const TABLE_1_LOG: &str = "tests/fixtures/studies/table-1.csv";
/// Table 1 as printed, `[row][column]` = the row's wave chosen over the column's.
const TABLE_1: [[u64; 3]; 3] = [[0, 29, 34], [7, 0, 31], [2, 5, 0]];
/// The names experiments/paired-waves.toml gives the three waves, in Table 1's order.
const WAVES: [(&str, &str); 3] = [
    ("model", "modeled wave"),
    ("high", "high-frequency wave"),
    ("low", "low-frequency wave"),
];
/// The Thurstone scale of Table 1 as PAPER-DATA.md computes it (fig. 2 shows it as a plot).
const TABLE_1_SCALE: [f64; 3] = [1.711, 0.967, 0.0];
/// §3: the participants' consistency, χ²(40) = 64.33, p < 0.01.
const AGREEMENT: (f64, u64) = (64.33, 40);

/// §4.4: the comparison levels of c, the repetitions, the participants, the 25 % and 75 %
/// points of the logistic fit.
const PAPER_LEVELS: [f64; 9] = [0.18, 0.22, 0.26, 0.29, 0.33, 0.37, 0.41, 0.45, 0.49];
const PAPER_REPETITIONS: u32 = 10;
const PAPER_PARTICIPANTS: u32 = 3;
const PAPER_QUARTILES: (f64, f64) = (0.29, 0.42);
/// Studies simulated for the page: the coverage known to about ±0.6 % (a binomial's 95 % margin
/// at 95 % over 5000 studies), in about ten seconds.
const PLAN_STUDIES: u32 = 5000;
const PLAN_RESAMPLES: u32 = 1000;

/// §5, fig. 7 (135°, 25 kHz): Asum = 0.0027·V − 0.2277, R² = 0.6358, zero at 84.33 ml.
const FIG_7_SLOPE: f64 = 0.0027;
const FIG_7_INTERCEPT: f64 = -0.2277;
const FIG_7_R_SQUARED: f64 = 0.6358;
const FIG_7_TILT_DEG: f64 = 135.0;
/// §4.1, §5: the accelerometer's sample rate.
const PAPER_SAMPLE_RATE: u32 = 25_000;
/// §5: the bottle; §3.1: "five seconds each, which is a typical duration for pouring 300 ml".
const PAPER_CAPACITY_ML: f64 = 300.0;
const PAPER_POUR_S: f64 = 5.0;
/// §4.3: water's c.
const PAPER_WATER_C: f64 = 0.33;
/// §5: tilts of the residual-quantity recordings at which the ratio is checked here (the
/// pouring ones; at 90° the default bottle barely pours).
const RATIO_TILTS_DEG: [f64; 3] = [115.0, 135.0, 155.0];

/// The verdicts' tolerances, stated on the page beside each table.
const SCALE_TOLERANCE: f64 = 0.0005;
/// V0 within 5 ml, as the fit's own round trip (MODEL.md §13) holds it; close within 15 ml.
const V0_TOLERANCE_ML: (f64, f64) = (5.0, 15.0);
/// The pour within 2 % of 5 s (the fit's round trip), close within 10 %.
const POUR_TOLERANCE: (f64, f64) = (0.02, 0.10);
/// c within 0.02 (the fit's round trip), close within 0.05.
const RATIO_TOLERANCE: (f64, f64) = (0.02, 0.05);

/// One row of a comparison: what, the paper's figure, the product's, the verdict.
struct Row {
    what: String,
    paper: String,
    product: String,
    verdict: String,
}

impl Row {
    fn new(
        what: impl Into<String>,
        paper: impl Into<String>,
        product: String,
        verdict: &str,
    ) -> Self {
        Self {
            what: what.into(),
            paper: paper.into(),
            product,
            verdict: verdict.to_owned(),
        }
    }
}

fn table(rows: &[Row]) -> String {
    let mut text = String::from("| quantity | paper | product | verdict |\n|---|---|---|---|\n");
    for row in rows {
        let _ = writeln!(
            text,
            "| {} | {} | {} | {} |",
            row.what, row.paper, row.product, row.verdict
        );
    }
    text
}

/// "reproduced" within `tolerance.0` of the paper, "close" within `tolerance.1`, else "differs".
fn verdict(difference: f64, tolerance: (f64, f64)) -> &'static str {
    match difference.abs() {
        d if d <= tolerance.0 => "reproduced",
        d if d <= tolerance.1 => "close",
        _ => "differs",
    }
}

/// Regenerates docs/paper.md with the release CLI (built by the caller).
pub fn paper() -> nice_plug_xtask::Result<()> {
    println!("paper: Table 1, the §4.4 plan, fits at 25 kHz, the pour (about a minute)");
    let started = std::time::Instant::now();
    let work = sake_glug_io::temp_dir_beside(&target_dir().join("paper"))?;
    let sections = [
        table_1()?,
        constant_stimuli()?,
        amplitude_law(work.path())?,
        pour(work.path())?,
        constant_ratio(work.path())?,
        defaults()?,
    ];
    let mut page = format!(
        "# The paper's numbers, reproduced\n\n\
         Every figure that Ikeno, Okazaki, Hachisu and Kajimoto report as a number, beside what \
         the product gives for it. Nothing here is typed by hand but the paper's figures: the \
         product's column is computed by the release `sake-glug` each time the page is made \
         (`cargo xtask docs paper`, xtask/src/paper.rs).\n\n{}",
        stamp(started.elapsed())
    );
    for section in sections {
        page.push('\n');
        page.push_str(&section);
    }
    // A figure that is none means a run went wrong: the old page stays rather than a made-up one.
    if let Some(line) = page.lines().find(|line| {
        line.split(|c: char| !c.is_alphanumeric())
            .any(|word| word == "NaN" || word == "inf")
    }) {
        anyhow::bail!("{PAGE} not written: a figure is not a number in {line:?}");
    }
    write_all_or_nothing(Path::new(PAGE), &page)?;
    println!("{PAGE} regenerated");
    Ok(())
}

fn write_all_or_nothing(path: &Path, text: &str) -> nice_plug_xtask::Result<()> {
    let file = sake_glug_io::PendingFile::beside(path, ".md")?;
    let mut writer = file.writer()?;
    writer.write_all(text.as_bytes())?;
    writer.flush()?;
    drop(writer);
    sake_glug_io::PendingFile::commit_all(vec![file])?;
    Ok(())
}

fn json_output(args: &[&str]) -> nice_plug_xtask::Result<Value> {
    let text = output(&cli(), args)?;
    serde_json::from_str(&text)
        .with_context(|| format!("`sake-glug {}` gave no JSON", args.join(" ")))
}

fn number(value: &Value, what: &str) -> nice_plug_xtask::Result<f64> {
    value
        .as_f64()
        .ok_or_else(|| anyhow!("{what}: no number in {value}"))
}

/// §3: Table 1 through `analyze paired`: its counts, its scale, Mosteller's test, the agreement.
fn table_1() -> nice_plug_xtask::Result<String> {
    let json = json_output(&["analyze", "paired", TABLE_1_LOG, "--json"])?;
    let mut rows = Vec::new();
    for (row, (name, label)) in WAVES.iter().enumerate() {
        let index = |wanted: &str| {
            json["stimuli"]
                .as_array()
                .and_then(|names| names.iter().position(|n| n == wanted))
                .ok_or_else(|| anyhow!("`analyze paired` names no stimulus {wanted}"))
        };
        let i = index(name)?;
        for (column, (other, other_label)) in WAVES.iter().enumerate() {
            if row == column {
                continue;
            }
            let j = index(other)?;
            let counted = json["counts"][i][j]
                .as_u64()
                .ok_or_else(|| anyhow!("no count {name} over {other}"))?;
            let paper = TABLE_1[row][column];
            rows.push(Row::new(
                format!("{label} chosen over the {other_label}"),
                paper.to_string(),
                counted.to_string(),
                if counted == paper {
                    "reproduced"
                } else {
                    "differs"
                },
            ));
        }
        let scale = number(&json["scale"][name], "scale")?;
        let paper = TABLE_1_SCALE[row];
        rows.push(Row::new(
            format!("Thurstone scale of the {label}"),
            format!("{paper:.3}"),
            format!("{scale:.4}"),
            verdict(scale - paper, (SCALE_TOLERANCE, SCALE_TOLERANCE)),
        ));
    }
    let test = |key: &str| -> nice_plug_xtask::Result<(f64, u64, f64)> {
        let test = &json[key];
        Ok((
            number(&test["chi2"], key)?,
            test["df"].as_u64().ok_or_else(|| anyhow!("{key}: no df"))?,
            number(&test["p"], key)?,
        ))
    };
    let (fit_chi2, fit_df, fit_p) = test("fit")?;
    rows.push(Row::new(
        "Mosteller's test of Case V's fit",
        "not reported",
        format!("χ²({fit_df}) = {fit_chi2:.3}, p = {fit_p:.3}"),
        if fit_p >= 0.05 {
            "the model fits (p ≥ 0.05)"
        } else {
            "the model does not fit (p < 0.05)"
        },
    ));
    let (chi2, df, p) = test("agreement")?;
    rows.push(Row::new(
        "consistency of the participants",
        format!("χ²({}) = {}, p < 0.01", AGREEMENT.1, AGREEMENT.0),
        format!("χ²({df}) = {chi2:.2}, p = {p:.3}"),
        "not comparable: the paper publishes no participant's own answers (the log deals \
         Table 1 out evenly) nor how its test was built",
    ));
    Ok(format!(
        "## §3 Paired comparison: Table 1 and fig. 2\n\n\
         `sake-glug analyze paired {TABLE_1_LOG} --json`: Table 1 entered as trials (6 \
         participants, 108 trials), read as PAPER-DATA.md reads it (a cell counts the answers \
         that chose the row's wave over the column's). A count is reproduced when equal; a scale \
         value when within {SCALE_TOLERANCE} (the paper's scale is known to 3 decimals).\n\n{}",
        table(&rows)
    ))
}

/// §4.4: the design simulated with observers at the paper's 25 % and 75 % points.
fn constant_stimuli() -> nice_plug_xtask::Result<String> {
    let levels = PAPER_LEVELS.map(|level| level.to_string()).join(",");
    let (p25, p75) = (PAPER_QUARTILES.0.to_string(), PAPER_QUARTILES.1.to_string());
    let (repetitions, participants) = (
        PAPER_REPETITIONS.to_string(),
        PAPER_PARTICIPANTS.to_string(),
    );
    let (studies, resamples) = (PLAN_STUDIES.to_string(), PLAN_RESAMPLES.to_string());
    let args = [
        "analyze",
        "plan",
        "constant",
        "--levels",
        &levels,
        "--repetitions",
        &repetitions,
        "--participants",
        &participants,
        "--p25",
        &p25,
        "--p75",
        &p75,
        "--studies",
        &studies,
        "--resamples",
        &resamples,
        "--seed",
        "1",
        "--json",
    ];
    let json = json_output(&args)?;
    let fitted = json["fitted"]
        .as_u64()
        .ok_or_else(|| anyhow!("plan: no fitted"))?;
    let mut text = format!(
        "## §4.4 Constant stimuli: how precisely could the paper know its thresholds?\n\n\
         `sake-glug {}`: {PLAN_STUDIES} studies of the paper's design ({PAPER_PARTICIPANTS} \
         participants × {} levels × {PAPER_REPETITIONS} repetitions, pooled as fig. 5 pools \
         them) drawn from observers whose logistic passes through the paper's 25 % and 75 % \
         points, each fitted as `analyze constant` fits a log (95 % BCa intervals, \
         {PLAN_RESAMPLES} resamples); {fitted} had a fit. Coverage is reproduced when the nominal \
         95 % lies within its Clopper-Pearson 95 % interval over the studies, close within 3 \
         points of it.\n\n\
         | point | truth (paper) | where 95 % of the studies' estimates fall | median \
         interval width | coverage of the truth | verdict |\n|---|---|---|---|---|---|\n",
        args[..args.len() - 1].join(" "),
        PAPER_LEVELS.len(),
    );
    for percent in ["25", "50", "75"] {
        let point = &json["points"][percent];
        let get = |field: &str| number(&point[field], field);
        let (low, high) = (get("coverage_low")?, get("coverage_high")?);
        let verdict = match (low, high) {
            (low, high) if (low..=high).contains(&0.95) => "reproduced",
            (low, high) if low - 0.03 <= 0.95 && 0.95 <= high + 0.03 => "close",
            _ => "differs",
        };
        let paper_point = match percent {
            "50" => format!("{} (midway; not reported)", get("truth")?),
            _ => format!("{}", get("truth")?),
        };
        let _ = writeln!(
            text,
            "| {percent} % | {paper_point} | {:.3} … {:.3} | {:.3} | {:.1} % ({:.1} … {:.1} %) | \
             {verdict} |",
            get("estimate_low")?,
            get("estimate_high")?,
            get("median_width")?,
            100.0 * get("coverage")?,
            100.0 * low,
            100.0 * high,
        );
    }
    let width = |percent: &str| number(&json["points"][percent]["median_width"], "median_width");
    let _ = writeln!(
        text,
        "\nSo a study of this design knows its 25 % point to about ±{:.3} and its 75 % point to \
         about ±{:.3} in c (half the median interval): the paper's 0.29 and 0.42 are each one \
         such estimate, and a repetition of the study would put them, 95 times in 100, within \
         the range of the third column.",
        width("25")? / 2.0,
        width("75")? / 2.0,
    );
    Ok(text)
}

/// A scene of the default bottle held at `tilt_deg`, at the paper's sample rate.
fn held_scene(dir: &Path, tilt_deg: f64) -> nice_plug_xtask::Result<std::path::PathBuf> {
    let scene = dir.join(format!("held-{tilt_deg}.toml"));
    std::fs::write(
        &scene,
        format!("sample_rate = {PAPER_SAMPLE_RATE}\ntilt_deg = {tilt_deg:.1}\n"),
    )?;
    Ok(scene)
}

/// What the fit of a render of the default bottle held at `tilt_deg` gives: its JSON, its
/// report, and the units it used (their c = A1/(A1 + A2), in time order).
struct FitOfRender {
    json: Value,
    report: String,
    used_ratios: Vec<f64>,
    /// c = A1/(A1 + A2) of every audible unit the engine rendered.
    engine_ratios: Vec<f64>,
}

fn fit_render(dir: &Path, tilt_deg: f64) -> nice_plug_xtask::Result<FitOfRender> {
    let scene = held_scene(dir, tilt_deg)?;
    let name = format!("held-{tilt_deg}");
    let wav = dir.join(format!("{name}.wav"));
    let engine_units = dir.join(format!("{name}-engine-units.csv"));
    run_quiet(&[
        "render",
        &scene.to_string_lossy(),
        "-o",
        &wav.to_string_lossy(),
        "--units",
        &engine_units.to_string_lossy(),
    ])?;
    let session = dir.join(format!("{name}-session.toml"));
    std::fs::write(
        &session,
        format!(
            "capacity_ml = {PAPER_CAPACITY_ML:.1}\n[[recording]]\naudio = \"{name}.wav\"\n\
             tilt_deg = {tilt_deg:.1}\nstart_ml = {PAPER_CAPACITY_ML:.1}\n"
        ),
    )?;
    let report = dir.join(format!("{name}-fit.md"));
    let units = dir.join(format!("{name}-fit-units.csv"));
    let json = json_output(&[
        "fit",
        &session.to_string_lossy(),
        "--json",
        "--report",
        &report.to_string_lossy(),
        "--units",
        &units.to_string_lossy(),
    ])?;
    let used_ratios = csv_rows(&units)?
        .into_iter()
        .filter(|row| {
            row.get("used")
                .is_some_and(|used| used == "true" || used == "1")
        })
        .filter_map(|row| ratio(&row, "a1", "a2"))
        .collect();
    let engine_ratios = csv_rows(&engine_units)?
        .into_iter()
        .filter(|row| row.get("audible").is_some_and(|audible| audible == "1"))
        .filter_map(|row| ratio(&row, "a1", "a2"))
        .collect();
    Ok(FitOfRender {
        json,
        report: read_text(&report)?,
        used_ratios,
        engine_ratios,
    })
}

fn ratio(row: &std::collections::HashMap<String, String>, a1: &str, a2: &str) -> Option<f64> {
    let a1: f64 = row.get(a1)?.parse().ok()?;
    let a2: f64 = row.get(a2)?.parse().ok()?;
    (a1 + a2 > 0.0).then(|| a1 / (a1 + a2))
}

/// A file this module had the CLI write, read through the product's one reader.
fn read_text(path: &Path) -> nice_plug_xtask::Result<String> {
    /// The most a table or report of these renders holds, far above the few hundred kB they are.
    const MOST_BYTES: u64 = 64 << 20;
    sake_glug_io::read::text_within(path, MOST_BYTES)
        .map_err(|failure| anyhow!("{}: {failure}", path.display()))
}

/// A CSV file with a header, each row as its column names' values.
fn csv_rows(
    path: &Path,
) -> nice_plug_xtask::Result<Vec<std::collections::HashMap<String, String>>> {
    let text = read_text(path)?;
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let header = reader.headers()?.clone();
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.with_context(|| path.display().to_string())?;
        rows.push(
            header
                .iter()
                .zip(record.iter())
                .map(|(name, value)| (name.to_owned(), value.to_owned()))
                .collect(),
        );
    }
    Ok(rows)
}

fn run_quiet(args: &[&str]) -> nice_plug_xtask::Result<()> {
    let out = std::process::Command::new(cli()).args(args).output()?;
    if !out.status.success() {
        anyhow::bail!(
            "`sake-glug {}` failed ({}): {}",
            args.join(" "),
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    Ok(())
}

fn median(values: &[f64]) -> f64 {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    match sorted.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => sorted[n / 2],
        n => (sorted[n / 2 - 1] + sorted[n / 2]) / 2.0,
    }
}

/// An estimate of `sake-glug fit --json`: its value, its 95 % interval if it has one, and the
/// units it comes from.
type Estimate = (f64, Option<(f64, f64)>, u64);

/// §5, fig. 7: the amplitude law that `sake-glug fit` finds in a render of the default bottle
/// held at 135° and recorded at 25 kHz.
fn amplitude_law(dir: &Path) -> nice_plug_xtask::Result<String> {
    let fit = fit_render(dir, FIG_7_TILT_DEG)?;
    let estimate = |key: &str| -> nice_plug_xtask::Result<Estimate> {
        let estimate = &fit.json["estimates"][key];
        let interval = estimate["low"].as_f64().zip(estimate["high"].as_f64());
        Ok((
            number(&estimate["value"], key)?,
            interval,
            estimate["n"].as_u64().unwrap_or(0),
        ))
    };
    let (zero, zero_interval, units) = estimate("amplitude.silent_below_ml")?;
    let (r_squared, _, _) = estimate("R² of Asum against V")?;
    // The line as the fit's report prints it: "Asum = α · V + β (R² = …)".
    let line = fit
        .report
        .lines()
        .find_map(|line| line.split_once("Asum = ").map(|(_, rest)| rest.to_owned()))
        .ok_or_else(|| anyhow!("the fit's report has no amplitude law"))?;
    let (slope, intercept) = line
        .split_once(" · V + ")
        .and_then(|(slope, rest)| {
            let intercept = rest.split_whitespace().next()?;
            Some((
                slope.trim().parse::<f64>().ok()?,
                intercept.parse::<f64>().ok()?,
            ))
        })
        .ok_or_else(|| anyhow!("cannot read the fit's line from {line:?}"))?;
    // The line over its value at the full bottle: the paper's units (its accelerometer's) and
    // the render's (its samples) differ by a factor, which this takes out.
    let relative = |slope: f64, intercept: f64| slope / (slope * PAPER_CAPACITY_ML + intercept);
    let paper_relative = relative(FIG_7_SLOPE, FIG_7_INTERCEPT);
    let product_relative = relative(slope, intercept);
    let paper_zero = -FIG_7_INTERCEPT / FIG_7_SLOPE;
    let interval = zero_interval.map_or_else(
        || "no interval".to_owned(),
        |(low, high)| format!("95 % interval {low:.1} … {high:.1}"),
    );
    let rows = [
        Row::new(
            "Asum against V (V in ml)",
            format!("{FIG_7_SLOPE}·V − {}", -FIG_7_INTERCEPT),
            format!(
                "{slope}·V {} {}",
                if intercept < 0.0 { "−" } else { "+" },
                intercept.abs()
            ),
            "not comparable as printed: Asum is in the recording's units (an accelerometer's, \
             a render's samples)",
        ),
        Row::new(
            "slope over Asum at 300 ml (/ml)",
            format!("{paper_relative:.5}"),
            format!("{product_relative:.5}"),
            verdict(
                (product_relative - paper_relative) / paper_relative,
                (0.05, 0.15),
            ),
        ),
        Row::new(
            "zero of the line, V0 (ml)",
            format!("{paper_zero:.2}"),
            format!("{zero:.2} ({interval}, {units} units)"),
            verdict(zero - paper_zero, V0_TOLERANCE_ML),
        ),
        Row::new(
            "R² of the line",
            format!("{FIG_7_R_SQUARED}"),
            format!("{r_squared:.4}"),
            if r_squared > FIG_7_R_SQUARED + 0.1 {
                "differs, as it should: the default bottle's Asum has no spread (σ_A = 0, \
                 `amplitude.spread`), the paper's recordings scatter"
            } else {
                verdict(r_squared - FIG_7_R_SQUARED, (0.02, 0.1))
            },
        ),
    ];
    Ok(format!(
        "## §5, fig. 7: the amplitude law\n\n\
         The default bottle held at {FIG_7_TILT_DEG}° from full, rendered at the paper's \
         {PAPER_SAMPLE_RATE} Hz and fitted by `sake-glug fit` (a session of that one recording, \
         `start_ml = 300`): the line through the units' Asum against V. Relative slope reproduced \
         within 5 %, close within 15 %; V0 reproduced within {} ml (the fit's own round trip, \
         MODEL.md §13), close within {} ml.\n\n{}",
        V0_TOLERANCE_ML.0,
        V0_TOLERANCE_ML.1,
        table(&rows)
    ))
}

/// When a render's bottle is empty (the first row of its state table at 0 ml; or, where the
/// render ends within the last sample's outflow, that row's time plus its volume over the
/// outflow), and its rate between 1 s and 3 s. `scene_text` None renders the built-in pour.
fn empties_at(
    dir: &Path,
    name: &str,
    scene_text: Option<&str>,
) -> nice_plug_xtask::Result<(f64, f64)> {
    let state = dir.join(format!("{name}-state.csv"));
    let wav = dir.join(format!("{name}.wav"));
    let (state_arg, wav_arg) = (state.to_string_lossy(), wav.to_string_lossy());
    let mut args = vec!["render"];
    let scene = dir.join(format!("{name}.toml"));
    let scene_arg = scene.to_string_lossy();
    if let Some(text) = scene_text {
        std::fs::write(&scene, text)?;
        args.push(&scene_arg);
    }
    args.extend([
        "-o",
        &wav_arg,
        "--state",
        &state_arg,
        "--state-rate",
        "1000",
    ]);
    run_quiet(&args)?;
    let rows: Vec<[f64; 3]> = csv_rows(&state)?
        .iter()
        .filter_map(|row| {
            let get = |column: &str| row.get(column)?.parse().ok();
            Some([get("time_s")?, get("volume_ml")?, get("outflow_ml_per_s")?])
        })
        .collect();
    let [last_time, last_volume, last_outflow] = *rows
        .last()
        .ok_or_else(|| anyhow!("{name}: an empty state table"))?;
    let empty = match rows.iter().find(|[_, volume, _]| *volume <= 1e-9) {
        Some([time, _, _]) => *time,
        None if last_outflow > 0.0 && last_volume / last_outflow < 1e-3 => {
            last_time + last_volume / last_outflow
        }
        None => anyhow::bail!("{name}: the bottle never empties in {}", state.display()),
    };
    // The rate between 1 s and 3 s, where both scenes are held at 135°.
    let at = |time: f64| {
        rows.iter()
            .find(|[t, _, _]| *t >= time)
            .map(|[_, volume, _]| *volume)
            .ok_or_else(|| anyhow!("{name}: no state at {time} s"))
    };
    Ok((empty, (at(1.0)? - at(3.0)?) / 2.0))
}

/// §3.1: a 300 ml pour of about 5 s.
fn pour(dir: &Path) -> nice_plug_xtask::Result<String> {
    let (held, held_rate) = empties_at(dir, "pour-held", Some("tilt_deg = 135.0\n"))?;
    let (default, _) = empties_at(dir, "pour-default", None)?;
    let paper_rate = PAPER_CAPACITY_ML / PAPER_POUR_S;
    let rows = [
        Row::new(
            "300 ml held at 135° from full: empty at (s)",
            format!("about {PAPER_POUR_S}"),
            format!("{held:.3}"),
            verdict((held - PAPER_POUR_S) / PAPER_POUR_S, POUR_TOLERANCE),
        ),
        Row::new(
            "the rate at 135° (ml/s)",
            format!("{paper_rate} (300 ml in 5 s)"),
            format!("{held_rate:.2}"),
            verdict((held_rate - paper_rate) / paper_rate, POUR_TOLERANCE),
        ),
        Row::new(
            "the built-in pour (tilted 90° → 135° over its first 0.5 s): empty at (s)",
            format!("about {PAPER_POUR_S}"),
            format!("{default:.3}"),
            verdict((default - PAPER_POUR_S) / PAPER_POUR_S, POUR_TOLERANCE),
        ),
    ];
    Ok(format!(
        "## §3.1 The 5 s pour of 300 ml\n\n\
         `sake-glug render --state` at 1000 rows a second (simulated drain, MODEL.md §3): the \
         first row at 0 ml (where a render ends within its last row's outflow, that row's time plus \
         its volume over the outflow). Reproduced within {:.0} % of the paper's 5 s, close within {:.0} %.\n\n{}",
        100.0 * POUR_TOLERANCE.0,
        100.0 * POUR_TOLERANCE.1,
        table(&rows)
    ))
}

/// §4.3 and §5, eq. 2: A1 and A2 fall with V in a constant ratio c, at every tilt.
fn constant_ratio(dir: &Path) -> nice_plug_xtask::Result<String> {
    let mut rows = Vec::new();
    let mut engine_worst = 0.0f64;
    let mut engine_units = 0;
    for tilt_deg in RATIO_TILTS_DEG {
        let fit = fit_render(dir, tilt_deg)?;
        for ratio in &fit.engine_ratios {
            engine_worst = engine_worst.max((ratio - PAPER_WATER_C).abs());
        }
        engine_units += fit.engine_ratios.len();
        let ratios = &fit.used_ratios;
        let (first, second) = ratios.split_at(ratios.len() / 2);
        let drift = median(second) - median(first);
        let overall = median(ratios);
        let worse = (overall - PAPER_WATER_C).abs().max(drift.abs());
        rows.push(Row::new(
            format!(
                "{tilt_deg}°: the fit's c = A1/(A1 + A2), median of {} units used",
                ratios.len()
            ),
            format!("{PAPER_WATER_C}, constant"),
            format!("{overall:.3}; second half of the pour less the first: {drift:+.3}"),
            verdict(worse, RATIO_TOLERANCE),
        ));
    }
    rows.push(Row::new(
        format!("the engine's own units at the three tilts ({engine_units} audible)"),
        format!("{PAPER_WATER_C}, constant"),
        format!("A1/(A1 + A2) at most {engine_worst:.1e} from {PAPER_WATER_C}"),
        verdict(engine_worst, (1e-9, RATIO_TOLERANCE.1)),
    ));
    Ok(format!(
        "## §4.3, §5, eq. 2: a constant ratio over time and tilt\n\n\
         The default bottle held at each tilt from full at {PAPER_SAMPLE_RATE} Hz, fitted by \
         `sake-glug fit --units`: each used unit's A1/(A1 + A2). Reproduced when the median and \
         its drift over the pour (the second half's median less the first's) both lie within \
         {} of the paper's c, close within {}; the engine's own units (`render --units`) within \
         10⁻⁹.\n\n{}",
        RATIO_TOLERANCE.0,
        RATIO_TOLERANCE.1,
        table(&rows)
    ))
}

/// The product's defaults (`sake-glug parameters`) beside the paper's values.
fn defaults() -> nice_plug_xtask::Result<String> {
    let listing = output(&cli(), &["parameters"])?;
    // The default column of the row of a scene key, as a number (its unit dropped).
    let default_of = |key: &str| -> nice_plug_xtask::Result<f64> {
        let key = format!("`{key}`");
        let row = listing
            .lines()
            .find(|line| {
                line.split('|')
                    .nth(2)
                    .is_some_and(|cell| cell.trim() == key)
            })
            .ok_or_else(|| anyhow!("`sake-glug parameters` lists no {key}"))?;
        let cell = row.split('|').nth(6).unwrap_or_default().trim();
        cell.split_whitespace()
            .next()
            .and_then(|number| number.trim_end_matches(['%', '°']).parse().ok())
            .ok_or_else(|| anyhow!("{key}: no default number in {cell:?}"))
    };
    let compare = |what: &str, key: &str, paper: f64, section: &str, tolerance: f64| {
        default_of(key).map(|default| {
            Row::new(
                format!("{what} (`{key}`)"),
                format!("{} ({section})", (paper * 100.0).round() / 100.0),
                format!("{default}"),
                verdict(default - paper, (tolerance, tolerance)),
            )
        })
    };
    let mut rows = vec![
        compare("water's c", "viscosity_c", PAPER_WATER_C, "§4.3", 1e-9)?,
        compare(
            "capacity, ml",
            "bottle.capacity_ml",
            PAPER_CAPACITY_ML,
            "§5",
            1e-9,
        )?,
        compare(
            "pour time of a full bottle, s",
            "pour_time_s",
            PAPER_POUR_S,
            "§3.1",
            1e-9,
        )?,
        compare(
            "silent below, ml",
            "amplitude.silent_below_ml",
            -FIG_7_INTERCEPT / FIG_7_SLOPE,
            "fig. 7's zero, 0.2277/0.0027",
            0.001,
        )?,
    ];
    for (what, key) in [
        ("f1, Hz", "glug.f1_hz"),
        ("f2, Hz", "glug.f2_hz"),
        ("B1, /s", "glug.b1_per_s"),
        ("B2, /s", "glug.b2_per_s"),
        ("pocket, ml", "bottle.pocket_ml"),
    ] {
        rows.push(Row::new(
            format!("{what} (`{key}`)"),
            "not reported",
            format!("{}", default_of(key)?),
            "derived (MODEL.md §4, §5): the paper gives no value",
        ));
    }
    Ok(format!(
        "## The product's defaults and the paper's values\n\n\
         `sake-glug parameters`' defaults. Reproduced when equal (V0 within 0.001 ml: the \
         default is the paper's 0.2277/0.0027 scaled with the capacity).\n\n{}",
        table(&rows)
    ))
}
