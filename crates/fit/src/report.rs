//! The fit's report (markdown): the recordings (units detected and used, the share of each
//! recording's energy they explain), each liquid's estimates with their 95 % intervals (or why
//! there is none), what was kept at its default, and every warning. Every name from outside (a
//! file, a liquid) is shown escaped and without a character that breaks the table.

use std::fmt::Write;

use super::liquid::LiquidFit;
use super::recording::LOW_EXPLAINED;
use super::session_fit::SessionFit;
use super::stats::BOOTSTRAP_RESAMPLES;
use sake_glug_io::text::printable;

/// `text` for a Markdown table cell: control characters escaped, `|` as `\|`.
fn cell(text: &str) -> String {
    printable(text).replace('|', "\\|")
}

/// The report of `fit`.
pub fn report_markdown(fit: &SessionFit) -> String {
    let mut out = String::new();
    let session = &fit.session;
    let origin = if session.from_clips {
        let names: Vec<String> = fit.recordings.iter().map(|r| cell(&r.name())).collect();
        names.join(", ")
    } else {
        cell(&session.path.to_string_lossy())
    };
    let _ = writeln!(out, "# Fit of {origin}\n");
    let _ = writeln!(
        out,
        "The method of MODEL.md §13 on {} recording(s) of a {} ml bottle. Intervals are 95 %: a \
         bootstrap over units ({BOOTSTRAP_RESAMPLES} resamples) for the units' estimates, ±1.96 \
         standard errors of the drain line for the rates.\n",
        session.recordings.len(),
        session.capacity_ml
    );
    let _ = writeln!(out, "## Recordings\n");
    let _ = writeln!(
        out,
        "| recording | file | liquid | tilt (°) | rate (Hz) | length (s) | audible glug units | used | energy explained | outflow (ml/s) | from | rest (ml) |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    for recording in &fit.recordings {
        let spec = &recording.spec;
        let (rate, from) = match recording.drain {
            Some(drain) => (
                format!("{:.2}", drain.rate_ml_per_s()),
                if drain.from_weight {
                    "weight log"
                } else {
                    "glug count × pocket"
                },
            ),
            None => ("—".into(), "—"),
        };
        let _ = writeln!(
            out,
            "| {} | {} | {} | {} | {} | {:.2} | {} | {} | {:.0} %{} | {} | {} | {} |",
            cell(&spec.key),
            cell(&recording.name()),
            cell(&spec.liquid),
            spec.tilt_deg,
            recording.sample_rate,
            recording.duration_s,
            recording.detected.len(),
            recording.units.len(),
            100.0 * recording.explained,
            if recording.explained < LOW_EXPLAINED {
                " (low)"
            } else {
                ""
            },
            rate,
            from,
            recording
                .rest_ml
                .map_or("—".into(), |ml| format!("{ml:.1}")),
        );
    }
    for liquid in &fit.liquids {
        let _ = writeln!(
            out,
            "\n## Liquid `{}` ({} of {} audible glug units used)\n",
            cell(&liquid.liquid),
            liquid.units,
            liquid.detected
        );
        let _ = writeln!(
            out,
            "| estimate | value | 95 % interval | units | in the model | from |"
        );
        let _ = writeln!(out, "|---|---|---|---|---|---|");
        for estimate in &liquid.estimates {
            let interval = match estimate.interval {
                Some((low, high)) => format!("{} … {}", sig(low), sig(high)),
                None => estimate.note.as_deref().map_or("—".into(), cell),
            };
            let _ = writeln!(
                out,
                "| `{}` | {} | {} | {} | {} | {} |",
                estimate.key,
                if estimate.has_value() {
                    sig(estimate.value)
                } else {
                    "—".into()
                },
                interval,
                estimate.units.map_or("—".into(), |n| n.to_string()),
                if estimate.in_model { "yes" } else { "no" },
                estimate.source.name()
            );
        }
        if let Some(listening) = &liquid.listening {
            let _ =
                writeln!(
                out,
                "\nFitted by listening (the units' model did not sound like the recordings): {}; \
                 the summed misses of what a listener hears (rate, pitch, fall, bright share, \
                 spectral distance, each in its tolerance) went from {:.2} to {:.2}.",
                listening.set.iter().map(|k| format!("`{k}`")).collect::<Vec<_>>().join(", "),
                listening.cost[0],
                listening.cost[1]
            );
        }
        if let Some(law) = liquid.amplitude_law {
            // Its zero is V0's estimate: a number only where V0 has one.
            let silent_key = sake_glug_engine::Constant::SilentBelow.quantity().scene_key;
            let zero = liquid
                .estimates
                .iter()
                .find(|e| e.key == silent_key && e.has_value())
                .map_or_else(
                    || "no zero worth a number (see `amplitude.silent_below_ml`)".to_owned(),
                    |e| format!("zero at {} ml", sig(e.value)),
                );
            let _ = writeln!(
                out,
                "\nAmplitude law (fig. 7): Asum = {} · V {} {} (R² = {:.3}), {zero}.",
                sig(law.slope),
                if law.intercept < 0.0 { "−" } else { "+" },
                sig(law.intercept.abs()),
                law.r_squared,
            );
        }
        write_pitch_table(&mut out, fit, liquid);
        if !liquid.kept_default.is_empty() {
            let _ = writeln!(out, "\nKept at the default:\n");
            for (key, why) in &liquid.kept_default {
                let _ = writeln!(out, "- `{key}`: {}", printable(why));
            }
        }
    }
    let _ = writeln!(out, "\n## Curves\n");
    for (name, points) in [("drain", &fit.curves.drain), ("rest", &fit.curves.rest)] {
        match points {
            Some(points) => {
                let _ = writeln!(out, "- {name}: {points:?}");
            }
            None => {
                let _ = writeln!(out, "- {name}: the default");
            }
        }
    }
    let _ = writeln!(out, "\n## Warnings\n");
    if fit.warnings.is_empty() {
        let _ = writeln!(out, "None.");
    }
    for warning in &fit.warnings {
        let _ = writeln!(out, "- {}", printable(warning));
    }
    out
}

/// Four significant digits.
/// The units' own frequencies beside the model's at their volumes (the headspace law of MODEL.md
/// §5.1), at most [`PITCH_ROWS`] units of each of the liquid's recordings.
fn write_pitch_table(out: &mut String, fit: &SessionFit, liquid: &LiquidFit) {
    let capacity_ml = fit.session.capacity_ml;
    let _ = writeln!(
        out,
        "\nPitch against the headspace (the units' own f beside the model's at their volume):\n"
    );
    let _ = writeln!(
        out,
        "| recording | onset (s) | V (ml) | f1 (Hz) | model's f1 | f2 (Hz) | model's f2 |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|");
    let hz = |value: f64| {
        if value.is_finite() {
            format!("{value:.1}")
        } else {
            "—".to_owned()
        }
    };
    for recording in fit
        .recordings
        .iter()
        .filter(|r| r.spec.liquid == liquid.liquid)
    {
        for unit in recording
            .units
            .iter()
            .filter(|u| u.volume_ml.is_finite())
            .take(PITCH_ROWS)
        {
            let model = liquid.model_hz(unit.volume_ml, capacity_ml);
            let _ = writeln!(
                out,
                "| {} | {:.3} | {:.1} | {} | {} | {} | {} |",
                cell(&recording.name()),
                unit.fit.onset_s,
                unit.volume_ml,
                hz(unit.fit.frequency_hz[0]),
                hz(model[0]),
                hz(unit.fit.frequency_hz[1]),
                hz(model[1]),
            );
        }
    }
}

/// The units of a recording shown in the pitch table, at most.
const PITCH_ROWS: usize = 12;

fn sig(value: f64) -> String {
    if !value.is_finite() {
        return "—".into();
    }
    if value == 0.0 {
        return "0".into();
    }
    let decimals = (3 - value.abs().log10().floor() as i32).max(0) as usize;
    format!("{value:.decimals$}")
}
