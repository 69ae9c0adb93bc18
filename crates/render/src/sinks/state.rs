//! `state`: the bottle at a fixed rate ([`StateRow`], MODEL.md §14), streamed to the file as
//! the render reaches each row's sample.

use std::collections::VecDeque;
use std::fs::File;
use std::io::{self, BufWriter, Write};

use super::{OutputError, OutputFormat, PendingFile, Sink, SinkContext};
use crate::render::BottleReport;
use crate::tables::{csv_header, write_row, StateRow, StateSchedule};
use crate::RenderSummary;

/// `state` (`.csv`): the bottle at the state rate (MODEL.md §14); read by programs, not played.
pub(super) const FORMAT: OutputFormat = OutputFormat {
    name: "state",
    extension: "csv",
    by_extension: false,
    built: true,
    open,
    read_back: None,
    carries_c: "—",
};

/// The sink of a `state` output; a rate above the scene's sample rate is refused here.
pub(super) fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    let schedule = StateSchedule::new(context.scene, context.options.state_rate)?;
    let file = PendingFile::beside(context.path, ".csv").map_err(OutputError::io(context.path))?;
    let mut writer = file.writer().map_err(OutputError::io(context.path))?;
    let head = format!("{}\n", csv_header(StateRow::COLUMNS));
    writer
        .write_all(head.as_bytes())
        .map_err(OutputError::io(context.path))?;
    Ok(Box::new(StateFile {
        file,
        writer,
        schedule,
        bytes: head.len() as u64,
        end_unknown: context.scene.duration_samples().is_none(),
        samples_seen: 0,
        unconfirmed: VecDeque::new(),
        line: String::new(),
        failed: None,
    }))
}

struct StateFile {
    file: PendingFile,
    writer: BufWriter<File>,
    schedule: StateSchedule,
    /// Bytes written so far.
    bytes: u64,
    /// The scene has no duration: its render may run past its end.
    end_unknown: bool,
    /// Samples of the output so far.
    samples_seen: u64,
    /// `(sample, where its row starts in the file)` of the rows whose sample the output has not
    /// reached yet, while the end is unknown: a render without a duration runs on past its end
    /// until it sees it, and the rows past the end are cut off when it is known (16 bytes a
    /// row of silence, until the next sound).
    unconfirmed: VecDeque<(u64, u64)>,
    /// The row being written, reused.
    line: String,
    /// The first write that failed: reported when the render ends.
    failed: Option<io::Error>,
}

impl Sink for StateFile {
    fn samples(&mut self, block: &[f32]) -> Result<(), OutputError> {
        self.samples_seen += block.len() as u64;
        while let Some(&(sample, _)) = self.unconfirmed.front() {
            if sample >= self.samples_seen {
                break;
            }
            self.unconfirmed.pop_front();
        }
        Ok(())
    }

    fn next_bottle_report(&self, _position: u64) -> Option<u64> {
        Some(self.schedule.next_report())
    }

    fn bottle(&mut self, report: &BottleReport) {
        let Some((sample, row)) = self.schedule.row(report) else {
            return;
        };
        if self.failed.is_some() {
            return;
        }
        self.line.clear();
        write_row(StateRow::COLUMNS, &row, &mut self.line);
        if self.end_unknown && sample >= self.samples_seen {
            self.unconfirmed.push_back((sample, self.bytes));
        }
        self.bytes += self.line.len() as u64;
        if let Err(error) = self.writer.write_all(self.line.as_bytes()) {
            self.failed = Some(error);
        }
    }

    fn finish(mut self: Box<Self>, summary: &RenderSummary) -> Result<PendingFile, OutputError> {
        let path = self.file.path().to_owned();
        if let Some(error) = self.failed.take() {
            return Err(OutputError::io(&path)(error));
        }
        self.writer.flush().map_err(OutputError::io(&path))?;
        let past_end = self
            .unconfirmed
            .iter()
            .find(|&&(sample, _)| sample >= summary.samples);
        if let Some(&(_, offset)) = past_end {
            self.writer
                .get_ref()
                .set_len(offset)
                .map_err(OutputError::io(&path))?;
        }
        Ok(self.file)
    }
}
