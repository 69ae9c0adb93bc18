//! MIDI learn: the user arms one of the MIDI panel's rows (the editor's "Learn" button, or the
//! standalone app's `--learn`), and the next CC the device sends is taken for that row, with
//! its channel. Atomics only, so that `process()` takes the CC without a lock or an allocation.

use std::sync::atomic::{AtomicU32, AtomicU8, Ordering};

use sake_glug_device::midi::{MidiMap, MidiSetting};
use sake_glug_engine::Control;

/// No row is armed.
const DISARMED: u8 = u8::MAX;

/// Which row of the MIDI panel waits for a CC, shared by the editor, the app and the audio
/// thread. Not saved with the state: a learn in progress is not part of a project.
#[derive(Debug)]
pub struct MidiLearn {
    /// The armed row's index in [`MidiSetting::all`], or [`DISARMED`].
    armed: AtomicU8,
    /// The last CC learnt, for whoever reports it (the app prints it): 0 until one is, then
    /// `1 << 24 | row << 16 | channel << 8 | cc`.
    learnt: AtomicU32,
}

impl Default for MidiLearn {
    fn default() -> Self {
        Self {
            armed: AtomicU8::new(DISARMED),
            learnt: AtomicU32::new(0),
        }
    }
}

/// One CC learnt: the row, and the channel and CC it took.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Learnt {
    /// The row that took the CC.
    pub setting: MidiSetting,
    /// The device's channel, 0–15.
    pub channel: u8,
    /// The CC number, 0–127.
    pub cc: u8,
}

impl std::fmt::Display for Learnt {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} = CC {} on channel {}",
            self.setting.label(),
            self.cc,
            self.channel + 1
        )
    }
}

/// A row that can learn a CC: every row of the panel but the channel (which each learnt CC sets).
pub fn learnable(setting: MidiSetting) -> bool {
    setting != MidiSetting::Channel
}

fn index_of(setting: MidiSetting) -> u8 {
    MidiSetting::all()
        .position(|other| other == setting)
        .map_or(DISARMED, |index| index as u8)
}

fn setting_at(index: u8) -> Option<MidiSetting> {
    MidiSetting::all().nth(index as usize)
}

impl MidiLearn {
    /// Waits for the next CC for `setting` (a row that cannot learn is ignored).
    pub fn arm(&self, setting: MidiSetting) {
        if learnable(setting) {
            self.armed.store(index_of(setting), Ordering::Release);
        }
    }

    /// Stops waiting; the map stays as it was.
    pub fn cancel(&self) {
        self.armed.store(DISARMED, Ordering::Release);
    }

    /// The row waiting for a CC, if any.
    pub fn armed(&self) -> Option<MidiSetting> {
        setting_at(self.armed.load(Ordering::Acquire))
    }

    /// The audio thread's side: if a row is armed, it takes this CC (once: the row is disarmed
    /// in the same atomic step, so a cancel that comes first wins), and `map` learns it.
    /// Returns what was learnt. Atomic accesses only: real-time safe.
    pub fn take(&self, map: &mut MidiMap, channel: u8, cc: u8) -> Option<Learnt> {
        let index = self.armed.load(Ordering::Acquire);
        let setting = setting_at(index)?;
        // A 14-bit device sends tilt's MSB before its LSB: the LSB row waits past the MSB.
        if setting == MidiSetting::TiltLsb && map.cc[Control::Tilt] == Some(cc) {
            return None;
        }
        self.armed
            .compare_exchange(index, DISARMED, Ordering::AcqRel, Ordering::Acquire)
            .ok()?;
        map.learn(setting, channel, cc);
        self.learnt.store(
            1 << 24 | u32::from(index) << 16 | u32::from(channel) << 8 | u32::from(cc),
            Ordering::Release,
        );
        Some(Learnt {
            setting,
            channel,
            cc,
        })
    }

    /// The last CC learnt in this session, if any.
    pub fn last_learnt(&self) -> Option<Learnt> {
        let packed = self.learnt.load(Ordering::Acquire);
        if packed >> 24 == 0 {
            return None;
        }
        Some(Learnt {
            setting: setting_at((packed >> 16) as u8)?,
            channel: (packed >> 8) as u8,
            cc: packed as u8,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_armed_row_takes_one_cc_and_its_channel() {
        let learn = MidiLearn::default();
        let mut map = MidiMap::default();
        assert_eq!(learn.take(&mut map, 2, 20), None, "nothing armed");
        assert_eq!(map, MidiMap::default());
        learn.arm(MidiSetting::Cc(Control::Tilt));
        let learnt = learn.take(&mut map, 3, 20).expect("armed");
        assert_eq!(map.cc[Control::Tilt], Some(20));
        assert_eq!(map.channel, Some(3));
        assert_eq!(learn.armed(), None, "one CC only");
        assert_eq!(learn.last_learnt(), Some(learnt));
        assert_eq!(learnt.to_string(), "Tilt CC (MSB) = CC 20 on channel 4");
        assert_eq!(learn.take(&mut map, 3, 21), None);
    }

    #[test]
    fn the_lsb_row_waits_past_tilts_msb() {
        let learn = MidiLearn::default();
        let mut map = MidiMap::default();
        learn.arm(MidiSetting::TiltLsb);
        assert_eq!(learn.take(&mut map, 0, 16), None, "CC 16 is tilt's MSB");
        assert_eq!(learn.armed(), Some(MidiSetting::TiltLsb));
        assert!(learn.take(&mut map, 0, 52).is_some());
        assert_eq!((map.cc[Control::Tilt], map.tilt_lsb), (Some(16), Some(52)));
    }

    #[test]
    fn a_cancel_leaves_the_map_and_the_channel_row_cannot_be_armed() {
        let learn = MidiLearn::default();
        let mut map = MidiMap::default();
        learn.arm(MidiSetting::Cc(Control::Viscosity));
        learn.cancel();
        assert_eq!(learn.take(&mut map, 0, 30), None);
        learn.arm(MidiSetting::Channel);
        assert_eq!(learn.armed(), None);
        assert_eq!(map, MidiMap::default());
    }
}
