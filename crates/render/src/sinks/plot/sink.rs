//! The pour plot's sink: the waveform decimated, every glug, and the bottle as the render
//! reports it, drawn once the render has ended.

use super::draw::{draw, PlotData, POUR_PLOT};
use super::series::{BottleSeries, Waveform};
use crate::clips::{clip_onsets, envelope_breakpoints, Glug};
use crate::memory::max_units;
use crate::render::BottleReport;
use crate::sinks::clip::clip_source;
use crate::sinks::{OutputError, PendingFile, Sink, SinkContext};
use crate::RenderSummary;
use sake_glug_engine::{UnitOnset, Voicing};

/// The sink of a `.png` output: it keeps the waveform decimated to a bounded size, every glug,
/// and the reports of the bottle (thinned past a bound), and draws them once the render has
/// ended.
pub(crate) fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
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
        let bounded = Waveform::MAX_BYTES + 2 * BottleSeries::MAX_BYTES + POUR_PLOT.bitmap_bytes();
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
        POUR_PLOT.draw_into(&self.file, |root| draw(&data, root))?;
        Ok(self.file)
    }
}
