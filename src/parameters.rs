//! `sake-glug parameters`: every control and model constant as the engine's tables declare it
//! (plugin parameter id, scene key, name, range, the step a parameter snaps to, default), as the
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
        "| ID | scene key | name | range | step | default | notes |".to_owned(),
        "|---|---|---|---|---|---|---|".to_owned(),
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
    format!(
        "| {} | {} | {} | {range} | {step} | {default} | {} |",
        code_or_dash(quantity.param_id),
        code_or_dash(quantity.scene_key),
        quantity.name,
        quantity.note
    )
}
