//! `units`: one CSV row per glug unit ([`UnitRow`]), streamed to the file as each unit starts;
//! no unit is kept.

use std::fs::File;
use std::io::{self, BufWriter, Write};

use super::{OutputError, OutputFormat, PendingFile, Sink, SinkContext};
use crate::tables::{csv_header, write_row, UnitRow};
use crate::RenderSummary;
use sake_glug_engine::{UnitOnset, Voicing};

/// `units` (`.csv`): one row per glug unit (MODEL.md §14); read by programs, not played.
pub(super) const FORMAT: OutputFormat = OutputFormat {
    name: "units",
    extension: "csv",
    by_extension: false,
    built: true,
    open,
    read_back: None,
    carries_c: "—",
};

/// The sink of a `units` output.
pub(super) fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    let file = PendingFile::beside(context.path, ".csv").map_err(OutputError::io(context.path))?;
    let mut writer = file.writer().map_err(OutputError::io(context.path))?;
    writeln!(writer, "{}", csv_header(UnitRow::COLUMNS)).map_err(OutputError::io(context.path))?;
    Ok(Box::new(UnitsFile {
        file,
        writer,
        sample_rate: context.scene.sample_rate as f64,
        line: String::new(),
        failed: None,
    }))
}

struct UnitsFile {
    file: PendingFile,
    writer: BufWriter<File>,
    sample_rate: f64,
    /// The row being written, reused.
    line: String,
    /// The first write that failed: reported when the render ends.
    failed: Option<io::Error>,
}

impl Sink for UnitsFile {
    fn unit_started(&mut self, onset: &UnitOnset, voicing: Voicing) {
        if self.failed.is_some() {
            return;
        }
        self.line.clear();
        let row = UnitRow::of(onset, voicing, self.sample_rate);
        write_row(UnitRow::COLUMNS, &row, &mut self.line);
        if let Err(error) = self.writer.write_all(self.line.as_bytes()) {
            self.failed = Some(error);
        }
    }

    fn finish(mut self: Box<Self>, _: &RenderSummary) -> Result<PendingFile, OutputError> {
        let path = self.file.path().to_owned();
        match self.failed.take() {
            Some(error) => Err(OutputError::io(&path)(error)),
            None => {
                self.writer.flush().map_err(OutputError::io(&path))?;
                Ok(self.file)
            }
        }
    }
}
