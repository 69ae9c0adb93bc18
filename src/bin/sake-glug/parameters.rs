//! `sake-glug parameters`: every control and model constant as the engine's tables declare it
//! (plugin parameter id, scene key, name, range, default), as the Markdown table the README
//! shows. `cargo xtask docs` writes it there; a test checks the README holds it.

use std::process::ExitCode;

use clap::Args;

use sake_glug::engine::config::{CEILING_DB, DRAIN, SEED};
use sake_glug::engine::{Constant, Control, Quantity};

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
        "| ID | scene key | name | range | default | notes |".to_owned(),
        "|---|---|---|---|---|---|".to_owned(),
    ];
    let quantities = Control::ALL
        .iter()
        .map(|control| control.quantity())
        .chain(Constant::ALL.iter().map(|constant| constant.quantity()));
    rows.extend(quantities.map(number_row));
    rows.push(row(
        &SEED,
        &format!("{}–{}", SEED.range.min, SEED.range.max),
        &format!("{}", SEED.range.default),
    ));
    rows.push(row(&DRAIN, "Simulate / Follow", "Simulate"));
    rows.push(number_row(&CEILING_DB));
    rows.join("\n") + "\n"
}

fn number_row(quantity: &Quantity) -> String {
    let (min, max) = quantity.knob_bounds();
    let unit = quantity.unit;
    let mut range = format!("{min}–{max}{unit}");
    if quantity.knob.skew.is_some() {
        range.push_str(" (skewed)");
    }
    let engine = quantity.range;
    if (min, max) != (engine.min, engine.max) && !quantity.scene_key.is_empty() {
        range.push_str(&format!("; scenes {}–{}", engine.min, engine.max));
    }
    row(quantity, &range, &format!("{}{unit}", engine.default))
}

fn row(quantity: &Quantity, range: &str, default: &str) -> String {
    let scene_key = match quantity.scene_key {
        "" => "—".to_owned(),
        key => format!("`{key}`"),
    };
    format!(
        "| `{}` | {scene_key} | {} | {range} | {default} | {} |",
        quantity.param_id, quantity.name, quantity.note
    )
}
