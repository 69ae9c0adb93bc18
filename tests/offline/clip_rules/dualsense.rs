//! Validator of the `dualsense` WAV: what the DualSense's USB audio interface plays (4
//! channels — audio left and right, actuator left and right — of 16-bit PCM at 48 kHz); and
//! its fixtures.

use std::io::Cursor;

use super::{check_binary_fixtures, Violation};

rules! {
    NotWav => "not_wav": "the file is a RIFF/WAVE file a WAV reader opens",
    ChannelCount => "channel_count":
        "it has 4 channels: audio left, audio right, actuator left, actuator right",
    SampleRate => "sample_rate": "its sample rate is 48 000 Hz",
    SampleFormat => "sample_format": "its samples are 16-bit integer PCM",
}

/// Every rule the file breaks, empty if it is valid.
pub fn validate(bytes: &[u8]) -> Vec<Violation<Rule>> {
    let reader = match hound::WavReader::new(Cursor::new(bytes)) {
        Ok(reader) => reader,
        Err(e) => return vec![violation(Rule::NotWav, e.to_string())],
    };
    let spec = reader.spec();
    let mut violations = Vec::new();
    if spec.channels != 4 {
        violations.push(violation(Rule::ChannelCount, format!("{}", spec.channels)));
    }
    if spec.sample_rate != 48_000 {
        violations.push(violation(Rule::SampleRate, format!("{}", spec.sample_rate)));
    }
    if spec.bits_per_sample != 16 || spec.sample_format != hound::SampleFormat::Int {
        violations.push(violation(Rule::SampleFormat, format!("{spec:?}")));
    }
    violations
}

/// The frames of a valid file: `[audio L, audio R, actuator L, actuator R]`.
pub fn parse(bytes: &[u8]) -> Vec<[i16; 4]> {
    let violations = validate(bytes);
    assert!(
        violations.is_empty(),
        "invalid DualSense WAV: {violations:#?}"
    );
    let samples: Vec<i16> = hound::WavReader::new(Cursor::new(bytes))
        .unwrap()
        .samples::<i16>()
        .map(Result::unwrap)
        .collect();
    samples
        .chunks_exact(4)
        .map(|frame| [frame[0], frame[1], frame[2], frame[3]])
        .collect()
}

#[test]
fn dualsense_fixtures_follow_their_rules() {
    check_binary_fixtures("dualsense", validate);
}
