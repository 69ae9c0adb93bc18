//! The stability cases of `sake-glug stability` at test lengths (seconds; ten minutes for the
//! long render): every case must pass every check it states. See docs/stability.md.

use sake_glug::reports::stability::{Outcome, Scale, StabilityCase};

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
