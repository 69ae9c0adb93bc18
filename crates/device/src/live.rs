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

use sake_glug_engine::{Control, PerControl};

/// Each control as a live input last set it, and how many refills it asked for.
#[derive(Debug)]
pub struct LiveControls {
    /// f64 bits of each control.
    values: PerControl<AtomicU64>,
    /// How many times each control was set.
    changes: PerControl<AtomicU64>,
    refills: AtomicU64,
}

impl Default for LiveControls {
    fn default() -> Self {
        Self {
            values: PerControl::from_fn(|_| AtomicU64::new(0)),
            changes: PerControl::from_fn(|_| AtomicU64::new(0)),
            refills: AtomicU64::new(0),
        }
    }
}

impl LiveControls {
    /// Sets `control` to `value`, clamped to the control's range (a NaN is ignored).
    pub fn set(&self, control: Control, value: f64) {
        if value.is_nan() {
            return;
        }
        let range = control.range();
        let value = value.clamp(range.min, range.max);
        self.values[control].store(value.to_bits(), Ordering::Relaxed);
        self.changes[control].fetch_add(1, Ordering::Release);
    }

    /// Asks for one refill of the bottle (MODEL.md §8).
    pub fn refill(&self) {
        self.refills.fetch_add(1, Ordering::Release);
    }

    /// How many times `control` has been set.
    pub fn changes(&self, control: Control) -> u64 {
        self.changes[control].load(Ordering::Acquire)
    }

    /// The last value of `control`, if it was ever set.
    pub fn value(&self, control: Control) -> Option<f64> {
        (self.changes(control) > 0)
            .then(|| f64::from_bits(self.values[control].load(Ordering::Relaxed)))
    }

    /// How many refills were asked for.
    pub fn refills(&self) -> u64 {
        self.refills.load(Ordering::Acquire)
    }
}

/// What changed since a [`LiveReader`] last looked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LiveChanges {
    /// The new value of each control, where one came.
    pub values: PerControl<Option<f64>>,
    /// Whether at least one refill was asked for (several in between count as one: the bottle
    /// is full after the first).
    pub refill: bool,
}

impl Default for LiveChanges {
    /// Nothing changed.
    fn default() -> Self {
        Self {
            values: PerControl::splat(None),
            refill: false,
        }
    }
}

impl LiveChanges {
    /// Each new value with its control.
    pub fn set_values(&self) -> impl Iterator<Item = (Control, f64)> + '_ {
        self.values
            .iter()
            .filter_map(|(control, value)| Some((control, value?)))
    }
}

/// The audio thread's side: remembers what it has already applied.
#[derive(Debug, Clone, Copy)]
pub struct LiveReader {
    seen: PerControl<u64>,
    refills_seen: u64,
}

impl Default for LiveReader {
    fn default() -> Self {
        Self {
            seen: PerControl::splat(0),
            refills_seen: 0,
        }
    }
}

impl LiveReader {
    /// What changed since the last call; real-time safe (atomic loads only).
    pub fn poll(&mut self, live: &LiveControls) -> LiveChanges {
        let mut changes = LiveChanges::default();
        for &control in Control::ALL {
            let count = live.changes(control);
            if count != self.seen[control] {
                self.seen[control] = count;
                changes.values[control] =
                    Some(f64::from_bits(live.values[control].load(Ordering::Relaxed)));
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
