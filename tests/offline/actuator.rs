//! `sake-glug render --actuator` (MODEL.md §18): the device, simulated here by a filter the test
//! builds from the profile's own points (not the engine's code), delivers the model's per-unit
//! ratio with the compensation and not without; the compensation adds no clipping; bad profiles
//! are refused with the key named.

use std::path::{Path, PathBuf};

use nalgebra::{DMatrix, DVector};
use rustfft::num_complex::Complex;
use rustfft::FftPlanner;

use crate::command::sake_glug;

/// A profile whose response slopes 24 dB across the glug's band (about 8 dB from f1 to f2), so
/// that an uncompensated render is far from the model's ratio.
const SLOPED: &str = "name = \"sloped\"\n\
response = [[20.0, -24.0], [1000.0, 0.0]]\n\
band_hz = [20.0, 1000.0]\n\
max_amplitude = 1.0\n\
sample_rate_hz = 48000\n";

fn repository() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The `[Hz, dB]` points of a profile's text, read with toml (not the project's reader).
fn points_of(text: &str) -> Vec<(f64, f64)> {
    let table: toml::Table = text.parse().unwrap();
    table["response"]
        .as_array()
        .unwrap()
        .iter()
        .map(|point| {
            let pair = point.as_array().unwrap();
            let number = |value: &toml::Value| {
                value
                    .as_float()
                    .unwrap_or_else(|| value.as_integer().unwrap() as f64)
            };
            (number(&pair[0]), number(&pair[1]))
        })
        .collect()
}

/// The response (linear) at `hz`: straight lines in log frequency between the points, the end
/// points' level outside them.
fn response_at(points: &[(f64, f64)], hz: f64) -> f64 {
    let db = if hz <= points[0].0 {
        points[0].1
    } else if hz >= points[points.len() - 1].0 {
        points[points.len() - 1].1
    } else {
        let after = points.iter().position(|&(f, _)| f > hz).unwrap();
        let ((f0, d0), (f1, d1)) = (points[after - 1], points[after]);
        d0 + (d1 - d0) * (hz / f0).ln() / (f1 / f0).ln()
    };
    10f64.powf(db / 20.0)
}

/// The device: `samples` through a zero-phase filter whose magnitude is the profile's response,
/// applied bin by bin on a zero-padded FFT.
fn through_device(samples: &[f64], points: &[(f64, f64)], sample_rate: f64) -> Vec<f64> {
    let size = (samples.len() * 2).next_power_of_two();
    let mut spectrum: Vec<Complex<f64>> = samples
        .iter()
        .map(|&x| Complex::new(x, 0.0))
        .chain(std::iter::repeat(Complex::new(0.0, 0.0)))
        .take(size)
        .collect();
    let mut planner = FftPlanner::new();
    planner.plan_fft_forward(size).process(&mut spectrum);
    for (bin, value) in spectrum.iter_mut().enumerate() {
        let hz = bin.min(size - bin) as f64 * sample_rate / size as f64;
        *value *= response_at(points, hz.max(1e-3)) / size as f64;
    }
    planner.plan_fft_inverse(size).process(&mut spectrum);
    spectrum[..samples.len()].iter().map(|x| x.re).collect()
}

/// A row of the units table.
struct Unit {
    onset_s: f64,
    viscosity: f64,
    frequency_hz: [f64; 2],
    decay_per_s: [f64; 2],
    /// A1 and A2 as driven (compensated).
    driven: [f64; 2],
    /// A1 + A2, 0 for a unit not heard.
    amplitude: f64,
}

fn units_of(path: &Path) -> Vec<Unit> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let headers = reader.headers().unwrap().clone();
    let column = |name: &str| headers.iter().position(|header| header == name).unwrap();
    let columns = [
        "onset_s",
        "viscosity_c",
        "f1_hz",
        "f2_hz",
        "b1_per_s",
        "b2_per_s",
        "a1",
        "a2",
        "audible",
    ]
    .map(column);
    reader
        .records()
        .map(|record| {
            let record = record.unwrap();
            let value = |index: usize| record[columns[index]].parse::<f64>().unwrap();
            Unit {
                onset_s: value(0),
                viscosity: value(1),
                frequency_hz: [value(2), value(3)],
                decay_per_s: [value(4), value(5)],
                driven: [value(6), value(7)],
                amplitude: (value(6) + value(7)) * value(8),
            }
        })
        .collect()
}

/// Each unit's two components as driven in `signal`, which went through `device`: a
/// least-squares fit of every unit's e^(−Bτ)·sin and e^(−Bτ)·cos at its own f1 and f2 (onsets,
/// frequencies and decays from the units table), each put through the same device, to the
/// whole signal at once, so that overlapping units are told apart. (Fitting the unfiltered
/// shapes instead reads each component 0.2–0.7 dB low: the device tilts the tail one
/// component's spectrum lays under the other's, and that leaks into the fit.)
fn driven_amplitudes(
    signal: &[f64],
    units: &[Unit],
    sample_rate: f64,
    device: impl Fn(&[f64]) -> Vec<f64>,
) -> Vec<[f64; 2]> {
    // The filter's output spreads a little either side of its input: room for it.
    const MARGIN: usize = 4096;
    // Each basis function through the device: its first sample and its values.
    let mut basis: Vec<(usize, Vec<f64>)> = Vec::new();
    for unit in units {
        let start = (unit.onset_s * sample_rate).floor() as usize + 1;
        for k in 0..2 {
            let decay = unit.decay_per_s[k];
            // Until e^(−Bτ) < 10⁻⁶.
            let length = ((6.0 * 10f64.ln() / decay) * sample_rate) as usize;
            let end = (start + length).min(signal.len());
            let from = start.saturating_sub(MARGIN);
            for phase in [0.0, std::f64::consts::FRAC_PI_2] {
                let shape: Vec<f64> = (from..end + MARGIN)
                    .map(|n| {
                        let tau = n as f64 / sample_rate - unit.onset_s;
                        if n < start || n >= end {
                            return 0.0;
                        }
                        (-decay * tau).exp()
                            * (std::f64::consts::TAU * unit.frequency_hz[k] * tau + phase).sin()
                    })
                    .collect();
                basis.push((from, device(&shape)));
            }
        }
    }
    let dot = |(a_start, a): (usize, &[f64]), (b_start, b): (usize, &[f64])| {
        let start = a_start.max(b_start);
        let end = (a_start + a.len()).min(b_start + b.len());
        (start..end.max(start))
            .map(|n| a[n - a_start] * b[n - b_start])
            .sum::<f64>()
    };
    let count = basis.len();
    let mut gram = DMatrix::<f64>::zeros(count, count);
    for i in 0..count {
        for j in i..count {
            let value = dot((basis[i].0, &basis[i].1), (basis[j].0, &basis[j].1));
            gram[(i, j)] = value;
            gram[(j, i)] = value;
        }
    }
    let projections = DVector::from_iterator(
        count,
        basis
            .iter()
            .map(|(start, values)| dot((*start, values), (0, signal))),
    );
    let weights = gram
        .cholesky()
        .expect("independent units")
        .solve(&projections);
    (0..units.len())
        .map(|unit| {
            let amplitude = |k: usize| {
                let at = unit * 4 + k * 2;
                weights[at].hypot(weights[at + 1])
            };
            [amplitude(0), amplitude(1)]
        })
        .collect()
}

fn read_wav(path: &Path) -> (Vec<f64>, f64) {
    let mut reader = hound::WavReader::open(path).unwrap();
    let rate = reader.spec().sample_rate as f64;
    let samples = reader
        .samples::<f32>()
        .map(|sample| sample.unwrap() as f64)
        .collect();
    (samples, rate)
}

/// Renders the default pour (its first 1.5 s) with `extra` arguments, as samples and units.
fn render(directory: &Path, name: &str, extra: &[&str]) -> (Vec<f64>, f64, Vec<Unit>) {
    let scene = directory.join("short.toml");
    std::fs::write(&scene, "duration_s = 1.5\ntilt_deg = 135.0\n").unwrap();
    let (wav, units) = (format!("{name}.wav"), format!("{name}.units.csv"));
    let mut args = vec![
        "render",
        scene.to_str().unwrap(),
        "-o",
        &wav,
        "--units",
        &units,
    ];
    args.extend_from_slice(extra);
    let output = sake_glug(directory, &args);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let (samples, rate) = read_wav(&directory.join(&wav));
    (samples, rate, units_of(&directory.join(&units)))
}

/// Each loud unit's delivered ratio (dB) less the model's c/(1 − c), through the device: the
/// components driven, read back from the device's output, each times the device's response at
/// its own frequency (the acceleration it delivers of it).
fn ratio_errors_db(directory: &Path, profile: &str, extra: &[&str]) -> Vec<f64> {
    let (samples, rate, units) = render(directory, "take", extra);
    let points = points_of(profile);
    let device = |signal: &[f64]| through_device(signal, &points, rate);
    let driven = driven_amplitudes(&device(&samples), &units, rate, device);
    let loudest = units.iter().map(|unit| unit.amplitude).fold(0.0, f64::max);
    assert!(units.len() >= 8, "{} units", units.len());
    units
        .iter()
        .zip(driven)
        .filter(|(unit, _)| unit.amplitude > 0.1 * loudest)
        .map(|(unit, [a1, a2])| {
            let [f1, f2] = unit.frequency_hz;
            let delivered = (a1 * response_at(&points, f1)) / (a2 * response_at(&points, f2));
            20.0 * delivered.log10() - 20.0 * (unit.viscosity / (1.0 - unit.viscosity)).log10()
        })
        .collect()
}

#[test]
fn through_the_device_the_compensated_render_keeps_each_units_ratio() {
    let directory = tempfile::tempdir().unwrap();
    let path = directory.path().join("sloped.toml");
    std::fs::write(&path, SLOPED).unwrap();
    let haptuator =
        std::fs::read_to_string(repository().join("actuators/haptuator-mark2.toml")).unwrap();
    for (profile, argument) in [
        (SLOPED, path.to_str().unwrap()),
        (&*haptuator, "haptuator-mark2"),
    ] {
        let with = ratio_errors_db(directory.path(), profile, &["--actuator", argument]);
        let without = ratio_errors_db(directory.path(), profile, &[]);
        let worst = |errors: &[f64]| errors.iter().fold(0.0f64, |worst, e| worst.max(e.abs()));
        let least = |errors: &[f64]| errors.iter().fold(f64::MAX, |least, e| least.min(e.abs()));
        eprintln!(
            "{argument}: compensated within {:.2e} dB, uncompensated off by {:.2} to {:.2} dB",
            worst(&with),
            least(&without),
            worst(&without)
        );
        assert!(worst(&with) < 0.5, "{argument}, compensated: {with:.3?}");
        assert!(
            without.iter().all(|error| error.abs() > 0.5),
            "{argument}, uncompensated: {without:.3?}"
        );
    }
}

#[test]
fn the_compensation_adds_no_clipping_and_holds_the_largest_drive() {
    let directory = tempfile::tempdir().unwrap();
    let at_ceiling = |samples: &[f64], ceiling: f64| {
        samples
            .iter()
            .filter(|sample| sample.abs() >= ceiling as f32 as f64)
            .count()
    };
    let (plain, _, _) = render(directory.path(), "plain", &[]);
    for name in [
        "haptuator-mark2",
        "lra",
        "phone",
        "dualsense",
        "vr-controller",
    ] {
        let (samples, _, _) = render(directory.path(), name, &["--actuator", name]);
        assert!(
            at_ceiling(&samples, 1.0) <= at_ceiling(&plain, 1.0),
            "{name}: more samples at the ceiling than without a profile"
        );
    }
    // A device that takes half of full scale, played 12 dB louder than the pour's default:
    // the output is held within the half.
    let half = directory.path().join("half.toml");
    std::fs::write(
        &half,
        SLOPED.replace("max_amplitude = 1.0", "max_amplitude = 0.5"),
    )
    .unwrap();
    let loud = directory.path().join("loud.toml");
    std::fs::write(
        &loud,
        "duration_s = 1.5\ntilt_deg = 135.0\n[output]\ngain_db = 6.0\n",
    )
    .unwrap();
    let output = sake_glug(
        directory.path(),
        &[
            "render",
            loud.to_str().unwrap(),
            "-o",
            "half.wav",
            "--actuator",
            half.to_str().unwrap(),
        ],
    );
    assert!(output.status.success());
    let (samples, _) = read_wav(&directory.path().join("half.wav"));
    let peak = samples.iter().fold(0.0f64, |peak, x| peak.max(x.abs()));
    assert!(peak <= 0.5 && at_ceiling(&samples, 0.5) > 0, "peak {peak}");
}

#[test]
fn bad_profiles_are_refused_with_the_file_and_the_key_named() {
    let directory = tempfile::tempdir().unwrap();
    let cases = [
        (
            SLOPED.replace(
                "[[20.0, -24.0], [1000.0, 0.0]]",
                "[[1000.0, 0.0], [20.0, -24.0]]",
            ),
            "`response`: point 2",
        ),
        (SLOPED.replace("-24.0", "nan"), "`response`: point 1"),
        (
            SLOPED.replace("[20.0, 1000.0]\n", "[10.0, 1000.0]\n"),
            "`band_hz`",
        ),
        (
            SLOPED.replace("max_amplitude = 1.0", "max_amplitude = 2.0"),
            "`max_amplitude`",
        ),
        (SLOPED.replace("name = \"sloped\"\n", ""), "`name`"),
    ];
    for (index, (text, key)) in cases.iter().enumerate() {
        let path = directory.path().join(format!("bad{index}.toml"));
        std::fs::write(&path, text).unwrap();
        let output = sake_glug(
            directory.path(),
            &[
                "render",
                "-o",
                "x.wav",
                "--actuator",
                path.to_str().unwrap(),
            ],
        );
        let message = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{message}");
        assert!(
            message.contains(key) && message.contains(&format!("bad{index}.toml")),
            "{message:?} lacks {key:?} or the file"
        );
        assert!(!directory.path().join("x.wav").exists(), "no file written");
    }
    let output = sake_glug(
        directory.path(),
        &["render", "-o", "x.wav", "--actuator", "no-such-device"],
    );
    let message = String::from_utf8_lossy(&output.stderr);
    assert!(
        message.contains("no-such-device") && message.contains("haptuator-mark2"),
        "{message}"
    );
}

/// The fidelity report's delivered-c columns for the `wav` row, as `(mean, worst)` pairs:
/// uncompensated, compensated.
fn delivered_columns(report: &str) -> [(f64, f64); 2] {
    let row = report
        .lines()
        .find(|line| line.starts_with("| `wav` |"))
        .unwrap_or_else(|| panic!("no wav row in {report}"));
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    let pair = |cell: &str| {
        let (mean, worst) = cell.split_once(" / ").unwrap_or_else(|| panic!("{row}"));
        (mean.parse().unwrap(), worst.parse().unwrap())
    };
    [pair(cells[cells.len() - 3]), pair(cells[cells.len() - 2])]
}

#[test]
fn the_fidelity_report_gives_the_c_the_device_delivers() {
    let directory = tempfile::tempdir().unwrap();
    let path = directory.path().join("sloped.toml");
    std::fs::write(&path, SLOPED).unwrap();
    let output = sake_glug(
        directory.path(),
        &[
            "render",
            "--fidelity",
            "-o",
            "f.wav",
            "--units",
            "f.units.csv",
            "--actuator",
            path.to_str().unwrap(),
        ],
    );
    assert!(output.status.success());
    let report = String::from_utf8_lossy(&output.stdout);
    // Each audible unit's delivered c, worked out here from the units table and the points.
    let points = points_of(SLOPED);
    let shift = |drive: &dyn Fn(&Unit) -> [f64; 2], units: &[Unit]| {
        let shifts: Vec<f64> = units
            .iter()
            .filter(|unit| unit.amplitude > 0.0)
            .map(|unit| {
                let [a1, a2] = drive(unit);
                let [r1, r2] = unit.frequency_hz.map(|hz| response_at(&points, hz));
                a1 * r1 / (a1 * r1 + a2 * r2) - unit.viscosity
            })
            .collect();
        let mean = shifts.iter().sum::<f64>() / shifts.len() as f64;
        (
            mean,
            shifts.iter().fold(0.0f64, |worst, s| worst.max(s.abs())),
        )
    };
    let units = units_of(&directory.path().join("f.units.csv"));
    let model = |unit: &Unit| [unit.viscosity, 1.0 - unit.viscosity];
    let compensated = |unit: &Unit| unit.driven;
    let [without, with] = delivered_columns(&report);
    let expected = [shift(&model, &units), shift(&compensated, &units)];
    for ((printed, expected), name) in [without, with]
        .into_iter()
        .zip(expected)
        .zip(["uncompensated", "compensated"])
    {
        assert!(
            (printed.0 - expected.0).abs() <= 0.0006 && (printed.1 - expected.1).abs() <= 0.0006,
            "{name}: printed {printed:?}, worked out {expected:?}\n{report}"
        );
    }
    assert!(
        without.0 < -0.1,
        "the sloped device thins the liquid: {without:?}"
    );
    // A platform that plays c itself says so.
    assert!(report.contains("as carried"), "{report}");
}

/// `sake-glug measure-actuator` refuses a plan or a profile it could not write before anything
/// plays, with the option or the key named (exit status 2), and a server it cannot reach with
/// status 1; none of them writes a file. (Measuring itself is tested on JACK: tests/host.)
#[test]
fn measure_actuator_refuses_what_it_cannot_measure_before_playing() {
    let directory = tempfile::tempdir().unwrap();
    for (options, named) in [
        (&["--per-octave", "0"][..], "--per-octave"),
        (&["--from", "20", "--measure", "0.2"], "--measure"),
        (&["--level", "3"], "--level"),
        (&["--to", "10"], "--from/--to"),
        (&["--max-amplitude", "2"], "`max_amplitude`"),
        (&["--name", " "], "`name`"),
    ] {
        let mut args = vec!["measure-actuator", "-o", "device.toml"];
        args.extend_from_slice(options);
        let output = sake_glug(directory.path(), &args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{options:?}: {stderr}");
        assert!(stderr.contains(named), "{options:?}: {stderr}");
        assert!(!directory.path().join("device.toml").exists());
    }
    // No server of that name, and none started: refused after the plan, before the file.
    let output = std::process::Command::new(env!("CARGO_BIN_EXE_sake-glug"))
        .current_dir(directory.path())
        .args(["measure-actuator", "-o", "device.toml"])
        .env("JACK_DEFAULT_SERVER", "sakeglug-no-such-server")
        .env("JACK_NO_START_SERVER", "1")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("cannot reach a JACK server"), "{stderr}");
    // Not even the temporary file beside it is left.
    let left: Vec<_> = std::fs::read_dir(directory.path()).unwrap().collect();
    assert!(left.is_empty(), "{left:?}");
}
