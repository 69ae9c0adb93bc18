//! The model's automatable inputs, each declared once in [`declare_controls!`]'s table below: its
//! scene key, plugin parameter id, display name and unit, range and default, knob, and the
//! device (MIDI CC, OSC address) that may drive it. Every per-control array in the code is a
//! [`PerControl`], indexable by [`Control`], and scene parsing, automation lanes, the plugin's
//! parameters, MIDI and OSC targets, live overrides, presets and the reports read this table.

use std::ops::{Index, IndexMut};

use super::quantity::{Knob, Quantity, Range};

/// How a tilt device reaches a control: the MIDI setting that names its CC, and its OSC address.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DeviceInput {
    /// The saved MIDI setting (plugin state and a scene's `[midi]` table) holding its CC number.
    pub midi_setting: &'static str,
    /// The CC number it listens to by default (a general-purpose controller).
    pub default_cc: u8,
    /// Its OSC address.
    pub osc_address: &'static str,
}

/// One automatable input, as every part of the product knows it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControlSpec {
    /// Name, scene key, parameter id, range, default and knob.
    pub quantity: Quantity,
    /// Whether it drives the pour (the output gain drives only the output stage, §6).
    pub drives_pour: bool,
    /// A tilt device's way in, where it has one.
    pub device: Option<DeviceInput>,
}

macro_rules! declare_controls {
    ($( $(#[$doc:meta])* $variant:ident, $field:ident => $spec:expr; )*) => {
        /// One automatable input of the model (MODEL.md §1, §6).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum Control {
            $( $(#[$doc])* $variant, )*
        }

        impl Control {
            /// Every control, in table order (the order of the plugin's main group).
            pub const ALL: &'static [Control] = &[$( Control::$variant ),*];

            /// Everything declared about this control.
            pub const fn spec(self) -> &'static ControlSpec {
                static SPECS: &[ControlSpec] = &[$( $spec ),*];
                &SPECS[self as usize]
            }
        }

        /// One `T` per [`Control`], by name or indexed by the control.
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub struct PerControl<T> {
            $( $(#[$doc])* pub $field: T, )*
        }

        impl<T> PerControl<T> {
            /// Each control's value from `value_of`.
            #[inline]
            pub fn from_fn(mut value_of: impl FnMut(Control) -> T) -> Self {
                Self { $( $field: value_of(Control::$variant), )* }
            }

            /// Each control's value, taken by value through `map`.
            #[inline]
            pub fn into_map<U>(self, mut map: impl FnMut(Control, T) -> U) -> PerControl<U> {
                PerControl { $( $field: map(Control::$variant, self.$field), )* }
            }

            /// A mutable reference to each control's value.
            #[inline]
            pub fn each_mut(&mut self) -> PerControl<&mut T> {
                PerControl { $( $field: &mut self.$field, )* }
            }
        }

        impl<T> Index<Control> for PerControl<T> {
            type Output = T;
            #[inline]
            fn index(&self, control: Control) -> &T {
                match control {
                    $( Control::$variant => &self.$field, )*
                }
            }
        }

        impl<T> IndexMut<Control> for PerControl<T> {
            #[inline]
            fn index_mut(&mut self, control: Control) -> &mut T {
                match control {
                    $( Control::$variant => &mut self.$field, )*
                }
            }
        }
    };
}

declare_controls! {
    /// Tilt θ (degrees): 0 upright, 90 horizontal, 180 upside down.
    Tilt, tilt_deg => ControlSpec {
        quantity: Quantity {
            name: "Tilt",
            unit: "°",
            scene_key: "tilt_deg",
            param_id: "tilt",
            note: "0 upright, 90 horizontal, 180 upside down",
            range: Range::new(0.0, 180.0, 0.0),
            knob: Knob::full(2),
        },
        drives_pour: true,
        device: Some(DeviceInput {
            midi_setting: "midi_cc_tilt",
            default_cc: 16,
            osc_address: "/sakeglug/tilt",
        }),
    };
    /// Viscosity ratio c (0…1): the share of the f1 component; water 0.33.
    Viscosity, viscosity => ControlSpec {
        quantity: Quantity {
            name: "Viscosity",
            unit: "",
            scene_key: "viscosity_c",
            param_id: "visc",
            note: "c: share of the f1 component; water 0.33",
            range: Range::new(0.0, 1.0, 0.33),
            knob: Knob::full(3),
        },
        drives_pour: true,
        device: Some(DeviceInput {
            midi_setting: "midi_cc_viscosity",
            default_cc: 17,
            osc_address: "/sakeglug/viscosity",
        }),
    };
    /// Fill level φ (percent of capacity C) that the bottle is (re)filled to.
    Fill, fill_percent => ControlSpec {
        quantity: Quantity {
            name: "Fill level",
            unit: " %",
            scene_key: "fill_percent",
            param_id: "fill",
            note: "the level a refill or reset fills to",
            range: Range::new(0.0, 100.0, 100.0),
            knob: Knob::full(1),
        },
        drives_pour: true,
        device: Some(DeviceInput {
            midi_setting: "midi_cc_fill",
            default_cc: 18,
            osc_address: "/sakeglug/fill",
        }),
    };
    /// Pour time T (s): how long a full bottle takes to empty at the reference tilt 135°.
    PourTime, pour_time_s => ControlSpec {
        quantity: Quantity {
            name: "Pour time",
            unit: " s",
            scene_key: "pour_time_s",
            param_id: "pour",
            note: "seconds to empty a full bottle at 135°",
            range: Range::new(0.01, 3600.0, 5.0),
            // Below 0.1 s or above 2 minutes is no pour.
            knob: Knob::full(2).within(0.1, 120.0).skewed(-1.5),
        },
        drives_pour: true,
        device: None,
    };
    /// Output gain (dB): G = 10^(gain/20).
    Gain, gain_db => ControlSpec {
        quantity: Quantity {
            name: "Output gain",
            unit: " dB",
            scene_key: "output.gain_db",
            param_id: "gain",
            note: "G = 10^(gain/20), ramped over 10 ms (MODEL.md §6)",
            range: Range::new(-120.0, 24.0, -6.0),
            // The engine's whole range would make the knob coarse.
            knob: Knob::full(2).within(-60.0, 12.0),
        },
        drives_pour: false,
        device: None,
    };
}

impl Control {
    /// The control's name, scene key, parameter id, range and knob.
    pub const fn quantity(self) -> &'static Quantity {
        &self.spec().quantity
    }

    /// The control's allowed range and default.
    pub const fn range(self) -> Range {
        self.spec().quantity.range
    }

    /// The controls that drive the pour (all but the output gain).
    pub fn pour() -> impl Iterator<Item = Control> {
        POUR_CONTROLS.iter().copied()
    }

    /// The controls a tilt device can set, with how it reaches them.
    pub fn device_inputs() -> impl Iterator<Item = (Control, &'static DeviceInput)> {
        Control::ALL
            .iter()
            .filter_map(|&control| Some((control, control.spec().device.as_ref()?)))
    }
}

/// The controls that drive the pour, picked from the table at compile time: a loop over them
/// unrolls to one check per control, where filtering the table at run time cost a check of each
/// control's spec in every span (the engine compares the pour's inputs once a span).
const POUR_CONTROLS: [Control; pour_control_count()] = {
    let mut pour = [Control::Tilt; pour_control_count()];
    let (mut index, mut taken) = (0, 0);
    while index < Control::ALL.len() {
        if Control::ALL[index].spec().drives_pour {
            pour[taken] = Control::ALL[index];
            taken += 1;
        }
        index += 1;
    }
    pour
};

/// How many controls drive the pour.
const fn pour_control_count() -> usize {
    let (mut index, mut count) = (0, 0);
    while index < Control::ALL.len() {
        if Control::ALL[index].spec().drives_pour {
            count += 1;
        }
        index += 1;
    }
    count
}

impl<T: Copy> PerControl<T> {
    /// The same value for every control.
    pub fn splat(value: T) -> Self {
        Self::from_fn(|_| value)
    }

    /// Each value through `map`.
    #[inline]
    pub fn map<U>(&self, mut map: impl FnMut(Control, T) -> U) -> PerControl<U> {
        PerControl::from_fn(|control| map(control, self[control]))
    }

    /// Each control with its value, in table order.
    pub fn iter(&self) -> impl Iterator<Item = (Control, T)> + '_ {
        Control::ALL.iter().map(|&control| (control, self[control]))
    }
}

/// The inputs of the model as one sample sees them (MODEL.md §1, §6).
pub type ControlValues = PerControl<f64>;

impl Default for ControlValues {
    /// Every control at its default.
    fn default() -> Self {
        Self::from_fn(|control| control.range().default)
    }
}

impl ControlValues {
    /// Every value brought into its range (see [`Range::sanitize`]).
    #[inline]
    pub fn sanitized(self) -> Self {
        self.map(|control, value| control.range().sanitize(value))
    }

    /// Whether the controls that drive the pour are equal to those of `other` (the output gain
    /// aside).
    #[inline]
    pub fn same_pour_as(&self, other: &Self) -> bool {
        Control::pour().all(|control| self[control] == other[control])
    }
}

/// The model's inputs as a function of the sample index: how the reference and the timed
/// renders read a scene, sample by sample.
pub trait ControlSource {
    /// The inputs (the output gain in dB among them) at `sample`.
    fn at(&self, sample: u64) -> ControlValues;
}

impl<F: Fn(u64) -> ControlValues> ControlSource for F {
    fn at(&self, sample: u64) -> ControlValues {
        self(sample)
    }
}

/// One automatable input over a block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Lane<'a> {
    /// The same value at every sample of the block.
    Constant(f64),
    /// One value per sample of the block; a lane shorter than the block holds its last value.
    Samples(&'a [f64]),
}

impl Lane<'_> {
    /// The value at sample `index` of the block.
    #[inline]
    pub fn at(&self, index: usize) -> f64 {
        match *self {
            Lane::Constant(value) => value,
            Lane::Samples(values) => match values.get(index) {
                Some(&value) => value,
                None => values.last().copied().unwrap_or(f64::NAN),
            },
        }
    }

    /// Whether the lane is a [`Lane::Constant`].
    pub fn is_constant(&self) -> bool {
        matches!(self, Lane::Constant(_))
    }

    /// Whether the lane has the very same value (bit for bit) at every one of its first `len`
    /// samples: a constant, or samples that do not change over them.
    #[inline]
    pub fn is_constant_over(&self, len: usize) -> bool {
        match *self {
            Lane::Constant(_) => true,
            Lane::Samples(values) => match values.first() {
                Some(first) => values[..len.min(values.len())]
                    .iter()
                    .all(|value| value.to_bits() == first.to_bits()),
                None => true,
            },
        }
    }
}

/// A lane's straight line between two automation points `(time_s, value)` (MODEL.md §10): the
/// one interpolation that a scene's lanes and the C library's ramps both compute, so that a ramp
/// gives the samples of the two-point lane it stands for, bit for bit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearSegment {
    /// The earlier point.
    pub start: (f64, f64),
    /// The later point; at its time and after, the lane holds its value.
    pub end: (f64, f64),
}

impl LinearSegment {
    /// The value on the line at `time_s`, for a time from the start's up to (not at) the end's.
    #[inline]
    pub fn value_at(&self, time_s: f64) -> f64 {
        let ((t0, v0), (t1, v1)) = (self.start, self.end);
        v0 + (v1 - v0) * (time_s - t0) / (t1 - t0)
    }
}

/// The time of sample `sample` (s) at `sample_rate` (Hz): the time a lane is read at.
#[inline]
pub fn sample_time_s(sample: u64, sample_rate: f64) -> f64 {
    sample as f64 / sample_rate
}

/// The automatable inputs of the model for one block (MODEL.md §1, §5, §6).
pub type Controls<'a> = PerControl<Lane<'a>>;

impl Default for Controls<'_> {
    fn default() -> Self {
        Self::constant(ControlValues::default())
    }
}

impl<'a> Controls<'a> {
    /// Controls held at `values` for the whole block.
    pub fn constant(values: ControlValues) -> Self {
        values.map(|_, value| Lane::Constant(value))
    }

    /// The values the model sees at sample `index` of the block.
    #[inline]
    pub fn values_at(&self, index: usize) -> ControlValues {
        self.map(|_, lane| lane.at(index))
    }

    /// Whether the pour inputs are constant over the block (the output gain aside).
    pub fn pour_is_constant(&self) -> bool {
        Control::pour().all(|control| self[control].is_constant())
    }

    /// Whether the pour inputs hold the very same values over the first `len` samples, as
    /// constants or as samples that do not change (the output gain aside).
    pub fn pour_is_constant_over(&self, len: usize) -> bool {
        Control::pour().all(|control| self[control].is_constant_over(len))
    }

    /// Whether every lane, the output gain's too, is a [`Lane::Constant`]: then the block is the
    /// same from any of its samples on.
    #[inline]
    pub fn is_constant(&self) -> bool {
        Control::ALL
            .iter()
            .all(|&control| self[control].is_constant())
    }

    /// A block of the same controls starting `offset` samples later.
    pub fn offset(&self, offset: usize) -> Self {
        self.map(|_, lane| match lane {
            Lane::Samples(values) if offset < values.len() => Lane::Samples(&values[offset..]),
            Lane::Samples(values) => Lane::Constant(values.last().copied().unwrap_or(f64::NAN)),
            constant => constant,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_control_is_indexed_by_its_own_field() {
        let values = ControlValues::from_fn(|control| control as usize as f64);
        for (index, &control) in Control::ALL.iter().enumerate() {
            assert_eq!(values[control], index as f64);
        }
        assert_eq!(values.viscosity, Control::Viscosity as usize as f64);
    }

    #[test]
    fn keys_and_ids_are_unique() {
        for (index, a) in Control::ALL.iter().enumerate() {
            for b in &Control::ALL[index + 1..] {
                assert_ne!(a.quantity().scene_key, b.quantity().scene_key);
                assert_ne!(a.quantity().param_id, b.quantity().param_id);
            }
        }
    }
}
