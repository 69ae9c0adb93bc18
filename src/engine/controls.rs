//! The per-sample inputs of a block: each a constant or one value per sample.

use super::config::{ControlValues, GAIN_DB};

/// The model's inputs as a function of the sample index: how the reference and the timed
/// renders read a scene, sample by sample.
pub trait ControlSource {
    /// The inputs and the output gain in dB at `sample`.
    fn at(&self, sample: u64) -> (ControlValues, f64);
}

impl<F: Fn(u64) -> (ControlValues, f64)> ControlSource for F {
    fn at(&self, sample: u64) -> (ControlValues, f64) {
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

/// The automatable inputs of the model for one block (MODEL.md §1, §5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Controls<'a> {
    /// Tilt θ (degrees).
    pub tilt_deg: Lane<'a>,
    /// Viscosity ratio c.
    pub viscosity: Lane<'a>,
    /// Fill level φ (percent of capacity).
    pub fill_percent: Lane<'a>,
    /// Pour time T (s).
    pub pour_time_s: Lane<'a>,
    /// Output gain (dB).
    pub gain_db: Lane<'a>,
}

impl Default for Controls<'_> {
    fn default() -> Self {
        Self::constant(ControlValues::default(), GAIN_DB.default)
    }
}

impl<'a> Controls<'a> {
    /// Controls held at `values` and `gain_db` for the whole block.
    pub fn constant(values: ControlValues, gain_db: f64) -> Self {
        Self {
            tilt_deg: Lane::Constant(values.tilt_deg),
            viscosity: Lane::Constant(values.viscosity),
            fill_percent: Lane::Constant(values.fill_percent),
            pour_time_s: Lane::Constant(values.pour_time_s),
            gain_db: Lane::Constant(gain_db),
        }
    }

    /// The values the model sees at sample `index` of the block.
    #[inline]
    pub fn values_at(&self, index: usize) -> ControlValues {
        ControlValues {
            tilt_deg: self.tilt_deg.at(index),
            viscosity: self.viscosity.at(index),
            fill_percent: self.fill_percent.at(index),
            pour_time_s: self.pour_time_s.at(index),
        }
    }

    /// Whether the pour inputs are constant over the block (the output gain aside).
    pub fn pour_is_constant(&self) -> bool {
        self.tilt_deg.is_constant()
            && self.viscosity.is_constant()
            && self.fill_percent.is_constant()
            && self.pour_time_s.is_constant()
    }

    /// Whether the pour inputs hold the very same values over the first `len` samples, as
    /// constants or as samples that do not change (the output gain aside).
    pub fn pour_is_constant_over(&self, len: usize) -> bool {
        self.tilt_deg.is_constant_over(len)
            && self.viscosity.is_constant_over(len)
            && self.fill_percent.is_constant_over(len)
            && self.pour_time_s.is_constant_over(len)
    }

    /// A block of the same controls starting `offset` samples later.
    pub fn offset(&self, offset: usize) -> Self {
        let shift = |lane: Lane<'a>| match lane {
            Lane::Samples(values) if offset < values.len() => Lane::Samples(&values[offset..]),
            Lane::Samples(values) => Lane::Constant(values.last().copied().unwrap_or(f64::NAN)),
            constant => constant,
        };
        Self {
            tilt_deg: shift(self.tilt_deg),
            viscosity: shift(self.viscosity),
            fill_percent: shift(self.fill_percent),
            pour_time_s: shift(self.pour_time_s),
            gain_db: shift(self.gain_db),
        }
    }
}
