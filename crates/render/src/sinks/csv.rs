//! Samples as CSV in Syntacts' format: one sample per line, no header, no time column; or, with
//! [`OutputOptions::csv_time`](super::OutputOptions), a header and each sample's time. Streamed
//! to the file as they are rendered.

use std::fmt::Write as _;
use std::fs::File;
use std::io::{self, BufWriter, Write};

use super::read_back::{no_limits, ReadBack};
use super::{OutputError, OutputFormat, PendingFile, Sink, SinkContext};
use crate::RenderSummary;

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

/// The columns of a CSV of samples with its time column: t_n = n / fs (s), and the sample.
pub const TIMED_SAMPLE_COLUMNS: [&str; 2] = ["time_s", "sample"];

/// Writes `samples`, the first being sample `first` at `sample_rate` (Hz), one per line after
/// its time (as [`write_csv_samples`], each value the shortest text that reads back the same).
fn write_timed_samples(
    samples: &[f32],
    first: u64,
    sample_rate: f64,
    out: &mut impl io::Write,
) -> io::Result<()> {
    let mut block = String::with_capacity(BLOCK_BYTES + 64);
    for (n, sample) in (first..).zip(samples) {
        writeln!(block, "{},{sample}", n as f64 / sample_rate)
            .expect("writing to a String cannot fail");
        if block.len() >= BLOCK_BYTES {
            out.write_all(block.as_bytes())?;
            block.clear();
        }
    }
    out.write_all(block.as_bytes())
}

/// `.csv`: one sample per line, no header (Syntacts' format).
pub(super) const FORMAT: OutputFormat = OutputFormat {
    name: "csv",
    extension: "csv",
    by_extension: true,
    built: true,
    open,
    read_back: Some(ReadBack::Waveform {
        limits: no_limits,
        haptic: None,
    }),
    carries_c: super::wav::WAVEFORM_CARRIES_C,
};

/// The sink of a `.csv` output.
pub(super) fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    let file = PendingFile::beside(context.path, ".csv").map_err(OutputError::io(context.path))?;
    let mut writer = file.writer().map_err(OutputError::io(context.path))?;
    let timed = context
        .options
        .csv_time
        .then_some(context.scene.sample_rate as f64);
    if timed.is_some() {
        writeln!(writer, "{}", TIMED_SAMPLE_COLUMNS.join(","))
            .map_err(OutputError::io(context.path))?;
    }
    Ok(Box::new(CsvFile {
        file,
        writer,
        timed,
        written: 0,
    }))
}

/// A CSV of samples being written to its temporary file.
struct CsvFile {
    file: PendingFile,
    writer: BufWriter<File>,
    /// With a time column: the sample rate (Hz).
    timed: Option<f64>,
    /// Samples written so far.
    written: u64,
}

impl Sink for CsvFile {
    fn samples(&mut self, block: &[f32]) -> Result<(), OutputError> {
        let written = match self.timed {
            None => write_csv_samples(block, &mut self.writer),
            Some(sample_rate) => {
                write_timed_samples(block, self.written, sample_rate, &mut self.writer)
            }
        };
        self.written += block.len() as u64;
        written.map_err(OutputError::io(self.file.path()))
    }

    fn finish(mut self: Box<Self>, _: &RenderSummary) -> Result<PendingFile, OutputError> {
        self.writer
            .flush()
            .map_err(OutputError::io(self.file.path()))?;
        Ok(self.file)
    }
}
