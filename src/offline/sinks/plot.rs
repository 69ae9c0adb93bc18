//! The pour plot: the rendered waveform with its haptic envelope and glug onsets, the bottle's
//! volume and its tilt, stacked on one time axis so a glug can be traced to the pour.

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::clip::clip_source;
use super::{OutputError, PendingFile, Sink, SinkContext};
use crate::engine::UnitOnset;
use crate::offline::clips::{clip_onsets, envelope_breakpoints, Glug};
use crate::offline::RenderSummary;

/// The sink of a `.png` output: it keeps every sample, glug and report of the bottle, and draws
/// them once the render has ended.
pub(super) fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    let scene = context.scene;
    // The volume at the start: the fill level, as a reset fills the bottle (MODEL.md §8).
    let first_volume_ml = scene.config.capacity_ml * scene.lanes.fill_percent.value_at(0.0) / 100.0;
    Ok(Box::new(PlotSink {
        file: PendingFile::beside(context.path, ".png").map_err(OutputError::io(context.path))?,
        context,
        samples: Vec::new(),
        glugs: Vec::new(),
        volume_ml: vec![(0.0, first_volume_ml)],
    }))
}

struct PlotSink<'a> {
    file: PendingFile,
    context: SinkContext<'a>,
    samples: Vec<f32>,
    glugs: Vec<Glug>,
    /// `(t, V)`: the volume at the start and after every block.
    volume_ml: Vec<(f64, f64)>,
}

impl Sink for PlotSink<'_> {
    fn samples(&mut self, block: &[f32]) -> Result<(), OutputError> {
        self.samples.extend_from_slice(block);
        Ok(())
    }

    fn unit_started(&mut self, onset: &UnitOnset, output_gain: f64) {
        let sample_rate = self.context.scene.sample_rate;
        self.glugs
            .push(Glug::of_unit(onset, output_gain, sample_rate));
    }

    /// A point of V(t) every 10 ms at least.
    fn bottle_every(&self) -> Option<usize> {
        Some((self.context.scene.sample_rate as usize / 100).max(1))
    }

    fn bottle(&mut self, position: u64, volume_ml: f64) {
        let fs = self.context.scene.sample_rate as f64;
        self.volume_ml.push((position as f64 / fs, volume_ml));
    }

    fn finish(self: Box<Self>, summary: &RenderSummary) -> Result<PendingFile, OutputError> {
        let scene = self.context.scene;
        let source = clip_source(&self.context, &self.glugs, summary);
        let envelope: Vec<(f64, f64)> = envelope_breakpoints(&source)
            .iter()
            .map(|point| (point.time_s, point.amplitude))
            .collect();
        let onsets_s: Vec<f64> = clip_onsets(&source)
            .into_iter()
            .map(|index| self.glugs[index].onset_s)
            .collect();
        let tilt_deg: Vec<(f64, f64)> = self
            .volume_ml
            .iter()
            .map(|&(t, _)| (t, scene.lanes.tilt_deg.value_at(t)))
            .collect();
        let data = PlotData {
            sample_rate: scene.sample_rate as f64,
            samples: &self.samples,
            envelope: &envelope,
            onsets_s: &onsets_s,
            volume_ml: &self.volume_ml,
            capacity_ml: scene.config.capacity_ml,
            tilt_deg: &tilt_deg,
        };
        draw_pour_plot(&data, self.file.temp_path())?;
        Ok(self.file)
    }
}

/// What the pour plot shows. Every time is in seconds from the start of the render.
#[derive(Debug, Clone, Copy)]
pub struct PlotData<'a> {
    /// Sample rate of `samples` in Hz.
    pub sample_rate: f64,
    /// The rendered output, full scale ±1.
    pub samples: &'a [f32],
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

/// Why the pour plot could not be drawn.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The font compiled into the program could not be registered.
    #[error("could not draw the pour plot {path}: the embedded font did not load")]
    Font {
        /// The plot that was to be drawn.
        path: PathBuf,
    },
    /// Drawing or writing the PNG failed.
    #[error("could not draw the pour plot {path}: {message}")]
    Draw {
        /// The plot that was to be drawn.
        path: PathBuf,
        /// What plotters reported.
        message: String,
    },
}

const SIZE_PX: (u32, u32) = (1600, 1100);
const WAVE_COLOUR: RGBColor = RGBColor(70, 100, 160);
const ENVELOPE_COLOUR: RGBColor = RGBColor(230, 120, 20);
const ONSET_COLOUR: RGBColor = RGBColor(200, 30, 30);
/// Room left of every panel for its tick labels and axis name; the same for all three so
/// their time axes line up.
const Y_LABEL_AREA_PX: u32 = 90;

/// Draws the pour plot as a PNG at `path`: (a) the waveform as its min/max per pixel column
/// with ± the clip envelope and a tick at every glug onset, (b) the volume V(t) in ml from 0
/// to the capacity, (c) the tilt in degrees from 0 to 180.
pub fn draw_pour_plot(data: &PlotData, path: &Path) -> Result<(), PlotError> {
    let draw_error = |error: &dyn std::fmt::Display| PlotError::Draw {
        path: path.to_owned(),
        message: error.to_string(),
    };

    // A font compiled into the binary: no system font library needed.
    plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        epaint_default_fonts::UBUNTU_LIGHT,
    )
    .map_err(|_| PlotError::Font {
        path: path.to_owned(),
    })?;

    let end_s = plot_end_s(data);
    let root = BitMapBackend::new(path, SIZE_PX).into_drawing_area();
    root.fill(&WHITE).map_err(|e| draw_error(&e))?;
    let root = root
        .titled(
            "Sake pour: glug waveform, bottle volume and tilt",
            ("sans-serif", 30),
        )
        .map_err(|e| draw_error(&e))?;
    let panels = root.split_evenly((3, 1));

    // (a) Waveform, envelope and onsets.
    let peak = data
        .samples
        .iter()
        .map(|s| f64::from(s.abs()))
        .chain(data.envelope.iter().map(|&(_, a)| a.abs()))
        .fold(1e-3, f64::max)
        * 1.05;
    let mut wave = ChartBuilder::on(&panels[0])
        .margin(12)
        .x_label_area_size(35)
        .y_label_area_size(Y_LABEL_AREA_PX)
        .caption(
            "(a) waveform, haptic envelope and glug onsets",
            ("sans-serif", 22),
        )
        .build_cartesian_2d(0.0..end_s, -peak..peak)
        .map_err(|e| draw_error(&e))?;
    wave.configure_mesh()
        .y_desc("amplitude (full scale)")
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(|e| draw_error(&e))?;
    let columns = wave.plotting_area().dim_in_pixel().0.max(1) as usize;
    wave.draw_series(
        column_ranges(data.samples, data.sample_rate, end_s, columns)
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
        .caption("(b) volume in the bottle", ("sans-serif", 22))
        .build_cartesian_2d(0.0..end_s, 0.0..capacity_ml)
        .map_err(|e| draw_error(&e))?;
    volume
        .configure_mesh()
        .y_desc("volume (ml)")
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
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
        .caption("(c) bottle tilt", ("sans-serif", 22))
        .build_cartesian_2d(0.0..end_s, 0.0..180.0)
        .map_err(|e| draw_error(&e))?;
    tilt.configure_mesh()
        .x_desc("time (s)")
        .y_desc("tilt (°)")
        .label_style(("sans-serif", 16))
        .axis_desc_style(("sans-serif", 18))
        .draw()
        .map_err(|e| draw_error(&e))?;
    tilt.draw_series(LineSeries::new(
        data.tilt_deg.iter().copied(),
        GREEN.stroke_width(2),
    ))
    .map_err(|e| draw_error(&e))?;

    root.present().map_err(|e| draw_error(&e))
}

/// The end of the shared time axis: the latest time any panel has data for.
fn plot_end_s(data: &PlotData) -> f64 {
    let samples_s = if data.sample_rate > 0.0 {
        data.samples.len() as f64 / data.sample_rate
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
    samples: &[f32],
    sample_rate: f64,
    end_s: f64,
    columns: usize,
) -> impl Iterator<Item = (f64, f64, f64)> + '_ {
    let column_s = end_s / columns as f64;
    let sample_at = move |t: f64| ((t * sample_rate).floor().max(0.0) as usize).min(samples.len());
    (0..columns).filter_map(move |column| {
        let start_s = column as f64 * column_s;
        let first = sample_at(start_s);
        // Take at least one sample so a zoomed-in render still shows a stroke per column.
        let last = sample_at(start_s + column_s)
            .max(first + 1)
            .min(samples.len());
        let slice = samples.get(first..last).filter(|s| !s.is_empty())?;
        let (low, high) = slice
            .iter()
            .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &s| {
                (lo.min(s), hi.max(s))
            });
        Some((start_s + 0.5 * column_s, f64::from(low), f64::from(high)))
    })
}
