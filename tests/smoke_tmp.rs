use sake_glug::engine::*;
use sake_glug::reference;

#[test]
fn smoke() {
    let fs = 48_000.0;
    let config = ModelConfig::default().deterministic();
    let len = 48_000 * 8;
    let tilt = |n: u64| { let t = n as f64 / fs; if t < 0.5 { 90.0 + 45.0 * t / 0.5 } else { 135.0 } };
    let tilts: Vec<f64> = (0..len as u64).map(tilt).collect();
    let mut engine = Engine::new(fs, config);
    let controls = Controls { tilt_deg: Lane::Samples(&tilts), ..Controls::default() };
    let mut out = vec![0f32; len];
    let t0 = std::time::Instant::now();
    engine.process(&controls, &mut out);
    eprintln!("engine {:?}", t0.elapsed());
    let mut src = |n: u64| (ControlValues { tilt_deg: tilt(n), ..ControlValues::default() }, -6.0);
    let r = reference::render(fs, config, &mut src, 0..len as u64);
    let peak = r.samples.iter().fold(0f64, |a, b| a.max(b.abs()));
    let err = out.iter().zip(&r.samples).fold(0f64, |a, (x, y)| a.max((*x as f64 - y).abs()));
    eprintln!("units {} peak {peak} err {} dB; stats {:?}", r.onsets.len(), 20.0 * (err / peak).log10(), engine.stats());
}
