//! `sake-glug parameters`: every control and model constant as the engine's tables declare it
//! (plugin parameter id, the key pedalboard names it by, scene key, name, range, the step a
//! parameter snaps to, default), as the
//! Markdown table the guide shows (docs/guide/sound-designer.md); a constant the plugin has no parameter for shows as set by
//! scenes only. `cargo xtask docs` writes it there; a test checks the guide holds it.

use std::process::ExitCode;

use clap::Args;

use sake_glug_engine::config::{CEILING_DB, DRAIN, SEED};
use sake_glug_engine::{Constant, Control, Quantity};

#[derive(Args, Debug)]
pub struct ParametersArgs {}

/// Prints the table.
pub fn run(_args: ParametersArgs) -> ExitCode {
    print!("{}", table());
    ExitCode::SUCCESS
}

/// The Markdown table: the controls (the plugin's main group), then the model's constants and
/// settings (its Model group), in the plugin's order.
fn table() -> String {
    let mut rows = vec![
        "| ID | pedalboard key | scene key | name | range | step | default | notes |".to_owned(),
        "|---|---|---|---|---|---|---|---|".to_owned(),
    ];
    let quantities = Control::ALL
        .iter()
        .map(|control| control.quantity())
        .chain(Constant::ALL.iter().map(|constant| constant.quantity()));
    rows.extend(quantities.map(number_row));
    rows.push(row(
        &SEED,
        &format!("{}–{}", SEED.range.min, SEED.range.max),
        &SEED.knob.step_text(),
        &format!("{}", SEED.range.default),
    ));
    rows.push(row(&DRAIN, "Simulate / Follow", "—", "Simulate"));
    rows.push(number_row(&CEILING_DB));
    rows.join("\n") + "\n"
}

fn number_row(quantity: &Quantity) -> String {
    let unit = quantity.unit;
    let engine = quantity.range;
    let range = if quantity.param_id.is_empty() {
        format!("scenes only: {}–{}{unit}", engine.min, engine.max)
    } else {
        let (min, max) = quantity.knob_bounds();
        let mut range = format!("{min}–{max}{unit}");
        if quantity.knob.skew.is_some() {
            range.push_str(" (skewed)");
        }
        if (min, max) != (engine.min, engine.max) && !quantity.scene_key.is_empty() {
            range.push_str(&format!("; scenes {}–{}", engine.min, engine.max));
        }
        range
    };
    // Scenes take any value in range; only a parameter snaps.
    let step = if quantity.param_id.is_empty() {
        "—".to_owned()
    } else {
        format!("{}{unit}", quantity.knob.step_text())
    };
    row(
        quantity,
        &range,
        &step,
        &format!("{}{unit}", shown(engine.default)),
    )
}

/// A default as the table shows it: to four decimals at most (V0's is 84.333…).
fn shown(value: f64) -> String {
    let text = format!("{value:.4}");
    text.trim_end_matches('0').trim_end_matches('.').to_owned()
}

fn row(quantity: &Quantity, range: &str, step: &str, default: &str) -> String {
    let code_or_dash = |text: &str| match text {
        "" => "—".to_owned(),
        text => format!("`{text}`"),
    };
    // A quantity without a parameter has no key in a host either.
    let pedalboard = match quantity.param_id {
        "" => String::new(),
        _ => pedalboard_key(quantity.name, quantity.unit),
    };
    format!(
        "| {} | {} | {} | {} | {range} | {step} | {default} | {} |",
        code_or_dash(quantity.param_id),
        code_or_dash(&pedalboard),
        code_or_dash(quantity.scene_key),
        quantity.name,
        quantity.note
    )
}

/// The key pedalboard (Spotify's Python host) gives the VST3's parameter of `name` and `unit`
/// in `plugin.parameters`, as its `to_python_parameter_name` makes it: the name, a space and the
/// unit (the VST3's units label), lowercased, `#`/`♯` as `_sharp` and `♭` as `_flat`, every
/// character but an ASCII letter or digit `_`, each run of `_` one, none at either end (f2 in
/// Hz is `f2_hz`). tests/host/test_parameter_keys.py holds each to pedalboard's own list.
fn pedalboard_key(name: &str, unit: &str) -> String {
    let label = match unit {
        "" => name.to_owned(),
        unit => format!("{name} {unit}"),
    };
    let lowered = label
        .to_lowercase()
        .trim()
        .replace(['#', '♯'], "_sharp")
        .replace('♭', "_flat");
    let mut key = String::with_capacity(lowered.len());
    for c in lowered.chars() {
        let c = if c.is_ascii_alphanumeric() { c } else { '_' };
        if !(c == '_' && key.ends_with('_')) {
            key.push(c);
        }
    }
    key.trim_matches('_').to_owned()
}

#[cfg(test)]
mod tests {
    use super::pedalboard_key;

    /// pedalboard's own names for the parameters of its issues and tests.
    #[test]
    fn the_key_is_pedalboards() {
        assert_eq!(pedalboard_key("Tilt", "°"), "tilt");
        assert_eq!(pedalboard_key("f2", " Hz"), "f2_hz");
        assert_eq!(pedalboard_key("Output ceiling", " dB"), "output_ceiling_db");
        assert_eq!(pedalboard_key("Fill level", " %"), "fill_level");
        assert_eq!(pedalboard_key("Key #", ""), "key_sharp");
    }
}
