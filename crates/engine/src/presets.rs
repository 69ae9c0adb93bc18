//! Starting points for a sound designer: a liquid (its viscosity ratio c) and a bottle (its
//! size, pocket, pour time and the frequencies and decays of its glug). The plugin's editor
//! offers them in its preset menu and the command line as scene files under `presets/`.
//!
//! The liquids follow the paper: water is c = 0.33, and its perceived-viscosity thresholds lie
//! at c = 0.29 (25 %: felt as thinner than water) and c = 0.42 (75 %: felt as thicker). The two
//! threshold presets change c alone, keeping water's pour time, so that a study of them (or a
//! listener) meets one cue, not two; the liquids that also pour slower keep their own names. The
//! bottles keep the model's shape and scale it: a smaller bottle glugs higher, faster and with
//! smaller pockets; those values are chosen by ear, not measured.

use super::config::{Constant, ModelConfig};
use super::controls::{Control, ControlValues};

/// One value a preset sets: a control or a model constant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PresetValue {
    /// A control's value (held for the whole pour).
    Control(Control, f64),
    /// A model constant's value.
    Constant(Constant, f64),
}

/// A named set of values; everything it does not name keeps its default.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Preset {
    /// The name shown in menus.
    pub name: &'static str,
    /// A file-name-safe identifier (`presets/<id>.toml`).
    pub id: &'static str,
    /// What it is for.
    pub description: &'static str,
    /// What it sets, each value once.
    pub values: &'static [PresetValue],
}

use PresetValue::{Constant as K, Control as C};

/// The 300 ml bottle of the paper with its measured glug: every preset sets these, so that
/// picking one after another leaves nothing of the first.
const PAPER_BOTTLE: [PresetValue; 8] = [
    C(Control::Viscosity, 0.33),
    C(Control::PourTime, 5.0),
    K(Constant::Capacity, 300.0),
    K(Constant::Pocket, 5.0),
    K(Constant::F1, 80.0),
    K(Constant::F2, 300.0),
    K(Constant::B1, 45.0),
    K(Constant::B2, 40.0),
];

/// The paper's bottle with `changes` made to it.
const fn paper_bottle_with<const N: usize>(changes: [PresetValue; N]) -> [PresetValue; 8] {
    let mut values = PAPER_BOTTLE;
    let mut change = 0;
    while change < N {
        let mut slot = 0;
        while slot < values.len() {
            if same_target(values[slot], changes[change]) {
                values[slot] = changes[change];
            }
            slot += 1;
        }
        change += 1;
    }
    values
}

const fn same_target(a: PresetValue, b: PresetValue) -> bool {
    match (a, b) {
        (C(a, _), C(b, _)) => a as usize == b as usize,
        (K(a, _), K(b, _)) => a as usize == b as usize,
        _ => false,
    }
}

/// The constants of the rules the implementation added to the paper's model: the headspace law
/// (MODEL.md §5.1) and the glide (§5.2). The paper's bottle keeps its frequencies constant, so
/// its presets leave them out of their files; picked in a menu, a preset that names none of them
/// sets them to their defaults ([`Preset::menu_values`]).
pub const ADDED_RULES: [Constant; 7] = [
    Constant::Headspace,
    Constant::F1Exponent,
    Constant::F2Exponent,
    Constant::F1GlideRatio,
    Constant::F2GlideRatio,
    Constant::F1GlideTime,
    Constant::F2GlideTime,
];

/// A 720 ml glass bottle of water emptying: its neck and shoulder hold 60 ml of air when full, and
/// the air above the liquid rings as a Helmholtz cavity (γ1 = ½), from 190 Hz at the first glug
/// to about a third of it (66 Hz) at the last audible one (V0, 202 ml); the pocket's own ring, bright and
/// short (1.15 kHz, −60 dB in 46 ms), stays put.
const GLASS_BOTTLE: [PresetValue; 11] = [
    C(Control::Viscosity, 0.33),
    C(Control::PourTime, 10.0),
    K(Constant::Capacity, 720.0),
    K(Constant::Pocket, 9.0),
    K(Constant::F1, 190.0),
    K(Constant::F2, 1_150.0),
    K(Constant::B1, 30.0),
    K(Constant::B2, 150.0),
    K(Constant::Headspace, 60.0),
    K(Constant::F1Exponent, 0.5),
    K(Constant::F2Exponent, 0.0),
];

/// Every preset, in menu order.
pub const PRESETS: [Preset; 8] = [
    Preset {
        name: "Water",
        id: "water",
        description: "c = 0.33 in the paper's 300 ml bottle",
        values: &PAPER_BOTTLE,
    },
    Preset {
        name: "Thin (c 0.29)",
        id: "thin",
        description: "a liquid felt as thinner than water: the paper's 25 % threshold, c = 0.29",
        values: &paper_bottle_with([C(Control::Viscosity, 0.29)]),
    },
    Preset {
        name: "Sake",
        id: "sake",
        description: "a little more viscous than water (c = 0.36), poured a little slower",
        values: &paper_bottle_with([C(Control::Viscosity, 0.36), C(Control::PourTime, 5.5)]),
    },
    Preset {
        name: "Thick (c 0.42)",
        id: "thick",
        description: "a liquid felt as thicker than water: the paper's 75 % threshold, c = 0.42",
        values: &paper_bottle_with([C(Control::Viscosity, 0.42)]),
    },
    Preset {
        name: "Syrup (c 0.6)",
        id: "syrup",
        description: "well past the 75 % threshold (c = 0.6): slow, low, heavy glugs",
        values: &paper_bottle_with([
            C(Control::Viscosity, 0.6),
            C(Control::PourTime, 12.0),
            K(Constant::B1, 38.0),
            K(Constant::B2, 34.0),
        ]),
    },
    Preset {
        name: "Small bottle",
        id: "small-bottle",
        description: "a one-gō (180 ml) tokkuri of water: higher, quicker, smaller glugs",
        values: &paper_bottle_with([
            K(Constant::Capacity, 180.0),
            K(Constant::Pocket, 3.0),
            C(Control::PourTime, 3.5),
            K(Constant::F1, 100.0),
            K(Constant::F2, 380.0),
            K(Constant::B1, 55.0),
            K(Constant::B2, 50.0),
        ]),
    },
    Preset {
        name: "Large bottle",
        id: "large-bottle",
        description: "a four-gō (720 ml) bottle of water: lower, slower, bigger glugs",
        values: &paper_bottle_with([
            K(Constant::Capacity, 720.0),
            K(Constant::Pocket, 9.0),
            C(Control::PourTime, 10.0),
            K(Constant::F1, 62.0),
            K(Constant::F2, 230.0),
            K(Constant::B1, 36.0),
            K(Constant::B2, 32.0),
        ]),
    },
    Preset {
        name: "Glass bottle (falling pitch)",
        id: "glass-bottle",
        description: "a 720 ml glass bottle of water whose glug falls in pitch as it empties: \
                      f1 follows its headspace as a Helmholtz cavity (γ1 = 0.5) over a bright \
                      1.15 kHz pocket. Like the paper's bottle it pours its last part without \
                      a glug, below the amplitude law's V0 (amplitude.silent_below_ml, the \
                      paper's share of its capacity); 0 there glugs to the end",
        values: &GLASS_BOTTLE,
    },
];

impl Preset {
    /// The preset with this identifier.
    pub fn find(id: &str) -> Option<&'static Preset> {
        PRESETS.iter().find(|preset| preset.id == id)
    }

    /// Every preset's identifier, for help texts and messages.
    pub fn ids() -> String {
        let ids: Vec<&str> = PRESETS.iter().map(|preset| preset.id).collect();
        ids.join(", ")
    }

    /// What picking the preset in a menu sets: its own values, then each constant of the
    /// rules added to the paper's model ([`ADDED_RULES`]) it leaves out at its default, so that picking one preset after another
    /// leaves nothing of the first.
    pub fn menu_values(&self) -> impl Iterator<Item = PresetValue> + '_ {
        let left_out = ADDED_RULES.into_iter().filter(|law| {
            !self
                .values
                .iter()
                .any(|value| matches!(value, K(constant, _) if constant == law))
        });
        self.values
            .iter()
            .copied()
            .chain(left_out.map(|constant| K(constant, constant.range().default)))
    }

    /// The model's constants: the preset's, the rest (seed, spreads, drain) as `base` has them.
    pub fn config(&self, mut base: ModelConfig) -> ModelConfig {
        for value in self.values {
            if let K(constant, value) = *value {
                constant.set(&mut base, value);
            }
        }
        base
    }

    /// The inputs it sets; the others stay as `base` has them.
    pub fn controls(&self, mut base: ControlValues) -> ControlValues {
        for value in self.values {
            if let C(control, value) = *value {
                base[control] = value;
            }
        }
        base
    }
}
