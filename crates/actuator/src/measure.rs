//! Measuring a device's response (`sake-glug measure-actuator`, MODEL.md §18.1): stepped sines
//! played on the device while an accelerometer on it is recorded; each step's level at its own
//! frequency is read off the recording and the points become a profile.
//!
//! The method is independent of the audio interface: a [`Rig`] plays a block of samples and
//! records as many, and says whether the interface dropped a cycle (an xrun) meanwhile. The
//! JACK rig is [`crate::jack_rig`] (feature `audio`); the tests drive an offline rig.

use std::f64::consts::TAU;

use sake_glug_engine::actuator::{MAX_RESPONSE_DB, MAX_RESPONSE_POINTS, RESPONSE_HZ};

use crate::ProfileText;

/// Each step fades in and out over this long (s), so that the device is not kicked.
const FADE_S: f64 = 0.005;
/// Silence after each step (s), so that the device rings down before the next one.
const GAP_S: f64 = 0.05;
/// The fewest periods of the lowest frequency the analysed part of a step holds: enough that the
/// window's leakage from the accelerometer's offset and from noise elsewhere stays negligible.
pub const MIN_PERIODS: f64 = 8.0;
/// A step spoiled by an xrun is played again, at most this many times in all.
pub const MAX_TRIES: usize = 4;
/// A point heard less than this far (dB) above the silence's level at its frequency is
/// reported as noisy.
pub const NOISY_BELOW_DB: f64 = 20.0;
/// A recorded sample at or above this magnitude counts as clipped.
const CLIPPED: f32 = 0.999;

/// What to play: the frequencies, the drive and each step's timing.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The step frequencies (Hz), increasing.
    pub frequencies_hz: Vec<f64>,
    /// The drive's peak (linear, of full scale).
    pub amplitude: f64,
    /// Skipped at each step's start (s): the interface's round trip and the device's transient.
    pub settle_s: f64,
    /// Analysed after that (s).
    pub measure_s: f64,
    /// How many times the whole set of steps is measured.
    pub repeats: usize,
}

/// Why a measurement was refused or failed.
#[derive(Debug, thiserror::Error)]
pub enum MeasureError {
    /// A setting of the plan is refused: the option and why.
    #[error("{option}: {reason}")]
    Plan {
        /// The command line's option.
        option: &'static str,
        /// Why.
        reason: String,
    },
    /// The audio interface failed.
    #[error("{0}")]
    Audio(String),
    /// Xruns spoiled a step every time it was played.
    #[error(
        "the audio interface dropped cycles (xruns) during the step at {hz} Hz {MAX_TRIES} times \
         running: lower the system's load or raise the interface's period"
    )]
    Xruns {
        /// The step's frequency.
        hz: f64,
    },
    /// The recording clipped: the level cannot be read.
    #[error(
        "the input clipped during the step at {hz} Hz: lower the drive (--level) or the input's gain"
    )]
    Clipped {
        /// The step's frequency.
        hz: f64,
    },
    /// Nothing of the drive came back at any step.
    #[error(
        "the input heard nothing of the drive at any step: is the accelerometer connected to the \
         port recorded (--record-from)?"
    )]
    Silent,
    /// Too little came back at a frequency for a profile to hold.
    #[error(
        "at {hz} Hz the input gave back {db:.1} dB of the drive, {below:.1} dB below the strongest \
         point (a profile spans at most {MAX_RESPONSE_DB} dB): is the accelerometer connected?"
    )]
    NothingBack {
        /// The step's frequency.
        hz: f64,
        /// The level (dB re the drive).
        db: f64,
        /// How far below the strongest point.
        below: f64,
    },
}

fn plan_error(option: &'static str, reason: String) -> MeasureError {
    MeasureError::Plan { option, reason }
}

impl Plan {
    /// Steps from `from_hz` to `to_hz`, both included, `per_octave` to an octave, spaced evenly in
    /// log frequency; the rest as given. Checked against the sample rate the rig runs at.
    pub fn stepped(
        from_hz: f64,
        to_hz: f64,
        per_octave: f64,
        amplitude: f64,
        settle_s: f64,
        measure_s: f64,
        repeats: usize,
    ) -> Result<Self, MeasureError> {
        if !(from_hz.is_finite() && from_hz >= RESPONSE_HZ.0 && to_hz > from_hz) {
            return Err(plan_error(
                "--from/--to",
                format!(
                    "expected {} Hz ≤ from < to, got {from_hz} to {to_hz} Hz",
                    RESPONSE_HZ.0
                ),
            ));
        }
        if !(per_octave.is_finite() && per_octave > 0.0) {
            return Err(plan_error(
                "--per-octave",
                format!("expected a number of steps above 0, got {per_octave}"),
            ));
        }
        let octaves = (to_hz / from_hz).log2();
        let steps = (octaves * per_octave).ceil() as usize + 1;
        if steps > MAX_RESPONSE_POINTS {
            return Err(plan_error(
                "--per-octave",
                format!(
                    "{steps} steps over {octaves:.2} octaves: a profile holds at most \
                     {MAX_RESPONSE_POINTS} points"
                ),
            ));
        }
        let frequencies_hz = (0..steps)
            .map(|step| from_hz * (to_hz / from_hz).powf(step as f64 / (steps - 1) as f64))
            .collect();
        if !(amplitude > 0.0 && amplitude <= 1.0) {
            return Err(plan_error(
                "--level",
                "expected a drive above -inf and at most 0 dBFS".into(),
            ));
        }
        if !(settle_s.is_finite() && settle_s >= 2.0 * FADE_S) {
            return Err(plan_error(
                "--settle",
                format!("expected at least {} s", 2.0 * FADE_S),
            ));
        }
        if !(measure_s.is_finite() && measure_s * from_hz >= MIN_PERIODS && measure_s <= 60.0) {
            return Err(plan_error(
                "--measure",
                format!(
                    "expected at most 60 s and at least {MIN_PERIODS} periods of the lowest step \
                     ({:.3} s at {from_hz} Hz), got {measure_s} s",
                    MIN_PERIODS / from_hz
                ),
            ));
        }
        if repeats == 0 {
            return Err(plan_error("--repeat", "expected 1 or more".into()));
        }
        Ok(Self {
            frequencies_hz,
            amplitude,
            settle_s,
            measure_s,
            repeats,
        })
    }

    /// Refuses a rate at which the highest step reaches Nyquist.
    fn check_rate(&self, sample_rate_hz: u32) -> Result<(), MeasureError> {
        let highest = self.frequencies_hz.last().copied().unwrap_or(0.0);
        if highest >= 0.45 * sample_rate_hz as f64 {
            return Err(plan_error(
                "--to",
                format!("{highest} Hz is too near Nyquist at the interface's {sample_rate_hz} Hz"),
            ));
        }
        Ok(())
    }

    /// One step's samples at `frequency_hz` (0: silence as long as a step).
    pub fn step(&self, frequency_hz: f64, sample_rate_hz: u32) -> Vec<f32> {
        let rate = sample_rate_hz as f64;
        let sounding = ((self.settle_s + self.measure_s + FADE_S) * rate).round() as usize;
        let gap = (GAP_S * rate).round() as usize;
        let fade = (FADE_S * rate).round().max(1.0) as usize;
        let mut samples = vec![0.0f32; sounding + gap];
        if frequency_hz > 0.0 {
            for (n, sample) in samples[..sounding].iter_mut().enumerate() {
                let edge = n.min(sounding - 1 - n);
                let envelope = if edge < fade {
                    0.5 - 0.5 * (std::f64::consts::PI * edge as f64 / fade as f64).cos()
                } else {
                    1.0
                };
                *sample = (self.amplitude * envelope * (TAU * frequency_hz * n as f64 / rate).sin())
                    as f32;
            }
        }
        samples
    }

    /// The part of a step's recording analysed at `frequency_hz`: after the settling, a whole
    /// number of periods within the measuring time.
    fn window(&self, frequency_hz: f64, sample_rate_hz: u32) -> std::ops::Range<usize> {
        let rate = sample_rate_hz as f64;
        let start = (self.settle_s * rate).round() as usize;
        let periods = (self.measure_s * frequency_hz).floor().max(1.0);
        let length = (periods / frequency_hz * rate).round() as usize;
        start..start + length
    }
}

/// The level at `frequency_hz` (peak, linear) in `samples`: the mean removed (an
/// accelerometer's offset), a Hann window, the transform at that one frequency.
pub fn level_at(samples: &[f32], frequency_hz: f64, sample_rate_hz: u32) -> f64 {
    let count = samples.len();
    if count < 2 {
        return 0.0;
    }
    let mean = samples.iter().map(|&s| s as f64).sum::<f64>() / count as f64;
    let step = TAU * frequency_hz / sample_rate_hz as f64;
    let (mut re, mut im, mut weight) = (0.0, 0.0, 0.0);
    for (n, &sample) in samples.iter().enumerate() {
        let hann = 0.5 - 0.5 * (TAU * n as f64 / (count - 1) as f64).cos();
        let x = (sample as f64 - mean) * hann;
        re += x * (step * n as f64).cos();
        im += x * (step * n as f64).sin();
        weight += hann;
    }
    2.0 * re.hypot(im) / weight
}

/// One block played and recorded by an audio interface.
pub struct Take {
    /// As many samples as were played, from the same first cycle.
    pub recorded: Vec<f32>,
    /// The interface dropped a cycle (an xrun) while it played.
    pub spoiled: bool,
}

/// An audio interface that plays on the device and records its accelerometer.
pub trait Rig {
    /// The rate it runs at (Hz).
    fn sample_rate_hz(&self) -> u32;
    /// Plays `samples` and records as many, starting in the same cycle.
    fn play_and_record(&mut self, samples: &[f32]) -> Result<Take, MeasureError>;
}

/// What a measurement found, ready to write.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// The rate it was measured at (Hz).
    pub sample_rate_hz: u32,
    /// `[Hz, dB]`: each point's mean level over the repeats, 0 dB the strongest point.
    pub points: Vec<(f64, f64)>,
    /// Each point's spread over the repeats (dB, largest less smallest); with one repeat, none.
    pub spread_db: Option<Vec<f64>>,
    /// Each point's level above the silence recorded at its frequency (dB; infinite when the
    /// silence held nothing there).
    pub above_noise_db: Vec<f64>,
    /// The steps played again because an xrun spoiled them.
    pub replayed: usize,
}

impl Measured {
    /// The profile: the points, the band they span (or `band_hz`), the device's largest drive.
    pub fn profile(
        &self,
        name: &str,
        band_hz: Option<[f64; 2]>,
        max_amplitude: f64,
        comments: Vec<String>,
    ) -> ProfileText {
        let first = self.points.first().map_or(0.0, |point| point.0);
        let last = self.points.last().map_or(0.0, |point| point.0);
        ProfileText {
            name: name.to_owned(),
            comments,
            points: self.points.clone(),
            band_hz: band_hz.unwrap_or([first, last]),
            max_amplitude,
            sample_rate_hz: self.sample_rate_hz,
            spread_db: self.spread_db.clone(),
        }
    }

    /// The points heard less than [`NOISY_BELOW_DB`] above the silence.
    pub fn noisy_points(&self) -> impl Iterator<Item = (f64, f64)> + '_ {
        self.points
            .iter()
            .zip(&self.above_noise_db)
            .filter(|(_, above)| **above < NOISY_BELOW_DB)
            .map(|(point, above)| (point.0, *above))
    }
}

/// Measures the device on `rig` as `plan` says; `progress` hears each step as it ends (repeat,
/// step, steps).
pub fn measure(
    plan: &Plan,
    rig: &mut dyn Rig,
    progress: &mut dyn FnMut(usize, usize, usize),
) -> Result<Measured, MeasureError> {
    let rate = rig.sample_rate_hz();
    plan.check_rate(rate)?;
    let mut replayed = 0;
    let mut play = |frequency_hz: f64| -> Result<Vec<f32>, MeasureError> {
        let samples = plan.step(frequency_hz, rate);
        for _ in 0..MAX_TRIES {
            let take = rig.play_and_record(&samples)?;
            if !take.spoiled {
                let window = plan.window(frequency_hz.max(plan.frequencies_hz[0]), rate);
                let analysed = take
                    .recorded
                    .get(window)
                    .ok_or_else(|| MeasureError::Audio("the recording came back short".into()))?;
                if analysed.iter().any(|sample| sample.abs() >= CLIPPED) {
                    return Err(MeasureError::Clipped { hz: frequency_hz });
                }
                return Ok(analysed.to_vec());
            }
            replayed += 1;
        }
        Err(MeasureError::Xruns { hz: frequency_hz })
    };

    // Silence first: what the input hears at each frequency with the device at rest.
    let silence = play(0.0)?;
    let steps = plan.frequencies_hz.len();
    let noise: Vec<f64> = plan
        .frequencies_hz
        .iter()
        .map(|&hz| {
            let window = plan.window(hz, rate);
            level_at(&silence[..window.len().min(silence.len())], hz, rate)
        })
        .collect();
    // levels[repeat][step], dB re the drive.
    let mut levels = vec![vec![0.0; steps]; plan.repeats];
    for (repeat, row) in levels.iter_mut().enumerate() {
        for (step, &hz) in plan.frequencies_hz.iter().enumerate() {
            let recorded = play(hz)?;
            row[step] = 20.0 * (level_at(&recorded, hz, rate) / plan.amplitude).log10();
            progress(repeat, step, steps);
        }
    }
    let mean: Vec<f64> = (0..steps)
        .map(|step| levels.iter().map(|row| row[step]).sum::<f64>() / plan.repeats as f64)
        .collect();
    let strongest = mean.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !strongest.is_finite() {
        return Err(MeasureError::Silent);
    }
    let mut points = Vec::with_capacity(steps);
    for (&hz, &db) in plan.frequencies_hz.iter().zip(&mean) {
        let relative = db - strongest;
        if !(relative.is_finite() && relative >= -MAX_RESPONSE_DB) {
            return Err(MeasureError::NothingBack {
                hz,
                db,
                below: -relative,
            });
        }
        points.push((hz, relative));
    }
    let spread_db = (plan.repeats > 1).then(|| {
        (0..steps)
            .map(|step| {
                let column = levels.iter().map(|row| row[step]);
                let high = column.clone().fold(f64::NEG_INFINITY, f64::max);
                let low = column.fold(f64::INFINITY, f64::min);
                high - low
            })
            .collect()
    });
    let above_noise_db = mean
        .iter()
        .zip(&noise)
        .map(|(db, level)| db + 20.0 * plan.amplitude.log10() - 20.0 * level.log10())
        .collect();
    Ok(Measured {
        sample_rate_hz: rate,
        points,
        spread_db,
        above_noise_db,
        replayed,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ActuatorProfile;

    /// An offline rig: a second-order high-pass (90 Hz, Q 0.707, the RBJ cookbook's) between the
    /// drive and the input, a fixed round trip, a gain, and optionally an xrun on given takes.
    struct FilterRig {
        rate: u32,
        delay: usize,
        gain: f64,
        offset: f32,
        spoil: Vec<usize>,
        takes: usize,
    }

    impl FilterRig {
        fn new() -> Self {
            Self {
                rate: 48_000,
                // 100 ms: a slow interface's round trip, within the settling.
                delay: 4800,
                gain: 0.3,
                offset: 0.05,
                spoil: Vec::new(),
                takes: 0,
            }
        }

        fn coefficients(&self) -> ([f64; 3], [f64; 3]) {
            let w = TAU * 90.0 / self.rate as f64;
            let alpha = w.sin() / (2.0 * std::f64::consts::FRAC_1_SQRT_2);
            let b = [
                (1.0 + w.cos()) / 2.0,
                -(1.0 + w.cos()),
                (1.0 + w.cos()) / 2.0,
            ];
            let a = [1.0 + alpha, -2.0 * w.cos(), 1.0 - alpha];
            (b, a)
        }

        /// The filter's response at `hz` (dB), from its transfer function.
        fn response_db(&self, hz: f64) -> f64 {
            let (b, a) = self.coefficients();
            let w = TAU * hz / self.rate as f64;
            let at = |c: [f64; 3]| {
                let re = c[0] + c[1] * w.cos() + c[2] * (2.0 * w).cos();
                let im = -c[1] * w.sin() - c[2] * (2.0 * w).sin();
                re.hypot(im)
            };
            20.0 * (at(b) / at(a)).log10()
        }
    }

    impl Rig for FilterRig {
        fn sample_rate_hz(&self) -> u32 {
            self.rate
        }

        fn play_and_record(&mut self, samples: &[f32]) -> Result<Take, MeasureError> {
            self.takes += 1;
            let (b, a) = self.coefficients();
            let (mut x1, mut x2, mut y1, mut y2) = (0.0, 0.0, 0.0, 0.0);
            let mut recorded = vec![self.offset; samples.len()];
            for (n, &x) in samples.iter().enumerate() {
                let x = x as f64;
                let y = (b[0] * x + b[1] * x1 + b[2] * x2 - a[1] * y1 - a[2] * y2) / a[0];
                (x2, x1, y2, y1) = (x1, x, y1, y);
                if let Some(slot) = recorded.get_mut(n + self.delay) {
                    *slot += (self.gain * y) as f32;
                }
            }
            let spoiled = self.spoil.contains(&self.takes);
            if spoiled {
                // What an xrun leaves: a cycle of silence in the middle.
                let middle = recorded.len() / 2;
                recorded[middle..middle + 1024].fill(0.0);
            }
            Ok(Take { recorded, spoiled })
        }
    }

    fn plan(repeats: usize) -> Plan {
        Plan::stepped(30.0, 1000.0, 2.0, 0.25, 0.15, 0.3, repeats).unwrap()
    }

    #[test]
    fn a_known_filter_is_measured_within_a_tenth_of_a_db() {
        let mut rig = FilterRig::new();
        let measured = measure(&plan(1), &mut rig, &mut |_, _, _| {}).unwrap();
        let strongest = measured
            .points
            .iter()
            .map(|(hz, _)| rig.response_db(*hz))
            .fold(f64::NEG_INFINITY, f64::max);
        for &(hz, db) in &measured.points {
            let expected = rig.response_db(hz) - strongest;
            assert!(
                (db - expected).abs() < 0.1,
                "{hz} Hz: {db} dB, expected {expected} dB"
            );
        }
        assert_eq!(measured.spread_db, None);
        assert!(measured.noisy_points().next().is_none());
    }

    #[test]
    fn the_written_profile_reads_back_with_its_spread() {
        let mut rig = FilterRig::new();
        let measured = measure(&plan(3), &mut rig, &mut |_, _, _| {}).unwrap();
        let spread = measured.spread_db.clone().unwrap();
        assert_eq!(spread.len(), measured.points.len());
        // The same filter every time: the repeats agree.
        assert!(spread.iter().all(|db| *db < 1e-6), "{spread:?}");
        let text = measured.profile("rig", None, 0.8, vec!["measured".into()]);
        let profile = ActuatorProfile::parse(&text.to_toml()).unwrap();
        assert_eq!(profile.points(), &measured.points[..]);
        assert_eq!(profile.spread_db(), Some(&spread[..]));
        assert_eq!(profile.sample_rate_hz(), 48_000);
    }

    #[test]
    fn a_step_an_xrun_spoiled_is_played_again() {
        let mut rig = FilterRig::new();
        // Takes 1 (the silence), 3 and 4 (the second step, twice) lose a cycle.
        rig.spoil = vec![3, 4];
        let measured = measure(&plan(1), &mut rig, &mut |_, _, _| {}).unwrap();
        assert_eq!(measured.replayed, 2);
        let clean = measure(&plan(1), &mut FilterRig::new(), &mut |_, _, _| {}).unwrap();
        assert_eq!(measured.points, clean.points);

        let mut rig = FilterRig::new();
        rig.spoil = (3..3 + MAX_TRIES).collect();
        let error = measure(&plan(1), &mut rig, &mut |_, _, _| {}).unwrap_err();
        assert!(matches!(error, MeasureError::Xruns { .. }), "{error}");
    }

    #[test]
    fn a_clipped_input_or_a_silent_one_is_refused() {
        let mut rig = FilterRig::new();
        rig.gain = 8.0;
        let error = measure(&plan(1), &mut rig, &mut |_, _, _| {}).unwrap_err();
        assert!(matches!(error, MeasureError::Clipped { .. }), "{error}");

        let mut rig = FilterRig::new();
        rig.gain = 0.0;
        let error = measure(&plan(1), &mut rig, &mut |_, _, _| {}).unwrap_err();
        assert!(matches!(error, MeasureError::Silent), "{error}");

        // Silent above 300 Hz only: those points are refused by name.
        struct Deaf(FilterRig);
        impl Rig for Deaf {
            fn sample_rate_hz(&self) -> u32 {
                self.0.rate
            }
            fn play_and_record(&mut self, samples: &[f32]) -> Result<Take, MeasureError> {
                let loud = level_at(samples, 30.0, 48_000) > 0.01;
                let mut take = self.0.play_and_record(samples)?;
                if !loud {
                    take.recorded.fill(0.0);
                }
                Ok(take)
            }
        }
        let error = measure(&plan(1), &mut Deaf(FilterRig::new()), &mut |_, _, _| {}).unwrap_err();
        assert!(matches!(error, MeasureError::NothingBack { .. }), "{error}");
    }

    #[test]
    fn noise_in_the_silence_is_reported() {
        struct Noisy(FilterRig);
        impl Rig for Noisy {
            fn sample_rate_hz(&self) -> u32 {
                self.0.rate
            }
            fn play_and_record(&mut self, samples: &[f32]) -> Result<Take, MeasureError> {
                let mut take = self.0.play_and_record(samples)?;
                // A hum at 50 Hz as strong as the drive's level there.
                for (n, sample) in take.recorded.iter_mut().enumerate() {
                    *sample += (0.01 * (TAU * 50.0 * n as f64 / 48_000.0).sin()) as f32;
                }
                Ok(take)
            }
        }
        let plan = Plan::stepped(50.0, 400.0, 1.0, 0.25, 0.15, 0.3, 1).unwrap();
        let measured = measure(&plan, &mut Noisy(FilterRig::new()), &mut |_, _, _| {}).unwrap();
        let noisy: Vec<f64> = measured.noisy_points().map(|(hz, _)| hz).collect();
        assert_eq!(noisy, [50.0]);
    }

    #[test]
    fn plans_beyond_a_profile_or_too_short_are_refused() {
        for (plan, option) in [
            (
                Plan::stepped(20.0, 20_000.0, 12.0, 0.25, 0.2, 0.5, 1),
                "--per-octave",
            ),
            (
                Plan::stepped(20.0, 1000.0, 3.0, 0.25, 0.2, 0.2, 1),
                "--measure",
            ),
            (
                Plan::stepped(20.0, 1000.0, 3.0, 1.5, 0.2, 0.5, 1),
                "--level",
            ),
            (
                Plan::stepped(20.0, 1000.0, 3.0, 0.25, 0.2, 0.5, 0),
                "--repeat",
            ),
            (
                Plan::stepped(500.0, 100.0, 3.0, 0.25, 0.2, 0.5, 1),
                "--from/--to",
            ),
        ] {
            match plan {
                Err(MeasureError::Plan { option: named, .. }) => assert_eq!(named, option),
                other => panic!("{option}: {other:?}"),
            }
        }
        let plan = Plan::stepped(100.0, 20_000.0, 1.0, 0.25, 0.2, 0.5, 1).unwrap();
        let mut rig = FilterRig::new();
        rig.rate = 32_000;
        assert!(matches!(
            measure(&plan, &mut rig, &mut |_, _, _| {}),
            Err(MeasureError::Plan { option: "--to", .. })
        ));
    }
}
