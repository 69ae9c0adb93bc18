//! Rules of the haptic clip formats: a validator per format with one named rule per
//! requirement, fixtures that pass or break exactly one rule, and the clips written from a
//! synthetic pour checked against the rules and the model.

/// A format's `Rule` enum from `Variant => "snake_name": "what it requires",` lines: the name
/// is that of the invalid fixture that breaks only it.
macro_rules! rules {
    ($($variant:ident => $name:literal: $description:literal,)+) => {
        /// A requirement of the format.
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub enum Rule {
            $($variant,)+
        }

        impl crate::clip_rules::Rule for Rule {
            const ALL: &'static [Self] = &[$(Rule::$variant,)+];

            fn name(&self) -> &'static str {
                match self {
                    $(Rule::$variant => $name,)+
                }
            }

            fn description(&self) -> &'static str {
                match self {
                    $(Rule::$variant => $description,)+
                }
            }
        }

        fn violation(rule: Rule, detail: impl Into<String>) -> crate::clip_rules::Violation<Rule> {
            crate::clip_rules::Violation {
                rule,
                detail: detail.into(),
            }
        }
    };
}

pub mod ahap;
pub mod android_ogg;
pub mod android_waveform;
pub mod android_xml;
mod clips_written;
pub mod dualsense;
pub mod haps;
pub mod haptic;
mod limits_over_seeds;
mod platforms_written;
pub mod rumble;

use std::fmt::Debug;
use std::path::{Path, PathBuf};

/// One broken rule and where it was broken.
#[derive(Debug, Clone)]
pub struct Violation<R> {
    /// The rule that was broken.
    pub rule: R,
    /// Where and how; shown through `Debug` when a test fails, so the compiler sees no read.
    #[allow(dead_code)]
    pub detail: String,
}

/// A named requirement of a file format.
pub trait Rule: Copy + PartialEq + Debug + 'static {
    /// Every rule of the format.
    const ALL: &'static [Self];
    /// The rule in snake case: the name of the invalid fixture that breaks only it.
    fn name(&self) -> &'static str;
    /// What the rule requires.
    fn description(&self) -> &'static str;
}

/// The fixture files of `kind` ("valid" or "invalid") with the given extension, sorted.
pub fn fixtures(kind: &str, extension: &str) -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/clips")
        .join(kind);
    let mut paths: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == extension))
        .collect();
    paths.sort();
    paths
}

/// Every valid fixture passes; every rule has an invalid fixture named after it that is
/// refused for that rule and no other; no invalid fixture is named after an unknown rule.
pub fn check_fixtures<R: Rule>(extension: &str, validate: impl Fn(&str) -> Vec<Violation<R>>) {
    check_binary_fixtures(extension, |bytes| match std::str::from_utf8(bytes) {
        Ok(text) => validate(text),
        Err(e) => panic!("a .{extension} fixture is not UTF-8: {e}"),
    })
}

/// [`check_fixtures`] for a format whose files are bytes, not text.
pub fn check_binary_fixtures<R: Rule>(
    extension: &str,
    validate: impl Fn(&[u8]) -> Vec<Violation<R>>,
) {
    let read =
        |path: &Path| std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let valid = fixtures("valid", extension);
    assert!(!valid.is_empty(), "no valid .{extension} fixtures");
    for path in &valid {
        let violations = validate(&read(path));
        assert!(
            violations.is_empty(),
            "{} should be valid but breaks {violations:#?}",
            path.display()
        );
    }

    let invalid = fixtures("invalid", extension);
    for path in &invalid {
        let stem = path
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or_default();
        let rule = R::ALL
            .iter()
            .find(|rule| rule.name() == stem)
            .unwrap_or_else(|| panic!("{} is named after no rule", path.display()));
        let violations = validate(&read(path));
        assert!(
            !violations.is_empty(),
            "{} should break \"{}\" but passes",
            path.display(),
            rule.description()
        );
        let others: Vec<&Violation<R>> = violations.iter().filter(|v| v.rule != *rule).collect();
        assert!(
            others.is_empty(),
            "{} should break only \"{}\" but also breaks {others:#?}",
            path.display(),
            rule.description()
        );
    }
    for rule in R::ALL {
        let expected = format!("{}.{extension}", rule.name());
        assert!(
            invalid
                .iter()
                .any(|p| p.file_name().is_some_and(|f| f == expected.as_str())),
            "no invalid fixture {expected} for \"{}\"",
            rule.description()
        );
    }
}
