//! Samples at another rate: the project's one resampler, for a format that plays one rate only
//! (the DualSense's 48 kHz) and for a study's recording played at the interface's rate. rubato's synchronous FFT resampler (`Fft`): the ratio of two whole rates is fixed
//! and exact, which is the job it is made for (band-limited, as good as its asynchronous sinc
//! resampler, and faster). It is fed as the render runs, in chunks of its own size whatever the
//! render's blocks, so the output is the same at every block size; its delay is trimmed, so the
//! output lines up with the input; and `n` samples in give exactly ⌈n·to/from⌉ out.
//!
//! Settings: f64 samples, one channel, fixed input chunks of [`CHUNK_FRAMES`], rubato's
//! default sub-chunks (FFT blocks of about 256 input frames, rounded to the rates' smallest
//! common block) and its default anti-aliasing window (Blackman-Harris²).

use rubato::audioadapter_buffers::direct::InterleavedSlice;
use rubato::{Fft, FixedSync, Indexing, Resampler};

/// Input frames handed to the resampler at a time.
const CHUNK_FRAMES: usize = 1024;

/// A stream of samples resampled from one rate to another: fed with [`Resample::push`] in blocks
/// of any size, ended with [`Resample::finish`]; the output is the same at every block size.
pub struct Resample {
    fft: Fft<f64>,
    /// Input not yet handed to the resampler: less than a chunk.
    input: Vec<f64>,
    /// The resampler's output of one call.
    output: Vec<f64>,
    /// Output frames still to drop at the start: the resampler's delay.
    delay_left: usize,
    from_hz: u32,
    to_hz: u32,
    /// Input samples taken.
    taken: u64,
    /// Output samples given.
    given: u64,
}

impl Resample {
    /// A resampler from `from_hz` to `to_hz` (both above 0).
    pub fn new(from_hz: u32, to_hz: u32) -> Self {
        let fft = Fft::<f64>::new(
            from_hz as usize,
            to_hz as usize,
            CHUNK_FRAMES,
            1,
            FixedSync::Input,
        )
        .expect("two rates above 0 and a chunk above 0 make a resampler");
        Self {
            input: Vec::with_capacity(fft.input_frames_max()),
            output: vec![0.0; fft.output_frames_max()],
            delay_left: fft.output_delay(),
            fft,
            from_hz,
            to_hz,
            taken: 0,
            given: 0,
        }
    }

    /// The samples out for `input` samples in: ⌈input·to/from⌉.
    pub fn output_len(from_hz: u32, to_hz: u32, input: u64) -> u64 {
        (input as u128 * to_hz as u128).div_ceil(from_hz as u128) as u64
    }

    /// Memory the resampler keeps (bytes), as far as its sizes tell: its FFT blocks, their
    /// spectra, plans and overlaps, and the chunks in and out.
    pub fn memory_bytes(&self) -> u64 {
        let blocks = (self.fft.fft_size_in() + self.fft.fft_size_out()) as u64;
        let chunks = (self.input.capacity() + self.output.len()) as u64;
        // Each block's frames are held about eight times over (input, output, overlap, their
        // complex spectra and the FFTs' scratch), 16 bytes at most each.
        8 * 16 * blocks + 8 * chunks
    }

    /// Takes the next samples, and hands `emit` the output they complete.
    pub fn push<E>(
        &mut self,
        mut samples: &[f32],
        emit: &mut impl FnMut(&[f64]) -> Result<(), E>,
    ) -> Result<(), E> {
        self.taken += samples.len() as u64;
        while !samples.is_empty() {
            let room = self.fft.input_frames_next() - self.input.len();
            let (these, rest) = samples.split_at(room.min(samples.len()));
            self.input.extend(these.iter().map(|&y| f64::from(y)));
            samples = rest;
            if self.input.len() == self.fft.input_frames_next() {
                self.run(None, emit)?;
            }
        }
        Ok(())
    }

    /// After the last sample: the rest of the output, up to ⌈taken·to/from⌉ samples in all.
    pub fn finish<E>(mut self, emit: &mut impl FnMut(&[f64]) -> Result<(), E>) -> Result<(), E> {
        let total = Self::output_len(self.from_hz, self.to_hz, self.taken);
        if !self.input.is_empty() {
            let partial = self.input.len();
            self.run(Some(partial), emit)?;
        }
        // What is still inside the resampler comes out as zeros are pumped through it.
        while self.given < total {
            self.run(Some(0), emit)?;
        }
        Ok(())
    }

    /// Runs the resampler once on the chunk held (`partial`: the frames of it that are real, the
    /// rest read as silence) and hands on its output, less the delay and anything past the end.
    fn run<E>(
        &mut self,
        partial: Option<usize>,
        emit: &mut impl FnMut(&[f64]) -> Result<(), E>,
    ) -> Result<(), E> {
        let frames_in = self.fft.input_frames_next();
        self.input.resize(frames_in, 0.0);
        let indexing = Indexing {
            partial_len: partial,
            ..Indexing::default()
        };
        let input = InterleavedSlice::new(&self.input, 1, frames_in)
            .expect("the input holds one chunk of one channel");
        let frames_out = self.output.len();
        let mut output = InterleavedSlice::new_mut(&mut self.output, 1, frames_out)
            .expect("the output holds the most one call writes");
        let (_, written) = self
            .fft
            .process_into_buffer(&input, &mut output, Some(&indexing))
            .expect("buffers sized as the resampler asks");
        self.input.clear();
        let skipped = self.delay_left.min(written);
        self.delay_left -= skipped;
        let available = written - skipped;
        // Before `finish` the end is not known, and the delay keeps the output behind the
        // input; after it, the output stops at ⌈taken·to/from⌉.
        let wanted = match partial {
            None => available,
            Some(_) => {
                let total = Self::output_len(self.from_hz, self.to_hz, self.taken);
                available.min((total - self.given) as usize)
            }
        };
        self.given += wanted as u64;
        emit(&self.output[skipped..skipped + wanted])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `samples` resampled, fed in blocks of `block`.
    fn resampled(samples: &[f32], from_hz: u32, to_hz: u32, block: usize) -> Vec<f64> {
        let mut out = Vec::new();
        let mut emit = |chunk: &[f64]| -> Result<(), ()> {
            out.extend_from_slice(chunk);
            Ok(())
        };
        let mut resample = Resample::new(from_hz, to_hz);
        for chunk in samples.chunks(block) {
            resample.push(chunk, &mut emit).unwrap();
        }
        resample.finish(&mut emit).unwrap();
        out
    }

    fn tone(hz: f64, amplitude: f64, rate_hz: u32, samples: usize) -> Vec<f32> {
        (0..samples)
            .map(|n| {
                (amplitude * (std::f64::consts::TAU * hz * n as f64 / rate_hz as f64).sin()) as f32
            })
            .collect()
    }

    /// The frequency (Hz) of a tone from its rising zero crossings (interpolated), and its
    /// level (dB re full scale, RMS), over `samples`.
    fn frequency_and_level(samples: &[f64], rate_hz: u32) -> (f64, f64) {
        let crossings: Vec<f64> = samples
            .windows(2)
            .enumerate()
            .filter(|(_, pair)| pair[0] < 0.0 && pair[1] >= 0.0)
            .map(|(n, pair)| n as f64 + pair[0] / (pair[0] - pair[1]))
            .collect();
        let (first, last) = (crossings[0], crossings[crossings.len() - 1]);
        let hz = (crossings.len() - 1) as f64 * rate_hz as f64 / (last - first);
        let whole = &samples[first.ceil() as usize..last.floor() as usize];
        let rms = (whole.iter().map(|y| y * y).sum::<f64>() / whole.len() as f64).sqrt();
        (hz, 20.0 * rms.log10())
    }

    /// A 1 kHz tone at −6 dB, 44.1 kHz to 48 kHz: every sample away from the ends within
    /// −80 dB of the tone at 48 kHz (so on time: the delay is trimmed), its frequency within
    /// 0.01 Hz and its level within 0.01 dB; and exactly ⌈n·48000/44100⌉ samples.
    #[test]
    fn a_tone_keeps_its_frequency_level_and_time() {
        let input = tone(1000.0, 0.5, 44_100, 44_100);
        let output = resampled(&input, 44_100, 48_000, 4096);
        assert_eq!(output.len(), 48_000);
        let ideal = tone(1000.0, 0.5, 48_000, 48_000);
        let edge = 480;
        let worst = output[edge..48_000 - edge]
            .iter()
            .zip(&ideal[edge..48_000 - edge])
            .map(|(y, x)| (y - f64::from(*x)).abs())
            .fold(0.0, f64::max);
        assert!(worst < 1e-4, "worst error {worst}");
        let (hz, db) = frequency_and_level(&output[edge..48_000 - edge], 48_000);
        let expected_db = 20.0 * (0.5 / 2f64.sqrt()).log10();
        eprintln!("1 kHz at 44.1 kHz → {hz:.5} Hz, {db:.5} dB (expected {expected_db:.5} dB); worst sample error {worst:.2e}");
        assert!((hz - 1000.0).abs() < 0.01, "{hz} Hz");
        assert!((db - expected_db).abs() < 0.01, "{db} dB");
    }

    /// Down as well as up, and from rates whose common block is small or large.
    #[test]
    fn every_ratio_gives_its_length_and_its_tone() {
        for from_hz in [8_000, 22_050, 44_101, 96_000, 192_000] {
            let seconds = 0.5;
            let n = (from_hz as f64 * seconds) as usize;
            let output = resampled(&tone(440.0, 0.25, from_hz, n), from_hz, 48_000, 1000);
            assert_eq!(
                output.len() as u64,
                Resample::output_len(from_hz, 48_000, n as u64)
            );
            let edge = 960;
            let (hz, db) = frequency_and_level(&output[edge..output.len() - edge], 48_000);
            let expected_db = 20.0 * (0.25 / 2f64.sqrt()).log10();
            assert!((hz - 440.0).abs() < 0.01, "{from_hz} Hz: {hz} Hz");
            assert!((db - expected_db).abs() < 0.02, "{from_hz} Hz: {db} dB");
        }
    }

    /// The render's blocks do not change a sample; nor does an empty render fail.
    #[test]
    fn the_output_is_the_same_at_every_block_size() {
        let input: Vec<f32> = (0..20_000)
            .map(|n| ((n * 7919 % 1000) as f32 / 500.0) - 1.0)
            .collect();
        let whole = resampled(&input, 44_100, 48_000, input.len());
        for block in [1, 37, 1024, 4096] {
            assert_eq!(
                resampled(&input, 44_100, 48_000, block),
                whole,
                "blocks of {block}"
            );
        }
        assert!(resampled(&[], 44_100, 48_000, 64).is_empty());
        assert_eq!(resampled(&[0.5], 44_100, 48_000, 64).len(), 2);
    }
}
