//! MODEL.md §5: a unit is two decaying sinusoids at f1 and f2 with amplitudes c·a(V) and
//! (1 − c)·a(V); a(V) follows the paper's fit and is zero below ≈ 84 ml of 300.

use rustfft::{num_complex::Complex, FftPlanner};
use sake_glug_engine::pour::UnitShape;
use sake_glug_engine::GRID;
use sake_glug_engine::{
    AnchoredF32, Controls, DrainMode, Engine, Lane, ModelConfig, Synthesis, UnitOnset,
};

const FS: f64 = 48_000.0;

/// One unit, rendered alone on the default path for `len` samples.
fn render_unit(onset: UnitOnset, len: usize) -> Vec<f32> {
    let mut bank = AnchoredF32::new(FS);
    bank.start_unit(&onset);
    let mut out = vec![0.0f32; len];
    for (period, chunk) in out.chunks_mut(GRID).enumerate() {
        bank.synthesize((period * GRID) as u64, chunk);
        bank.advance(((period + 1) * GRID) as u64);
    }
    out
}

fn unit(viscosity: f64, decay_per_s: [f64; 2]) -> UnitOnset {
    UnitOnset {
        sample: 0,
        fraction: 0.25,
        volume_ml: 300.0,
        tilt_deg: 135.0,
        pocket_ml: 5.0,
        amplitude: 1.0,
        viscosity,
        shape: UnitShape {
            frequency_hz: [80.0, 300.0],
            frequency_spread: [1.0, 1.0],
            decay_per_s,
            amplitude_factor: 1.0,
            glide: ModelConfig::default().glide,
        },
        actuator_gain: [1.0, 1.0],
    }
}

/// Magnitude spectrum, zero-padded to `padded` points; bin k is k·FS/padded Hz.
fn spectrum(samples: &[f32], padded: usize) -> Vec<f64> {
    let mut buffer: Vec<Complex<f64>> = samples
        .iter()
        .map(|&y| Complex::new(y as f64, 0.0))
        .chain(std::iter::repeat(Complex::new(0.0, 0.0)))
        .take(padded)
        .collect();
    FftPlanner::new()
        .plan_fft_forward(padded)
        .process(&mut buffer);
    buffer[..padded / 2].iter().map(|z| z.norm()).collect()
}

/// The frequency and height of the largest peak between `low_hz` and `high_hz`.
fn peak_between(magnitudes: &[f64], padded: usize, low_hz: f64, high_hz: f64) -> (f64, f64) {
    let bin_hz = FS / padded as f64;
    let (low, high) = ((low_hz / bin_hz) as usize, (high_hz / bin_hz) as usize);
    let (index, height) =
        magnitudes[low..high]
            .iter()
            .enumerate()
            .fold(
                (0, 0.0),
                |best, (i, &m)| if m > best.1 { (i, m) } else { best },
            );
    ((low + index) as f64 * bin_hz, height)
}

#[test]
fn a_unit_peaks_at_f1_and_f2_with_heights_in_the_ratio_c_to_one_minus_c() {
    let padded = 1 << 18;
    for c in [0.33, 0.5, 0.8] {
        // Equal decays, so the peak heights A/(2B) compare the amplitudes alone.
        let samples = render_unit(unit(c, [40.0, 40.0]), 48_000);
        let magnitudes = spectrum(&samples, padded);
        let (f1, h1) = peak_between(&magnitudes, padded, 40.0, 160.0);
        let (f2, h2) = peak_between(&magnitudes, padded, 200.0, 400.0);
        // A damped sine's magnitude peak sits slightly below f (by ≈ B²/(8π²f)), and the other
        // component's skirt pulls it a little further.
        assert!((f1 - 80.0).abs() < 1.5, "f1 peak at {f1} Hz");
        assert!((f2 - 300.0).abs() < 1.5, "f2 peak at {f2} Hz");
        let ratio = h1 / h2;
        let expected = c / (1.0 - c);
        // The other component's skirt adds a few per cent at each peak.
        assert!(
            (ratio / expected - 1.0).abs() < 0.06,
            "c = {c}: {ratio} vs {expected}"
        );
    }
}

/// The largest difference between a rendered unit and the closed form of its component
/// `index` alone (τ from the onset at 0.25 of sample 0).
fn distance_from_single_component(samples: &[f32], index: usize, onset: &UnitOnset) -> f64 {
    let amplitude = onset.component_amplitudes()[index];
    let (f, b) = (
        onset.shape.frequency_hz[index],
        onset.shape.decay_per_s[index],
    );
    samples
        .iter()
        .enumerate()
        .skip(1)
        .map(|(n, &y)| {
            let tau = (n as f64 - 0.25) / FS;
            let exact = amplitude * (-b * tau).exp() * (std::f64::consts::TAU * f * tau).sin();
            (y as f64 - exact).abs()
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_unit_is_its_closed_form_from_its_onset_on() {
    let onset = unit(1.0, [45.0, 40.0]);
    let samples = render_unit(onset, 24_000);
    assert_eq!(
        samples[0], 0.0,
        "nothing before the onset at 0.25 of a sample"
    );
    assert!(distance_from_single_component(&samples, 0, &onset) < 1e-6);
}

#[test]
fn c_of_zero_or_one_sounds_one_component_only() {
    for (c, present) in [(0.0, 1), (1.0, 0)] {
        let onset = unit(c, [45.0, 40.0]);
        let samples = render_unit(onset, 24_000);
        assert!(samples.iter().any(|&y| y.abs() > 0.1));
        assert!(
            distance_from_single_component(&samples, present, &onset) < 1e-6,
            "c = {c}"
        );
    }
}

/// RMS of a steady pour in follow mode, where V is the fill level at every sample.
fn follow_mode_rms(fill_percent: f64) -> (f64, u64) {
    let config = ModelConfig {
        drain: DrainMode::Follow,
        ..ModelConfig::default().deterministic()
    };
    let mut engine = Engine::new(FS, config);
    let controls = Controls {
        tilt_deg: Lane::Constant(135.0),
        fill_percent: Lane::Constant(fill_percent),
        ..Controls::default()
    };
    let mut out = vec![0.0f32; 96_000];
    engine.process(&controls, &mut out);
    let rms = (out.iter().map(|&y| (y as f64).powi(2)).sum::<f64>() / out.len() as f64).sqrt();
    (rms, engine.stats().units_started)
}

#[test]
fn amplitude_follows_the_papers_law_and_vanishes_below_84_ml() {
    let (full, units_full) = follow_mode_rms(100.0);
    assert!(full > 0.01);
    for fill_percent in [80.0, 50.0, 30.0] {
        let (rms, units) = follow_mode_rms(fill_percent);
        assert_eq!(units, units_full, "same onsets at {fill_percent} %");
        let volume_ml = 3.0 * fill_percent;
        let law = (0.0027 * volume_ml - 0.2277) / 0.5823;
        // Each unit takes V at its sub-sample onset, up to one sample's outflow (0.00125 ml)
        // below the fill level: a(V) may sit up to 0.0027·0.00125/0.5823 ≈ 6e-6 lower.
        assert!(
            (rms / full - law).abs() < 1e-5,
            "{fill_percent} %: {} vs {law}",
            rms / full
        );
    }
    // 84 ml of 300 is 28 %: units still start, but pour without vibration.
    let (silent, units) = follow_mode_rms(28.0);
    assert!(units > 20);
    assert_eq!(silent, 0.0);
}

/// The caps of MODEL.md §11 in a 10 ms flood (625 pockets due per sample, 8 started): the
/// start budget admits a burst of 8 units and then 6000 a second, whatever the sample rate, and
/// admits or refuses whole units.
#[test]
fn the_start_budget_is_a_rate_in_time_and_admits_whole_units() {
    let admitted_at = |fs: f64| {
        // Follow mode keeps the bottle full, so every unit has both components.
        let config = ModelConfig {
            pocket_ml: 0.001,
            drain: DrainMode::Follow,
            ..ModelConfig::default().deterministic()
        };
        let mut engine = Engine::new(fs, config);
        let controls = Controls {
            tilt_deg: Lane::Constant(135.0),
            pour_time_s: Lane::Constant(0.01),
            ..Controls::default()
        };
        // 10 ms of flood; no component decays below −120 dB that soon.
        let mut out = vec![0.0f32; (0.01 * fs) as usize];
        engine.process(&controls, &mut out);
        let stats = engine.stats();
        let started = stats.units_started - stats.units_skipped;
        let given_up = engine.components_given_up();
        assert_eq!(given_up % 2, 0, "{fs} Hz: half a unit was given up");
        let admitted = started - given_up / 2;
        assert_eq!(
            engine.sounding_components() as u64,
            2 * admitted,
            "{fs} Hz: every admitted unit sounds both components"
        );
        admitted
    };
    let at_48k = admitted_at(48_000.0);
    // 8 at once, then 6000 /s over the 10 ms of the flood.
    assert!((67..=69).contains(&at_48k), "{at_48k} units at 48 kHz");
    for fs in [44_100.0, 96_000.0, 192_000.0] {
        assert!(
            admitted_at(fs).abs_diff(at_48k) <= 1,
            "{} units at {fs} Hz, {at_48k} at 48 kHz",
            admitted_at(fs)
        );
    }
}
