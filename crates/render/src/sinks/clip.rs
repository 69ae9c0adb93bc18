//! The sink every clip format shares: the glugs kept as the render starts them, the document
//! written from them once it has ended.

use std::io::Write;

use super::read_back::{ReadBack, WrittenClip};
use super::{OutputError, OutputOptions, PendingFile, Sink, SinkContext};
use crate::clips::{ClipSource, Glug};
use crate::loudness::HapticPeak;
use crate::memory::max_units;
use crate::RenderSummary;
use sake_glug_engine::{UnitOnset, Voicing};

/// The sink of a clip, a document written from the render's glugs once it has ended: it keeps
/// every glug, none of the samples.
pub(super) struct ClipSink<'a> {
    file: PendingFile,
    context: SinkContext<'a>,
    glugs: Vec<Glug>,
    document: fn(&ClipSource, &OutputOptions) -> String,
    /// Memory one glug takes until the document is written (see [`Sink::memory_bytes`]).
    bytes_per_glug: u64,
}

impl<'a> ClipSink<'a> {
    pub(super) fn open(
        context: SinkContext<'a>,
        document: fn(&ClipSource, &OutputOptions) -> String,
        bytes_per_glug: u64,
    ) -> Result<Box<dyn Sink + 'a>, OutputError> {
        Ok(Box::new(Self {
            file: PendingFile::beside(context.path, "").map_err(OutputError::io(context.path))?,
            context,
            glugs: Vec::new(),
            document,
            bytes_per_glug,
        }))
    }
}

impl Sink for ClipSink<'_> {
    fn memory_bytes(&self) -> u64 {
        max_units(self.context.scene).saturating_mul(self.bytes_per_glug)
    }

    fn unit_started(&mut self, onset: &UnitOnset, voicing: Voicing) {
        let sample_rate = self.context.scene.sample_rate;
        self.glugs
            .push(Glug::of_unit(onset, voicing.output_gain, sample_rate));
    }

    fn finish(self: Box<Self>, summary: &RenderSummary) -> Result<PendingFile, OutputError> {
        let source = clip_source(&self.context, &self.glugs, summary);
        let options = self.context.options;
        let path = self.context.path;
        let text = match (options.haptic_peak, self.context.read_back) {
            (Some(peak), Some(ReadBack::Clip(read, _))) => {
                let drive = DriveGain::of(self.document, read, path, &source, options, peak)?;
                let glugs = drive.glugs(&self.glugs);
                (self.document)(&drive.source(&source, &glugs), options)
            }
            _ => (self.document)(&source, options),
        };
        let mut writer = self.file.writer().map_err(OutputError::io(path))?;
        writer
            .write_all(text.as_bytes())
            .and_then(|()| writer.flush())
            .map_err(OutputError::io(path))?;
        Ok(self.file)
    }
}

/// The clip of `glugs` from the render `summary` ended.
pub(super) fn clip_source<'g>(
    context: &SinkContext<'g>,
    glugs: &'g [Glug],
    summary: &RenderSummary,
) -> ClipSource<'g> {
    ClipSource {
        duration_s: summary.duration_s(),
        glugs,
        ceiling: context.scene.output_ceiling(),
        scene_name: context.scene_name,
        seed: context.scene.config.seed,
    }
}

/// `--haptic-peak` (MODEL.md §19): the one gain that brings a clip's strongest moment, as its
/// own format carries it and reads it back (a breakpoint, a 10 ms step's mean, a frame), to the
/// drive asked for. Every glug and the ceiling are scaled by it alike, so the clip keeps its
/// shape; the actuator's compensation is already in the glugs, so it comes first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct DriveGain(pub f64);

/// How a clip format is read back (`super::read_back::ReadBack::Clip`).
type Read = fn(&WrittenClip) -> Result<super::read_back::Reading, OutputError>;

impl DriveGain {
    /// The gain for the document `document` writes of `source`, read back by `read`: measured,
    /// then measured again at the drive found, as a format's own steps (Android's 255 levels,
    /// rumble's 4 decimals) blur a reading taken at a low level.
    pub(crate) fn of(
        document: fn(&ClipSource, &OutputOptions) -> String,
        read: Read,
        path: &std::path::Path,
        source: &ClipSource,
        options: &OutputOptions,
        peak: HapticPeak,
    ) -> Result<Self, OutputError> {
        const MEASUREMENTS: usize = 3;
        let mut gain = Self(1.0);
        for _ in 0..MEASUREMENTS {
            let glugs = gain.glugs(source.glugs);
            let scaled = gain.source(source, &glugs);
            let text = document(&scaled, options);
            let reading = read(&WrittenClip {
                path,
                text: &text,
                source: &scaled,
            })?;
            let carried = reading.peak_drive(source.duration_s);
            // A clip with nothing in it stays silent: no gain raises nothing.
            if carried <= 0.0 || carried == peak.level() {
                break;
            }
            gain = Self(gain.0 * peak.level() / carried);
        }
        Ok(gain)
    }

    /// `glugs` at this gain.
    pub(crate) fn glugs(self, glugs: &[Glug]) -> Vec<Glug> {
        glugs
            .iter()
            .map(|glug| Glug {
                amplitudes: glug.amplitudes.map(|a| a * self.0),
                ..*glug
            })
            .collect()
    }

    /// `source` with `glugs` (at this gain) and its ceiling scaled alike.
    pub(crate) fn source<'g>(self, source: &ClipSource<'g>, glugs: &'g [Glug]) -> ClipSource<'g> {
        ClipSource {
            glugs,
            ceiling: source.ceiling * self.0,
            ..*source
        }
    }
}
