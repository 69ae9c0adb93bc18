//! Error against the f64 reference (MODEL.md §9) at test lengths: the default path stays under
//! −100 dB on long renders, no path drifts with length, and the recursive paths' re-anchoring
//! bounds their error. `sake-glug accuracy` measures the same at 1 s, 1 min and 1 h.

use std::ops::Range;

use sake_glug_reports::accuracy::{self, Case, SynthesisPath};

const FS: f64 = 48_000.0;

fn scene(name: &str) -> Case {
    accuracy::cases()
        .into_iter()
        .find(|s| s.name == name)
        .expect("a scene of the accuracy set")
}

/// Max error (dB re the window's reference peak) of `path` in each window of a render of
/// `seconds`: the first and the last ten seconds.
fn window_errors(path: SynthesisPath, scene: &Case, seconds: f64) -> Vec<f64> {
    let len = (seconds * FS) as u64;
    let windows: Vec<Range<u64>> = accuracy::windows(len, FS);
    let (reference, _) = accuracy::reference_windows(scene, FS, &windows);
    let (samples, _) = accuracy::path_windows(path, scene, FS, len, &windows);
    let mut errors = Vec::new();
    let mut start = 0;
    for window in &windows {
        let end = start + (window.end - window.start) as usize;
        errors.push(accuracy::error_db(&samples[start..end], &reference[start..end]).0);
        start = end;
    }
    errors
}

#[test]
fn default_path_is_below_minus_100_db_on_long_renders() {
    // Twenty minutes of a never-decaying unit, and ten of refilled random pours.
    for (name, seconds) in [("ring", 1200.0), ("pours", 600.0)] {
        let errors = window_errors(SynthesisPath::Default, &scene(name), seconds);
        assert_eq!(errors.len(), 2);
        for error in errors {
            assert!(error < -100.0, "{name}: {error:.1} dB");
        }
    }
}

#[test]
fn no_path_drifts_with_render_length() {
    // The ring scene's content is the same at every point of the render, so the error of its
    // last ten seconds may not exceed that of its first ten seconds.
    let ring = scene("ring");
    for path in [
        SynthesisPath::Default,
        SynthesisPath::RecursiveF64,
        SynthesisPath::RecursiveF32,
    ] {
        let errors = window_errors(path, &ring, 1200.0);
        assert!(
            errors[1] <= errors[0] + 1.0,
            "{}: first 10 s {:.1} dB, last 10 s {:.1} dB",
            path.name(),
            errors[0],
            errors[1]
        );
    }
}

#[test]
fn recursive_paths_are_reanchored() {
    let ring = scene("ring");
    let f64_errors = window_errors(SynthesisPath::RecursiveF64, &ring, 600.0);
    assert!(
        f64_errors[1] < -130.0,
        "recursive f64 at 10 min: {:.1} dB",
        f64_errors[1]
    );
    // An f32 recursion of 65 536 samples shows its rounding but, re-anchored, stays bounded: an
    // unanchored one would have lost more than 30 dB more over 10 minutes.
    let f32_errors = window_errors(SynthesisPath::RecursiveF32, &ring, 600.0);
    assert!(
        (-90.0..-40.0).contains(&f32_errors[1]),
        "recursive f32 at 10 min: {:.1} dB",
        f32_errors[1]
    );
}

#[test]
fn every_engine_path_matches_the_reference_on_a_one_second_pour() {
    let pours = scene("pours");
    for (path, budget) in [
        (SynthesisPath::Default, -110.0),
        (SynthesisPath::RecursiveF64, -110.0),
        (SynthesisPath::RecursiveF32, -80.0),
    ] {
        let error = window_errors(path, &pours, 1.0)[0];
        assert!(error < budget, "{}: {error:.1} dB", path.name());
    }
}

#[test]
fn the_budget_is_gated_at_every_length_and_a_nan_row_fails() {
    let pours = [scene("pours")];
    let rows = accuracy::measure(&pours, &[1.0], FS, |_| {});
    assert_eq!(accuracy::budget_failures(&rows), Vec::<String>::new());
    // Over budget at 1 s: a short render answers to the budget too.
    let mut over = rows.clone();
    let default = over
        .iter_mut()
        .find(|row| row.path == SynthesisPath::Default)
        .unwrap();
    default.max_error_db = -99.0;
    let failures = accuracy::budget_failures(&over);
    assert_eq!(failures.len(), 1, "{failures:?}");
    assert!(
        failures[0].contains("default (f32 anchored) / 1 s"),
        "{failures:?}"
    );
    // A sample rate of 0 leaves nothing to compare: every engine path's row is NaN and fails.
    let empty = accuracy::measure(&pours, &[1.0], 0.0, |_| {});
    let failures = accuracy::budget_failures(&empty);
    assert_eq!(failures.len(), 3, "{failures:?}");
    assert!(failures.iter().all(|failure| failure.contains("NaN")));
}
