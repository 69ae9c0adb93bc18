//! The fit of a minute's recording (issue 17): a 60 s, 25 kHz render of the default model held
//! full at 135° (follow mode, 12 units a second) with noise 40 dB below the glugs, written as a
//! WAV file and fitted by `sake_glug_fit` as `sake-glug fit` does; beside it, measured in the
//! same run, the same units fitted one by one by SciPy's `curve_fit` (`benches/scipy_fit.py`)
//! from the starts `sake-glug fit` used, and how far the two fits lie apart.

use std::path::Path;

use criterion::Criterion;
use sake_glug_fit::{fit_session, fit_units, Audio, FitSession, UnitFit, UnitMethod};
use sake_glug_render::{render_scene_to_vec, Scene};

use super::{best_of, python_with, run_timed_script};

const RECORDING: &str = "sample_rate = 25000\nduration_s = 60.0\ntilt_deg = 135.0\n\
                         [output]\ndrain = \"follow\"\n";
/// The noise's level below the RMS of the glugs (dB).
const NOISE_DB: f64 = -40.0;

/// Benchmarks the fit and returns the line the report quotes.
pub fn fit_versus_scipy(c: &mut Criterion) -> String {
    let folder = tempfile::tempdir().expect("a temporary folder");
    let session_path = write_recording(folder.path());
    let session = FitSession::load(&session_path).expect("the benchmark's session is valid");
    let fit = fit_session(&session).expect("the benchmark's recording fits");
    let mut group = c.benchmark_group("fit of a 60 s, 25 kHz recording");
    group.sample_size(10);
    group.bench_function("sake-glug fit", |b| {
        b.iter(|| fit_session(&session).expect("fits"))
    });
    group.finish();
    let fit_s = best_of(3, &mut || {
        fit_session(&session).expect("fits");
    });
    let audio = Audio::read(&session.recordings[0].audio, "minute.wav")
        .expect("the benchmark's recording reads");
    let units_s = best_of(3, &mut || {
        fit_units(&audio.samples, audio.sample_rate);
    });
    // SciPy is handed eq. 1 as it stands: the units that eq. 1 gave (on a render, every one).
    let units: Vec<UnitFit> = fit.recordings[0]
        .units
        .iter()
        .map(|u| u.fit)
        .filter(|u| u.method == UnitMethod::Eq1)
        .collect();
    let ours = format!(
        "fit of a 60 s, 25 kHz recording ({} units): sake-glug fit {fit_s:.2} s (the unit fits \
         alone {units_s:.2} s)",
        units.len()
    );
    let every_sample = scipy_fits(&audio, &units, Samples::Every);
    let ours_only = scipy_fits(&audio, &units, Samples::AsFitted);
    match (every_sample, ours_only) {
        (Ok((scipy_s, fitted)), Ok((scipy_strided_s, _))) => format!(
            "{ours}; SciPy curve_fit of the same units from the same starts: {scipy_s:.2} s on \
             every sample of the windows (the whole fit {}), {scipy_strided_s:.2} s on the samples \
             sake-glug fits (every {}th: {}); against SciPy's fits on every sample, {}",
            speed(fit_s, scipy_s),
            units.first().map_or(1, |u| u.stride),
            speed(fit_s, scipy_strided_s),
            agreement(&units, &fitted)
        ),
        (Err(why), _) | (_, Err(why)) => format!("{ours}; SciPy not measured: {why}"),
    }
}

/// "N× faster than SciPy" (or slower) for our time against SciPy's.
fn speed(ours_s: f64, scipy_s: f64) -> String {
    if scipy_s >= ours_s {
        format!("{:.1}× faster than SciPy", scipy_s / ours_s)
    } else {
        format!("{:.1}× slower than SciPy", ours_s / scipy_s)
    }
}

/// Which samples of each window SciPy is handed.
#[derive(Clone, Copy, PartialEq)]
enum Samples {
    /// All of them: what a researcher would write.
    Every,
    /// Those `sake-glug fit` read (every `stride`-th): the same problem for both solvers.
    AsFitted,
}

/// Renders the recording, adds the noise, and writes it and its session into `folder`.
fn write_recording(folder: &Path) -> std::path::PathBuf {
    let scene = Scene::parse(RECORDING).expect("the benchmark scene is valid");
    let (mut samples, _) = render_scene_to_vec(&scene).expect("renders");
    let peak = samples.iter().fold(0.0f32, |p, y| p.max(y.abs())) as f64;
    let loud: Vec<f64> = samples
        .iter()
        .map(|&y| y as f64)
        .filter(|y| y.abs() > 0.1 * peak)
        .collect();
    let glug_rms = (loud.iter().map(|y| y * y).sum::<f64>() / loud.len() as f64).sqrt();
    add_noise(&mut samples, glug_rms * 10f64.powf(NOISE_DB / 20.0));
    let spec = hound::WavSpec {
        channels: 1,
        sample_rate: scene.sample_rate,
        bits_per_sample: 32,
        sample_format: hound::SampleFormat::Float,
    };
    let mut wav = hound::WavWriter::create(folder.join("minute.wav"), spec).expect("a WAV file");
    for sample in samples {
        wav.write_sample(sample).expect("writes");
    }
    wav.finalize().expect("writes");
    let session = folder.join("session.toml");
    std::fs::write(
        &session,
        "capacity_ml = 300.0\n[[recording]]\naudio = \"minute.wav\"\ntilt_deg = 135.0\n\
         start_ml = 300.0\n",
    )
    .expect("writes");
    session
}

/// Nearly normal noise of standard deviation `sigma` (a sum of twelve uniforms from a fixed
/// generator: the same recording on every run).
fn add_noise(samples: &mut [f32], sigma: f64) {
    let mut state = 0x5eed_u64;
    let mut uniform = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    for sample in samples {
        let normal: f64 = (0..12).map(|_| uniform()).sum();
        *sample += (sigma * normal) as f32;
    }
}

/// Runs `benches/scipy_fit.py` on the windows `sake-glug fit` fitted: each the recording less
/// the units fitted before it, as the fit saw it. Returns SciPy's time (s) and its fits.
fn scipy_fits(
    audio: &Audio,
    units: &[UnitFit],
    samples: Samples,
) -> Result<(f64, Vec<[f64; 7]>), String> {
    let python = python_with("scipy").ok_or("no python3 with scipy found")?;
    let fs = audio.sample_rate as f64;
    let (mut table, mut windows) = (Vec::new(), Vec::new());
    for (index, unit) in units.iter().enumerate() {
        let (first, end) = unit.window;
        let stride = match samples {
            Samples::Every => 1,
            Samples::AsFitted => unit.stride,
        };
        let earlier: Vec<&UnitFit> = units[..index]
            .iter()
            .filter(|e| e.onset_s > first as f64 / fs - 0.5)
            .collect();
        let read: Vec<usize> = (first..end).step_by(stride).collect();
        for &n in &read {
            let t = n as f64 / fs;
            let before: f64 = earlier.iter().map(|e| e.value_at(t)).sum();
            windows.extend_from_slice(&(f64::from(audio.samples[n]) - before).to_le_bytes());
        }
        for value in [first as f64, read.len() as f64, stride as f64]
            .into_iter()
            .chain(unit.start)
        {
            table.extend_from_slice(&value.to_le_bytes());
        }
    }
    let dir = tempfile::tempdir().map_err(|e| e.to_string())?;
    let (units_path, windows_path, out_path) = (
        dir.path().join("units.f64"),
        dir.path().join("windows.f64"),
        dir.path().join("fitted.f64"),
    );
    std::fs::write(&units_path, &table).map_err(|e| e.to_string())?;
    std::fs::write(&windows_path, &windows).map_err(|e| e.to_string())?;
    let seconds = run_timed_script(
        &python,
        "scipy_fit.py",
        &[
            units_path.as_os_str(),
            windows_path.as_os_str(),
            fs.to_string().as_ref(),
            out_path.as_os_str(),
        ],
    )?;
    let fitted: Vec<[f64; 7]> = std::fs::read(&out_path)
        .map_err(|e| e.to_string())?
        .chunks_exact(8 * 7)
        .map(|row| {
            std::array::from_fn(|k| {
                f64::from_le_bytes(row[8 * k..8 * k + 8].try_into().expect("8 bytes"))
            })
        })
        .collect();
    if fitted.len() != units.len() {
        return Err(format!("{} fits for {} units", fitted.len(), units.len()));
    }
    Ok((seconds, fitted))
}

/// How far SciPy's fits lie from ours: the median and largest relative difference of f and B
/// (both components) and the absolute difference of c, over the units SciPy fitted.
fn agreement(units: &[UnitFit], fitted: &[[f64; 7]]) -> String {
    let (mut f, mut b, mut c) = (Vec::new(), Vec::new(), Vec::new());
    let mut failed = 0;
    for (unit, p) in units.iter().zip(fitted) {
        if p.iter().any(|v| !v.is_finite()) {
            failed += 1;
            continue;
        }
        // SciPy's components in our order (f1 the lower).
        let (low, high) = if p[3] <= p[4] { (0, 1) } else { (1, 0) };
        for (k, j) in [low, high].into_iter().enumerate() {
            f.push((p[3 + j] / unit.frequency_hz[k] - 1.0).abs());
            b.push((p[5 + j] / unit.decay_per_s[k] - 1.0).abs());
        }
        c.push((p[1 + low] / (p[1] + p[2]) - unit.viscosity()).abs());
    }
    let spread = |values: &mut Vec<f64>| {
        values.sort_by(f64::total_cmp);
        let median = values.get(values.len() / 2).copied().unwrap_or(f64::NAN);
        (median, values.last().copied().unwrap_or(f64::NAN))
    };
    let ((f_median, f_max), (b_median, b_max), (c_median, c_max)) =
        (spread(&mut f), spread(&mut b), spread(&mut c));
    format!(
        "the fits differ by f {:.2} % (median; largest {:.2} %), B {:.2} % ({:.2} %), c {c_median:.4} \
         ({c_max:.4}); SciPy failed on {failed} units",
        100.0 * f_median,
        100.0 * f_max,
        100.0 * b_median,
        100.0 * b_max,
    )
}
