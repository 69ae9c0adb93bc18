//! Starting points for a sound designer: a liquid (its viscosity ratio c) and a bottle (its
//! size, pocket, pour time and the frequencies and decays of its glug). The plugin's editor
//! offers them in its preset menu and the command line as scene files under `presets/`.
//!
//! The liquids follow the paper: water is c = 0.33, and its perceived-viscosity thresholds lie
//! at c = 0.29 (25 %: felt as thinner than water) and c = 0.42 (75 %: felt as thicker). The
//! bottles keep the model's shape and scale it: a smaller bottle glugs higher, faster and with
//! smaller pockets; those values are chosen by ear, not measured.

use super::config::{ControlValues, ModelConfig};

/// A named set of constants and inputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Preset {
    /// The name shown in menus.
    pub name: &'static str,
    /// A file-name-safe identifier (`presets/<id>.toml`).
    pub id: &'static str,
    /// What it is for.
    pub description: &'static str,
    /// Viscosity ratio c.
    pub viscosity: f64,
    /// Bottle capacity C (ml).
    pub capacity_ml: f64,
    /// Air pocket per glug b (ml).
    pub pocket_ml: f64,
    /// Time to empty a full bottle at 135° (s).
    pub pour_time_s: f64,
    /// f1 and f2 (Hz).
    pub frequency_hz: [f64; 2],
    /// B1 and B2 (1/s).
    pub decay_per_s: [f64; 2],
}

/// The 300 ml bottle of the paper with its measured glug.
const PAPER_BOTTLE: Preset = Preset {
    name: "Water",
    id: "water",
    description: "c = 0.33 in the paper's 300 ml bottle",
    viscosity: 0.33,
    capacity_ml: 300.0,
    pocket_ml: 5.0,
    pour_time_s: 5.0,
    frequency_hz: [80.0, 300.0],
    decay_per_s: [45.0, 40.0],
};

/// Every preset, in menu order.
pub const PRESETS: [Preset; 7] = [
    PAPER_BOTTLE,
    Preset {
        name: "Thin (c 0.29)",
        id: "thin",
        description: "a liquid felt as thinner than water: the paper's 25 % threshold, c = 0.29",
        viscosity: 0.29,
        ..PAPER_BOTTLE
    },
    Preset {
        name: "Sake",
        id: "sake",
        description: "a little more viscous than water (c = 0.36), poured a little slower",
        viscosity: 0.36,
        pour_time_s: 5.5,
        ..PAPER_BOTTLE
    },
    Preset {
        name: "Thick (c 0.42)",
        id: "thick",
        description: "a liquid felt as thicker than water: the paper's 75 % threshold, c = 0.42",
        viscosity: 0.42,
        pour_time_s: 7.0,
        ..PAPER_BOTTLE
    },
    Preset {
        name: "Syrup (c 0.6)",
        id: "syrup",
        description: "well past the 75 % threshold (c = 0.6): slow, low, heavy glugs",
        viscosity: 0.6,
        pour_time_s: 12.0,
        decay_per_s: [38.0, 34.0],
        ..PAPER_BOTTLE
    },
    Preset {
        name: "Small bottle",
        id: "small-bottle",
        description: "a one-gō (180 ml) tokkuri of water: higher, quicker, smaller glugs",
        capacity_ml: 180.0,
        pocket_ml: 3.0,
        pour_time_s: 3.5,
        frequency_hz: [100.0, 380.0],
        decay_per_s: [55.0, 50.0],
        ..PAPER_BOTTLE
    },
    Preset {
        name: "Large bottle",
        id: "large-bottle",
        description: "a four-gō (720 ml) bottle of water: lower, slower, bigger glugs",
        capacity_ml: 720.0,
        pocket_ml: 9.0,
        pour_time_s: 10.0,
        frequency_hz: [62.0, 230.0],
        decay_per_s: [36.0, 32.0],
        ..PAPER_BOTTLE
    },
];

impl Preset {
    /// The preset with this identifier.
    pub fn find(id: &str) -> Option<&'static Preset> {
        PRESETS.iter().find(|preset| preset.id == id)
    }

    /// The model's constants: the preset's, the rest (seed, spreads, drain) as `base` has them.
    pub fn config(&self, base: ModelConfig) -> ModelConfig {
        ModelConfig {
            capacity_ml: self.capacity_ml,
            pocket_ml: self.pocket_ml,
            frequency_hz: self.frequency_hz,
            decay_per_s: self.decay_per_s,
            ..base
        }
    }

    /// The inputs it sets (the tilt and fill level stay as `base` has them).
    pub fn controls(&self, base: ControlValues) -> ControlValues {
        ControlValues {
            viscosity: self.viscosity,
            pour_time_s: self.pour_time_s,
            ..base
        }
    }
}
