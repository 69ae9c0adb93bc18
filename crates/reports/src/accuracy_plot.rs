//! The work-precision diagram of the accuracy report, drawn to a PNG (feature `plot`) and
//! written all or nothing by the plot crate.

use sake_glug_plot::plotters::prelude::*;
use sake_glug_plot::{Canvas, Plot, PlotError, FONT};

use super::accuracy::{length_label, Measurement, SynthesisPath};

/// The diagram.
const ACCURACY_PLOT: Plot = Plot::new("accuracy plot", (1000, 680));

/// (speed, error in dB, render length in s) of one path at one length.
type PlotPoint = (f64, f64, f64);

/// The floor at which the reference (error 0 by definition) is drawn on the diagram.
const PLOT_FLOOR_DB: f64 = -200.0;

/// Draws the work-precision diagram: speed across, the worst error over the cases up, one line
/// per path through its render lengths.
pub fn draw_accuracy_plot(rows: &[Measurement], file: &std::path::Path) -> Result<(), PlotError> {
    ACCURACY_PLOT.write(file, |root| draw(rows, root))
}

fn draw(rows: &[Measurement], root: &Canvas<'_>) -> Result<(), Box<dyn std::error::Error>> {
    let mut lengths: Vec<f64> = rows.iter().map(|r| r.length_s).collect();
    lengths.sort_by(f64::total_cmp);
    lengths.dedup();
    // Per path and length: the worst error over the cases, and the total speed over them.
    let lines: Vec<(SynthesisPath, Vec<PlotPoint>)> = SynthesisPath::ALL
        .iter()
        .map(|&path| {
            let points = lengths
                .iter()
                .filter_map(|&length_s| {
                    let cells: Vec<&Measurement> = rows
                        .iter()
                        .filter(|r| r.path == path && r.length_s == length_s)
                        .collect();
                    if cells.is_empty() {
                        return None;
                    }
                    let error = cells
                        .iter()
                        .map(|r| r.max_error_db)
                        .fold(f64::NEG_INFINITY, f64::max)
                        .max(PLOT_FLOOR_DB);
                    // Harmonic mean: the speed of rendering all cases one after another.
                    let speed = cells.len() as f64
                        / cells.iter().map(|r| 1.0 / r.times_real_time).sum::<f64>();
                    Some((speed, error, length_s))
                })
                .collect();
            (path, points)
        })
        .collect();

    let speeds = lines.iter().flat_map(|(_, p)| p.iter().map(|q| q.0));
    let (low, high) = speeds.fold((f64::INFINITY, 0.0f64), |(l, h), s| (l.min(s), h.max(s)));
    let x_range = (low / 2.0).max(1e-3)..high * 2.0;

    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(root)
        .caption(
            "Sake Glug: error against run time (48 kHz; worst of the cases)",
            (FONT, 24),
        )
        .margin(20)
        .x_label_area_size(55)
        .y_label_area_size(75)
        .build_cartesian_2d(x_range.log_scale(), PLOT_FLOOR_DB - 10.0..0.0)?;
    chart
        .configure_mesh()
        .x_labels(8)
        .x_label_formatter(&|x| format!("{x:.0}"))
        .light_line_style(RGBColor(238, 238, 238))
        .x_desc("speed (× real time, log)")
        .y_desc("largest sample error re peak (dB)")
        .axis_desc_style((FONT, 18))
        .label_style((FONT, 15))
        .draw()?;
    // The error budget of MODEL.md §9.
    chart.draw_series(DashedLineSeries::new(
        [(low / 2.0, -100.0), (high * 2.0, -100.0)],
        6,
        4,
        RED.mix(0.6).stroke_width(1),
    ))?;
    chart.draw_series(std::iter::once(Text::new(
        "budget: −100 dB at 1 h",
        (low / 1.8, -97.0),
        (FONT, 14).into_font().color(&RED),
    )))?;

    let colours = [BLACK, BLUE, RGBColor(0, 150, 0), MAGENTA];
    for ((path, points), colour) in lines.iter().zip(colours) {
        let colour: RGBAColor = colour.to_rgba();
        let label = if *path == SynthesisPath::Reference {
            format!("{} (error 0: drawn at {PLOT_FLOOR_DB} dB)", path.name())
        } else {
            path.name().to_string()
        };
        chart
            .draw_series(LineSeries::new(
                points.iter().map(|&(s, e, _)| (s, e)),
                colour.stroke_width(2),
            ))?
            .label(label)
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2))
            });
        chart.draw_series(
            points
                .iter()
                .map(|&(s, e, _)| Circle::new((s, e), 4, colour.filled())),
        )?;
        // Lengths that do not drift land on one spot: stagger their labels upwards.
        chart.draw_series(points.iter().enumerate().map(|(k, &(s, e, length_s))| {
            let lift = 4.0 + 7.0 * k as f64;
            Text::new(
                length_label(length_s),
                (s, e + lift),
                (FONT, 13).into_font(),
            )
        }))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, 15))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()?;
    Ok(())
}
