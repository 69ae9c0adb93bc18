//! Render speed of the default path, as × real time (criterion's throughput in samples/s divided
//! by the sample rate), beside the memory limit: merely filling a buffer of the same length.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use sake_glug::offline::render_scene;
use sake_glug::offline::Scene;

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

/// Renders into `out` (the sink a WAV writer would be), returning the sample count.
fn render_into(scene: &Scene, out: &mut Vec<f32>) -> usize {
    out.clear();
    render_scene(
        scene,
        |block| {
            out.extend_from_slice(block);
            Ok::<(), sake_glug::offline::RenderError>(())
        },
        &mut |_| {},
    )
    .expect("renders");
    out.len()
}

fn bench(c: &mut Criterion) {
    for (name, scene) in [
        ("default scene", Scene::default()),
        ("one hour of pours", hour_of_pours()),
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
        report_realtime_factors(name, &scene, samples, &mut out);
    }
}

/// One line with the figures the project reports: × real time and the ratio to the memory limit,
/// both measured here in the same run (best of five).
fn report_realtime_factors(name: &str, scene: &Scene, samples: usize, out: &mut Vec<f32>) {
    let best = |f: &mut dyn FnMut()| {
        (0..5)
            .map(|_| {
                let start = std::time::Instant::now();
                f();
                start.elapsed().as_secs_f64()
            })
            .fold(f64::INFINITY, f64::min)
    };
    let render_s = best(&mut || {
        render_into(scene, out);
    });
    let fill_s = best(&mut || {
        out.clear();
        out.resize(samples, 0.0);
    });
    let seconds = samples as f64 / scene.sample_rate as f64;
    println!(
        "{name}: render {:.0}× real time; filling the buffer {:.0}× real time; render costs {:.1}× the fill",
        seconds / render_s,
        seconds / fill_s,
        render_s / fill_s
    );
}

criterion_group!(benches, bench);
criterion_main!(benches);
