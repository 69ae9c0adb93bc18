//! One render, many files: every file asked for is a [`Sink`] of the same single pass (the same
//! units and samples), and the files replace their targets all or nothing.
//!
//! Every sink writes to a temporary file beside its target; the targets are replaced only once
//! every sink has finished, so a failed or interrupted render leaves no partial file, and a
//! render that may need more memory than the machine has is refused before it starts.

use std::cell::RefCell;
use std::path::PathBuf;

use super::loudness::{LevelStage, Levelled};
use super::memory::available_bytes;
use super::render::{render_scene, BottleReport, RenderError, RenderObserver, RenderSummary};
use super::scene::Scene;
use super::sinks::read_back::ReadBack;
use super::sinks::{
    remove_own_temps, remove_stale_temps, Clipped, Output, OutputError, OutputOptions, PendingFile,
    Sink, SinkContext,
};
use sake_glug_engine::{UnitOnset, Voicing};

/// What a render wrote.
#[derive(Debug, Clone)]
pub struct RenderReport {
    /// The render itself.
    pub summary: RenderSummary,
    /// Each file written, with its size in bytes, in the order they were asked for.
    pub files: Vec<(PathBuf, u64)>,
    /// Temporary files of another render found beside the targets, whose process the system
    /// could not say is gone: perhaps left by a render that was killed, to be named to the user.
    pub leftovers: Vec<PathBuf>,
    /// The units that can be felt or heard (a above 0), as the clips count their glugs; the
    /// summary's units include the rest.
    pub audible_units: u64,
    /// The level of the waveform files (their gain and loudness), when a level was asked for
    /// ([`OutputOptions::level`]) or measured ([`OutputOptions::measure_loudness`]).
    pub levelled: Option<Levelled>,
    /// The files whose samples pass full scale, in the order they were asked for: each is
    /// named to the user.
    pub clipped: Vec<Clipped>,
}

/// Renders `scene` once and writes every file of `outputs` from that pass, each in its format. `scene_name` goes into the clips' metadata; `observer` hears what the
/// render reports (a closure: the samples rendered so far), and is asked after every block
/// whether to stop (then nothing is written).
pub fn render_to_files(
    scene: &Scene,
    scene_name: &str,
    outputs: &[Output],
    options: &OutputOptions,
    observer: impl RenderObserver,
) -> Result<RenderReport, OutputError> {
    let leftovers = outputs
        .iter()
        .flat_map(|output| remove_stale_temps(&output.path))
        .collect();
    // Each sink refuses here, before the render starts, what it knows it cannot write.
    let sinks = outputs
        .iter()
        .map(|output| {
            output.format.open(SinkContext {
                path: &output.path,
                scene,
                scene_name,
                options,
                read_back: output.format.read_back(),
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    refuse_what_cannot_fit(outputs, &sinks)?;
    // The haptic channels --haptic-peak drives, each with the rate its peak is measured at.
    let driven: Vec<Option<u32>> = outputs
        .iter()
        .map(
            |output| match (options.haptic_peak, output.format.read_back()) {
                (Some(_), Some(ReadBack::Waveform { haptic, .. })) => {
                    haptic.map(|channel| (channel.rate)(scene))
                }
                _ => None,
            },
        )
        .collect();
    let peak_rates: Vec<u32> = driven.iter().flatten().copied().collect();
    // The level stage (MODEL.md §19): a first pass measures, the second is written at its gain.
    let mut level = LevelStage::new::<OutputError>(
        scene,
        &options.level,
        options.measure_loudness,
        &peak_rates,
        &observer,
    )?;
    let mut sinks = sinks;
    if let Some(drive) = options.haptic_peak {
        for (sink, rate) in sinks.iter_mut().zip(&driven) {
            let Some(peak) = rate.and_then(|rate| level.peak_at(rate)) else {
                continue;
            };
            // A channel with nothing in it stays silent: no gain raises nothing.
            if peak > 0.0 {
                sink.haptic_gain(drive.level() / (peak * level.gain()));
            }
        }
    }
    let sinks = RefCell::new(sinks);
    let mut fanout = Fanout {
        sinks: &sinks,
        observer,
        audible_units: 0,
        sample_rate: scene.sample_rate,
    };
    let summary = render_scene(
        scene,
        |block: &[f32]| {
            let block = level.apply(block);
            sinks
                .borrow_mut()
                .iter_mut()
                .try_for_each(|sink| sink.samples(block))
        },
        &mut fanout,
    )?;
    let (observer, audible_units) = (fanout.observer, fanout.audible_units);
    let sinks = sinks.into_inner();
    let clipped = sinks.iter().filter_map(|sink| sink.clipped()).collect();
    let finished = sinks
        .into_iter()
        .map(|sink| sink.finish(&summary))
        .collect::<Result<Vec<_>, _>>()?;
    if observer.interrupted() {
        return Err(RenderError::Interrupted.into());
    }
    // Every file is complete: only now do they replace their targets, all together.
    let files = PendingFile::commit_all(finished)?;
    let levelled = level.finish();
    Ok(RenderReport {
        summary,
        files,
        leftovers,
        audible_units,
        levelled,
        clipped,
    })
}

/// Removes the temporary files this process's renders to `outputs` have open, for a process
/// that ends at once instead of returning from [`render_to_files`] (which removes them itself);
/// a render still running may then fail, so call it only on the way out.
pub fn remove_temporary_files(outputs: &[Output]) {
    for output in outputs {
        remove_own_temps(&output.path);
    }
}

/// Refuses a render whose sinks may together keep more memory than the machine has available.
fn refuse_what_cannot_fit(
    outputs: &[Output],
    sinks: &[Box<dyn Sink + '_>],
) -> Result<(), OutputError> {
    let files: Vec<(PathBuf, u64)> = outputs
        .iter()
        .zip(sinks)
        .map(|(output, sink)| (output.path.clone(), sink.memory_bytes()))
        .filter(|&(_, bytes)| bytes > 0)
        .collect();
    let needed = files
        .iter()
        .fold(0u64, |sum, &(_, bytes)| sum.saturating_add(bytes));
    match available_bytes() {
        Some(available) if needed > available => Err(OutputError::TooBig {
            needed,
            available,
            files,
        }),
        _ => Ok(()),
    }
}

/// Tells every sink, and the caller's observer, what the render reports besides its samples
/// (which the render hands to its sample closure, hence the shared cell).
struct Fanout<'s, 'a, O> {
    sinks: &'s RefCell<Vec<Box<dyn Sink + 'a>>>,
    observer: O,
    /// Units with a above 0 so far ([`crate::clips::is_audible`]).
    audible_units: u64,
    sample_rate: u32,
}

impl<O: RenderObserver> RenderObserver for Fanout<'_, '_, O> {
    fn progress(&mut self, rendered: u64) {
        self.observer.progress(rendered)
    }

    fn unit_started(&mut self, onset: &UnitOnset, voicing: Voicing) {
        let glug = crate::clips::Glug::of_unit(onset, voicing.output_gain, self.sample_rate);
        self.audible_units += u64::from(crate::clips::is_audible(&glug));
        for sink in self.sinks.borrow_mut().iter_mut() {
            sink.unit_started(onset, voicing);
        }
        self.observer.unit_started(onset, voicing);
    }

    /// The soonest any sink or the observer asked for.
    fn next_bottle_report(&self, position: u64) -> Option<u64> {
        self.sinks
            .borrow()
            .iter()
            .filter_map(|sink| sink.next_bottle_report(position))
            .chain(self.observer.next_bottle_report(position))
            .min()
    }

    fn bottle(&mut self, report: &BottleReport) {
        for sink in self.sinks.borrow_mut().iter_mut() {
            sink.bottle(report);
        }
        self.observer.bottle(report);
    }

    fn interrupted(&self) -> bool {
        self.observer.interrupted()
    }
}
