//! Samples as CSV in Syntacts' format: one sample per line, no header, no time column; streamed
//! to the file as they are rendered.

use std::fmt::Write as _;
use std::fs::File;
use std::io::{self, BufWriter, Write};

use super::{OutputError, PendingFile, Sink, SinkContext};
use crate::offline::RenderSummary;

/// How much text is gathered before it is written: large enough that the writer sees few
/// calls, small enough to stay in cache.
const BLOCK_BYTES: usize = 64 * 1024;

/// Writes one sample per line. Each value is written with Rust's `Display` for `f32`, the
/// shortest text that parses back to exactly the same `f32`, so the CSV is lossless. Text is
/// gathered in blocks and written whole rather than sample by sample.
pub fn write_csv_samples(samples: &[f32], out: &mut impl io::Write) -> io::Result<()> {
    let mut block = String::with_capacity(BLOCK_BYTES + 64);
    for sample in samples {
        writeln!(block, "{sample}").expect("writing to a String cannot fail");
        if block.len() >= BLOCK_BYTES {
            out.write_all(block.as_bytes())?;
            block.clear();
        }
    }
    out.write_all(block.as_bytes())?;
    out.flush()
}

/// The sink of a `.csv` output.
pub(super) fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    let file = PendingFile::beside(context.path, ".csv").map_err(OutputError::io(context.path))?;
    let writer = file.writer().map_err(OutputError::io(context.path))?;
    Ok(Box::new(CsvFile { file, writer }))
}

/// A CSV of samples being written to its temporary file.
struct CsvFile {
    file: PendingFile,
    writer: BufWriter<File>,
}

impl Sink for CsvFile {
    fn samples(&mut self, block: &[f32]) -> Result<(), OutputError> {
        write_csv_samples(block, &mut self.writer).map_err(OutputError::io(self.file.path()))
    }

    fn finish(mut self: Box<Self>, _: &RenderSummary) -> Result<PendingFile, OutputError> {
        self.writer
            .flush()
            .map_err(OutputError::io(self.file.path()))?;
        Ok(self.file)
    }
}
