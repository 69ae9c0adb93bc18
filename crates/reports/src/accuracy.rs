//! Error against run time (MODEL.md §9): every synthesis path renders a fixed set of cases at
//! several lengths and is compared with the f64 direct reference; the result is a table and a
//! work-precision diagram.
//!
//! Long renders are compared on windows — the first [`WINDOW_S`] seconds and the last
//! [`WINDOW_S`] seconds — because the direct reference costs one exp and one sin per component
//! and sample. The fast paths always render the whole length (so any drift would show in the
//! last window); the reference runs its pour over the whole length and evaluates its units only
//! inside the windows.

use std::ops::Range;
use std::time::Instant;

use super::timing::{self, RenderSpec};
use sake_glug_engine::synthesis::reference;
use sake_glug_engine::{
    AnchoredF32, ControlSource, ControlValues, DrainMode, ModelConfig, RecursiveF32, RecursiveF64,
    Synthesis,
};

/// Seconds compared at the start and at the end of a long render.
pub const WINDOW_S: f64 = 10.0;
/// The render lengths of the table, in seconds: 1 s, 1 min, 1 h.
pub const LENGTHS_S: [f64; 3] = [1.0, 60.0, 3600.0];
/// The error budget of MODEL.md §9 for the default path: below this at every render length (the
/// contract states it for an hour and forbids drift with length, so it holds at any length).
pub const BUDGET_DB: f64 = -100.0;

/// A case of the accuracy set: constants and inputs as a function of time.
#[derive(Clone, Copy)]
pub struct Case {
    /// Short name, as in the table.
    pub name: &'static str,
    /// What the case exercises.
    pub purpose: &'static str,
    /// The model's constants.
    pub config: ModelConfig,
    /// The inputs at time t (s).
    pub inputs: fn(f64) -> ControlValues,
}

impl Case {
    /// The case's inputs at `sample` of a render at `sample_rate` (the output gain at its default).
    pub fn controls(&self, sample_rate: f64) -> impl ControlSource + '_ {
        move |sample: u64| (self.inputs)(sample as f64 / sample_rate)
    }
}

/// The fixed set of cases.
pub fn cases() -> Vec<Case> {
    vec![
        Case {
            name: "pours",
            purpose: "the default scene (tilt 90°→135° over 0.5 s) repeated every 8 s with a \
                      refill, random spreads on: glugs throughout the render",
            config: ModelConfig::default(),
            inputs: |t| {
                let cycle = (t / 8.0).floor();
                let t_in = t - 8.0 * cycle;
                let tilt_deg = if t_in < 0.5 {
                    90.0 + 45.0 * t_in / 0.5
                } else if t_in < 6.0 {
                    135.0
                } else {
                    0.0
                };
                // In simulate mode a change of fill refills (MODEL.md §8).
                let fill_percent = if (cycle as u64).is_multiple_of(2) {
                    100.0
                } else {
                    99.9
                };
                ControlValues {
                    tilt_deg,
                    fill_percent,
                    ..ControlValues::default()
                }
            },
        },
        Case {
            name: "steady",
            purpose: "follow mode held full at 135°: 12 glugs/s of full amplitude for the \
                      whole render, deterministic",
            config: ModelConfig {
                drain: DrainMode::Follow,
                ..ModelConfig::default().deterministic()
            },
            inputs: |_| ControlValues {
                tilt_deg: 135.0,
                ..ControlValues::default()
            },
        },
        Case {
            name: "ring",
            purpose: "one unit with B1 = B2 = 0 that rings for the whole render: any drift of \
                      an oscillator's phase or magnitude accumulates here",
            config: ModelConfig {
                decay_per_s: [0.0, 0.0],
                ..ModelConfig::default().deterministic()
            },
            // 0.09 s at 135° lets 5.4 ml out: one 5 ml pocket, so exactly one unit.
            inputs: |t| ControlValues {
                tilt_deg: if t < 0.09 { 135.0 } else { 0.0 },
                ..ControlValues::default()
            },
        },
    ]
}

/// The synthesis paths of the project.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SynthesisPath {
    /// `reference::evaluate`: f64 closed form at every sample.
    Reference,
    /// The real-time path: f32 powers from an f64 anchor every 64 samples.
    Default,
    /// Per-sample f64 rotation, re-anchored every 65 536 samples.
    RecursiveF64,
    /// Per-sample f32 rotation, re-anchored every 65 536 samples.
    RecursiveF32,
}

impl SynthesisPath {
    /// Every path, in table order.
    pub const ALL: [SynthesisPath; 4] = [
        SynthesisPath::Reference,
        SynthesisPath::Default,
        SynthesisPath::RecursiveF64,
        SynthesisPath::RecursiveF32,
    ];

    /// The path's name in the table.
    pub fn name(self) -> &'static str {
        match self {
            SynthesisPath::Reference => "reference (f64 direct)",
            SynthesisPath::Default => "default (f32 anchored)",
            SynthesisPath::RecursiveF64 => "recursive f64",
            SynthesisPath::RecursiveF32 => "recursive f32",
        }
    }
}

/// One row of the table.
#[derive(Debug, Clone)]
pub struct Measurement {
    /// The case's name.
    pub case: &'static str,
    /// The synthesis path measured.
    pub path: SynthesisPath,
    /// Length of the render (s).
    pub length_s: f64,
    /// Largest |error| over the compared windows relative to the reference's peak there, in dB
    /// (−∞ when identical).
    pub max_error_db: f64,
    /// RMS error over the compared windows relative to the same peak, in dB.
    pub rms_error_db: f64,
    /// Audio seconds rendered per second of run time. For the reference: the compared windows'
    /// audio per second (its pour still runs over the whole length).
    pub times_real_time: f64,
}

/// The windows compared for a render of `len` samples.
pub fn windows(len: u64, sample_rate: f64) -> Vec<Range<u64>> {
    let window = (WINDOW_S * sample_rate) as u64;
    if len <= 2 * window {
        vec![Range { start: 0, end: len }]
    } else {
        vec![0..window, len - window..len]
    }
}

/// Error of `samples` against `reference` (same windows): (max dB, RMS dB) relative to the
/// reference's peak.
pub fn error_db(samples: &[f32], reference: &[f64]) -> (f64, f64) {
    assert_eq!(samples.len(), reference.len());
    let peak = reference.iter().fold(0.0f64, |a, y| a.max(y.abs()));
    let (mut worst, mut sum_sq) = (0.0f64, 0.0f64);
    for (&y, &r) in samples.iter().zip(reference) {
        let error = y as f64 - r;
        worst = worst.max(error.abs());
        sum_sq += error * error;
    }
    let rms = (sum_sq / samples.len().max(1) as f64).sqrt();
    (db(worst / peak), db(rms / peak))
}

fn db(ratio: f64) -> f64 {
    20.0 * ratio.log10()
}

/// The reference's samples over `windows` of a render of `len` samples, and its speed.
pub fn reference_windows(case: &Case, sample_rate: f64, windows: &[Range<u64>]) -> (Vec<f64>, f64) {
    let began = Instant::now();
    let mut samples = Vec::new();
    for window in windows {
        let controls = case.controls(sample_rate);
        samples.extend(
            reference::evaluate(sample_rate, case.config, &controls, window.clone()).samples,
        );
    }
    let audio_s = samples.len() as f64 / sample_rate;
    (samples, audio_s / began.elapsed().as_secs_f64())
}

/// Renders `case` for `len` samples on `path` (not the reference) and returns the samples
/// inside `windows` and the speed in × real time.
pub fn path_windows(
    path: SynthesisPath,
    case: &Case,
    sample_rate: f64,
    len: u64,
    windows: &[Range<u64>],
) -> (Vec<f32>, f64) {
    fn run<S: Synthesis>(case: &Case, spec: &RenderSpec, fs: f64) -> (Vec<f32>, f64) {
        let render = timing::timed_render::<S>(spec, &case.controls(fs));
        let audio_s = spec.len as f64 / fs;
        (render.kept, audio_s / render.engine_time.as_secs_f64())
    }
    let spec = RenderSpec {
        sample_rate,
        config: case.config,
        len,
        keep: windows,
        energy_span: 0,
    };
    match path {
        SynthesisPath::Reference => panic!("the reference is the yardstick, not a path under test"),
        SynthesisPath::Default => run::<AnchoredF32>(case, &spec, sample_rate),
        SynthesisPath::RecursiveF64 => run::<RecursiveF64>(case, &spec, sample_rate),
        SynthesisPath::RecursiveF32 => run::<RecursiveF32>(case, &spec, sample_rate),
    }
}

/// Measures every path on every case at every length; `progress` hears of each row as it is done.
pub fn measure(
    cases: &[Case],
    lengths_s: &[f64],
    sample_rate: f64,
    mut progress: impl FnMut(&Measurement),
) -> Vec<Measurement> {
    let mut rows = Vec::new();
    for case in cases {
        for &length_s in lengths_s {
            let len = (length_s * sample_rate).round() as u64;
            let windows = windows(len, sample_rate);
            let (reference, reference_speed) = reference_windows(case, sample_rate, &windows);
            for path in SynthesisPath::ALL {
                let row = if path == SynthesisPath::Reference {
                    Measurement {
                        case: case.name,
                        path,
                        length_s,
                        max_error_db: f64::NEG_INFINITY,
                        rms_error_db: f64::NEG_INFINITY,
                        times_real_time: reference_speed,
                    }
                } else {
                    let (samples, speed) = path_windows(path, case, sample_rate, len, &windows);
                    let (max_error_db, rms_error_db) = error_db(&samples, &reference);
                    Measurement {
                        case: case.name,
                        path,
                        length_s,
                        max_error_db,
                        rms_error_db,
                        times_real_time: speed,
                    }
                };
                progress(&row);
                rows.push(row);
            }
        }
    }
    rows
}

/// Why the rows fail MODEL.md §9, one line each; empty if they pass. A row whose error is NaN
/// (empty or silent windows: a length or sample rate of 0) fails whatever its path, and the
/// default path fails at any length where its max error is not below [`BUDGET_DB`].
pub fn budget_failures(rows: &[Measurement]) -> Vec<String> {
    let mut failures = Vec::new();
    for row in rows {
        let label = format!(
            "{} / {} / {}",
            row.case,
            row.path.name(),
            length_label(row.length_s)
        );
        if row.max_error_db.is_nan() || row.rms_error_db.is_nan() {
            failures.push(format!(
                "{label}: the error is NaN (nothing was compared: empty or silent windows)"
            ));
        } else if row.path == SynthesisPath::Default && row.max_error_db >= BUDGET_DB {
            failures.push(format!(
                "{label}: max error {:.1} dB is not below the budget of {BUDGET_DB} dB",
                row.max_error_db
            ));
        }
    }
    failures
}

/// A length as the table shows it.
pub fn length_label(length_s: f64) -> String {
    if length_s >= 3600.0 && length_s % 3600.0 == 0.0 {
        format!("{} h", length_s / 3600.0)
    } else if length_s >= 60.0 && length_s % 60.0 == 0.0 {
        format!("{} min", length_s / 60.0)
    } else {
        format!("{length_s} s")
    }
}

fn db_label(value: f64) -> String {
    if value == f64::NEG_INFINITY {
        "0 (yardstick)".to_string()
    } else {
        format!("{value:.1}")
    }
}

/// The rows as a Markdown table.
pub fn table(rows: &[Measurement]) -> String {
    let mut text = String::from(
        "| case | path | length | max error (dB re peak) | RMS error (dB re peak) | × real time |\n\
         |---|---|---|---:|---:|---:|\n",
    );
    for row in rows {
        text += &format!(
            "| {} | {} | {} | {} | {} | {:.0} |\n",
            row.case,
            row.path.name(),
            length_label(row.length_s),
            db_label(row.max_error_db),
            db_label(row.rms_error_db),
            row.times_real_time,
        );
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_cover_short_renders_whole_and_long_ones_at_both_ends() {
        assert_eq!(windows(48_000, 48_000.0), vec![0..48_000]);
        let hour = 3600 * 48_000;
        assert_eq!(
            windows(hour, 48_000.0),
            vec![0..480_000, hour - 480_000..hour]
        );
    }

    #[test]
    fn error_is_relative_to_the_reference_peak() {
        let (max, rms) = error_db(&[0.5, -0.5], &[0.5, -0.5005]);
        assert!((max - db(0.0005 / 0.5005)).abs() < 1e-6);
        assert!(rms < max);
    }

    #[test]
    fn the_ring_scene_starts_exactly_one_unit() {
        let case = cases().into_iter().find(|s| s.name == "ring").unwrap();
        let controls = case.controls(48_000.0);
        let render = reference::evaluate(48_000.0, case.config, &controls, 0..48_000);
        assert_eq!(render.onsets.len(), 1);
    }
}
