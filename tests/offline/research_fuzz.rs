//! Property-based fuzz tests for the files a researcher hands the product besides scenes: model
//! files (`ModelFile::parse`), study specs (`Spec::parse`), fit sessions (`FitSession::parse`),
//! study logs (`analyze_paired_logs`, `analyze_constant_logs`) and the logs `--resume` continues
//! (`TrialLog::resume`, whose file must come out byte for byte as it went in). The libFuzzer targets (fuzz/) cover the
//! renderer's and the plugin's inputs; these parsers came later, so each is fuzzed here from a
//! valid file, mutated: text replaced, inserted or removed at any place, with the bytes that break
//! parsers (quotes, brackets, separators, newlines, control characters, numbers at and beyond
//! every edge). Proptest's default of 256 cases a run.
//!
//! Property: never a panic, and either a result or an error whose message has no control
//! character but its own line breaks (a file's bytes must never reach the terminal raw: an escape
//! sequence could retitle or recolour it).

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use proptest::prelude::*;

use sake_glug_analysis::{
    analyze_constant_logs, analyze_paired_logs, DryRuns, PsychometricOptions,
};
use sake_glug_fit::FitSession;
use sake_glug_model_file::ModelFile;
use sake_glug_study::{
    order_seed, plan_trials, Rendered, Silent, Spec, StudyError, StudySession, Trial, TrialLog,
};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// What a mutation splices in: what breaks TOML, CSV and number parsers, and what a terminal
/// obeys.
const SPLICES: &[&str] = &[
    "\u{1b}]0;owned\u{7}",
    "\u{1b}[31m",
    "\u{0}",
    "\r",
    "\n",
    "\"",
    "'",
    "[",
    "]]",
    "=",
    ",",
    "#",
    "nan",
    "inf",
    "-inf",
    "-1",
    "0",
    "1e308",
    "1e-320",
    "18446744073709551616",
    "é",
    "\u{202e}",
    "[[recording]]\n",
    "[curves]\nrest = [[0.0, 2.0]]\n",
];

/// One edit of a text: at a fraction of its length, remove `remove` characters and insert one
/// splice or a short run of arbitrary characters.
#[derive(Debug, Clone)]
struct Edit {
    at: f64,
    remove: usize,
    insert: String,
}

fn edit() -> impl Strategy<Value = Edit> {
    let insert = prop_oneof![
        prop::sample::select(SPLICES).prop_map(str::to_owned),
        "\\PC{0,6}",
        Just(String::new()),
    ];
    (0.0..=1.0f64, 0usize..6, insert).prop_map(|(at, remove, insert)| Edit { at, remove, insert })
}

/// `text` with `edits` applied in turn, on character boundaries.
fn mutate(text: &str, edits: &[Edit]) -> String {
    let mut chars: Vec<char> = text.chars().collect();
    for edit in edits {
        let at = ((chars.len() as f64 * edit.at) as usize).min(chars.len());
        let end = (at + edit.remove).min(chars.len());
        chars.splice(at..end, edit.insert.chars());
    }
    chars.into_iter().collect()
}

/// The property of every error: a message, and no control character in it but a line break.
fn assert_clean(what: &str, message: &str) {
    assert!(!message.is_empty(), "{what}: an empty error");
    assert!(
        message.chars().all(|c| !c.is_control() || c == '\n'),
        "{what}: a raw control character in {message:?}"
    );
}

fn read(path: &str) -> String {
    std::fs::read_to_string(Path::new(ROOT).join(path)).unwrap()
}

/// A session as the fit reads it; its recordings need not exist, as parsing comes first.
const SESSION: &str = "capacity_ml = 300.0\n\n[[recording]]\naudio = \"pour-135.wav\"\n\
    tilt_deg = 135.0\nstart_ml = 300.0\nliquid = \"water\"\n\n[[recording]]\n\
    audio = \"pour-90.wav\"\ntilt_deg = 90.0\nstart_ml = 250.0\n\
    weight = { csv = \"scale.csv\", time = \"t\", column = \"g\" }\n";

const PAIRED_LOG: &str = "participant,trial,design,first,second,answer,rt_s,seed\n\
    p1,1,paired,model,high,model,0.8,7\np1,2,paired,high,low,low,1.1,7\n\
    p1,3,paired,low,model,model,0.9,7\np2,1,paired,high,model,high,0.7,9\n";

const CONSTANT_LOG: &str = "participant,trial,design,first,second,answer,rt_s,seed,level,\
    chose_comparison\np1,1,constant,standard,comparison,standard,0.6,3,0.18,0\n\
    p1,2,constant,comparison,standard,comparison,0.6,3,0.18,1\n\
    p1,3,constant,standard,comparison,standard,0.6,3,0.25,0\n\
    p1,4,constant,comparison,standard,comparison,0.6,3,0.33,1\n\
    p1,5,constant,standard,comparison,standard,0.6,3,0.33,0\n\
    p1,6,constant,comparison,standard,comparison,0.6,3,0.42,1\n\
    p1,7,constant,standard,comparison,comparison,0.6,3,0.49,1\n\
    p1,8,constant,comparison,standard,standard,0.6,3,0.49,0\n\
    p1,9,constant,standard,comparison,comparison,0.6,3,0.49,1\n";

/// The paper's paired study, participant `p1`: its spec, its trials, its stimuli (unrendered:
/// a resume checks names, never samples) and a log of its first 7 answers as the runner writes
/// it.
struct ResumeBase {
    spec: Spec,
    trials: Vec<Trial>,
    rendered: Vec<Rendered>,
    seed: u64,
    log: String,
}

const PARTICIPANT: &str = "p1";

impl ResumeBase {
    fn get() -> &'static Self {
        static BASE: OnceLock<ResumeBase> = OnceLock::new();
        BASE.get_or_init(|| {
            let spec = Spec::load(&Path::new(ROOT).join("experiments/paired-waves.toml")).unwrap();
            let seed = order_seed(spec.seed, PARTICIPANT);
            let trials = plan_trials(&spec, seed);
            let rendered = spec
                .stimuli
                .iter()
                .map(|_| Rendered {
                    samples: Vec::new(),
                    gain_db: -1.5,
                    level: 1.0,
                })
                .collect();
            let mut base = ResumeBase {
                spec,
                trials,
                rendered,
                seed,
                log: String::new(),
            };
            let folder = tempfile::tempdir().unwrap();
            let path = folder.path().join("log.csv");
            let mut log = TrialLog::create(&path).unwrap();
            let mut answers = "\n1\n2\n2\n1\n1\n2\n1\n".as_bytes();
            let stopped =
                base.session()
                    .run(0, &mut Silent, &mut log, &mut answers, &mut std::io::sink());
            assert!(matches!(
                stopped,
                Err(StudyError::InputClosed { answered: 7, .. })
            ));
            drop(log);
            base.log = std::fs::read_to_string(&path).unwrap();
            base
        })
    }

    fn session(&self) -> StudySession<'_> {
        StudySession {
            spec: &self.spec,
            participant: PARTICIPANT,
            seed: self.seed,
            trials: &self.trials,
            rendered: &self.rendered,
            dry_run: false,
        }
    }
}

proptest! {
    // No regression files written next to the sources, as in tests/support/fuzz.rs.
    #![proptest_config(ProptestConfig { failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn a_mutated_model_file_loads_or_is_refused_cleanly(
        edits in prop::collection::vec(edit(), 1..8),
    ) {
        let text = mutate(&read("tests/fixtures/models/fitted.toml"), &edits);
        if let Err(error) = ModelFile::parse("fitted.toml", &text) {
            assert_clean("model file", &error.to_string());
        }
    }

    #[test]
    fn a_mutated_study_spec_loads_or_is_refused_cleanly(
        edits in prop::collection::vec(edit(), 1..8),
        constant in any::<bool>(),
    ) {
        let name = if constant { "viscosity-constant" } else { "paired-waves" };
        let path = PathBuf::from(ROOT).join(format!("experiments/{name}.toml"));
        let text = mutate(&std::fs::read_to_string(&path).unwrap(), &edits);
        if let Err(error) = Spec::parse(&text, &path) {
            assert_clean("study spec", &error.to_string());
        }
    }

    #[test]
    fn a_mutated_fit_session_is_read_or_refused_cleanly(
        edits in prop::collection::vec(edit(), 1..8),
    ) {
        let folder = tempfile::tempdir().unwrap();
        let text = mutate(SESSION, &edits);
        if let Err(error) = FitSession::parse(&text, &folder.path().join("session.toml")) {
            assert_clean("fit session", &error.to_string());
        }
    }

    #[test]
    fn a_mutated_study_log_is_analysed_or_refused_cleanly(
        edits in prop::collection::vec(edit(), 1..8),
        constant in any::<bool>(),
    ) {
        let folder = tempfile::tempdir().unwrap();
        let log = folder.path().join("log.csv");
        let base = if constant { CONSTANT_LOG } else { PAIRED_LOG };
        std::fs::write(&log, mutate(base, &edits)).unwrap();
        let refused = if constant {
            let options = PsychometricOptions { resamples: 20, ..PsychometricOptions::default() };
            analyze_constant_logs(&[&log], &options, DryRuns::Refused).err()
        } else {
            analyze_paired_logs(&[&log], DryRuns::Refused).err()
        };
        if let Some(error) = refused {
            assert_clean("study log", &error.to_string());
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { failure_persistence: None, ..ProptestConfig::default() })]

    /// A log mutated anywhere (its rows, its answers, its end) resumes or is refused cleanly,
    /// and in either case is left byte for byte as it was: a resume writes nothing before the
    /// session's next answer.
    #[test]
    fn a_mutated_log_resumes_or_is_refused_and_is_never_changed(
        edits in prop::collection::vec(edit(), 1..8),
    ) {
        let base = ResumeBase::get();
        let folder = tempfile::tempdir().unwrap();
        let path = folder.path().join("log.csv");
        let text = mutate(&base.log, &edits);
        std::fs::write(&path, &text).unwrap();
        match base.session().resume_log(&path) {
            Ok((_, done)) => prop_assert!(done <= base.trials.len()),
            Err(error) => assert_clean("resumed log", &error.to_string()),
        }
        prop_assert_eq!(std::fs::read_to_string(&path).unwrap(), text);
    }
}

/// The mutations reach past the parsers' first line of defence: the valid bases load as they
/// are, so a refusal above is the edit's doing.
#[test]
fn the_bases_are_valid() {
    ModelFile::parse("fitted.toml", &read("tests/fixtures/models/fitted.toml")).unwrap();
    for name in ["paired-waves", "viscosity-constant"] {
        let path = PathBuf::from(ROOT).join(format!("experiments/{name}.toml"));
        Spec::load(&path).unwrap();
    }
    let folder = tempfile::tempdir().unwrap();
    FitSession::parse(SESSION, &folder.path().join("session.toml")).unwrap();
    let base = ResumeBase::get();
    let log = folder.path().join("resumed.csv");
    std::fs::write(&log, &base.log).unwrap();
    let (_, done) = base.session().resume_log(&log).unwrap();
    assert_eq!(done, 7);
    for (base, constant) in [(PAIRED_LOG, false), (CONSTANT_LOG, true)] {
        let log = folder.path().join("log.csv");
        std::fs::write(&log, base).unwrap();
        if constant {
            let options = PsychometricOptions {
                resamples: 20,
                ..PsychometricOptions::default()
            };
            analyze_constant_logs(&[&log], &options, DryRuns::Refused).unwrap();
        } else {
            analyze_paired_logs(&[&log], DryRuns::Refused).unwrap();
        }
    }
}
