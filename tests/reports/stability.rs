//! The stability cases of `sake-glug stability` at test lengths (seconds; ten minutes for the
//! long render): every case must pass every check it states. See docs/stability.md.

use sake_glug_engine::{AnchoredF32, Synthesis, UnitOnset};
use sake_glug_reports::stability::{Outcome, Property, Scale, StabilityCase};

fn assert_all_pass(outcomes: Vec<Outcome>) {
    assert!(!outcomes.is_empty());
    let failed: Vec<String> = outcomes
        .iter()
        .filter(|o| !o.passed())
        .map(|o| format!("{} / {}: {}", o.group, o.name, o.summary()))
        .collect();
    assert!(failed.is_empty(), "failed cases:\n{}", failed.join("\n"));
}

#[test]
fn decay_rates_from_zero_to_1e9() {
    assert_all_pass(StabilityCase::DecaySweep.run(Scale::Test));
}

#[test]
fn frequencies_from_zero_to_above_nyquist() {
    assert_all_pass(StabilityCase::FrequencySweep.run(Scale::Test));
}

#[test]
fn sample_rates_from_1_khz_to_768_khz_and_out_of_range() {
    assert_all_pass(StabilityCase::SampleRateSweep.run(Scale::Test));
}

#[test]
fn a_flood_of_onsets_is_capped_and_stays_cheap() {
    assert_all_pass(StabilityCase::Flood.run(Scale::Test));
}

#[test]
fn tilt_jumping_0_to_180_every_sample() {
    assert_all_pass(StabilityCase::TiltFlip.run(Scale::Test));
}

#[test]
fn hostile_values_for_every_input() {
    assert_all_pass(StabilityCase::HostileInputs.run(Scale::Test));
}

#[test]
fn ten_minutes_stay_stationary_and_do_not_drift() {
    assert_all_pass(StabilityCase::LongRender.run(Scale::Test));
}

/// A synthesis path `S` broken on purpose, as a synthesis fault would break it: the first sample
/// of the first unit that sounds is NaN. The limiter turns it into 0, so only a check before the
/// limiter can see it.
struct NanInFirstUnit<S> {
    path: S,
    /// No unit has sounded yet.
    armed: bool,
    /// The sample to make NaN, once the unit that sounds there has started.
    nan_at: Option<u64>,
}

impl<S: Synthesis> Synthesis for NanInFirstUnit<S> {
    fn new(sample_rate: f64) -> Self {
        Self {
            path: S::new(sample_rate),
            armed: true,
            nan_at: None,
        }
    }

    fn clear(&mut self) {
        self.path.clear();
    }

    fn is_empty(&self) -> bool {
        self.path.is_empty()
    }

    fn len(&self) -> usize {
        self.path.len()
    }

    fn given_up(&self) -> u64 {
        self.path.given_up()
    }

    fn take_peak_len(&mut self) -> usize {
        self.path.take_peak_len()
    }

    fn start_unit(&mut self, onset: &UnitOnset) -> bool {
        let sounding = self.path.len();
        let sounds = self.path.start_unit(onset);
        if self.armed && self.path.len() > sounding {
            self.armed = false;
            // A unit is heard from the sample after the one it starts in.
            self.nan_at = Some(onset.sample + 1);
        }
        sounds
    }

    fn synthesize(&mut self, span_start: u64, out: &mut [f32]) {
        self.path.synthesize(span_start, out);
        if let Some(sample) = self.nan_at {
            if let Some(y) = sample
                .checked_sub(span_start)
                .and_then(|offset| out.get_mut(offset as usize))
            {
                *y = f32::NAN;
                self.nan_at = None;
            }
        }
    }

    fn advance(&mut self, period_start: u64) {
        self.path.advance(period_start);
    }
}

/// A NaN in one unit is hidden from the output by the limiter (it becomes 0), so only a check
/// before the limiter can see it: every case that voices a component must fail.
#[test]
fn a_nan_in_a_unit_fails_the_suite() {
    type Broken = NanInFirstUnit<AnchoredF32>;
    let mut outcomes = StabilityCase::DecaySweep.run_on::<Broken>(Scale::Test);
    outcomes.extend(StabilityCase::TiltFlip.run_on::<Broken>(Scale::Test));
    for outcome in &outcomes {
        // A case whose components are all below −120 dB at their first sample (B = 10⁹ /s)
        // voices nothing, so there is nothing to break.
        let nothing_voiced = outcome.notes.contains("at most 0 sounding");
        let finite = outcome
            .checks
            .iter()
            .find(|check| check.what == Property::Finite)
            .unwrap();
        assert_eq!(
            finite.passed,
            nothing_voiced,
            "{} / {}: {}",
            outcome.group,
            outcome.name,
            outcome.summary()
        );
    }
    assert!(outcomes.iter().filter(|o| !o.passed()).count() >= 8);
}

/// The report's "at most N sounding" is the true peak, not the count at the end of a block: at
/// 1 kHz a 4096-sample block outlasts every unit, so a count taken at block ends reads 0.
#[test]
fn the_peak_voice_count_is_counted_where_it_happens() {
    use sake_glug_engine::{ControlValues, Controls, Engine, ModelConfig};
    use sake_glug_reports::timing::{self, RenderSpec};
    let fs = 1_000.0;
    let controls = |sample: u64| {
        let tilt_deg = if sample < 1_000 { 135.0 } else { 0.0 };
        ControlValues {
            tilt_deg,
            ..ControlValues::default()
        }
    };
    let len = 3_000;
    let spec = RenderSpec {
        sample_rate: fs,
        config: ModelConfig::default(),
        len,
        keep: &[],
        energy_span: 0,
    };
    let reported = timing::timed_render::<AnchoredF32>(&spec, &controls).max_sounding;
    // The truth, sample by sample.
    let mut engine = Engine::new(fs, ModelConfig::default());
    let mut truth = 0;
    for sample in 0..len {
        engine.process(&Controls::constant(controls(sample)), &mut [0.0]);
        truth = truth.max(engine.sounding_components());
    }
    assert!(truth > 0);
    assert_eq!(reported, truth);
}
