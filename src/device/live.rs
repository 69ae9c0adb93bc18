//! The latest values a live input (OSC) has set, shared with the audio thread without locks.
//!
//! One thread writes ([`LiveControls::set`], [`LiveControls::refill`]); the audio thread reads
//! with a [`LiveReader`], which only loads atomics: no lock, no allocation, no system call. Each
//! control has a sequence number that the writer bumps after storing the value, so the reader
//! sees that a value is new even when it equals the old one (a phone that sends the same tilt
//! again takes the control back from the parameter, as a repeated MIDI CC does). The reader may
//! see a newer value before its sequence number; it then applies that value twice, which is
//! harmless.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::device::midi::Target;
use crate::engine::config::{Range, FILL_PERCENT, TILT_DEG, VISCOSITY};

const TARGETS: [Target; 3] = [Target::Tilt, Target::Viscosity, Target::Fill];

fn range(target: Target) -> Range {
    match target {
        Target::Tilt => TILT_DEG,
        Target::Viscosity => VISCOSITY,
        Target::Fill => FILL_PERCENT,
    }
}

/// Tilt, viscosity and fill as a live input last set them, and how many refills it asked for.
#[derive(Debug, Default)]
pub struct LiveControls {
    /// f64 bits of each control, in the order of [`Target`].
    values: [AtomicU64; 3],
    /// How many times each control was set.
    changes: [AtomicU64; 3],
    refills: AtomicU64,
}

impl LiveControls {
    /// Sets `target` to `value`, clamped to the control's range (a NaN is ignored).
    pub fn set(&self, target: Target, value: f64) {
        if value.is_nan() {
            return;
        }
        let range = range(target);
        let value = value.clamp(range.min, range.max);
        let index = target as usize;
        self.values[index].store(value.to_bits(), Ordering::Relaxed);
        self.changes[index].fetch_add(1, Ordering::Release);
    }

    /// Asks for one refill of the bottle (MODEL.md §8).
    pub fn refill(&self) {
        self.refills.fetch_add(1, Ordering::Release);
    }

    /// How many times `target` has been set.
    pub fn changes(&self, target: Target) -> u64 {
        self.changes[target as usize].load(Ordering::Acquire)
    }

    /// The last value of `target`, if it was ever set.
    pub fn value(&self, target: Target) -> Option<f64> {
        (self.changes(target) > 0)
            .then(|| f64::from_bits(self.values[target as usize].load(Ordering::Relaxed)))
    }

    /// How many refills were asked for.
    pub fn refills(&self) -> u64 {
        self.refills.load(Ordering::Acquire)
    }
}

/// What changed since a [`LiveReader`] last looked.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LiveChanges {
    /// The new value of tilt, viscosity and fill (in the order of [`Target`]), where one came.
    pub values: [Option<f64>; 3],
    /// Whether at least one refill was asked for (several in between count as one: the bottle
    /// is full after the first).
    pub refill: bool,
}

impl LiveChanges {
    /// Each new value with its control.
    pub fn set_values(&self) -> impl Iterator<Item = (Target, f64)> + '_ {
        TARGETS
            .into_iter()
            .zip(self.values)
            .filter_map(|(target, value)| Some((target, value?)))
    }
}

/// The audio thread's side: remembers what it has already applied.
#[derive(Debug, Clone, Copy, Default)]
pub struct LiveReader {
    seen: [u64; 3],
    refills_seen: u64,
}

impl LiveReader {
    /// What changed since the last call; real-time safe (atomic loads only).
    pub fn poll(&mut self, live: &LiveControls) -> LiveChanges {
        let mut changes = LiveChanges::default();
        for target in TARGETS {
            let index = target as usize;
            let count = live.changes(target);
            if count != self.seen[index] {
                self.seen[index] = count;
                changes.values[index] =
                    Some(f64::from_bits(live.values[index].load(Ordering::Relaxed)));
            }
        }
        let refills = live.refills();
        if refills != self.refills_seen {
            self.refills_seen = refills;
            changes.refill = true;
        }
        changes
    }
}
