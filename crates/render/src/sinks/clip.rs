//! The sink every clip format shares: the glugs kept as the render starts them, the document
//! written from them once it has ended.

use std::io::Write;

use super::{OutputError, OutputOptions, PendingFile, Sink, SinkContext};
use crate::clips::{ClipSource, Glug};
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
        let text = (self.document)(&source, self.context.options);
        let path = self.context.path;
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
