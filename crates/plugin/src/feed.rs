//! What the audio thread shows the editor: the bottle's state, a scope of the output and the last
//! units' envelopes. Written with relaxed atomics (no lock, no allocation after construction); a
//! reader may see a slot half-updated, which only matters for one frame of a drawing.

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

use atomic_float::{AtomicF32, AtomicF64};

use sake_glug_engine::{PerControl, UnitOnset};

/// Scope columns kept (each the min and max of [`SCOPE_COLUMN_S`] of output).
pub const SCOPE_COLUMNS: usize = 600;
/// Output time each scope column covers (s).
pub const SCOPE_COLUMN_S: f64 = 0.001;
/// Units whose envelopes are kept.
pub const UNIT_SLOTS: usize = 8;

#[derive(Default)]
pub struct UnitSlot {
    pub onset_s: AtomicF64,
    pub amplitude: [AtomicF32; 2],
    pub frequency_hz: [AtomicF32; 2],
    pub decay_per_s: [AtomicF32; 2],
    pub volume_ml: AtomicF32,
}

/// A copy of one unit's envelope parameters, for drawing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitView {
    /// Seconds since the unit started.
    pub age_s: f64,
    /// A1, A2: the components' amplitudes, before the output gain.
    pub amplitude: [f32; 2],
    /// f1_i, f2_i (Hz).
    pub frequency_hz: [f32; 2],
    /// B1_i, B2_i: amplitude decay rates (1/s).
    pub decay_per_s: [f32; 2],
    /// V_i: the residual volume at the unit's onset (ml).
    pub volume_ml: f32,
}

/// What the audio thread publishes for the editor (see the module documentation).
pub struct Feed {
    /// Residual volume V at the end of the last `process()` (ml).
    pub volume_ml: AtomicF32,
    /// Bottle capacity C (ml).
    pub capacity_ml: AtomicF32,
    /// The tilt the engine uses (the parameter's, or the MIDI device's).
    pub tilt_deg: AtomicF32,
    /// Each control's value as the engine plays it: the parameter's, or a MIDI or OSC device's
    /// where one drives the control, for the editor to show beside the parameter.
    pub played: PerControl<AtomicF32>,
    /// Seconds of output rendered since the plugin was activated.
    pub now_s: AtomicF64,
    /// Units started since the bottle's last reset.
    pub units_started: AtomicU64,
    scope_min: Box<[AtomicF32]>,
    scope_max: Box<[AtomicF32]>,
    scope_written: AtomicUsize,
    units: Box<[UnitSlot]>,
    units_written: AtomicUsize,
    /// Asks the editor's window to redraw; the audio thread calls it (a relaxed atomic store,
    /// real-time safe) only when something it shows has changed, so an idle editor costs
    /// nothing.
    #[cfg(feature = "editor")]
    pub repaint: nice_plug_egui::RepaintNotifier,
}

/// What the editor shows, in a form cheap to compare block by block: when it is unchanged,
/// the editor is not redrawn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Visible {
    /// Units started (new envelopes, a new glug on the bottle).
    pub units: u64,
    /// The residual volume (ml), as drawn.
    pub volume_ml: f32,
    /// The tilt (degrees), as drawn.
    pub tilt_deg: f32,
    /// Each control as played (a device's value shows beside its slider).
    pub played: PerControl<f32>,
    /// Whether the output was sounding: the scope moves.
    pub sounding: bool,
}

/// Nothing drawn yet.
impl Default for Visible {
    fn default() -> Self {
        Self {
            units: 0,
            volume_ml: 0.0,
            tilt_deg: 0.0,
            played: PerControl::from_fn(|_| 0.0),
            sounding: false,
        }
    }
}

impl Visible {
    /// Whether the editor must be redrawn to show `self` after having shown `before`: when
    /// anything it draws moved, or while the output sounds (the scope scrolls).
    pub fn needs_redraw_after(self, before: Visible) -> bool {
        self != before || self.sounding
    }
}

impl Default for Feed {
    fn default() -> Self {
        let columns = || (0..SCOPE_COLUMNS).map(|_| AtomicF32::new(0.0)).collect();
        Self {
            volume_ml: AtomicF32::new(0.0),
            capacity_ml: AtomicF32::new(300.0),
            tilt_deg: AtomicF32::new(0.0),
            played: PerControl::from_fn(|_| AtomicF32::new(0.0)),
            now_s: AtomicF64::new(0.0),
            units_started: AtomicU64::new(0),
            scope_min: columns(),
            scope_max: columns(),
            scope_written: AtomicUsize::new(0),
            units: (0..UNIT_SLOTS).map(|_| UnitSlot::default()).collect(),
            units_written: AtomicUsize::new(0),
            #[cfg(feature = "editor")]
            repaint: nice_plug_egui::RepaintNotifier::new(),
        }
    }
}

impl Feed {
    /// Called by the audio thread after each block with what the editor would now show, and
    /// what it showed after the last block: asks for a redraw only if it must.
    pub fn publish(&self, now: Visible, before: Visible) {
        if now.needs_redraw_after(before) {
            #[cfg(feature = "editor")]
            self.repaint.request_repaint();
        }
    }

    /// Records a unit that started at `onset_s` (s, on the clock of `now_s`), in place of the
    /// oldest one kept.
    pub fn push_unit(&self, onset_s: f64, unit: &UnitOnset) {
        let index = self.units_written.load(Ordering::Relaxed);
        let slot = &self.units[index % UNIT_SLOTS];
        let amplitudes = unit.component_amplitudes();
        slot.onset_s.store(onset_s, Ordering::Relaxed);
        for (k, amplitude) in amplitudes.into_iter().enumerate() {
            slot.amplitude[k].store(amplitude as f32, Ordering::Relaxed);
            slot.frequency_hz[k].store(unit.shape.frequency_hz[k] as f32, Ordering::Relaxed);
            slot.decay_per_s[k].store(unit.shape.decay_per_s[k] as f32, Ordering::Relaxed);
        }
        slot.volume_ml
            .store(unit.volume_ml as f32, Ordering::Relaxed);
        self.units_written
            .store(index.wrapping_add(1), Ordering::Release);
    }

    /// The last units, newest first.
    pub fn units(&self) -> impl Iterator<Item = UnitView> + '_ {
        let written = self.units_written.load(Ordering::Acquire);
        let now = self.now_s.load(Ordering::Relaxed);
        (0..written.min(UNIT_SLOTS)).map(move |back| {
            let slot = &self.units[(written - 1 - back) % UNIT_SLOTS];
            let load2 = |pair: &[AtomicF32; 2]| {
                [
                    pair[0].load(Ordering::Relaxed),
                    pair[1].load(Ordering::Relaxed),
                ]
            };
            UnitView {
                age_s: now - slot.onset_s.load(Ordering::Relaxed),
                amplitude: load2(&slot.amplitude),
                frequency_hz: load2(&slot.frequency_hz),
                decay_per_s: load2(&slot.decay_per_s),
                volume_ml: slot.volume_ml.load(Ordering::Relaxed),
            }
        })
    }

    fn push_scope_column(&self, min: f32, max: f32) {
        let index = self.scope_written.load(Ordering::Relaxed);
        self.scope_min[index % SCOPE_COLUMNS].store(min, Ordering::Relaxed);
        self.scope_max[index % SCOPE_COLUMNS].store(max, Ordering::Relaxed);
        self.scope_written
            .store(index.wrapping_add(1), Ordering::Release);
    }

    /// The scope's columns `(min, max)`, oldest first.
    pub fn scope(&self) -> impl Iterator<Item = (f32, f32)> + '_ {
        let written = self.scope_written.load(Ordering::Acquire);
        let start = written.saturating_sub(SCOPE_COLUMNS);
        (start..written).map(move |index| {
            let slot = index % SCOPE_COLUMNS;
            (
                self.scope_min[slot].load(Ordering::Relaxed),
                self.scope_max[slot].load(Ordering::Relaxed),
            )
        })
    }
}

/// The audio thread's side of the scope: folds samples into min/max columns.
#[derive(Debug, Clone, Copy)]
pub struct ScopeWriter {
    samples_per_column: usize,
    count: usize,
    min: f32,
    max: f32,
}

impl ScopeWriter {
    pub fn new(sample_rate: f64) -> Self {
        Self {
            samples_per_column: ((sample_rate * SCOPE_COLUMN_S).round() as usize).max(1),
            count: 0,
            min: 0.0,
            max: 0.0,
        }
    }

    pub fn write(&mut self, feed: &Feed, samples: &[f32]) {
        for &sample in samples {
            self.min = self.min.min(sample);
            self.max = self.max.max(sample);
            self.count += 1;
            if self.count == self.samples_per_column {
                feed.push_scope_column(self.min, self.max);
                *self = Self::new_column(self.samples_per_column);
            }
        }
    }

    fn new_column(samples_per_column: usize) -> Self {
        Self {
            samples_per_column,
            count: 0,
            min: 0.0,
            max: 0.0,
        }
    }
}
