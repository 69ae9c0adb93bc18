//! `sake-glug experiment` and the study layer: specs and their errors, the trial order, level
//! matching, the dry run's folder, the log kept through a killed session and `--resume`; and
//! the study under attack (#31): the log protected (`log.rs`), the dry run bounded and open to
//! every user (`dry_run.rs`), hostile specs (`hostile_specs.rs`).

mod dry_run;
mod expectations;
mod hostile_specs;
mod log;
mod recorded;
mod three_intervals;
mod two_afc;

use std::io::{BufRead, BufReader, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use sake_glug_study::{
    level_of, order_seed, plan_trials, render_stimuli, Design, Equalize, Spec, StudyError,
};

fn experiments() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("experiments")
}

fn spec(text: &str) -> Result<Spec, StudyError> {
    Spec::parse(text, Path::new("study.toml"))
}

/// A short paired spec, quick to render.
const SHORT_PAIRED: &str = r#"
design = "paired"
duration_s = 0.4
gap_s = 0.1
repetitions = 2
seed = 9
equalize = "peak"
[stimuli.model]
preset = "water"
[stimuli.high]
preset = "water"
viscosity_c = 0.0
[stimuli.low]
viscosity_c = 1.0
"#;

fn error_of(text: &str) -> String {
    spec(text).unwrap_err().to_string()
}

/// A spec's design is one of the runner's, named as `analyze discrimination` names the
/// discrimination designs (one declaration); an unknown one is refused with the list.
#[test]
fn designs_are_named_as_the_analysis_names_them() {
    for design in Design::ALL {
        assert_eq!(Design::from_name(design.name()), Some(design));
        if let Some(analysed) = design.discrimination() {
            assert_eq!(design.name(), analysed.name());
        }
        let parsed = spec(&SHORT_PAIRED.replace("\"paired\"", &format!("\"{}\"", design.name())));
        if let Ok(parsed) = parsed {
            assert_eq!(parsed.design, design);
        }
    }
    let unknown = error_of(&SHORT_PAIRED.replace("\"paired\"", "\"2AFC\""));
    assert!(
        unknown.contains(
            "`2AFC`: not a design; expected one of `paired`, `constant`, `2afc`, \
                          `triangle`, `abx`"
        ),
        "{unknown}"
    );
}

#[test]
fn spec_errors_name_the_file_and_the_key() {
    let unknown = error_of(&SHORT_PAIRED.replace("seed = 9", "seeds = 9"));
    assert!(unknown.starts_with("study.toml:"), "{unknown}");
    assert!(unknown.contains("seeds"), "{unknown}");

    let range = error_of(&SHORT_PAIRED.replace("viscosity_c = 1.0", "viscosity_c = 2.0"));
    assert!(range.contains("stimulus `low`"), "{range}");
    assert!(
        range.contains("`viscosity_c` = 2 is out of range"),
        "{range}"
    );

    let scene_key = error_of(&SHORT_PAIRED.replace("viscosity_c = 1.0", "viscosity = 1.0"));
    assert!(
        scene_key.contains("stimulus `low`") && scene_key.contains("unknown field `viscosity`"),
        "{scene_key}"
    );

    let preset = error_of(&SHORT_PAIRED.replace(
        "preset = \"water\"\n[stimuli.high]",
        "preset = \"wine\"\n[stimuli.high]",
    ));
    assert!(
        preset.contains("stimulus `model`") && preset.contains("no such preset"),
        "{preset}"
    );

    let one = error_of(
        "design = \"paired\"\nduration_s = 1.0\ngap_s = 0.5\nrepetitions = 1\n[stimuli.a]\n",
    );
    assert!(one.contains("at least 2"), "{one}");

    let constant = "design = \"constant\"\nduration_s = 1.0\ngap_s = 0.5\nrepetitions = 2\n\
                    [standard]\nviscosity_c = 0.33\n[comparisons]\n";
    let level = error_of(&format!("{constant}visc = [0.2, 0.4]\n"));
    assert!(
        level.contains("`comparisons.visc`: not a control or constant"),
        "{level}"
    );
    let other = error_of(&format!("{constant}pour_time_s = [4.0, 6.0]\n"));
    assert!(
        other.contains("must set the compared key `pour_time_s`"),
        "{other}"
    );
    let duration = error_of(&SHORT_PAIRED.replace("duration_s = 0.4", "duration_s = 0.0"));
    assert!(duration.contains("`duration_s` = 0"), "{duration}");
    let channels = error_of(&format!(
        "{SHORT_PAIRED}[channels]\nactuator = [1]\nheadphones = [1, 2]\n"
    ));
    assert!(channels.contains("channel 1 is both"), "{channels}");
    let noise = error_of(&format!("noise_dbfs = -30.0\n{SHORT_PAIRED}"));
    assert!(
        noise.contains("`noise_dbfs` needs headphone channels"),
        "{noise}"
    );
}

#[test]
fn the_dry_run_writes_each_trials_stimuli_and_the_list() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), SHORT_PAIRED).unwrap();
    let spec = Spec::load(&dir.path().join("study.toml")).unwrap();
    let trials = plan_trials(&spec, order_seed(spec.seed, "p1"));
    let rendered = render_stimuli(&spec, 48_000).unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_sake-glug"))
        .current_dir(dir.path())
        .args([
            "experiment",
            "study.toml",
            "--participant",
            "p1",
            "--log",
            "l.csv",
        ])
        .args(["--dry-run", "dry"])
        .stdin(Stdio::null())
        .output()
        .unwrap();
    // No answers: the files are written, and the dry run ends there as --no-answers does.
    assert_eq!(output.status.code(), Some(0));
    let mut names: Vec<String> = std::fs::read_dir(dir.path().join("dry"))
        .unwrap()
        .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names.len(), 2 * trials.len() + 1, "{names:?}");
    let list = log_rows(&dir.path().join("dry/trials.csv"));
    for ((trial, row), index) in trials.iter().zip(&list).zip(1..) {
        for (place, stimulus) in [(1, trial.first), (2, trial.second)] {
            let name = &spec.stimuli[stimulus].name;
            let file = format!("trial-{index:03}-{place}-{name}.wav");
            assert_eq!(&row[2 + place], file.as_str());
            let samples: Vec<f32> = hound::WavReader::open(dir.path().join("dry").join(&file))
                .unwrap()
                .into_samples()
                .map(Result::unwrap)
                .collect();
            assert_eq!(samples, rendered[stimulus].samples, "{file}");
        }
    }
    // A folder that holds anything is refused, and left as it was.
    std::fs::remove_file(dir.path().join("l.csv")).unwrap();
    let again = Command::new(env!("CARGO_BIN_EXE_sake-glug"))
        .current_dir(dir.path())
        .args([
            "experiment",
            "study.toml",
            "--participant",
            "p2",
            "--log",
            "l.csv",
        ])
        .args(["--dry-run", "dry"])
        .stdin(Stdio::null())
        .output()
        .unwrap();
    assert_eq!(again.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&again.stderr).contains("not an empty folder"));
    // Refused before anything was rendered (issue 40): the levels it prints once the stimuli
    // are rendered never came.
    assert!(
        !String::from_utf8_lossy(&again.stdout).contains("trials"),
        "{}",
        String::from_utf8_lossy(&again.stdout)
    );
    assert_eq!(log_rows(&dir.path().join("dry/trials.csv")), list);
    assert!(
        !dir.path().join("l.csv").exists(),
        "no log for a refused session"
    );
}

#[test]
fn the_shipped_studies_parse() {
    let paired = Spec::load(&experiments().join("paired-waves.toml")).unwrap();
    assert_eq!(paired.design, Design::Paired);
    let names: Vec<&str> = paired.stimuli.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["high", "low", "model"]);
    let constant = Spec::load(&experiments().join("viscosity-constant.toml")).unwrap();
    assert_eq!(constant.stimuli.len(), 10);
    assert_eq!(constant.equalize, Equalize::Peak);
    assert_eq!(constant.stimuli[3].level, Some(0.26));
}

#[test]
fn paired_trials_are_every_ordered_pair_each_repetition() {
    let spec = Spec::load(&experiments().join("paired-waves.toml")).unwrap();
    let trials = plan_trials(&spec, order_seed(spec.seed, "p1"));
    assert_eq!(trials.len(), 18);
    for first in 0..3 {
        for second in 0..3 {
            let count = trials
                .iter()
                .filter(|t| t.first == first && t.second == second)
                .count();
            assert_eq!(
                count,
                if first == second { 0 } else { 3 },
                "{first}, {second}"
            );
        }
    }
}

#[test]
fn constant_trials_counterbalance_the_standard() {
    let spec = Spec::load(&experiments().join("viscosity-constant.toml")).unwrap();
    let trials = plan_trials(&spec, order_seed(spec.seed, "p1"));
    assert_eq!(trials.len(), 90);
    for comparison in 1..spec.stimuli.len() {
        let standard_first = trials
            .iter()
            .filter(|t| t.first == 0 && t.second == comparison)
            .count();
        let standard_second = trials
            .iter()
            .filter(|t| t.first == comparison && t.second == 0)
            .count();
        assert_eq!(
            (standard_first, standard_second),
            (5, 5),
            "level {comparison}"
        );
    }
    // Odd repetitions: each level within one, the session as a whole too.
    let odd = Spec::parse(
        &std::fs::read_to_string(experiments().join("viscosity-constant.toml"))
            .unwrap()
            .replace("repetitions = 10", "repetitions = 3"),
        Path::new("odd.toml"),
    )
    .unwrap();
    let trials = plan_trials(&odd, 1);
    let first = trials.iter().filter(|t| t.first == 0).count() as i64;
    assert!(
        (2 * first - trials.len() as i64).abs() <= 1,
        "{first} of {}",
        trials.len()
    );
}

#[test]
fn the_order_is_fixed_by_the_seed_and_the_participant() {
    let spec = Spec::load(&experiments().join("paired-waves.toml")).unwrap();
    let order = |participant| plan_trials(&spec, order_seed(spec.seed, participant));
    assert_eq!(order("p1"), order("p1"));
    assert_ne!(order("p1"), order("p2"));
    // Fixed across platforms and versions: the log keeps the seed.
    assert_eq!(order_seed(0, ""), 0xcbf2_9ce4_8422_2325);
    assert_eq!(order_seed(0, "a"), 0xaf63_dc4c_8601_ec8c);
}

#[test]
fn equalized_stimuli_have_equal_levels() {
    for equalize in [Equalize::Peak, Equalize::Rms] {
        let text = SHORT_PAIRED.replace("\"peak\"", &format!("\"{}\"", equalize.name()));
        let spec = spec(&text).unwrap();
        let rendered = render_stimuli(&spec, 48_000).unwrap();
        let levels: Vec<f64> = rendered
            .iter()
            .map(|r| level_of(equalize, &r.samples))
            .collect();
        let gains: Vec<f64> = rendered.iter().map(|r| r.gain_db).collect();
        assert!(
            gains.iter().all(|&g| g <= 0.0) && gains.iter().any(|&g| g < -0.1),
            "{gains:?}"
        );
        for level in &levels {
            assert!(
                (level / levels[0] - 1.0).abs() < 1e-6,
                "{equalize:?}: {levels:?}"
            );
        }
    }
}

/// `experiment study.toml --participant PARTICIPANT --log LOG EXTRA…` in `dir`, with `input` as
/// its answers.
fn session_output(dir: &Path, participant: &str, log: &str, extra: &[&str], input: &str) -> Output {
    let mut args = vec!["study.toml", "--participant", participant, "--log", log];
    args.extend_from_slice(extra);
    run(dir, &args, input)
}

/// [`session_output`] of a session that must succeed.
fn session(dir: &Path, participant: &str, log: &str, extra: &[&str], input: &str) -> Output {
    let output = session_output(dir, participant, log, extra, input);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

/// Runs `sake-glug experiment ARGS` in `dir` to its end with `input` on its stdin; a run that
/// has not ended after a minute (it waits on something: a FIFO, a lock) is killed and fails.
fn run(dir: &Path, args: &[&str], input: &str) -> Output {
    let mut child = start(dir, args);
    let mut stdin = child.stdin.take().unwrap();
    // A run that ends early (refused) closes its stdin: what it did not read does not matter.
    let _ = stdin.write_all(input.as_bytes());
    drop(stdin);
    finish(child)
}

/// `child`'s output once it has ended, or a failure if it is still running after a minute.
fn finish(mut child: Child) -> Output {
    let started = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if started.elapsed() > Duration::from_secs(60) {
            child.kill().unwrap();
            panic!("still running after a minute: it waits for something");
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    child.wait_with_output().unwrap()
}

/// The answers of a whole session of `trials` trials: Enter, then `1` each time.
fn answers(trials: usize) -> String {
    format!("\n{}", "1\n".repeat(trials))
}

/// Asserts that `output` is a refusal (exit status 2) whose message holds each of `parts`;
/// returns the message.
fn refused(output: &Output, parts: &[&str]) -> String {
    let stderr = String::from_utf8_lossy(&output.stderr).into_owned();
    assert_eq!(
        output.status.code(),
        Some(2),
        "{:?}: {stderr}",
        output.status
    );
    assert!(!stderr.contains("panicked"), "{stderr}");
    for part in parts {
        assert!(stderr.contains(part), "no `{part}` in: {stderr}");
    }
    stderr
}

/// Runs `sake-glug experiment ARGS` in `dir` with its stdin piped.
fn start(dir: &Path, args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_sake-glug"))
        .current_dir(dir)
        .arg("experiment")
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn log_rows(path: &Path) -> Vec<csv::StringRecord> {
    csv::Reader::from_path(path)
        .unwrap()
        .records()
        .map(Result::unwrap)
        .collect()
}

fn wait_for_rows(path: &Path, rows: usize) {
    let started = Instant::now();
    while !path.exists() || log_rows(path).len() < rows {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no row {rows} in the log"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn a_killed_session_keeps_its_answers_and_resume_continues() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("study.toml"), SHORT_PAIRED).unwrap();
    let args = [
        "study.toml",
        "--participant",
        "p7",
        "--log",
        "log.csv",
        "--dry-run",
        "dry",
    ];
    let log = dir.path().join("log.csv");
    let mut child = start(dir.path(), &args);
    let mut stdin = child.stdin.take().unwrap();
    // A bad answer is asked again; each good one is in the log before the next trial.
    for (answer, rows) in [("", 0), ("x", 0), ("1", 1), ("", 1), ("2", 2), ("1", 3)] {
        writeln!(stdin, "{answer}").unwrap();
        stdin.flush().unwrap();
        wait_for_rows(&log, rows);
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let killed = log_rows(&log);
    assert_eq!(killed.len(), 3);

    // The trial list of the dry run is the session's order.
    let list: Vec<csv::StringRecord> = log_rows(&dir.path().join("dry/trials.csv"));
    assert_eq!(list.len(), 12);
    for file in ["trial-001-1-", "trial-012-2-"] {
        assert!(
            std::fs::read_dir(dir.path().join("dry"))
                .unwrap()
                .any(|entry| entry
                    .unwrap()
                    .file_name()
                    .to_string_lossy()
                    .starts_with(file)),
            "{file}"
        );
    }

    // Another participant's resume is refused, the log untouched.
    let other = start(
        dir.path(),
        &[
            "study.toml",
            "--participant",
            "p8",
            "--log",
            "log.csv",
            "--dry-run",
            "dry",
            "--resume",
        ],
    )
    .wait_with_output()
    .unwrap();
    assert_eq!(other.status.code(), Some(2));
    let message = String::from_utf8_lossy(&other.stderr);
    assert!(
        message.contains("log.csv, line 2: participant `p7`"),
        "{message}"
    );
    assert_eq!(log_rows(&log).len(), 3);
    // A new session may not overwrite it.
    let again = start(dir.path(), &args).wait_with_output().unwrap();
    assert!(String::from_utf8_lossy(&again.stderr).contains("already exists"));

    let mut resumed = start(dir.path(), &[&args[..], &["--resume"]].concat());
    let mut stdin = resumed.stdin.take().unwrap();
    writeln!(stdin).unwrap();
    for _ in 3..12 {
        writeln!(stdin, "wrong\n2").unwrap();
    }
    drop(stdin);
    let output = resumed.wait_with_output().unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert_eq!(
        stdout.matches("Please answer 1 or 2").count(),
        9,
        "{stdout}"
    );
    let rows = log_rows(&log);
    assert_eq!(rows.len(), 12);
    assert_eq!(rows[..3], killed[..]);
    for (index, (row, planned)) in rows.iter().zip(&list).enumerate() {
        assert_eq!(row[1], (index + 1).to_string());
        assert_eq!(
            (&row[3], &row[4]),
            (&planned[1], &planned[2]),
            "trial {}",
            index + 1
        );
        // Answers 1, 2, 1, then 2 on.
        let chosen = if index == 0 || index == 2 {
            &row[3]
        } else {
            &row[4]
        };
        assert_eq!(&row[5], chosen);
    }
    let reader = BufReader::new(std::fs::File::open(&log).unwrap());
    assert_eq!(reader.lines().count(), 13, "a header and 12 rows");
}

#[test]
fn the_constant_log_says_which_was_the_comparison() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(experiments().join("viscosity-constant.toml"))
        .unwrap()
        .replace("duration_s = 5.0", "duration_s = 0.3")
        .replace("repetitions = 10", "repetitions = 1");
    std::fs::write(dir.path().join("c.toml"), text).unwrap();
    let mut child = start(
        dir.path(),
        &[
            "c.toml",
            "--participant",
            "q",
            "--log",
            "c.csv",
            "--dry-run",
            "d",
        ],
    );
    let mut stdin = child.stdin.take().unwrap();
    writeln!(stdin).unwrap();
    for _ in 0..9 {
        writeln!(stdin, "1").unwrap();
    }
    drop(stdin);
    assert!(child.wait_with_output().unwrap().status.success());
    let mut reader = csv::Reader::from_path(dir.path().join("c.csv")).unwrap();
    let header = reader.headers().unwrap().clone();
    let column = |name| header.iter().position(|h| h == name).unwrap();
    for row in reader.records().map(Result::unwrap) {
        let comparison_first = &row[column("first")] != "standard";
        assert_eq!(
            &row[column("chose_comparison")],
            if comparison_first { "1" } else { "0" }
        );
        let comparison = if comparison_first {
            &row[column("first")]
        } else {
            &row[column("second")]
        };
        assert_eq!(comparison, format!("viscosity_c={}", &row[column("level")]));
    }
}

/// The keys a spec's unknown-key message names as expected, at the top or in `[section]`.
fn expected_keys(text: &str) -> Vec<String> {
    let error = error_of(text);
    let (_, listed) = error
        .split_once("expected one of ")
        .unwrap_or_else(|| panic!("no list of keys in: {error}"));
    listed
        .split(", ")
        .map(|key| key.trim_matches('`').to_owned())
        .collect()
}

/// experiments/README.md's tables of keys are the spec parser's: every key the parser takes (at
/// the top, in `[channels]`, and a stimulus's own) is listed, and nothing else.
#[test]
fn the_experiments_readme_lists_every_spec_key() {
    let readme = std::fs::read_to_string(experiments().join("README.md")).unwrap();
    // The first cell of each table row, without its backticks and brackets.
    let listed: Vec<String> = readme
        .lines()
        .filter_map(|line| line.strip_prefix("| `"))
        .map(|rest| {
            let key = &rest[..rest.find('`').unwrap()];
            key.trim_matches(['[', ']']).to_owned()
        })
        .collect();
    let mut top: Vec<String> = listed
        .iter()
        .map(|key| key.split('.').next().unwrap().to_owned())
        .filter(|key| !sake_glug_study::STIMULUS_KEYS.contains(&key.as_str()))
        .collect();
    let mut parsed = expected_keys(&SHORT_PAIRED.replace("seed = 9", "no_such_key = 9"));
    top.sort();
    parsed.sort();
    assert_eq!(
        top, parsed,
        "experiments/README.md's keys against the parser's"
    );
    let channels = expected_keys(&format!("{SHORT_PAIRED}\n[channels]\nno_such_key = 1\n"));
    let documented = readme
        .lines()
        .find(|line| line.starts_with("| `[channels]`"))
        .unwrap();
    for key in channels {
        assert!(
            documented.contains(&format!("`{key} =")),
            "[channels] {key}"
        );
    }
    for key in sake_glug_study::STIMULUS_KEYS {
        assert!(
            listed.iter().any(|listed| listed == key),
            "stimulus key {key}"
        );
    }
}
