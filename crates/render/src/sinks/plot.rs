//! The pour plot: the rendered waveform with its haptic envelope and glug onsets, the bottle's
//! volume and its tilt, stacked on one time axis so a glug can be traced to the pour.

use std::path::{Path, PathBuf};

use plotters::prelude::*;

use super::clip::clip_source;
use super::{OutputError, PendingFile, Sink, SinkContext};
use crate::clips::{clip_onsets, envelope_breakpoints, Glug};
use crate::memory::max_units;
use crate::render::BottleReport;
use crate::RenderSummary;
use sake_glug_engine::{UnitOnset, Voicing};

/// The sink of a `.png` output: it keeps the waveform decimated to a bounded size, every glug,
/// and the reports of the bottle (thinned past a bound), and draws them once the render has
/// ended.
pub(super) fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    let scene = context.scene;
    // The volume at the start: the fill level, as a reset fills the bottle (MODEL.md §8).
    let first_volume_ml = scene.config.capacity_ml * scene.lanes.fill_percent.value_at(0.0) / 100.0;
    Ok(Box::new(PlotSink {
        file: PendingFile::beside(context.path, ".png").map_err(OutputError::io(context.path))?,
        context,
        waveform: Waveform::default(),
        glugs: Vec::new(),
        volume_ml: BottleSeries::starting_at(first_volume_ml),
    }))
}

struct PlotSink<'a> {
    file: PendingFile,
    context: SinkContext<'a>,
    waveform: Waveform,
    glugs: Vec<Glug>,
    volume_ml: BottleSeries,
}

/// Memory a glug takes until the plot is drawn: the glug, its envelope breakpoints and onset.
const BYTES_PER_GLUG: u64 = 512;

/// The bitmap the plot is drawn in (RGB).
const BITMAP_BYTES: u64 = SIZE_PX.0 as u64 * SIZE_PX.1 as u64 * 3;

impl Sink for PlotSink<'_> {
    fn samples(&mut self, block: &[f32]) -> Result<(), OutputError> {
        self.waveform.extend(block);
        Ok(())
    }

    fn unit_started(&mut self, onset: &UnitOnset, voicing: Voicing) {
        let sample_rate = self.context.scene.sample_rate;
        self.glugs
            .push(Glug::of_unit(onset, voicing.output_gain, sample_rate));
    }

    /// A point of V(t) every 10 ms at least.
    fn next_bottle_report(&self, position: u64) -> Option<u64> {
        Some(position + (self.context.scene.sample_rate as u64 / 100).max(1))
    }

    fn bottle(&mut self, report: &BottleReport) {
        let fs = self.context.scene.sample_rate as f64;
        self.volume_ml
            .push((report.position as f64 / fs, report.volume_ml));
    }

    /// The waveform and the bottle at their bounds (the tilt as many points as the volume), the
    /// bitmap, and every glug the scene can start.
    fn memory_bytes(&self) -> u64 {
        let bounded = Waveform::MAX_BYTES + 2 * BottleSeries::MAX_BYTES + BITMAP_BYTES;
        max_units(self.context.scene)
            .saturating_mul(BYTES_PER_GLUG)
            .saturating_add(bounded)
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
        let volume_ml = self.volume_ml.into_points();
        let tilt_deg: Vec<(f64, f64)> = volume_ml
            .iter()
            .map(|&(t, _)| (t, scene.lanes.tilt_deg.value_at(t)))
            .collect();
        let data = PlotData {
            sample_rate: scene.sample_rate as f64,
            waveform: &self.waveform,
            envelope: &envelope,
            onsets_s: &onsets_s,
            volume_ml: &volume_ml,
            capacity_ml: scene.config.capacity_ml,
            tilt_deg: &tilt_deg,
        };
        // Drawn into the temporary file, but an error names the file asked for.
        draw_pour_plot(&data, self.file.temp_path())
            .map_err(|error| error.naming(self.file.path()))?;
        Ok(self.file)
    }
}

/// The rendered waveform as the plot draws it: the lowest and highest of every `per_bucket`
/// samples, one sample a bucket at first. Whenever the buckets reach [`Waveform::MAX_BUCKETS`]
/// neighbours are merged and each bucket from then on takes twice as many samples, so its
/// memory is bounded however long the render. Up to `MAX_BUCKETS` samples (43 s at 48 kHz) it
/// holds every sample and the plot is exactly that of the samples; beyond, a pixel column's
/// stroke may take in up to one bucket of its neighbours (never less than its own samples).
#[derive(Debug, Clone)]
pub struct Waveform {
    /// `(lowest, highest)` sample of each bucket.
    buckets: Vec<(f32, f32)>,
    per_bucket: u64,
    samples: u64,
}

impl Default for Waveform {
    fn default() -> Self {
        Self {
            buckets: Vec::new(),
            per_bucket: 1,
            samples: 0,
        }
    }
}

impl Waveform {
    /// The most buckets kept.
    pub const MAX_BUCKETS: usize = 1 << 21;
    /// The most bytes the buckets take.
    const MAX_BYTES: u64 = (Self::MAX_BUCKETS * std::mem::size_of::<(f32, f32)>()) as u64;

    /// The waveform of `samples`.
    pub fn of(samples: &[f32]) -> Self {
        let mut waveform = Self::default();
        waveform.extend(samples);
        waveform
    }

    /// Appends the next samples.
    pub fn extend(&mut self, mut samples: &[f32]) {
        while !samples.is_empty() {
            let filled = self.samples % self.per_bucket;
            if filled == 0 {
                if self.buckets.len() == Self::MAX_BUCKETS {
                    self.merge_neighbours();
                }
                self.buckets.push((f32::INFINITY, f32::NEG_INFINITY));
            }
            let room = self.per_bucket - filled;
            let (these, rest) = samples.split_at(room.min(samples.len() as u64) as usize);
            if let Some(bucket) = self.buckets.last_mut() {
                *bucket = these
                    .iter()
                    .fold(*bucket, |(low, high), &y| (low.min(y), high.max(y)));
            }
            self.samples += these.len() as u64;
            samples = rest;
        }
    }

    /// Halves the buckets, each now of twice the samples. Called when they are all full, so a
    /// new bucket starts right after.
    fn merge_neighbours(&mut self) {
        let merged: Vec<(f32, f32)> = self
            .buckets
            .chunks(2)
            .map(|pair| {
                pair.iter().fold(
                    (f32::INFINITY, f32::NEG_INFINITY),
                    |(low, high), &(l, h)| (low.min(l), high.max(h)),
                )
            })
            .collect();
        self.buckets.clear();
        self.buckets.extend(merged);
        self.per_bucket *= 2;
    }

    /// Samples appended so far.
    pub fn len(&self) -> u64 {
        self.samples
    }

    /// Whether no sample was appended.
    pub fn is_empty(&self) -> bool {
        self.samples == 0
    }

    /// The lowest and highest sample of `first..last` (not empty), taking in the whole buckets
    /// these fall in.
    fn range(&self, first: u64, last: u64) -> (f32, f32) {
        let buckets = (first / self.per_bucket) as usize..=((last - 1) / self.per_bucket) as usize;
        self.buckets[buckets].iter().fold(
            (f32::INFINITY, f32::NEG_INFINITY),
            |(low, high), &(l, h)| (low.min(l), high.max(h)),
        )
    }

    /// The largest |sample|.
    fn peak(&self) -> f32 {
        self.buckets
            .iter()
            .map(|&(low, high)| low.abs().max(high.abs()))
            .fold(0.0, f32::max)
    }
}

/// `(t, V)`: the volume at the start and at every report of the bottle, thinned like
/// [`Waveform`]: past [`BottleSeries::MAX_POINTS`] every other point is dropped and only every
/// other report kept from then on (the last one always), so a day's render keeps as many points
/// as the first 3 h at 100 a second.
struct BottleSeries {
    points: Vec<(f64, f64)>,
    /// Reports since the start, the one kept at the start counted as 0.
    reports: u64,
    keep_every: u64,
    last: (f64, f64),
}

impl BottleSeries {
    const MAX_POINTS: usize = 1 << 20;
    /// The most bytes the points take.
    const MAX_BYTES: u64 = (Self::MAX_POINTS * std::mem::size_of::<(f64, f64)>()) as u64;

    fn starting_at(volume_ml: f64) -> Self {
        Self {
            points: vec![(0.0, volume_ml)],
            reports: 0,
            keep_every: 1,
            last: (0.0, volume_ml),
        }
    }

    fn push(&mut self, point: (f64, f64)) {
        self.reports += 1;
        self.last = point;
        if !self.reports.is_multiple_of(self.keep_every) {
            return;
        }
        if self.points.len() == Self::MAX_POINTS {
            let mut kept = false;
            self.points.retain(|_| {
                kept = !kept;
                kept
            });
            self.keep_every *= 2;
            if !self.reports.is_multiple_of(self.keep_every) {
                return;
            }
        }
        self.points.push(point);
    }

    fn into_points(mut self) -> Vec<(f64, f64)> {
        if self.points.last() != Some(&self.last) {
            self.points.push(self.last);
        }
        self.points
    }
}

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
    let peak = std::iter::once(f64::from(data.waveform.peak()))
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

impl PlotError {
    /// The same error, naming `path` as the plot.
    fn naming(self, path: &Path) -> Self {
        let path = path.to_owned();
        match self {
            Self::Font { .. } => Self::Font { path },
            Self::Draw { message, .. } => Self::Draw { path, message },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Past its bound the waveform merges buckets: its memory stays bounded, and every range
    /// still takes in every sample's extremes.
    #[test]
    fn the_waveform_stays_bounded_and_keeps_every_extreme() {
        let samples: Vec<f32> = (0..5 * Waveform::MAX_BUCKETS + 3)
            .map(|i| ((i as f32) * 0.001).sin() * (1.0 + i as f32 * 1e-7))
            .collect();
        let mut waveform = Waveform::default();
        for block in samples.chunks(4096) {
            waveform.extend(block);
        }
        assert_eq!(waveform.len(), samples.len() as u64);
        assert!(waveform.buckets.len() <= Waveform::MAX_BUCKETS);
        assert_eq!(waveform.per_bucket, 8);
        let exact = |range: std::ops::Range<usize>| {
            samples[range]
                .iter()
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), &y| {
                    (l.min(y), h.max(y))
                })
        };
        for (first, last) in [(0, 1), (5, 6), (1_000_000, 3_333_333), (0, samples.len())] {
            let (low, high) = waveform.range(first as u64, last as u64);
            let (exact_low, exact_high) = exact(first..last);
            assert!(low <= exact_low && high >= exact_high, "{first}..{last}");
        }
        let peak = samples.iter().fold(0.0f32, |peak, y| peak.max(y.abs()));
        assert_eq!(waveform.peak(), peak);
        // Below the bound it is exact.
        let short = Waveform::of(&samples[..1000]);
        assert_eq!(short.range(10, 500), exact(10..500));
    }

    #[test]
    fn the_bottle_series_stays_bounded_and_keeps_its_ends() {
        let mut series = BottleSeries::starting_at(300.0);
        let reports = 3 * BottleSeries::MAX_POINTS + 7;
        for report in 1..=reports {
            series.push((report as f64, 300.0 - report as f64 * 1e-4));
        }
        let points = series.into_points();
        assert!(points.len() <= BottleSeries::MAX_POINTS + 1);
        assert_eq!(points[0], (0.0, 300.0));
        assert_eq!(points.last().unwrap().0, reports as f64);
        assert!(points.windows(2).all(|pair| pair[0].0 < pair[1].0));
    }
}
