//! Samples as CSV in Syntacts' format: one sample per line, no header, no time column.

use std::fmt::Write as _;
use std::io;

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
