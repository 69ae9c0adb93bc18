//! The harness of the property-based fuzz tests: proptest's runner with the case count of
//! `PROPTEST_CASES` (proptest's default, 256, in a normal test run) and a watchdog that turns a
//! hang into a failure.

use std::fmt::Debug;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use proptest::strategy::Strategy;
use proptest::test_runner::{Config, TestCaseError, TestRunner};

/// A case that runs this long is taken for a hang. Not a speed claim: cases take microseconds,
/// and this only bounds a loop that never ends.
const HANG_AFTER: Duration = Duration::from_secs(60);

/// Runs `property` on values of `strategy` until the configured number of cases passed or one
/// failed (then shrunk to a minimal input, which the panic shows).
pub fn run<S>(target: &str, strategy: S, property: impl Fn(S::Value) -> Result<(), TestCaseError>)
where
    S: Strategy,
    S::Value: Debug,
{
    let config = Config {
        // No regression files written next to the sources.
        failure_persistence: None,
        ..Config::default()
    };
    let finished = Arc::new(AtomicU64::new(0));
    let done = Arc::new(AtomicBool::new(false));
    let watchdog = {
        let (finished, done, target) = (finished.clone(), done.clone(), target.to_string());
        std::thread::spawn(move || {
            let mut last = (u64::MAX, Instant::now());
            while !done.load(Ordering::Relaxed) {
                std::thread::sleep(Duration::from_millis(200));
                let now = finished.load(Ordering::Relaxed);
                if now != last.0 {
                    last = (now, Instant::now());
                } else if last.1.elapsed() > HANG_AFTER {
                    eprintln!("fuzz {target}: HANG: no case finished for {HANG_AFTER:?}");
                    std::process::abort();
                }
            }
        })
    };
    let mut runner = TestRunner::new(config);
    let result = runner.run(&strategy, |value| {
        let outcome = property(value);
        finished.fetch_add(1, Ordering::Relaxed);
        outcome
    });
    done.store(true, Ordering::Relaxed);
    watchdog.join().unwrap();
    if let Err(error) = result {
        panic!("fuzz target {target}: {error}");
    }
}

/// A double from every corner: ordinary values, integers, the edges of f32 and f64, zeros of
/// both signs, infinities and NaN.
pub fn any_number() -> impl Strategy<Value = f64> {
    use proptest::prelude::*;
    prop_oneof![
        4 => -1e4f64..1e4,
        2 => (-200i64..1_000_000).prop_map(|n| n as f64),
        1 => prop::sample::select(vec![
            0.0,
            -0.0,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::MAX,
            f64::MIN,
            f64::MIN_POSITIVE,
            1e300,
            -1e300,
            f32::MAX as f64,
            1e39,
            5e-324,
        ]),
        1 => any::<f64>(),
    ]
}

/// `value` as TOML writes it (`nan`, `inf`, an exponent where Rust would print one).
pub fn toml_number(value: f64) -> String {
    if value.is_nan() {
        "nan".into()
    } else if value.is_infinite() {
        if value > 0.0 { "inf" } else { "-inf" }.into()
    } else {
        let text = format!("{value:?}");
        // TOML wants a digit after the point and accepts `1e300` as it is.
        if text.contains('.') || text.contains('e') {
            text
        } else {
            format!("{text}.0")
        }
    }
}

/// Byte edits for inputs that are nearly right: overwrite, insert or delete at positions taken
/// modulo the length (shared by every fuzz target that mutates a valid file or packet).
#[derive(Debug, Clone)]
pub enum Edit {
    /// Overwrite the byte at a position.
    Set(usize, u8),
    /// Insert a byte at a position.
    Insert(usize, u8),
    /// Remove the byte at a position.
    Remove(usize),
}

/// One to seven edits.
pub fn edits() -> impl Strategy<Value = Vec<Edit>> {
    use proptest::prelude::*;
    let edit = prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(at, byte)| Edit::Set(at, byte)),
        (any::<usize>(), any::<u8>()).prop_map(|(at, byte)| Edit::Insert(at, byte)),
        any::<usize>().prop_map(Edit::Remove),
    ];
    prop::collection::vec(edit, 1..8)
}

/// `bytes` with `edits` applied, then cut to at most `keep` bytes.
pub fn mutate(mut bytes: Vec<u8>, edits: &[Edit], keep: usize) -> Vec<u8> {
    for edit in edits {
        match *edit {
            Edit::Set(at, byte) if !bytes.is_empty() => {
                let at = at % bytes.len();
                bytes[at] = byte;
            }
            Edit::Insert(at, byte) => bytes.insert(at % (bytes.len() + 1), byte),
            Edit::Remove(at) if !bytes.is_empty() => {
                bytes.remove(at % bytes.len());
            }
            _ => {}
        }
    }
    bytes.truncate(keep);
    bytes
}
