//! The clips written from a synthetic pour: valid, one transient per audible glug at its
//! onset, a sensible breakpoint rate, viscosity carried into frequency, an envelope that is
//! the model's, lossless CSV, and a plot.

use std::f64::consts::TAU;
use std::io::Write;

use super::{ahap, haptic};
use sake_glug_render::clips::{
    envelope_at, envelope_breakpoints, is_audible, BandParseError, ClipSource, Glug, HapticBand,
};
use sake_glug_render::sinks::{
    ahap_json, draw_pour_plot, haptic_json, write_csv_samples, PlotData, PlotError, Waveform,
};

const GLUG_COUNT: usize = 50;
const SPACING_S: f64 = 0.08;
const DURATION_S: f64 = 4.2;
const CEILING: f64 = 0.95;
const SAMPLE_RATE: f64 = 48_000.0;
/// How close to its onset a glug's transient must be.
const ONSET_TOLERANCE_S: f64 = 0.001;

/// 50 glugs 80 ms apart at sub-sample onsets, amplitudes falling from above the ceiling,
/// every viscosity different (0.1..0.9 in shuffled order), every tenth glug inaudible.
fn synthetic_glugs() -> Vec<Glug> {
    (0..GLUG_COUNT)
        .map(|i| {
            let a = if i % 10 == 7 {
                0.0
            } else {
                1.1 * (1.0 - i as f64 / 60.0)
            };
            // 17 is coprime to 50: a permutation, so no two glugs share a viscosity.
            let c = 0.1 + 0.8 * ((i * 17) % GLUG_COUNT) as f64 / (GLUG_COUNT - 1) as f64;
            uniform_glug(0.05 + i as f64 * SPACING_S + 1.7e-5 * i as f64, a, c)
        })
        .collect()
}

fn uniform_glug(onset_s: f64, a: f64, c: f64) -> Glug {
    Glug {
        onset_s,
        amplitudes: [c * a, (1.0 - c) * a],
        frequency_hz: [80.0, 300.0],
        decay_per_s: [45.0, 40.0],
        viscosity: c,
        actuator_gain: [1.0, 1.0],
    }
}

fn source(glugs: &[Glug]) -> ClipSource<'_> {
    ClipSource {
        duration_s: DURATION_S,
        glugs,
        ceiling: CEILING,
        scene_name: "synthetic",
        seed: 4_242,
    }
}

/// The model's waveform, hard-limited at the ceiling.
fn render(glugs: &[Glug]) -> Vec<f32> {
    let length = (DURATION_S * SAMPLE_RATE) as usize;
    let mut samples = vec![0.0f64; length];
    for glug in glugs {
        let first = (glug.onset_s * SAMPLE_RATE).ceil() as usize;
        let last = ((glug.onset_s + 1.0) * SAMPLE_RATE) as usize;
        for (n, sample) in samples.iter_mut().enumerate().take(last).skip(first) {
            let tau = n as f64 / SAMPLE_RATE - glug.onset_s;
            *sample += (0..2)
                .map(|k| {
                    glug.amplitudes[k]
                        * (-glug.decay_per_s[k] * tau).exp()
                        * (TAU * glug.frequency_hz[k] * tau).sin()
                })
                .sum::<f64>();
        }
    }
    samples
        .into_iter()
        .map(|s| s.clamp(-CEILING, CEILING) as f32)
        .collect()
}

/// How many of `times` lie within the onset tolerance of `onset_s`.
fn near(times: &[f64], onset_s: f64) -> usize {
    times
        .iter()
        .filter(|&&t| (t - onset_s).abs() <= ONSET_TOLERANCE_S)
        .count()
}

/// `(glug, emphasis frequency)` for every audible glug.
fn emphasis_frequencies(glugs: &[Glug]) -> Vec<(Glug, f64)> {
    let clip = haptic::parse(&haptic_json(&source(glugs), &HapticBand::default()));
    glugs
        .iter()
        .filter(|g| is_audible(g))
        .map(|glug| {
            let point = clip
                .amplitude
                .iter()
                .find(|p| p.emphasis.is_some() && (p.time - glug.onset_s).abs() <= 1e-3)
                .expect("an emphasis at every audible onset");
            (*glug, point.emphasis.expect("emphasis").1)
        })
        .collect()
}

#[test]
fn written_clips_pass_the_validators() {
    let glugs = synthetic_glugs();
    let haptic_text = haptic_json(&source(&glugs), &HapticBand::default());
    let ahap_text = ahap_json(&source(&glugs));
    let haptic_violations = haptic::validate(&haptic_text);
    assert!(haptic_violations.is_empty(), "{haptic_violations:#?}");
    let ahap_violations = ahap::validate(&ahap_text);
    assert!(ahap_violations.is_empty(), "{ahap_violations:#?}");
    eprintln!(
        "{GLUG_COUNT} glugs over {DURATION_S} s: .haptic {} bytes, .ahap {} bytes",
        haptic_text.len(),
        ahap_text.len()
    );
}

#[test]
fn one_emphasis_per_audible_glug_at_its_onset() {
    let glugs = synthetic_glugs();
    let clip = haptic::parse(&haptic_json(&source(&glugs), &HapticBand::default()));
    let emphasis_times: Vec<f64> = clip
        .amplitude
        .iter()
        .filter(|p| p.emphasis.is_some())
        .map(|p| p.time)
        .collect();
    let audible = glugs.iter().filter(|g| is_audible(g)).count();
    assert!(
        audible < GLUG_COUNT,
        "the pour should include inaudible glugs"
    );
    assert_eq!(emphasis_times.len(), audible);
    for glug in &glugs {
        let expected = usize::from(is_audible(glug));
        assert_eq!(near(&emphasis_times, glug.onset_s), expected, "{glug:?}");
    }
}

#[test]
fn one_transient_per_audible_glug_at_its_onset() {
    let glugs = synthetic_glugs();
    let events = ahap::parse(&ahap_json(&source(&glugs)));
    let transient_times: Vec<f64> = events
        .iter()
        .filter(|e| e.event_type == "HapticTransient")
        .map(|e| e.time)
        .collect();
    let audible = glugs.iter().filter(|g| is_audible(g)).count();
    assert_eq!(transient_times.len(), audible);
    for glug in &glugs {
        let expected = usize::from(is_audible(glug));
        assert_eq!(near(&transient_times, glug.onset_s), expected, "{glug:?}");
    }
}

#[test]
fn breakpoint_rate_is_sensible() {
    let glugs = synthetic_glugs();
    let clip = haptic::parse(&haptic_json(&source(&glugs), &HapticBand::default()));
    let rate = clip.amplitude.len() as f64 / DURATION_S;
    eprintln!(
        "{} amplitude breakpoints over {DURATION_S} s: {rate:.1} per second",
        clip.amplitude.len()
    );
    // Meta Haptics Studio writes about 60 per second; an order either way is still sensible.
    assert!(
        (30.0..=120.0).contains(&rate),
        "{rate} breakpoints per second"
    );
}

#[test]
fn higher_viscosity_gives_lower_emphasis_frequency_and_sharpness() {
    let glugs = synthetic_glugs();
    let mut by_viscosity = emphasis_frequencies(&glugs);
    by_viscosity.sort_by(|a, b| a.0.viscosity.total_cmp(&b.0.viscosity));
    for pair in by_viscosity.windows(2) {
        assert!(pair[1].1 < pair[0].1, "emphasis frequency {pair:?}");
    }

    let events = ahap::parse(&ahap_json(&source(&glugs)));
    let mut sharpness: Vec<(f64, f64)> = glugs
        .iter()
        .filter(|g| is_audible(g))
        .map(|glug| {
            let transient = events
                .iter()
                .find(|e| {
                    e.event_type == "HapticTransient" && (e.time - glug.onset_s).abs() <= 1e-3
                })
                .expect("a transient at every audible onset");
            (
                glug.viscosity,
                transient.parameter("HapticSharpness").expect("sharpness"),
            )
        })
        .collect();
    sharpness.sort_by(|a, b| a.0.total_cmp(&b.0));
    for pair in sharpness.windows(2) {
        assert!(pair[1].1 < pair[0].1, "sharpness {pair:?}");
    }
}

#[test]
fn higher_viscosity_gives_a_lower_frequency_envelope() {
    let with_viscosity = |c: f64| -> Vec<(f64, f64)> {
        let glugs: Vec<Glug> = synthetic_glugs()
            .iter()
            // Below the ceiling: where a decay leaves it depends on the viscosity, and that
            // extra breakpoint would shift one envelope's times against the other's.
            .map(|g| uniform_glug(g.onset_s, 0.8 * (g.amplitudes[0] + g.amplitudes[1]), c))
            .collect();
        haptic::parse(&haptic_json(&source(&glugs), &HapticBand::default())).frequency
    };
    let (thin, thick) = (with_viscosity(0.2), with_viscosity(0.8));
    assert_eq!(thin.len(), thick.len());
    for (thin_point, thick_point) in thin.iter().zip(&thick) {
        assert_eq!(thin_point.0, thick_point.0, "the same breakpoint times");
        assert!(
            thick_point.1 < thin_point.1,
            "{thick_point:?} vs {thin_point:?}"
        );
    }
}

#[test]
fn envelope_breakpoints_lie_on_the_envelope_and_bound_the_waveform() {
    let glugs = synthetic_glugs();
    let breakpoints = envelope_breakpoints(&source(&glugs));
    for point in &breakpoints {
        let expected = envelope_at(&glugs, CEILING, point.time_s);
        assert!(
            (point.amplitude - expected).abs() <= 1e-12,
            "at {} s: {} written, {expected} on the envelope",
            point.time_s,
            point.amplitude
        );
    }
    // The file holds these breakpoints (serde_json's default parser may be an ulp off).
    let clip = haptic::parse(&haptic_json(&source(&glugs), &HapticBand::default()));
    assert_eq!(clip.amplitude.len(), breakpoints.len());
    for (written, point) in clip.amplitude.iter().zip(&breakpoints) {
        assert!((written.time - point.time_s).abs() <= 1e-12);
        assert!((written.amplitude - point.amplitude).abs() <= 1e-12);
    }
    // A player draws straight lines between breakpoints; they must stay above the sound.
    let samples = render(&glugs);
    let mut segment = 0;
    for (n, &sample) in samples.iter().enumerate() {
        let t = n as f64 / SAMPLE_RATE;
        while breakpoints[segment + 1].time_s < t {
            segment += 1;
        }
        let (start, end) = (&breakpoints[segment], &breakpoints[segment + 1]);
        let span = end.time_s - start.time_s;
        let line = if span > 0.0 {
            start.amplitude + (end.amplitude - start.amplitude) * (t - start.time_s) / span
        } else {
            end.amplitude
        };
        assert!(
            f64::from(sample.abs()) <= line + 1e-6,
            "at {t} s the waveform {sample} exceeds the clip's envelope {line}"
        );
    }
}

#[test]
fn clips_name_the_scene_and_seed() {
    let glugs = synthetic_glugs();
    let haptic_doc: serde_json::Value =
        serde_json::from_str(&haptic_json(&source(&glugs), &HapticBand::default())).unwrap();
    let source_text = haptic_doc["metadata"]["source"].as_str().unwrap();
    assert!(source_text.contains("synthetic") && source_text.contains("4242"));
    let ahap_doc: serde_json::Value = serde_json::from_str(&ahap_json(&source(&glugs))).unwrap();
    let description = ahap_doc["Metadata"]["Description"].as_str().unwrap();
    assert!(description.contains("synthetic") && description.contains("4242"));
    assert_eq!(ahap_doc["Version"].as_f64(), Some(1.0));
}

/// Counts the writes it receives.
struct CountingWriter {
    bytes: Vec<u8>,
    writes: usize,
}

impl Write for CountingWriter {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.writes += 1;
        self.bytes.extend_from_slice(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[test]
fn csv_parses_back_to_the_exact_samples() {
    let mut samples = render(&synthetic_glugs());
    samples.extend([
        0.0,
        -0.0,
        1.0 / 3.0,
        f32::MIN_POSITIVE,
        f32::MIN_POSITIVE / 8.0, // subnormal
        f32::MAX,
        -f32::EPSILON,
        0.1,
    ]);
    let mut out = CountingWriter {
        bytes: Vec::new(),
        writes: 0,
    };
    write_csv_samples(&samples, &mut out).unwrap();
    let text = String::from_utf8(out.bytes).unwrap();
    let parsed: Vec<f32> = text
        .lines()
        .map(|line| line.parse().unwrap_or_else(|e| panic!("{line:?}: {e}")))
        .collect();
    assert_eq!(
        parsed.len(),
        samples.len(),
        "one line per sample, no header"
    );
    for (n, (written, read)) in samples.iter().zip(&parsed).enumerate() {
        assert_eq!(
            written.to_bits(),
            read.to_bits(),
            "sample {n}: {written} read as {read}"
        );
    }
    // Written in blocks, not sample by sample.
    assert!(
        out.writes * 1000 < samples.len(),
        "{} writes for {} samples",
        out.writes,
        samples.len()
    );
}

#[test]
fn pour_plot_is_drawn() {
    let glugs = synthetic_glugs();
    let samples = render(&glugs);
    let envelope: Vec<(f64, f64)> = envelope_breakpoints(&source(&glugs))
        .iter()
        .map(|p| (p.time_s, p.amplitude))
        .collect();
    let onsets: Vec<f64> = glugs.iter().map(|g| g.onset_s).collect();
    let volume: Vec<(f64, f64)> = (0..=42)
        .map(|i| (i as f64 * 0.1, 720.0 - 150.0 * i as f64 * 0.1))
        .collect();
    let tilt: Vec<(f64, f64)> = (0..=42)
        .map(|i| (i as f64 * 0.1, (30.0 + 25.0 * i as f64 * 0.1).min(180.0)))
        .collect();
    let data = PlotData {
        sample_rate: SAMPLE_RATE,
        waveform: &Waveform::of(&samples),
        envelope: &envelope,
        onsets_s: &onsets,
        volume_ml: &volume,
        capacity_ml: 720.0,
        tilt_deg: &tilt,
    };
    let path = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("pour.png");
    draw_pour_plot(&data, &path).unwrap();
    let png = std::fs::read(&path).unwrap();
    assert!(png.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
    assert!(
        png.len() > 20_000,
        "suspiciously small plot: {} bytes",
        png.len()
    );

    // A folder that cannot be made (as root, only /proc refuses one).
    let nowhere = std::path::Path::new("/proc/no/such/dir/pour.png");
    let error = draw_pour_plot(&data, nowhere).unwrap_err();
    assert!(matches!(error, PlotError::Write { .. }), "{error:?}");
    assert!(
        error.to_string().contains("no/such/dir/pour.png"),
        "{error}"
    );
}

#[test]
fn haptic_band_parses_and_normalises() {
    let band: HapticBand = "80..300".parse().unwrap();
    assert_eq!(band, HapticBand::default());
    assert_eq!(
        " 20 .. 250 ".parse::<HapticBand>().unwrap(),
        HapticBand {
            low_hz: 20.0,
            high_hz: 250.0
        }
    );
    assert!(matches!(
        "80-300".parse::<HapticBand>(),
        Err(BandParseError::NotTwoNumbers { .. })
    ));
    assert!(matches!(
        "80..300..400".parse::<HapticBand>(),
        Err(BandParseError::NotTwoNumbers { .. })
    ));
    assert!(matches!(
        "inf..300".parse::<HapticBand>(),
        Err(BandParseError::NotFinite { .. })
    ));
    assert!(matches!(
        "NaN..300".parse::<HapticBand>(),
        Err(BandParseError::NotFinite { .. })
    ));
    assert!(matches!(
        "-5..300".parse::<HapticBand>(),
        Err(BandParseError::Negative { .. })
    ));
    assert!(matches!(
        "300..80".parse::<HapticBand>(),
        Err(BandParseError::LowNotBelowHigh { .. })
    ));
    assert!(matches!(
        "80..80".parse::<HapticBand>(),
        Err(BandParseError::LowNotBelowHigh { .. })
    ));
    assert_eq!(band.normalise(80.0), 0.0);
    assert_eq!(band.normalise(300.0), 1.0);
    assert_eq!(band.normalise(190.0), 0.5);
    assert_eq!(band.normalise(20.0), 0.0);
    assert_eq!(band.normalise(1000.0), 1.0);
}

#[test]
fn degenerate_sources_still_give_valid_clips() {
    let glug = |onset_s: f64, a: f64| uniform_glug(onset_s, a, 0.33);
    let cases: [(&str, f64, Vec<Glug>, usize); 7] = [
        ("no glugs", 1.0, vec![], 0),
        (
            "only inaudible glugs",
            1.0,
            vec![glug(0.2, 0.0), glug(0.4, 0.0)],
            0,
        ),
        ("no duration", 0.0, vec![glug(0.0, 0.5)], 1),
        (
            "a glug at the very start",
            0.5,
            vec![glug(0.0, 0.5), glug(0.1, 0.4)],
            2,
        ),
        (
            "two glugs at one onset",
            0.5,
            vec![glug(0.1, 0.5), glug(0.1, 0.6)],
            2,
        ),
        (
            "glugs outside the clip",
            0.5,
            vec![glug(-0.05, 0.9), glug(0.2, 0.3), glug(0.7, 0.5)],
            1,
        ),
        (
            "onsets closer than the lead",
            0.5,
            vec![glug(0.1, 0.5), glug(0.1002, 0.5)],
            2,
        ),
    ];
    for (name, duration_s, glugs, transients) in cases {
        let source = ClipSource {
            duration_s,
            ..source(&glugs)
        };
        let haptic_text = haptic_json(&source, &HapticBand::default());
        let haptic_violations = haptic::validate(&haptic_text);
        assert!(
            haptic_violations.is_empty(),
            "{name}: {haptic_violations:#?}"
        );
        let emphasis = haptic::parse(&haptic_text)
            .amplitude
            .iter()
            .filter(|p| p.emphasis.is_some())
            .count();
        assert_eq!(emphasis, transients, "{name}: emphasis");

        let ahap_text = ahap_json(&source);
        let ahap_violations = ahap::validate(&ahap_text);
        assert!(ahap_violations.is_empty(), "{name}: {ahap_violations:#?}");
        let transient_count = ahap::parse(&ahap_text)
            .iter()
            .filter(|e| e.event_type == "HapticTransient")
            .count();
        assert_eq!(transient_count, transients, "{name}: transients");
    }
}
