//! Render speed of the default path as × real time, on one core (the engine is single-threaded),
//! for three scenes: the default scene, one hour of repeated pours and one hour of continuous
//! pouring in follow mode. Beside each, measured in the same run: the memory limit (merely
//! filling a buffer of the same length) and the same glug train synthesised unit by unit with
//! NumPy (`benches/numpy_glug.py`, when a Python with NumPy is found: the project's `.venv`, then
//! `python3`). Then the fit of a minute's recording by `sake_glug_fit` against SciPy's
//! `curve_fit` of the same units (`render/fit.rs`, `benches/scipy_fit.py`).
//!
//! Criterion reports its own statistics; the lines the project quotes are printed after each
//! scene and written to `<target>/bench-render.md`, which `cargo xtask docs` copies into
//! docs/scaling.md.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use sake_glug_engine::{UnitOnset, Voicing};
use sake_glug_render::{render_scene, RenderError, RenderObserver, Scene};

#[path = "render/fit.rs"]
mod fit;
mod report;

/// One hour of repeated pours at 48 kHz: every 10 s tilt up and pour 6 s, put the bottle
/// upright, and refill it. A change of the fill level refills in simulate mode, so the level
/// steps (two points at one time) between 100 % and 99.9 % once per pour.
fn hour_of_pours() -> Scene {
    let (mut tilt, mut fill) = (Vec::new(), Vec::new());
    for pour in 0..360 {
        let t = pour as f64 * 10.0;
        tilt.push(format!(
            "[{t}, 90.0], [{}, 135.0], [{}, 135.0], [{}, 0.0]",
            t + 0.5,
            t + 6.0,
            t + 6.5
        ));
        let (from, to) = if pour % 2 == 0 {
            (100.0, 99.9)
        } else {
            (99.9, 100.0)
        };
        fill.push(format!("[{}, {from}], [{}, {to}]", t + 9.0, t + 9.0));
    }
    let text = format!(
        "duration_s = 3600.0\ntilt_deg = [{}]\nfill_percent = [{}]\n",
        tilt.join(", "),
        fill.join(", ")
    );
    Scene::parse(&text).expect("the benchmark scene is valid")
}

/// One hour of continuous pouring: follow mode holds the bottle full at 135°, so it glugs at
/// 12 units a second for the whole hour.
fn hour_of_follow_pouring() -> Scene {
    Scene::parse("duration_s = 3600.0\ntilt_deg = 135.0\n[output]\ndrain = \"follow\"\n")
        .expect("the benchmark scene is valid")
}

/// Renders into `out` (the sink a WAV writer would be), returning the sample count.
fn render_into(scene: &Scene, out: &mut Vec<f32>) -> usize {
    out.clear();
    render_scene(
        scene,
        |block| {
            out.extend_from_slice(block);
            Ok::<(), RenderError>(())
        },
        &mut |_| {},
    )
    .expect("renders");
    out.len()
}

/// Collects the units of a render, for the NumPy script.
#[derive(Default)]
struct Units(Vec<UnitOnset>);

impl RenderObserver for Units {
    fn unit_started(&mut self, onset: &UnitOnset, _voicing: Voicing) {
        self.0.push(*onset);
    }
}

fn bench(c: &mut Criterion) {
    let mut report = String::new();
    for (name, scene) in [
        ("default scene", Scene::default()),
        ("one hour of pours", hour_of_pours()),
        ("one hour of follow pouring", hour_of_follow_pouring()),
    ] {
        let mut out = Vec::new();
        let samples = render_into(&scene, &mut out);
        let mut group = c.benchmark_group(name);
        group.sample_size(10);
        group.throughput(Throughput::Elements(samples as u64));
        group.bench_function(BenchmarkId::new("render", samples), |b| {
            b.iter(|| render_into(&scene, &mut out))
        });
        group.bench_function(
            BenchmarkId::new("fill zeros (memory limit)", samples),
            |b| {
                b.iter(|| {
                    out.clear();
                    out.resize(samples, 0.0);
                    out.len()
                })
            },
        );
        group.finish();
        let line = realtime_factors(name, &scene, samples, &mut out);
        println!("{line}");
        writeln!(report, "{line}").expect("a String takes any text");
    }
    {
        let line = fit::fit_versus_scipy(c);
        println!("{line}");
        writeln!(report, "{line}").expect("a String takes any text");
    }
    report::save("render", &report);
}

/// The line the project quotes for one scene: × real time of the render, of filling the buffer
/// and of the NumPy synthesis, all measured here in the same run (best of five for the two
/// Rust figures, one run of the slower NumPy script).
fn realtime_factors(name: &str, scene: &Scene, samples: usize, out: &mut Vec<f32>) -> String {
    let render_s = best_of(5, &mut || {
        render_into(scene, out);
    });
    let fill_s = best_of(5, &mut || {
        out.clear();
        out.resize(samples, 0.0);
    });
    let seconds = samples as f64 / scene.sample_rate as f64;
    let numpy = match numpy_synthesis(scene, samples) {
        Ok((numpy_s, error_db)) => format!(
            "NumPy unit by unit {:.0}× (its samples {error_db:.0} dB from the render's)",
            seconds / numpy_s
        ),
        Err(why) => format!("NumPy not measured: {why}"),
    };
    format!(
        "{name} ({seconds:.1} s): render {:.0}× real time; filling the buffer {:.0}×; {numpy}",
        seconds / render_s,
        seconds / fill_s,
    )
}

/// Runs the script named `script` in `benches/` with `args` under `python` and returns the
/// seconds it says its own timed part took (its one line of output, `seconds=…`).
fn run_timed_script(python: &Path, script: &str, args: &[&std::ffi::OsStr]) -> Result<f64, String> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("benches")
        .join(script);
    let output = Command::new(python)
        .arg(&script)
        .args(args)
        .output()
        .map_err(|e| e.to_string())?;
    if !output.status.success() {
        return Err(String::from_utf8_lossy(&output.stderr).into_owned());
    }
    let stdout = String::from_utf8_lossy(&output.stdout);
    stdout
        .trim()
        .strip_prefix("seconds=")
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| format!("unexpected output from the script: {stdout}"))
}

/// The shortest of `runs` timings of `f` (s).
fn best_of(runs: usize, f: &mut dyn FnMut()) -> f64 {
    (0..runs)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Runs `benches/numpy_glug.py` on the units of one render of `scene`; returns the script's
/// synthesis time (s) and its largest difference from the render, relative to the render's peak
/// (dB): a check that it synthesised the same train.
fn numpy_synthesis(scene: &Scene, samples: usize) -> Result<(f64, f64), String> {
    let python = python_with("numpy").ok_or("no python3 with numpy found")?;
    let mut units = Units::default();
    let mut rendered = Vec::with_capacity(samples);
    render_scene(
        scene,
        |block| {
            rendered.extend_from_slice(block);
            Ok::<(), RenderError>(())
        },
        &mut units,
    )
    .expect("renders");
    let fs = scene.sample_rate as f64;
    let mut table = Vec::with_capacity(units.0.len() * 8 * 8);
    for unit in &units.0 {
        let onset_s = (unit.sample as f64 + unit.fraction) / fs;
        let [a1, a2] = unit.component_amplitudes();
        let [f1, f2] = unit.shape.frequency_hz;
        let [b1, b2] = unit.shape.decay_per_s;
        let gain_db = scene.lanes.gain_db.value_at(onset_s);
        for value in [onset_s, a1, a2, f1, f2, b1, b2, gain_db] {
            table.extend_from_slice(&value.to_le_bytes());
        }
    }
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let units_path = dir.path().join("units.f64");
    let out_path = dir.path().join("out.f32");
    std::fs::write(&units_path, &table).map_err(|e| e.to_string())?;
    let seconds = run_timed_script(
        &python,
        "numpy_glug.py",
        &[
            units_path.as_os_str(),
            samples.to_string().as_ref(),
            fs.to_string().as_ref(),
            out_path.as_os_str(),
        ],
    )?;
    let numpy: Vec<f32> = std::fs::read(&out_path)
        .map_err(|e| e.to_string())?
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        .collect();
    let peak = rendered.iter().fold(0.0f32, |p, y| p.max(y.abs())) as f64;
    let error = rendered
        .iter()
        .zip(&numpy)
        .fold(0.0f64, |e, (a, b)| e.max((*a as f64 - *b as f64).abs()));
    Ok((seconds, 20.0 * (error / peak).log10()))
}

/// The project's virtual environment (made by `cargo xtask test`), else `python3`, if `module`
/// imports in it.
fn python_with(module: &str) -> Option<PathBuf> {
    let venv = Path::new(env!("CARGO_MANIFEST_DIR")).join(".venv/bin/python");
    [venv, PathBuf::from("python3")].into_iter().find(|python| {
        Command::new(python)
            .args(["-c", &format!("import {module}")])
            .output()
            .is_ok_and(|out| out.status.success())
    })
}

criterion_group!(benches, bench);
criterion_main!(benches);
