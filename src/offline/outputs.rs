//! One render, many files: every file asked for is a [`Sink`] of the same single pass (the same
//! units and samples), and the files replace their targets all or nothing.
//!
//! Every sink writes to a temporary file beside its target; the targets are replaced only once
//! every sink has finished, so a failed render leaves no partial file.

use std::cell::RefCell;
use std::path::PathBuf;

use super::render::{render_scene, RenderObserver, RenderSummary};
use super::scene::Scene;
use super::sinks::{OutputError, OutputFormat, OutputOptions, PendingFile, Sink, SinkContext};
use crate::engine::UnitOnset;

/// What a render wrote.
#[derive(Debug, Clone)]
pub struct RenderReport {
    /// The render itself.
    pub summary: RenderSummary,
    /// Each file written, with its size in bytes, in the order they were asked for.
    pub files: Vec<(PathBuf, u64)>,
}

/// Renders `scene` once and writes every file of `outputs` from that pass, each in the format
/// its extension names. `scene_name` goes into the clips' metadata; `progress` hears the samples
/// rendered so far.
pub fn render_to_files(
    scene: &Scene,
    scene_name: &str,
    outputs: &[PathBuf],
    options: &OutputOptions,
    progress: impl FnMut(u64),
) -> Result<RenderReport, OutputError> {
    let formats = outputs
        .iter()
        .map(|path| OutputFormat::of_path(path))
        .collect::<Result<Vec<_>, _>>()?;
    // Each sink refuses here, before the render starts, what it knows it cannot write.
    let sinks = outputs
        .iter()
        .zip(formats)
        .map(|(path, format)| {
            format.open(SinkContext {
                path,
                scene,
                scene_name,
                options,
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let bottle_every = sinks.iter().filter_map(|sink| sink.bottle_every()).min();
    let sinks = RefCell::new(sinks);
    let summary = render_scene(
        scene,
        |block: &[f32]| {
            sinks
                .borrow_mut()
                .iter_mut()
                .try_for_each(|sink| sink.samples(block))
        },
        &mut Fanout {
            sinks: &sinks,
            bottle_every,
            progress,
        },
    )?;
    let finished = sinks
        .into_inner()
        .into_iter()
        .map(|sink| sink.finish(&summary))
        .collect::<Result<Vec<_>, _>>()?;
    // Every file is complete: only now do they replace their targets.
    let files = finished
        .into_iter()
        .map(PendingFile::commit)
        .collect::<Result<_, _>>()?;
    Ok(RenderReport { summary, files })
}

/// Tells every sink what the render reports besides its samples (which the render hands to
/// its sample closure, hence the shared cell).
struct Fanout<'s, 'a, P> {
    sinks: &'s RefCell<Vec<Box<dyn Sink + 'a>>>,
    /// The finest any sink asked for.
    bottle_every: Option<usize>,
    progress: P,
}

impl<P: FnMut(u64)> RenderObserver for Fanout<'_, '_, P> {
    fn progress(&mut self, rendered: u64) {
        (self.progress)(rendered)
    }

    fn unit_started(&mut self, onset: &UnitOnset, output_gain: f64) {
        for sink in self.sinks.borrow_mut().iter_mut() {
            sink.unit_started(onset, output_gain);
        }
    }

    fn bottle_every(&self) -> Option<usize> {
        self.bottle_every
    }

    fn bottle(&mut self, position: u64, volume_ml: f64) {
        for sink in self.sinks.borrow_mut().iter_mut() {
            sink.bottle(position, volume_ml);
        }
    }
}
