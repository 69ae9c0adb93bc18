//! A recorded take from the tilt device as a Standard MIDI File: its note-ons and control
//! changes, each at the sample where it takes effect.
//!
//! Times are exact: a message at time t takes effect at the first sample at or after t,
//! `ceil(t · fs)`, computed in integers so that a message on a sample boundary lands on that
//! sample rather than one later through rounding.

use midly::{Format, MetaMessage, MidiMessage, Timing, TrackEventKind};
use thiserror::Error;

use super::midi::MidiInput;
use sake_glug_io::text::printable;

/// The longest take read, in seconds: anything later is a corrupt delta time, not a pour.
pub const MAX_TAKE_SECONDS: u64 = 24 * 60 * 60;

/// The largest take file read ([`sake_glug_io::InputKind::MIDI_TAKE`]).
pub const MAX_TAKE_BYTES: u64 = sake_glug_io::InputKind::MIDI_TAKE.max_bytes;

/// The tempo of a file that sets none: 120 quarter notes per minute.
const DEFAULT_TEMPO_US: u32 = 500_000;

/// A [`MidiInput`] and the sample at which it takes effect.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TimedInput {
    /// The first sample at or after the message's time, counted from the start of the take.
    pub sample: u64,
    /// The message.
    pub input: MidiInput,
}

/// Why a take could not be read. Tracks are numbered from 1, as sequencers show them.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TakeError {
    /// midly could not read the file: not MIDI at all, or a broken header.
    #[error("not a Standard MIDI File: {reason}")]
    NotMidi {
        /// midly's message, with its causes.
        reason: String,
    },
    /// A RIFF-wrapped (RMID) file, which is not read.
    #[error("RIFF-wrapped MIDI (RMID) is not supported: save the take as a plain .mid file")]
    Riff,
    /// The file ends inside a chunk, or holds fewer tracks than its header declares.
    #[error("truncated MIDI file: {detail}")]
    Truncated {
        /// Where it ends early.
        detail: String,
    },
    /// An event that midly could not read; it stops reading a track there without an error,
    /// which would silently drop the rest of the take.
    #[error(
        "track {track}: the event at byte {offset} of the track is corrupt or cut off \
         ({event_count} events read before it)"
    )]
    BadEvent {
        /// The track, from 1.
        track: usize,
        /// The event's offset in the track chunk's data.
        offset: usize,
        /// How many events were read before it.
        event_count: usize,
    },
    /// Format 2: independent sequences, not one take.
    #[error(
        "format 2 (sequential) MIDI files hold independent sequences, not one take: \
         save the take as format 0 or 1"
    )]
    SequentialFormat,
    /// Metrical timing with 0 ticks per quarter note.
    #[error("the header's timing is 0 ticks per quarter note")]
    ZeroPpq,
    /// SMPTE timing with 0 ticks per frame.
    #[error("the header's SMPTE timing is 0 ticks per frame")]
    ZeroTicksPerFrame,
    /// SMPTE timing with a frame rate other than 24, 25, 29.97 or 30 fps.
    #[error("the header's SMPTE frame rate byte {byte:#04x} is not −24, −25, −29 or −30")]
    BadFrameRate {
        /// The division's high byte, a negative frame rate.
        byte: u8,
    },
    /// A Set Tempo of 0 µs per quarter note, which would stop time.
    #[error("track {track}: a tempo of 0 µs per quarter note at tick {tick}")]
    ZeroTempo {
        /// The track, from 1.
        track: usize,
        /// The tick of the tempo event.
        tick: u64,
    },
    /// A message past [`MAX_TAKE_SECONDS`].
    #[error(
        "track {track}: a message at tick {tick} comes after {seconds:.0} s, \
         past the {MAX_TAKE_SECONDS} s limit of a take"
    )]
    TooLong {
        /// The track, from 1.
        track: usize,
        /// The message's tick.
        tick: u64,
        /// Its time, roughly.
        seconds: f64,
    },
    /// A sample rate of 0, for which no sample exists.
    #[error("the sample rate is 0 Hz")]
    ZeroSampleRate,
}

/// Reads a take: every note-on and CC of every track, in time order (for equal times, track
/// order, then file order), each at the first sample at or after its time at `sample_rate` Hz.
///
/// Format 0 and 1 files are read, with metrical or SMPTE timing. In metrical timing the tempo
/// map applies to all tracks whichever track a Set Tempo is in, starting at 500 000 µs per
/// quarter note; in SMPTE timing ticks are fixed fractions of a second and Set Tempo is
/// ignored, as the standard says. 29.97 fps is taken as 30000/1001 frames per second. Events
/// after a track's End of Track are ignored.
pub fn read_midi_take(bytes: &[u8], sample_rate: u32) -> Result<Vec<TimedInput>, TakeError> {
    if sample_rate == 0 {
        return Err(TakeError::ZeroSampleRate);
    }
    if bytes.starts_with(b"RIFF") {
        return Err(TakeError::Riff);
    }
    check_frame_rate(bytes)?;
    let (header, tracks) = midly::parse(bytes).map_err(|error| TakeError::NotMidi {
        reason: midly_message(&error),
    })?;
    // midly reads past a chunk that is cut short without an error (outside its `strict`
    // feature), so the chunk lengths are checked here.
    let track_chunks = count_track_chunks(bytes)?;
    if header.format == Format::Sequential {
        return Err(TakeError::SequentialFormat);
    }
    let clock = Clock::new(header.timing, sample_rate)?;
    let declared = tracks.size_hint().0;
    if track_chunks < declared {
        return Err(TakeError::Truncated {
            detail: format!(
                "the header declares {declared} tracks but the file holds {track_chunks}"
            ),
        });
    }

    let mut events = Vec::new();
    for (index, track) in tracks.enumerate() {
        let track_number = index + 1;
        let mut track = track.map_err(|error| TakeError::NotMidi {
            reason: midly_message(&error),
        })?;
        let track_length = track.unread().len();
        let mut tick: u64 = 0;
        let mut event_count = 0;
        loop {
            let offset = track_length - track.unread().len();
            let event = match track.next() {
                Some(Ok(event)) => event,
                Some(Err(error)) => {
                    return Err(TakeError::NotMidi {
                        reason: midly_message(&error),
                    })
                }
                // midly ends a track early, without an error, at an event it cannot read.
                None if offset < track_length => {
                    return Err(TakeError::BadEvent {
                        track: track_number,
                        offset,
                        event_count,
                    })
                }
                None => break,
            };
            event_count += 1;
            tick = tick.saturating_add(u64::from(event.delta.as_int()));
            let kind = match event.kind {
                TrackEventKind::Meta(MetaMessage::EndOfTrack) => break,
                TrackEventKind::Meta(MetaMessage::Tempo(tempo)) => {
                    let tempo = tempo.as_int();
                    if tempo == 0 {
                        return Err(TakeError::ZeroTempo {
                            track: track_number,
                            tick,
                        });
                    }
                    EventKind::Tempo(tempo)
                }
                TrackEventKind::Midi { channel, message } => {
                    let channel = channel.as_int();
                    match message {
                        MidiMessage::NoteOn { vel, .. } if vel.as_int() > 0 => {
                            EventKind::Input(MidiInput::NoteOn { channel })
                        }
                        MidiMessage::Controller { controller, value } => {
                            EventKind::Input(MidiInput::Cc {
                                channel,
                                cc: controller.as_int(),
                                value: value.as_int(),
                            })
                        }
                        _ => continue,
                    }
                }
                _ => continue,
            };
            events.push(Event {
                tick,
                track: track_number,
                kind,
            });
        }
    }

    // A stable sort keeps track order, then file order, for equal ticks.
    events.sort_by_key(|event| event.tick);
    clock.place(&events)
}

/// One tempo change or input, at its tick from the start of the file.
struct Event {
    tick: u64,
    track: usize,
    kind: EventKind,
}

enum EventKind {
    /// A Set Tempo, in µs per quarter note.
    Tempo(u32),
    Input(MidiInput),
}

/// Turns ticks into samples exactly. One tick lasts `tick_numerator / tick_denominator` s,
/// where the numerator is the tempo in µs for metrical timing.
struct Clock {
    sample_rate: u128,
    tick_denominator: u128,
    tick_numerator: u128,
    follows_tempo: bool,
}

impl Clock {
    fn new(timing: Timing, sample_rate: u32) -> Result<Self, TakeError> {
        let (tick_numerator, tick_denominator, follows_tempo) = match timing {
            Timing::Metrical(ppq) => {
                let ppq = u128::from(ppq.as_int());
                if ppq == 0 {
                    return Err(TakeError::ZeroPpq);
                }
                // A tick lasts tempo_µs / (ppq · 10⁶) s.
                (u128::from(DEFAULT_TEMPO_US), ppq * 1_000_000, true)
            }
            Timing::Timecode(fps, ticks_per_frame) => {
                let ticks_per_frame = u128::from(ticks_per_frame);
                if ticks_per_frame == 0 {
                    return Err(TakeError::ZeroTicksPerFrame);
                }
                // A tick lasts 1 / (fps · ticks per frame) s; 29.97 fps is 30000/1001.
                match fps {
                    midly::Fps::Fps29 => (1001, 30_000 * ticks_per_frame, false),
                    other => (1, u128::from(other.as_int()) * ticks_per_frame, false),
                }
            }
        };
        Ok(Self {
            sample_rate: u128::from(sample_rate),
            tick_denominator,
            tick_numerator,
            follows_tempo,
        })
    }

    /// The inputs among `events` (sorted by tick) at their samples.
    fn place(mut self, events: &[Event]) -> Result<Vec<TimedInput>, TakeError> {
        let limit = u128::from(MAX_TAKE_SECONDS) * self.sample_rate * self.tick_denominator;
        // t · fs · tick_denominator at `tick`, kept exact across tempo changes.
        let mut scaled_time: u128 = 0;
        let mut tick = 0;
        let mut inputs = Vec::new();
        for event in events {
            // Ticks are below 2⁶⁴ and the factors below 2⁵⁶ together: the product cannot
            // overflow, and the sum stays under the limit checked below before it grows.
            let elapsed = u128::from(event.tick - tick);
            scaled_time += elapsed * self.tick_numerator * self.sample_rate;
            tick = event.tick;
            if scaled_time > limit {
                return Err(TakeError::TooLong {
                    track: event.track,
                    tick,
                    seconds: scaled_time as f64
                        / (self.sample_rate as f64 * self.tick_denominator as f64),
                });
            }
            match event.kind {
                EventKind::Tempo(tempo) if self.follows_tempo => {
                    self.tick_numerator = u128::from(tempo);
                }
                EventKind::Tempo(_) => {}
                EventKind::Input(input) => inputs.push(TimedInput {
                    sample: scaled_time.div_ceil(self.tick_denominator) as u64,
                    input,
                }),
            }
        }
        Ok(inputs)
    }
}

/// Refuses an SMPTE division with a frame rate byte that is not one of the four rates, before
/// midly reads it: midly negates the byte as an `i8`, which overflows (a panic in debug builds)
/// for 0x80. `bytes` starts at a chunk; midly reads every `MThd` chunk as a header, a later one
/// too, so [`count_track_chunks`] checks each.
fn check_frame_rate(bytes: &[u8]) -> Result<(), TakeError> {
    let header_length = bytes
        .get(4..8)
        .map(|length| u32::from_be_bytes([length[0], length[1], length[2], length[3]]));
    match (bytes.get(..4), header_length, bytes.get(12)) {
        // The division follows the format and track count, 6 bytes into a header of 6 or more.
        (Some(b"MThd"), Some(6..), Some(&byte)) if byte & 0x80 != 0 => match byte.wrapping_neg() {
            24 | 25 | 29 | 30 => Ok(()),
            _ => Err(TakeError::BadFrameRate { byte }),
        },
        _ => Ok(()),
    }
}

/// Walks the chunks of a file that starts with `MThd` and counts its `MTrk` chunks, refusing a
/// chunk that runs past the end of the file or a header with a frame rate midly cannot read.
fn count_track_chunks(bytes: &[u8]) -> Result<usize, TakeError> {
    let mut rest = bytes;
    let mut tracks = 0;
    let mut index = 0;
    while !rest.is_empty() {
        check_frame_rate(rest)?;
        let Some((head, body)) = rest.split_first_chunk::<8>() else {
            return Err(TakeError::Truncated {
                detail: format!(
                    "the file ends {} bytes into the header of chunk {}",
                    rest.len(),
                    index + 1
                ),
            });
        };
        let length = u32::from_be_bytes([head[4], head[5], head[6], head[7]]);
        let is_track = &head[..4] == b"MTrk";
        let Some(after) = usize::try_from(length).ok().and_then(|len| body.get(len..)) else {
            let what = if is_track {
                format!("track {}", tracks + 1)
            } else {
                format!(
                    "chunk {} ({})",
                    index + 1,
                    printable(&String::from_utf8_lossy(&head[..4]))
                )
            };
            return Err(TakeError::Truncated {
                detail: format!(
                    "{what} declares {length} bytes but only {} remain",
                    body.len()
                ),
            });
        };
        tracks += usize::from(is_track);
        index += 1;
        rest = after;
    }
    Ok(tracks)
}

/// midly's message and, in debug builds where midly keeps them, its causes.
fn midly_message(error: &midly::Error) -> String {
    let mut message = error.to_string();
    let mut cause = error.source();
    while let Some(inner) = cause {
        message.push_str(": ");
        // A cause's bare message, without its "invalid midi: " prefix again.
        message.push_str(inner.kind().message());
        cause = inner.source();
    }
    message
}
