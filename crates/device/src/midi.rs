//! MIDI from the tilt device: control changes drive tilt, viscosity and fill; plain Rust, no
//! plugin types, so that the mapping is tested on its own.
//!
//! Tilt takes a 14-bit MSB/LSB pair (the LSB on its own CC number, usually MSB + 32) or a 7-bit
//! CC; viscosity and fill take 7-bit CCs. A CC value overrides its parameter until the host
//! changes that parameter again: whichever moved last wins.

use sake_glug_engine::{Control, ControlValues, PerControl};

/// A CC number or channel byte that means "not mapped" / "any channel" in saved settings.
pub const OFF: u8 = 255;

/// The CC of 14-bit tilt's least significant half, by default (MSB + 32, as MIDI pairs them).
const DEFAULT_TILT_LSB: u8 = 48;

/// One saved MIDI setting: a byte in the plugin's state and in a scene's `[midi]` table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MidiSetting {
    /// The channel listened to, 0–15, or [`OFF`] for any.
    Channel,
    /// The CC number of a control a device can drive (tilt's MSB when tilt is 14-bit).
    Cc(Control),
    /// The CC number of tilt's LSB; [`OFF`] makes tilt 7-bit.
    TiltLsb,
}

impl MidiSetting {
    /// Every setting, in the order of [`MidiMap::to_raw`]: the channel, then each control a
    /// device can drive (tilt followed by its LSB).
    pub fn all() -> impl Iterator<Item = MidiSetting> {
        std::iter::once(MidiSetting::Channel).chain(Control::device_inputs().flat_map(
            |(control, _)| {
                let lsb = (control == Control::Tilt).then_some(MidiSetting::TiltLsb);
                std::iter::once(MidiSetting::Cc(control)).chain(lsb)
            },
        ))
    }

    /// Its name in the saved state and in a scene's `[midi]` table.
    pub fn key(self) -> &'static str {
        match self {
            MidiSetting::Channel => "midi_channel",
            MidiSetting::Cc(control) => control
                .spec()
                .device
                .map_or("", |device| device.midi_setting),
            MidiSetting::TiltLsb => "midi_cc_tilt_lsb",
        }
    }

    /// What the editor calls it.
    pub fn label(self) -> String {
        match self {
            MidiSetting::Channel => "Channel".to_owned(),
            MidiSetting::Cc(Control::Tilt) => "Tilt CC (MSB)".to_owned(),
            MidiSetting::Cc(control) => format!("{} CC", control.quantity().name),
            MidiSetting::TiltLsb => "Tilt LSB CC".to_owned(),
        }
    }

    /// Its largest value other than [`OFF`].
    pub fn max(self) -> u8 {
        match self {
            MidiSetting::Channel => 15,
            MidiSetting::Cc(_) | MidiSetting::TiltLsb => 127,
        }
    }
}

/// Which CCs and channel the plugin listens to (saved with the plugin's state).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MidiMap {
    /// 0–15, or `None` for any channel.
    pub channel: Option<u8>,
    /// The CC number (0–127) of each control a device drives (tilt's MSB when tilt is 14-bit);
    /// `None` if unmapped, and always for a control no device drives.
    pub cc: PerControl<Option<u8>>,
    /// With an LSB CC, tilt is 14-bit; without, 7-bit.
    pub tilt_lsb: Option<u8>,
}

impl Default for MidiMap {
    /// General-purpose controllers 1–3 (CC 16, 17, 18), tilt 14-bit with its LSB on CC 48.
    fn default() -> Self {
        Self {
            channel: None,
            cc: PerControl::from_fn(|control| Some(control.spec().device?.default_cc)),
            tilt_lsb: Some(DEFAULT_TILT_LSB),
        }
    }
}

impl MidiMap {
    /// The saved byte of `setting`, with [`OFF`] for unmapped / any channel.
    pub fn raw(&self, setting: MidiSetting) -> u8 {
        let value = match setting {
            MidiSetting::Channel => self.channel,
            MidiSetting::Cc(control) => self.cc[control],
            MidiSetting::TiltLsb => self.tilt_lsb,
        };
        value.unwrap_or(OFF)
    }

    /// Sets `setting` from its saved byte; anything out of range (a CC above 127, a channel
    /// above 15) reads as unmapped / any channel.
    pub fn set_raw(&mut self, setting: MidiSetting, byte: u8) {
        let value = (byte <= setting.max()).then_some(byte);
        match setting {
            MidiSetting::Channel => self.channel = value,
            MidiSetting::Cc(control) if control.spec().device.is_some() => self.cc[control] = value,
            MidiSetting::Cc(_) => {}
            MidiSetting::TiltLsb => self.tilt_lsb = value,
        }
    }

    /// From saved bytes in the order of [`MidiSetting::all`].
    pub fn from_raw(raw: impl IntoIterator<Item = u8>) -> Self {
        let mut map = Self::default();
        for (setting, byte) in MidiSetting::all().zip(raw) {
            map.set_raw(setting, byte);
        }
        map
    }

    /// The bytes saved with the state, in the order of [`MidiSetting::all`].
    pub fn to_raw(self) -> Vec<u8> {
        MidiSetting::all()
            .map(|setting| self.raw(setting))
            .collect()
    }

    /// MIDI learn: `setting` takes `cc` and the map listens on `channel` (the device's), as a
    /// CC the device sent while the user was learning that row. Any other row that had `cc` is
    /// unmapped, so that one CC drives one control. Learning the channel itself only sets it.
    pub fn learn(&mut self, setting: MidiSetting, channel: u8, cc: u8) {
        self.channel = (channel <= MidiSetting::Channel.max()).then_some(channel);
        if setting == MidiSetting::Channel || cc > setting.max() {
            return;
        }
        for other in MidiSetting::all().filter(|&other| other != MidiSetting::Channel) {
            if other != setting && self.raw(other) == cc {
                self.set_raw(other, OFF);
            }
        }
        self.set_raw(setting, cc);
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
    Set(Control, f64),
}

/// The control value for a position 0…1 of the device.
fn device_value(control: Control, position: f64) -> f64 {
    let range = control.range();
    range.min + position.clamp(0.0, 1.0) * (range.max - range.min)
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
    pub fn feed(
        &mut self,
        map: &MidiMap,
        channel: u8,
        cc: u8,
        value: u8,
    ) -> Option<(Control, f64)> {
        if !map.listens_on(channel) || cc > 127 {
            return None;
        }
        let value = value.min(127);
        let tilt = Control::Tilt;
        if Some(cc) == map.cc[tilt] {
            return Some(match map.tilt_lsb {
                Some(_) => {
                    self.tilt_msb = Some(value);
                    (tilt, device_value(tilt, fourteen_bit(value, self.tilt_lsb)))
                }
                None => (tilt, device_value(tilt, value as f64 / 127.0)),
            });
        }
        if map.tilt_lsb.is_some() && Some(cc) == map.tilt_lsb {
            self.tilt_lsb = value;
            let msb = self.tilt_msb?;
            return Some((tilt, device_value(tilt, fourteen_bit(msb, value))));
        }
        let position = value as f64 / 127.0;
        Control::device_inputs()
            .map(|(control, _)| control)
            .find(|&control| control != tilt && Some(cc) == map.cc[control])
            .map(|control| (control, device_value(control, position)))
    }
}

fn fourteen_bit(msb: u8, lsb: u8) -> f64 {
    ((msb as u32) << 7 | lsb as u32) as f64 / 16383.0
}

/// Which controls currently follow a device (MIDI or OSC) rather than their parameter.
#[derive(Debug, Clone, Copy)]
pub struct Overrides {
    /// The parameter values when last seen; a change means the host moved the parameter.
    seen: PerControl<Option<f64>>,
    device: PerControl<Option<f64>>,
}

impl Default for Overrides {
    fn default() -> Self {
        Self {
            seen: PerControl::splat(None),
            device: PerControl::splat(None),
        }
    }
}

impl Overrides {
    /// Makes `control` follow the device at `value` until the host changes its parameter.
    pub fn set(&mut self, control: Control, value: f64) {
        self.device[control] = Some(value);
    }

    /// Drops every override: every control follows its parameter again.
    pub fn clear(&mut self) {
        self.device = PerControl::splat(None);
    }

    /// The values the engine should use, given the parameters' values.
    pub fn apply(&mut self, params: ControlValues) -> ControlValues {
        let mut out = params;
        for &control in Control::ALL {
            let param = params[control];
            if self.seen[control].is_some_and(|seen| seen.to_bits() != param.to_bits()) {
                self.device[control] = None;
            }
            self.seen[control] = Some(param);
            if let Some(value) = self.device[control] {
                out[control] = value;
            }
        }
        out
    }
}
