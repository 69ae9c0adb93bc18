//! Draws the pour plot's three panels on the plot crate's canvas.

use std::path::Path;

use sake_glug_plot::plotters::prelude::*;
use sake_glug_plot::{Canvas, Plot, PlotError, FONT};

use super::series::Waveform;

/// What the pour plot shows. Every time is in seconds from the start of the render.
#[derive(Debug, Clone, Copy)]
pub struct PlotData<'a> {
    /// Sample rate of the waveform in Hz.
    pub sample_rate: f64,
    /// The rendered output, full scale ±1.
    pub waveform: &'a Waveform,
    /// `(t, amplitude)` breakpoints of the felt envelope, as written to the haptic clips.
    pub envelope: &'a [(f64, f64)],
    /// Onset times of the glugs.
    pub onsets_s: &'a [f64],
    /// `(t, V)`: liquid left in the bottle in ml.
    pub volume_ml: &'a [(f64, f64)],
    /// The bottle's capacity in ml: the top of the volume panel.
    pub capacity_ml: f64,
    /// `(t, tilt)`: the bottle's tilt in degrees (0 upright, 180 upside down).
    pub tilt_deg: &'a [(f64, f64)],
}

/// The plot: its name in messages and its size.
pub(super) const POUR_PLOT: Plot = Plot::new("pour plot", (1600, 1100));
const WAVE_COLOUR: RGBColor = RGBColor(70, 100, 160);
const ENVELOPE_COLOUR: RGBColor = RGBColor(230, 120, 20);
const ONSET_COLOUR: RGBColor = RGBColor(200, 30, 30);
/// Room left of every panel for its tick labels and axis name; the same for all three so
/// their time axes line up.
const Y_LABEL_AREA_PX: u32 = 90;

/// Draws the pour plot as a PNG at `path`, all or nothing: (a) the waveform as its min/max per
/// pixel column with ± the clip envelope and a tick at every glug onset, (b) the volume V(t) in
/// ml from 0 to the capacity, (c) the tilt in degrees from 0 to 180.
pub fn draw_pour_plot(data: &PlotData, path: &Path) -> Result<(), PlotError> {
    POUR_PLOT.write(path, |root| draw(data, root))
}

/// Draws the three panels on `root`; the error is plotters' message.
pub(super) fn draw(data: &PlotData, root: &Canvas<'_>) -> Result<(), String> {
    let draw_error = |error: &dyn std::fmt::Display| error.to_string();
    let end_s = plot_end_s(data);
    root.fill(&WHITE).map_err(|e| draw_error(&e))?;
    let root = root
        .titled(
            "Sake pour: glug waveform, bottle volume and tilt",
            (FONT, 30),
        )
        .map_err(|e| draw_error(&e))?;
    let panels = root.split_evenly((3, 1));

    // (a) Waveform, envelope and onsets.
    let peak = std::iter::once(f64::from(data.waveform.peak()))
        .chain(data.envelope.iter().map(|&(_, a)| a.abs()))
        .fold(1e-3, f64::max)
        * 1.05;
    let mut wave = ChartBuilder::on(&panels[0])
        .margin(12)
        .x_label_area_size(35)
        .y_label_area_size(Y_LABEL_AREA_PX)
        .caption("(a) waveform, haptic envelope and glug onsets", (FONT, 22))
        .build_cartesian_2d(0.0..end_s, -peak..peak)
        .map_err(|e| draw_error(&e))?;
    wave.configure_mesh()
        .y_desc("amplitude (full scale)")
        .label_style((FONT, 16))
        .axis_desc_style((FONT, 18))
        .draw()
        .map_err(|e| draw_error(&e))?;
    let columns = wave.plotting_area().dim_in_pixel().0.max(1) as usize;
    wave.draw_series(
        column_ranges(data.waveform, data.sample_rate, end_s, columns)
            .map(|(t, low, high)| PathElement::new(vec![(t, low), (t, high)], WAVE_COLOUR)),
    )
    .map_err(|e| draw_error(&e))?;
    for sign in [1.0, -1.0] {
        wave.draw_series(LineSeries::new(
            data.envelope.iter().map(|&(t, a)| (t, sign * a)),
            ENVELOPE_COLOUR.stroke_width(2),
        ))
        .map_err(|e| draw_error(&e))?;
    }
    wave.draw_series(data.onsets_s.iter().map(|&t| {
        PathElement::new(
            vec![(t, peak), (t, 0.9 * peak)],
            ONSET_COLOUR.stroke_width(2),
        )
    }))
    .map_err(|e| draw_error(&e))?;

    // (b) Volume left in the bottle.
    let capacity_ml = if data.capacity_ml > 0.0 {
        data.capacity_ml
    } else {
        1.0
    };
    let mut volume = ChartBuilder::on(&panels[1])
        .margin(12)
        .x_label_area_size(35)
        .y_label_area_size(Y_LABEL_AREA_PX)
        .caption("(b) volume in the bottle", (FONT, 22))
        .build_cartesian_2d(0.0..end_s, 0.0..capacity_ml)
        .map_err(|e| draw_error(&e))?;
    volume
        .configure_mesh()
        .y_desc("volume (ml)")
        .label_style((FONT, 16))
        .axis_desc_style((FONT, 18))
        .draw()
        .map_err(|e| draw_error(&e))?;
    volume
        .draw_series(LineSeries::new(
            data.volume_ml.iter().copied(),
            BLUE.stroke_width(2),
        ))
        .map_err(|e| draw_error(&e))?;

    // (c) Tilt.
    let mut tilt = ChartBuilder::on(&panels[2])
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(Y_LABEL_AREA_PX)
        .caption("(c) bottle tilt", (FONT, 22))
        .build_cartesian_2d(0.0..end_s, 0.0..180.0)
        .map_err(|e| draw_error(&e))?;
    tilt.configure_mesh()
        .x_desc("time (s)")
        .y_desc("tilt (°)")
        .label_style((FONT, 16))
        .axis_desc_style((FONT, 18))
        .draw()
        .map_err(|e| draw_error(&e))?;
    tilt.draw_series(LineSeries::new(
        data.tilt_deg.iter().copied(),
        GREEN.stroke_width(2),
    ))
    .map_err(|e| draw_error(&e))?;

    Ok(())
}

/// The end of the shared time axis: the latest time any panel has data for.
fn plot_end_s(data: &PlotData) -> f64 {
    let samples_s = if data.sample_rate > 0.0 {
        data.waveform.len() as f64 / data.sample_rate
    } else {
        0.0
    };
    let last = |series: &[(f64, f64)]| series.last().map_or(0.0, |&(t, _)| t);
    samples_s
        .max(last(data.envelope))
        .max(last(data.volume_ml))
        .max(last(data.tilt_deg))
        .max(1e-3)
}

/// `(time at the column's middle, min, max)` of the samples under each of `columns` pixel
/// columns spanning 0..end_s: a long render drawn as one vertical stroke per column instead of
/// millions of points. Columns without samples are left out.
fn column_ranges(
    waveform: &Waveform,
    sample_rate: f64,
    end_s: f64,
    columns: usize,
) -> impl Iterator<Item = (f64, f64, f64)> + '_ {
    let column_s = end_s / columns as f64;
    let samples = waveform.len();
    let sample_at = move |t: f64| ((t * sample_rate).floor().max(0.0) as u64).min(samples);
    (0..columns).filter_map(move |column| {
        let start_s = column as f64 * column_s;
        let first = sample_at(start_s);
        // Take at least one sample so a zoomed-in render still shows a stroke per column.
        let last = sample_at(start_s + column_s).max(first + 1).min(samples);
        if first >= last {
            return None;
        }
        let (low, high) = waveform.range(first, last);
        Some((start_s + 0.5 * column_s, f64::from(low), f64::from(high)))
    })
}
