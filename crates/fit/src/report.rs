//! The fit's report (markdown): the recordings, each liquid's estimates with their 95 %
//! intervals, what was kept at its default, and every warning.

use std::fmt::Write;

use super::estimate::SessionFit;
use super::stats::BOOTSTRAP_RESAMPLES;

/// The report of `fit`.
pub fn report_markdown(fit: &SessionFit) -> String {
    let mut out = String::new();
    let session = &fit.session;
    let _ = writeln!(out, "# Fit of {}\n", session.path.display());
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
        "| recording | file | liquid | tilt (°) | rate (Hz) | length (s) | units used | rejected | outflow (ml/s) | from | rest (ml) |"
    );
    let _ = writeln!(out, "|---|---|---|---|---|---|---|---|---|---|---|");
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
            "| {} | {} | {} | {} | {} | {:.2} | {} | {} | {} | {} | {} |",
            spec.key,
            spec.audio.display(),
            spec.liquid,
            spec.tilt_deg,
            recording.audio.sample_rate,
            recording.audio.duration_s(),
            recording.units.len(),
            recording.rejected,
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
            "\n## Liquid `{}` ({} units)\n",
            liquid.liquid, liquid.units
        );
        let _ = writeln!(out, "| estimate | value | 95 % interval | in the model |");
        let _ = writeln!(out, "|---|---|---|---|");
        for estimate in &liquid.estimates {
            let interval = estimate
                .interval
                .filter(|(low, high)| low.is_finite() && high.is_finite())
                .map_or("—".into(), |(low, high)| {
                    format!("{} … {}", sig(low), sig(high))
                });
            let _ = writeln!(
                out,
                "| `{}` | {} | {} | {} |",
                estimate.key,
                sig(estimate.value),
                interval,
                if estimate.in_model { "yes" } else { "no" }
            );
        }
        if let Some(law) = liquid.amplitude_law {
            let _ = writeln!(
                out,
                "\nAmplitude law (fig. 7): Asum = {} · V + {} (R² = {:.3}), zero at {} ml.",
                sig(law.slope),
                sig(law.intercept),
                law.r_squared,
                sig(-law.intercept / law.slope)
            );
        }
        if !liquid.kept_default.is_empty() {
            let _ = writeln!(out, "\nKept at the default:\n");
            for (key, why) in &liquid.kept_default {
                let _ = writeln!(out, "- `{key}`: {why}");
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
        let _ = writeln!(out, "- {warning}");
    }
    out
}

/// Four significant digits.
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
