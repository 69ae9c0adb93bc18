//! The analyses' figures: the Thurstone scale on a line (the paper's fig. 2) and the fitted
//! psychometric function over the proportions (fig. 5). Drawn and written, all or nothing, by
//! the plot crate.

use std::path::Path;

use sake_glug_plot::plotters::prelude::*;
use sake_glug_plot::{Plot, FONT};

use super::constant::{ConstantAnalysis, Placement, PointEstimate, POINT_PERCENTS};
use super::error::AnalysisError;
use super::paired::PairedAnalysis;

/// Fig. 2: the scale on one line.
const PAIRED_PLOT: Plot = Plot::new("plot", (1000, 300));
/// Fig. 5: the psychometric function.
const CONSTANT_PLOT: Plot = Plot::new("plot", (1000, 620));

/// The scale values on one line, each stimulus marked and named (fig. 2).
pub fn draw_paired_plot(analysis: &PairedAnalysis, path: &Path) -> Result<(), AnalysisError> {
    PAIRED_PLOT.write(path, |root| -> Result<(), String> {
        let fail = |error: &dyn std::fmt::Display| error.to_string();
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let top = analysis.scale.iter().copied().fold(0.0, f64::max).max(0.1);
        let margin = 0.08 * top;
        let mut chart = ChartBuilder::on(root)
            .margin(30)
            .caption("Thurstone Case V scale", (FONT, 26))
            .x_label_area_size(45)
            .build_cartesian_2d(-margin..top + margin, -1.0..1.0)
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .disable_y_axis()
            .disable_mesh()
            .x_desc("scale value (standard deviations of the discriminal dispersion)")
            .label_style((FONT, 16))
            .axis_desc_style((FONT, 18))
            .draw()
            .map_err(|e| fail(&e))?;
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(0.0, 0.0), (top, 0.0)],
                BLACK.stroke_width(2),
            )))
            .map_err(|e| fail(&e))?;
        // Names alternate above and below the line, so close values stay legible.
        for (index, (name, &value)) in analysis.stimuli.iter().zip(&analysis.scale).enumerate() {
            let above = index % 2 == 0;
            chart
                .draw_series([PathElement::new(
                    vec![(value, -0.15), (value, 0.15)],
                    RED.stroke_width(3),
                )])
                .map_err(|e| fail(&e))?;
            let label = format!("{name} ({value:.2})");
            let y = if above { 0.45 } else { -0.45 };
            chart
                .draw_series(std::iter::once(Text::new(
                    label,
                    (value, y),
                    (FONT, 18).into_font().color(&BLACK),
                )))
                .map_err(|e| fail(&e))?;
        }
        Ok(())
    })?;
    Ok(())
}

/// The proportion "comparison chosen" per level, the pooled fitted curve, its 25/50/75 %
/// points with their 95 % intervals, and each participant's curve in grey (fig. 5).
pub fn draw_constant_plot(analysis: &ConstantAnalysis, path: &Path) -> Result<(), AnalysisError> {
    CONSTANT_PLOT.write(path, |root| -> Result<(), String> {
        let fail = |error: &dyn std::fmt::Display| error.to_string();
        let pooled = &analysis.pooled;
        let (first, last) = (
            pooled.levels.first().map_or(0.0, |l| l.level),
            pooled.levels.last().map_or(1.0, |l| l.level),
        );
        let pad = 0.05 * (last - first);
        let (low, high) = (first - pad, last + pad);
        root.fill(&WHITE).map_err(|e| fail(&e))?;
        let mut chart = ChartBuilder::on(root)
            .margin(25)
            .caption(
                "Psychometric function (logistic, maximum likelihood)",
                (FONT, 26),
            )
            .x_label_area_size(50)
            .y_label_area_size(70)
            .build_cartesian_2d(low..high, 0.0..1.0)
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .x_desc("comparison level")
            .y_desc("proportion comparison chosen")
            .label_style((FONT, 16))
            .axis_desc_style((FONT, 18))
            .draw()
            .map_err(|e| fail(&e))?;
        let curve_points = |curve: &super::Logistic| {
            (0..=200)
                .map(|step| low + (high - low) * f64::from(step) / 200.0)
                .map(|x| (x, curve.probability(x)))
                .collect::<Vec<_>>()
        };
        for (_, fit) in &analysis.participants {
            if let Ok(fit) = fit {
                chart
                    .draw_series(LineSeries::new(
                        curve_points(&fit.curve),
                        RGBColor(200, 200, 200),
                    ))
                    .map_err(|e| fail(&e))?;
            }
        }
        chart
            .draw_series(LineSeries::new(
                curve_points(&pooled.curve),
                BLUE.stroke_width(3),
            ))
            .map_err(|e| fail(&e))?;
        chart
            .draw_series(
                pooled
                    .levels
                    .iter()
                    .map(|level| Circle::new((level.level, level.proportion()), 6, BLACK.filled())),
            )
            .map_err(|e| fail(&e))?;
        for (percent, point) in POINT_PERCENTS.iter().zip(&pooled.points) {
            let y = f64::from(*percent) / 100.0;
            let (label, marks) = match drawn_estimate(point, first, last) {
                Some((value, from, to)) => (
                    format!(
                        "{percent} %: {:.3} [{:.3}, {:.3}]",
                        point.value, point.low, point.high
                    ),
                    vec![
                        PathElement::new(vec![(from, y), (to, y)], RED.stroke_width(3)),
                        PathElement::new(
                            vec![(value, y - 0.03), (value, y + 0.03)],
                            RED.stroke_width(3),
                        ),
                    ],
                ),
                None => (
                    format!("{percent} %: beyond the levels tested, no estimate"),
                    Vec::new(),
                ),
            };
            chart
                .draw_series(
                    std::iter::once(PathElement::new(vec![(low, y), (high, y)], RED.mix(0.3)))
                        .chain(marks),
                )
                .map_err(|e| fail(&e))?;
            chart
                .draw_series(std::iter::once(Text::new(
                    label,
                    (low + 0.02 * (high - low), y + 0.045),
                    (FONT, 16).into_font().color(&RED),
                )))
                .map_err(|e| fail(&e))?;
        }
        Ok(())
    })?;
    Ok(())
}

/// A point's mark on the plot (the estimate and its interval's ends), as the text report gives
/// it: a point beyond the levels tested (`first` to `last`) is no estimate and gets no mark; an
/// interval's end beyond them is drawn at the last level.
fn drawn_estimate(point: &PointEstimate, first: f64, last: f64) -> Option<(f64, f64, f64)> {
    (point.placement == Placement::Within)
        .then(|| (point.value, point.low.max(first), point.high.min(last)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_an_estimate_within_the_levels_is_drawn() {
        let point = |value, placement| PointEstimate {
            value,
            low: value - 0.5,
            high: value + 0.5,
            placement,
        };
        assert_eq!(
            drawn_estimate(&point(0.4, Placement::Within), 0.2, 0.6),
            Some((0.4, 0.2, 0.6))
        );
        assert_eq!(
            drawn_estimate(&point(-1.0, Placement::BelowLevels), 0.2, 0.6),
            None
        );
        assert_eq!(
            drawn_estimate(&point(2.0, Placement::AboveLevels), 0.2, 0.6),
            None
        );
    }
}
