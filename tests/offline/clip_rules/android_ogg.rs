//! Validator of the `android-ogg` file, from what Android's media extractor takes for
//! haptic-coupled playback: an Ogg Vorbis stream whose comment header counts its haptic
//! channels (the last ones) as `ANDROID_HAPTIC=N`, N of 1 or 2 (Android's two haptic channels,
//! HAPTIC_A and HAPTIC_B), leaving at least one audio channel; and its fixtures. Files are
//! decoded with lewton, a decoder of its own, not the encoder that wrote them.

use std::io::Cursor;

use lewton::inside_ogg::OggStreamReader;

use super::{check_binary_fixtures, Violation};

rules! {
    NotOggVorbis => "not_ogg_vorbis": "the file is an Ogg Vorbis stream a decoder opens",
    NoHapticComment => "no_haptic_comment":
        "the comment header holds one ANDROID_HAPTIC=N",
    HapticCountOutOfRange => "haptic_count_out_of_range":
        "N is 1 or 2 and smaller than the stream's channel count (at least one audio channel)",
}

/// A decoded file: its channels (each its samples), sample rate, and haptic channel count.
pub struct Decoded {
    pub channels: Vec<Vec<f32>>,
    pub sample_rate: u32,
    pub haptic_channels: usize,
}

fn read(bytes: &[u8], violations: &mut Vec<Violation<Rule>>) -> Option<Decoded> {
    let mut reader = match OggStreamReader::new(Cursor::new(bytes)) {
        Ok(reader) => reader,
        Err(e) => {
            violations.push(violation(Rule::NotOggVorbis, e.to_string()));
            return None;
        }
    };
    let channel_count = reader.ident_hdr.audio_channels as usize;
    let counts: Vec<&str> = reader
        .comment_hdr
        .comment_list
        .iter()
        .filter(|(tag, _)| tag.eq_ignore_ascii_case("ANDROID_HAPTIC"))
        .map(|(_, value)| value.as_str())
        .collect();
    let haptic_channels = match counts.as_slice() {
        [count] => count.trim().parse::<usize>().ok(),
        _ => {
            violations.push(violation(Rule::NoHapticComment, format!("{counts:?}")));
            None
        }
    };
    if let Some(count) = counts
        .first()
        .filter(|_| haptic_channels.is_some() || counts.len() == 1)
    {
        let ok = haptic_channels.is_some_and(|n| (1..=2).contains(&n) && n < channel_count);
        if !ok {
            violations.push(violation(
                Rule::HapticCountOutOfRange,
                format!("ANDROID_HAPTIC={count} of {channel_count} channels"),
            ));
        }
    }
    let mut channels = vec![Vec::new(); channel_count];
    loop {
        match reader.read_dec_packet_generic::<Vec<Vec<f32>>>() {
            Ok(Some(packet)) => {
                for (channel, samples) in channels.iter_mut().zip(packet) {
                    channel.extend(samples);
                }
            }
            Ok(None) => break,
            Err(e) => {
                violations.push(violation(Rule::NotOggVorbis, e.to_string()));
                return None;
            }
        }
    }
    Some(Decoded {
        channels,
        sample_rate: reader.ident_hdr.audio_sample_rate,
        haptic_channels: haptic_channels.unwrap_or(0),
    })
}

/// Every rule the file breaks, empty if it is valid.
pub fn validate(bytes: &[u8]) -> Vec<Violation<Rule>> {
    let mut violations = Vec::new();
    read(bytes, &mut violations);
    violations
}

/// A valid file decoded, panicking on any rule it breaks.
pub fn parse(bytes: &[u8]) -> Decoded {
    let mut violations = Vec::new();
    let decoded = read(bytes, &mut violations);
    assert!(
        violations.is_empty(),
        "invalid Android Ogg: {violations:#?}"
    );
    decoded.expect("a valid file")
}

#[test]
fn android_ogg_fixtures_follow_their_rules() {
    check_binary_fixtures("ogg", validate);
}
