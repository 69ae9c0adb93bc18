//! The fit plot: (a) the first units of the first recording with their fits, (b) its spectrum
//! with f1 and f2, (c) Asum against V with the amplitude law (fig. 7), (d) V(t) per recording
//! with its drain line (fig. 6). A panel with nothing to draw (no unit with a volume, no weight
//! log nor drain line: a clip) says so in words instead of showing empty axes.

use sake_glug_io::PendingFile;
use sake_glug_plot::plotters::coord::types::RangedCoordf64;
use sake_glug_plot::plotters::prelude::*;
use sake_glug_plot::{Canvas, Plot, PlotError, FONT};

use super::recording::{FittedUnit, RecordingFit};
use super::session_fit::SessionFit;

/// The plot: its name in messages and its size.
const FIT_PLOT: Plot = Plot::new("fit plot", (1600, 1100));
/// The span of panel (a) (s).
const UNITS_SPAN_S: f64 = 0.4;

/// Draws the plot of `fit` into `file`, which [`crate::write_fit`] commits with the fit's other
/// files.
pub fn draw_fit_plot(fit: &SessionFit, file: &PendingFile) -> Result<(), PlotError> {
    FIT_PLOT.draw_into(file, |root| draw(fit, root))
}

/// Draws the four panels on `root`; the error is plotters' message.
fn draw(fit: &SessionFit, root: &Canvas<'_>) -> Result<(), String> {
    let e = |error: &dyn std::fmt::Display| error.to_string();
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let panels = root.split_evenly((2, 2));
    let colours = [BLUE, RED, GREEN, MAGENTA, CYAN, BLACK];

    // (a) The recording and the fitted units over its first glugs.
    if let Some(recording) = fit.recordings.iter().find(|r| !r.units.is_empty()) {
        let from_s = recording.units[0].fit.onset_s - 0.01;
        draw_units_panel(
            &panels[0],
            &format!("(a) {} and its unit fits", recording.spec.key),
            recording,
            &recording.units.iter().collect::<Vec<_>>(),
            from_s..from_s + UNITS_SPAN_S,
        )?;
    }

    // (b) The spectrum with f1 and f2.
    if let Some(recording) = fit.recordings.first() {
        let spectrum = &recording.spectrum;
        let top_hz =
            (3.0 * recording.start_hz[1]).min(spectrum.bin_hz * spectrum.power.len() as f64);
        let points: Vec<(f64, f64)> = spectrum
            .power
            .iter()
            .enumerate()
            .map(|(bin, &p)| (bin as f64 * spectrum.bin_hz, 10.0 * p.max(1e-30).log10()))
            .take_while(|p| p.0 <= top_hz)
            .collect();
        let high = points.iter().map(|p| p.1).fold(f64::MIN, f64::max);
        let mut chart = ChartBuilder::on(&panels[1])
            .margin(12)
            .caption("(b) spectrum, f1 and f2", (FONT, 22))
            .x_label_area_size(35)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..top_hz, (high - 70.0)..(high + 3.0))
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .x_desc("frequency (Hz)")
            .y_desc("power (dB)")
            .draw()
            .map_err(|x| e(&x))?;
        chart
            .draw_series(LineSeries::new(points, BLUE))
            .map_err(|x| e(&x))?;
        if let Some(liquid) = fit.liquids.first() {
            for key in ["glug.f1_hz", "glug.f2_hz"] {
                // An estimate without a value (a mode no unit rings) draws no line.
                if let Some(estimate) = liquid
                    .estimates
                    .iter()
                    .find(|x| x.key == key && x.has_value())
                {
                    let f = estimate.value;
                    chart
                        .draw_series(std::iter::once(PathElement::new(
                            vec![(f, high - 70.0), (f, high + 3.0)],
                            RED,
                        )))
                        .map_err(|x| e(&x))?;
                }
            }
        }
    }

    // (c) Asum against V, each liquid with its line.
    let capacity = fit.session.capacity_ml;
    let with_volume = fit
        .recordings
        .iter()
        .flat_map(|r| r.units.iter())
        .any(|u| u.volume_ml.is_finite());
    if !with_volume {
        say(
            &panels[2],
            "(c) Asum against V (fig. 7)",
            "No unit has a volume: give start_ml and enough units, or a weight log.",
        )
        .map_err(|x| e(&x))?;
    } else {
        let top = fit
            .recordings
            .iter()
            .flat_map(|r| r.units.iter().map(|u| u.fit.amplitude_sum()))
            .fold(1e-9, f64::max)
            * 1.1;
        let mut chart = ChartBuilder::on(&panels[2])
            .margin(12)
            .caption("(c) Asum against V (fig. 7)", (FONT, 22))
            .x_label_area_size(35)
            .y_label_area_size(70)
            .build_cartesian_2d(0.0..capacity, 0.0..top)
            .map_err(|x| e(&x))?;
        chart
            .configure_mesh()
            .x_desc("volume V (ml)")
            .y_desc("Asum")
            .draw()
            .map_err(|x| e(&x))?;
        for (index, liquid) in fit.liquids.iter().enumerate() {
            let colour = colours[index % colours.len()];
            let points = fit
                .recordings
                .iter()
                .filter(|r| r.spec.liquid == liquid.liquid)
                .flat_map(|r| r.units.iter())
                .filter(|u| u.volume_ml.is_finite())
                .map(|u| Circle::new((u.volume_ml, u.fit.amplitude_sum()), 2, colour.filled()));
            chart.draw_series(points).map_err(|x| e(&x))?;
            if let Some(line) = liquid.amplitude_law {
                let zero = (-line.intercept / line.slope).clamp(0.0, capacity);
                chart
                    .draw_series(LineSeries::new(
                        [(zero, line.at(zero)), (capacity, line.at(capacity))],
                        colour.stroke_width(2),
                    ))
                    .map_err(|x| e(&x))?;
            }
        }
    }

    // (d) V(t) per recording with its drain line.
    let drawn = fit
        .recordings
        .iter()
        .any(|r| r.weight.is_some() || r.drain.is_some());
    if !drawn {
        say(
            &panels[3],
            "(d) V(t) per recording and its line (fig. 6)",
            "No weight log and no drain line: the volumes over time are unknown.",
        )
        .map_err(|x| e(&x))?;
        return root.present().map_err(|x| e(&x));
    }
    let end_s = fit
        .recordings
        .iter()
        .map(|r| r.duration_s)
        .fold(0.1, f64::max);
    let mut chart = ChartBuilder::on(&panels[3])
        .margin(12)
        .caption("(d) V(t) per recording and its line (fig. 6)", (FONT, 22))
        .x_label_area_size(35)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..end_s, 0.0..capacity)
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc("V (ml)")
        .draw()
        .map_err(|x| e(&x))?;
    for (index, recording) in fit.recordings.iter().enumerate() {
        let colour = colours[index % colours.len()];
        if let Some(log) = &recording.weight {
            chart
                .draw_series(
                    log.points
                        .iter()
                        .map(|&p| Circle::new(p, 2, colour.filled())),
                )
                .map_err(|x| e(&x))?;
        }
        if let Some(drain) = recording.drain {
            let (from, to) = drain.span_s;
            chart
                .draw_series(LineSeries::new(
                    [(from, drain.line.at(from)), (to, drain.line.at(to))],
                    colour.stroke_width(2),
                ))
                .map_err(|x| e(&x))?
                .label(format!("{}°", recording.spec.tilt_deg))
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        }
    }
    if fit.recordings.iter().any(|r| r.drain.is_some()) {
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|x| e(&x))?;
    }
    root.present().map_err(|x| e(&x))
}

/// A panel's caption and, in its middle, why it shows nothing.
fn say<DB: DrawingBackend>(
    panel: &DrawingArea<DB, sake_glug_plot::plotters::coord::Shift>,
    caption: &str,
    why: &str,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let (_, height) = panel.dim_in_pixel();
    panel.draw_text(caption, &(FONT, 22).into_font().color(&BLACK), (12, 12))?;
    panel.draw_text(
        why,
        &(FONT, 20).into_font().color(&BLACK.mix(0.7)),
        (40, height as i32 / 2),
    )?;
    Ok(())
}

/// A panel of `recording`'s excerpt over `span_s` (clamped to it) in blue, and the sum of
/// `units`' fits in red: panel (a) of the fit plot and (d) of the comparison picture.
pub(crate) fn draw_units_panel(
    area: &Canvas<'_>,
    caption: &str,
    recording: &RecordingFit,
    units: &[&FittedUnit],
    span_s: std::ops::Range<f64>,
) -> Result<(), String> {
    let e = |error: &dyn std::fmt::Display| error.to_string();
    let fs = recording.sample_rate as f64;
    let samples = &recording.excerpt;
    let excerpt_s = samples.len() as f64 / fs;
    let (from_s, to_s) = (span_s.start.clamp(0.0, excerpt_s), span_s.end);
    let range =
        ((from_s * fs) as usize).min(samples.len())..((to_s * fs) as usize).min(samples.len());
    let mut chart = waveform_chart(area, caption, from_s..to_s, &samples[range.clone()])?;
    chart
        .draw_series(LineSeries::new(
            range
                .clone()
                .map(|n| (n as f64 / fs, f64::from(samples[n]))),
            BLUE.mix(0.6),
        ))
        .map_err(|x| e(&x))?;
    chart
        .draw_series(LineSeries::new(
            range.map(|n| {
                let t = n as f64 / fs;
                (t, units.iter().map(|u| u.fit.value_at(t)).sum::<f64>())
            }),
            RED,
        ))
        .map_err(|x| e(&x))?;
    Ok(())
}

/// The margin of a chart in its panel (px).
pub(crate) const CHART_MARGIN_PX: u32 = 12;
/// A caption's size (px), unless it must shrink to fit its panel…
pub(crate) const CAPTION_PX: u32 = 22;
/// …down to this at the least.
const SMALLEST_CAPTION_PX: u32 = 12;

/// The largest caption size, from [`CAPTION_PX`] down, at which `caption` fits across `area`
/// within its margins, so that no caption is cut at the panel's edge.
pub(crate) fn caption_px(area: &Canvas<'_>, caption: &str) -> u32 {
    let room = area.dim_in_pixel().0.saturating_sub(2 * CHART_MARGIN_PX);
    (SMALLEST_CAPTION_PX..=CAPTION_PX)
        .rev()
        .find(|&px| {
            area.estimate_text_size(caption, &(FONT, px).into_text_style(area))
                .is_ok_and(|(width, _)| width <= room)
        })
        .unwrap_or(SMALLEST_CAPTION_PX)
}

/// A waveform panel's chart on `area`: time (s) over `time_s`, and ±1.1 × the peak of `samples`
/// (the samples it will show), captioned and meshed as every waveform panel is.
pub(crate) fn waveform_chart<'a, 'b>(
    area: &'a Canvas<'b>,
    caption: &str,
    time_s: std::ops::Range<f64>,
    samples: &[f32],
) -> Result<ChartContext<'a, BitMapBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>, String>
{
    let e = |error: &dyn std::fmt::Display| error.to_string();
    let peak = samples
        .iter()
        .fold(1e-9f64, |p, &y| p.max(f64::from(y).abs()))
        * 1.1;
    let mut chart = ChartBuilder::on(area)
        .margin(CHART_MARGIN_PX)
        .caption(caption, (FONT, caption_px(area, caption)))
        .x_label_area_size(35)
        .y_label_area_size(70)
        .build_cartesian_2d(time_s, -peak..peak)
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .draw()
        .map_err(|x| e(&x))?;
    Ok(chart)
}
