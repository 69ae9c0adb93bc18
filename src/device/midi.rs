//! MIDI from the tilt device: control changes drive tilt, viscosity and fill; plain Rust, no
//! plugin types, so that the mapping is tested on its own.
//!
//! Tilt takes a 14-bit MSB/LSB pair (the LSB on its own CC number, usually MSB + 32) or a 7-bit
//! CC; viscosity and fill take 7-bit CCs. A CC value overrides its parameter until the host
//! changes that parameter again: whichever moved last wins.

use crate::engine::config::{Range, FILL_PERCENT, TILT_DEG, VISCOSITY};

/// A CC number or channel byte that means "not mapped" / "any channel" in saved settings.
pub const OFF: u8 = 255;

/// Which CCs and channel the plugin listens to (saved with the plugin's state).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MidiMap {
    /// 0–15, or `None` for any channel.
    pub channel: Option<u8>,
    /// CC number of tilt (its MSB when tilt is 14-bit), 0–127; `None` if unmapped.
    pub tilt_msb: Option<u8>,
    /// With an LSB CC, tilt is 14-bit; without, 7-bit.
    pub tilt_lsb: Option<u8>,
    /// CC number of viscosity c (7-bit), 0–127; `None` if unmapped.
    pub viscosity: Option<u8>,
    /// CC number of the fill level φ (7-bit), 0–127; `None` if unmapped.
    pub fill: Option<u8>,
}

impl Default for MidiMap {
    /// General-purpose controllers 1–3 (CC 16, 17, 18), tilt 14-bit with its LSB on CC 48.
    fn default() -> Self {
        Self {
            channel: None,
            tilt_msb: Some(16),
            tilt_lsb: Some(48),
            viscosity: Some(17),
            fill: Some(18),
        }
    }
}

impl MidiMap {
    /// From saved bytes `[channel, tilt MSB, tilt LSB, viscosity, fill]`; anything out of range
    /// (a CC above 127, a channel above 15) reads as unmapped / any channel.
    pub fn from_raw(raw: [u8; 5]) -> Self {
        let cc = |byte: u8| (byte < 128).then_some(byte);
        Self {
            channel: (raw[0] < 16).then_some(raw[0]),
            tilt_msb: cc(raw[1]),
            tilt_lsb: cc(raw[2]),
            viscosity: cc(raw[3]),
            fill: cc(raw[4]),
        }
    }

    /// The bytes saved with the state, `[channel, tilt MSB, tilt LSB, viscosity, fill]`, with
    /// [`OFF`] for unmapped / any channel.
    pub fn to_raw(self) -> [u8; 5] {
        let byte = |value: Option<u8>| value.unwrap_or(OFF);
        [
            byte(self.channel),
            byte(self.tilt_msb),
            byte(self.tilt_lsb),
            byte(self.viscosity),
            byte(self.fill),
        ]
    }

    fn listens_on(&self, channel: u8) -> bool {
        self.channel.is_none_or(|wanted| wanted == channel)
    }
}

/// A MIDI message the synth acts on, whether it comes from a host, the device, or a recorded
/// take: everything else is dropped before it gets here.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MidiInput {
    /// A note-on with a velocity above 0: refill the bottle (MODEL.md §8).
    NoteOn {
        /// 0–15.
        channel: u8,
    },
    /// A control change.
    Cc {
        /// 0–15.
        channel: u8,
        /// The controller number, 0–127.
        cc: u8,
        /// 0–127.
        value: u8,
    },
}

/// What a MIDI message asks of the engine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DeviceAction {
    /// Refill the bottle to its fill level.
    Refill,
    /// Set a control to a value in its own unit, overriding its parameter or scene lane.
    Set(Target, f64),
}

/// The controls a CC can drive, in the order of [`Overrides`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// Tilt θ (degrees).
    Tilt = 0,
    /// Viscosity ratio c.
    Viscosity = 1,
    /// Fill level φ (percent of capacity).
    Fill = 2,
}

impl Target {
    fn range(self) -> Range {
        match self {
            Target::Tilt => TILT_DEG,
            Target::Viscosity => VISCOSITY,
            Target::Fill => FILL_PERCENT,
        }
    }

    /// The control value for a position 0…1 of the device.
    fn value(self, position: f64) -> f64 {
        let range = self.range();
        range.min + position.clamp(0.0, 1.0) * (range.max - range.min)
    }
}

/// Turns CC messages into control values, assembling 14-bit tilt from its MSB and LSB.
#[derive(Debug, Clone, Copy, Default)]
pub struct CcDecoder {
    /// The last tilt MSB and LSB, until a reset.
    tilt_msb: Option<u8>,
    tilt_lsb: u8,
}

impl CcDecoder {
    /// Forgets the last tilt MSB and LSB.
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// The one decoding of MIDI the plugin and the offline renderer share: a note-on on a channel
    /// the map listens to refills, a mapped CC sets its control.
    pub fn decode(&mut self, map: &MidiMap, input: MidiInput) -> Option<DeviceAction> {
        match input {
            MidiInput::NoteOn { channel } => {
                map.listens_on(channel).then_some(DeviceAction::Refill)
            }
            MidiInput::Cc { channel, cc, value } => self
                .feed(map, channel, cc, value)
                .map(|(target, value)| DeviceAction::Set(target, value)),
        }
    }

    /// One CC message (`value` 0–127); returns the control it sets, if it is mapped.
    ///
    /// In 14-bit mode an MSB applies at once with the last LSB, and the LSB that follows
    /// refines it; an LSB without an MSB before it is only remembered. Keeping the last LSB
    /// (rather than zeroing it on a new MSB) gives the exact angle also through hosts that pass
    /// a CC on only when its value changes, as VST3 hosts may.
    pub fn feed(&mut self, map: &MidiMap, channel: u8, cc: u8, value: u8) -> Option<(Target, f64)> {
        if !map.listens_on(channel) || cc > 127 {
            return None;
        }
        let value = value.min(127);
        if Some(cc) == map.tilt_msb {
            return Some(match map.tilt_lsb {
                Some(_) => {
                    self.tilt_msb = Some(value);
                    (
                        Target::Tilt,
                        Target::Tilt.value(fourteen_bit(value, self.tilt_lsb)),
                    )
                }
                None => (Target::Tilt, Target::Tilt.value(value as f64 / 127.0)),
            });
        }
        if map.tilt_lsb.is_some() && Some(cc) == map.tilt_lsb {
            self.tilt_lsb = value;
            let msb = self.tilt_msb?;
            return Some((Target::Tilt, Target::Tilt.value(fourteen_bit(msb, value))));
        }
        let position = value as f64 / 127.0;
        if Some(cc) == map.viscosity {
            return Some((Target::Viscosity, Target::Viscosity.value(position)));
        }
        if Some(cc) == map.fill {
            return Some((Target::Fill, Target::Fill.value(position)));
        }
        None
    }
}

fn fourteen_bit(msb: u8, lsb: u8) -> f64 {
    ((msb as u32) << 7 | lsb as u32) as f64 / 16383.0
}

/// Which of tilt, viscosity and fill currently follow MIDI rather than their parameter.
#[derive(Debug, Clone, Copy, Default)]
pub struct Overrides {
    /// The parameter values when last seen; a change means the host moved the parameter.
    seen: [Option<f64>; 3],
    midi: [Option<f64>; 3],
}

impl Overrides {
    /// Makes `target` follow MIDI at `value` until the host changes its parameter.
    pub fn set(&mut self, target: Target, value: f64) {
        self.midi[target as usize] = Some(value);
    }

    /// Drops every MIDI override: tilt, viscosity and fill follow their parameters again.
    pub fn clear(&mut self) {
        self.midi = [None; 3];
    }

    /// The values the engine should use, given the parameters' values `[tilt, viscosity, fill]`.
    pub fn apply(&mut self, params: [f64; 3]) -> [f64; 3] {
        let mut out = params;
        for index in 0..3 {
            if self.seen[index].is_some_and(|seen| seen.to_bits() != params[index].to_bits()) {
                self.midi[index] = None;
            }
            self.seen[index] = Some(params[index]);
            if let Some(value) = self.midi[index] {
                out[index] = value;
            }
        }
        out
    }
}
