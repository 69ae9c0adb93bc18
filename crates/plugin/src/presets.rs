//! The presets as the plugin's parameters: which parameter each value of a [`Preset`] sets, for
//! the editor's menu. (The VST3 preset files are what the plugin's own wrapper saves once a host
//! has set those parameters: `tests/plugin/vstpreset.rs` writes and checks them.)

use nice_plug::prelude::*;

use crate::params::GlugParams;
use sake_glug_engine::{Preset, PresetValue};

/// The parameters a preset sets, each with the preset's value for it (the headspace law's and the
/// glide's at their defaults where the preset leaves them out: [`Preset::menu_values`]). Every other parameter (tilt,
/// fill level, gain, spreads, seed, drain, ceiling) is left as it is.
pub fn preset_values<'a>(
    preset: &'a Preset,
    params: &'a GlugParams,
) -> impl Iterator<Item = (&'a FloatParam, f64)> {
    preset.menu_values().map(move |value| match value {
        PresetValue::Control(control, value) => (&params.controls[control], value),
        PresetValue::Constant(constant, value) => (params.model.constant(constant), value),
    })
}
