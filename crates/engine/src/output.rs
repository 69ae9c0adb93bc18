//! The output stage of MODEL.md §6: the output gain, then the limiter that keeps every sample
//! finite, within the ceiling and free of denormals. Gain and ceiling reach a new value along a
//! straight ramp of [`OUTPUT_RAMP_S`], sample by sample, so that moving them does not click and
//! the same automation gives the same samples however time is cut into blocks.

use multiversion::multiversion;

use super::amplitude::db_to_gain;
use super::config::{CEILING, OUTPUT_RAMP_S};
use super::controls::{Control, Lane};
use super::synthesis::GRID;

/// A value that goes to each new target in a straight line of `len` samples.
///
/// The value at a sample is worked out from how far the ramp has gone, never summed step by
/// step, so skipping samples (silence) lands on the same value as stepping through them.
#[derive(Debug, Clone, Copy)]
struct Ramp {
    /// Where the ramp under way started: the value at the sample before its target changed.
    start: f64,
    target: f64,
    /// Samples of the ramp taken; `len` once the value is the target.
    taken: u32,
    len: u32,
    value: f64,
}

impl Ramp {
    fn settled_at(target: f64, len: u32) -> Self {
        Self {
            start: target,
            target,
            taken: len,
            len,
            value: target,
        }
    }

    /// A new target asked for from this sample on starts a new ramp from the value now.
    #[inline]
    fn retarget(&mut self, target: f64) {
        if target.to_bits() != self.target.to_bits() {
            self.start = self.value;
            self.target = target;
            self.taken = 0;
        }
    }

    /// The value at the next sample.
    #[inline]
    fn next(&mut self) -> f64 {
        if self.taken < self.len {
            self.skip(1);
        }
        self.value
    }

    /// Goes `samples` samples along the ramp.
    fn skip(&mut self, samples: u64) {
        if self.taken == self.len {
            return;
        }
        self.taken = (u64::from(self.taken) + samples).min(u64::from(self.len)) as u32;
        self.value = if self.taken == self.len {
            self.target
        } else {
            self.start + (self.target - self.start) * (f64::from(self.taken) / f64::from(self.len))
        };
    }

    fn is_settled(&self) -> bool {
        self.taken == self.len
    }
}

/// G of MODEL.md §6 for an output gain in dB, brought into range first (§11).
fn linear(gain_db: f64) -> f64 {
    db_to_gain(Control::Gain.range().sanitize(gain_db))
}

/// Counts kept by the output stage, since the last reset.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct LimiterCounts {
    /// Samples the limiter changed: over the ceiling or not finite.
    pub events: u64,
    /// Samples that were NaN or infinite before the limiter.
    pub non_finite: u64,
}

/// Gain, ceiling and limiter, with what they need to remember between blocks.
#[derive(Debug, Clone)]
pub(super) struct OutputStage {
    ramp_len: u32,
    /// The last output gain asked for (dB) and its linear value. Starts as a true pair (the
    /// default's): any key could arrive, NaN included, and must never find a stale value.
    gain_db: (f64, f64),
    gain: Ramp,
    ceiling: Ramp,
    /// No sample rendered since the reset: the first sample takes its gain and ceiling as they
    /// are, with no ramp from whatever came before (a bounce starts from silence).
    fresh: bool,
    pub limiter: LimiterCounts,
    /// A synthesis period's sum through the settled gain and the flush, for the short blocks
    /// that each take a part of it ([`OutputStage::apply_settled_from`]).
    gained: GainedPeriod,
}

/// [`gain_and_flush`] of a whole period's sum, kept with what it was worked out from.
#[derive(Debug, Clone)]
struct GainedPeriod {
    /// The sum's number (see `Synthesis::period_sum`), and the bits of the gain and the ceiling.
    key: Option<(u64, u64, u64)>,
    /// No sample of the period is NaN, infinite or past the ceiling: the limiter does nothing
    /// more to any part of it.
    within: bool,
    samples: [f32; GRID],
}

impl OutputStage {
    pub fn new(sample_rate: f64) -> Self {
        let ramp_len = ((sample_rate * OUTPUT_RAMP_S).round() as u32).max(1);
        let default_db = Control::Gain.range().default;
        let gain_db = (default_db, linear(default_db));
        Self {
            ramp_len,
            gain_db,
            gain: Ramp::settled_at(gain_db.1, ramp_len),
            ceiling: Ramp::settled_at(1.0, ramp_len),
            fresh: true,
            limiter: LimiterCounts::default(),
            gained: GainedPeriod {
                key: None,
                within: false,
                samples: [0.0; GRID],
            },
        }
    }

    pub fn reset(&mut self) {
        self.fresh = true;
        self.limiter = LimiterCounts::default();
    }

    /// The ceiling at the last sample rendered (linear).
    pub fn ceiling_now(&self) -> f64 {
        self.ceiling.value
    }

    /// The gain at the last sample rendered (linear).
    pub fn gain_now(&self) -> f64 {
        self.gain.value
    }

    /// The gain (linear) the output will have at sample `index` of a block about to be applied
    /// with `gain_db`: what a unit starting there is heard at. Changes nothing.
    pub fn gain_ahead(&self, gain_db: &Lane, index: usize) -> f64 {
        let target = |index: usize| linear(gain_db.at(index));
        let mut gain = if self.fresh {
            Ramp::settled_at(target(0), self.ramp_len)
        } else {
            self.gain
        };
        if gain_db.is_constant() {
            gain.retarget(target(0));
            gain.skip(index as u64 + 1);
        } else {
            for at in 0..=index {
                gain.retarget(target(at));
                gain.next();
            }
        }
        gain.value
    }

    /// The targets of a block's first sample: straight in after a reset, ramped to otherwise.
    #[inline]
    fn begin(&mut self, gain_db: f64, ceiling: f64) {
        let gain = self.linear_gain(gain_db);
        if std::mem::take(&mut self.fresh) {
            self.gain = Ramp::settled_at(gain, self.ramp_len);
            self.ceiling = Ramp::settled_at(ceiling, self.ramp_len);
        } else {
            self.gain.retarget(gain);
            self.ceiling.retarget(ceiling);
        }
    }

    #[inline]
    fn linear_gain(&mut self, gain_db: f64) -> f64 {
        if gain_db.to_bits() != self.gain_db.0.to_bits() {
            self.gain_db = (gain_db, linear(gain_db));
        }
        self.gain_db.1
    }

    /// Moves gain and ceiling through `len` samples that are silent (nothing sounds), as
    /// [`OutputStage::apply`] would have.
    pub fn pass_silence(&mut self, gain_db: &Lane, ceiling: f64, len: usize) {
        if len == 0 {
            return;
        }
        self.begin(gain_db.at(0), ceiling);
        self.ceiling.skip(len as u64);
        match gain_db {
            Lane::Constant(_) => self.gain.skip(len as u64),
            Lane::Samples(_) => {
                for index in 0..len {
                    let target = self.linear_gain(gain_db.at(index));
                    self.gain.retarget(target);
                    self.gain.next();
                }
            }
        }
    }

    /// Takes a block's targets when they hold over the whole of it (a constant gain lane, the
    /// ceiling of one block) and says whether gain and ceiling are then settled: if so, no
    /// sample of the block moves them, and [`OutputStage::apply_settled`] may take the whole
    /// block at once, after its synthesis, in place of [`OutputStage::apply`] and
    /// [`OutputStage::pass_silence`] span by span (those would only take the same targets
    /// again).
    #[inline]
    pub fn begin_constant_block(&mut self, gain_db: f64, ceiling: f64) -> bool {
        self.begin(gain_db, ceiling);
        self.is_settled()
    }

    /// Whether gain and ceiling have reached their targets: a block under the targets last
    /// taken moves neither.
    #[inline]
    pub fn is_settled(&self) -> bool {
        self.gain.is_settled() && self.ceiling.is_settled()
    }

    /// [`OutputStage::apply`] at a settled gain and ceiling (see
    /// [`OutputStage::begin_constant_block`]): sample by sample the same operations, so a block
    /// at once gives the bits and counts of its spans one by one; a silent span (zeros) stays
    /// zeros.
    ///
    /// Returns the block's largest |y| as written, which the pass knows without another.
    #[inline]
    pub fn apply_settled(&mut self, out: &mut [f32]) -> f32 {
        self.gain_and_limit(out, self.gain.value, self.ceiling.value as f32)
    }

    /// The gain, then the limiter, at one gain and ceiling; returns the largest |y| written.
    #[inline]
    fn gain_and_limit(&mut self, out: &mut [f32], gain: f64, ceiling: f32) -> f32 {
        let largest = gain_and_flush(out, gain);
        if largest > ceiling.to_bits() {
            self.limit(out, ceiling);
            return peak(out);
        }
        // The largest magnitude before the flush: a denormal one was flushed to 0, and so was
        // every other sample below it.
        if largest < f32::MIN_POSITIVE.to_bits() {
            0.0
        } else {
            f32::from_bits(largest)
        }
    }

    /// [`OutputStage::apply_settled`] of the samples `sum[offset..offset + out.len()]`, written to
    /// `out`, where `sum` is a synthesis period's sum numbered `number`: the whole period goes
    /// through the gain and the flush once, and each short block of it (a 16-frame call) copies
    /// its part. False, leaving `out` as it was, where the limiter has more to do in the period
    /// (then the block is applied on its own). The same bits: [`gain_and_flush`] works sample by
    /// sample, and a period with no sample past the ceiling has none in any part of it.
    #[inline(always)]
    pub fn apply_settled_from(
        &mut self,
        sum: &[f32; GRID],
        number: u64,
        offset: usize,
        out: &mut [f32],
    ) -> bool {
        let key = (
            number,
            self.gain.value.to_bits(),
            self.ceiling.value.to_bits(),
        );
        let gained = &mut self.gained;
        if gained.key != Some(key) {
            gained.key = Some(key);
            gained.samples = *sum;
            let ceiling = self.ceiling.value as f32;
            gained.within =
                gain_and_flush(&mut gained.samples, self.gain.value) <= ceiling.to_bits();
        }
        if !gained.within {
            return false;
        }
        out.copy_from_slice(&gained.samples[offset..offset + out.len()]);
        true
    }

    /// Output gain, then the guarantees of MODEL.md §6: finite, within the ceiling, no denormal.
    /// Counts what the limiter did, so that a check can look past it.
    #[inline]
    pub fn apply(&mut self, gain_db: &Lane, ceiling: f64, out: &mut [f32]) {
        if out.is_empty() {
            return;
        }
        self.begin(gain_db.at(0), ceiling);
        let constant_gain = gain_db.is_constant() && self.gain.is_settled();
        if constant_gain && self.ceiling.is_settled() {
            // The usual span, in one pass; the limiter's own pass only when it has work to do.
            let ceiling = self.ceiling.value as f32;
            if gain_and_flush(out, self.gain.value) > ceiling.to_bits() {
                self.limit(out, ceiling);
            }
            return;
        }
        if constant_gain {
            let gain = self.gain.value;
            for y in out.iter_mut() {
                *y = (*y as f64 * gain) as f32;
            }
        } else {
            for (index, y) in out.iter_mut().enumerate() {
                let target = self.linear_gain(gain_db.at(index));
                self.gain.retarget(target);
                *y = (*y as f64 * self.gain.next()) as f32;
            }
        }
        if self.ceiling.is_settled() {
            self.limit(out, self.ceiling.value as f32);
        } else {
            for y in out.iter_mut() {
                let ceiling = self.ceiling.next() as f32;
                self.limit(std::slice::from_mut(y), ceiling);
            }
        }
    }

    /// The limiter at one ceiling.
    #[inline]
    fn limit(&mut self, out: &mut [f32], ceiling: f32) {
        // Whether the limiter has anything to do: NaN, ±∞ or a sample past the ceiling. A
        // reduction the compiler vectorises; the counting pass below runs only when it does.
        let outside = out.iter().fold(false, |outside, y| {
            outside | y.is_nan() | (y.abs() > ceiling)
        });
        if outside {
            for y in out.iter() {
                self.limiter.events += u64::from(y.is_nan() | (y.abs() > ceiling));
                self.limiter.non_finite += u64::from(!y.is_finite());
            }
        }
        for y in out.iter_mut() {
            let value = *y;
            let clamped = value.clamp(-ceiling, ceiling);
            *y = if value.is_nan() | (value.abs() < f32::MIN_POSITIVE) {
                0.0
            } else {
                clamped
            };
        }
    }
}

/// The output gain, then the limiter's flush of denormals to 0, in one pass: returns the bits of
/// the largest |y| before the flush, which lie past `ceiling`'s exactly when some sample is NaN,
/// infinite or past `ceiling`, the only samples on which the limiter does more
/// (then [`OutputStage::limit`] runs over the result and gives the very bits and counts it gives
/// without the flush: a flushed sample was finite and below 2^−126, under any ceiling, which is
/// at least [`CEILING`]'s minimum, so it counts for nothing, and the limiter makes it 0 too).
/// Compiled like the synthesis for AVX2 and AVX-512 (the same IEEE operations in each lane, so
/// the same bits as the baseline).
#[multiversion(targets("x86_64+avx512f+avx512vl+avx2+avx", "x86_64+avx2+avx"))]
fn gain_and_flush(out: &mut [f32], gain: f64) -> u32 {
    const { assert!(CEILING.min as f32 >= f32::MIN_POSITIVE) };
    // The bits of |y| order as the magnitudes do, and NaN's lie above infinity's: the largest
    // is past the ceiling's exactly when some sample is NaN, infinite or past the ceiling (an
    // integer maximum, where the comparisons themselves would each need a reduction).
    let mut largest = 0;
    for y in out.iter_mut() {
        let value = (*y as f64 * gain) as f32;
        largest = largest.max(magnitude(value));
        *y = if magnitude(value) < f32::MIN_POSITIVE.to_bits() {
            0.0
        } else {
            value
        };
    }
    largest
}

/// |y| as bits: they order as the magnitudes do (NaN's above infinity's), so a maximum over
/// them is an integer maximum, which vectorises where a float `max`, for its NaN rules, does not.
#[inline(always)]
fn magnitude(y: f32) -> u32 {
    y.to_bits() & !(1 << 31)
}

/// The largest |y| of samples that are finite (an output block, which the limiter has been
/// through): what a render reports as its peak. Compiled like [`gain_and_flush`].
#[multiversion(targets("x86_64+avx512f+avx512vl+avx2+avx", "x86_64+avx2+avx"))]
pub fn peak(samples: &[f32]) -> f32 {
    // Below 2^31, the bits also order as an i32's, which the SIMD maximum works on.
    let largest = samples.iter().map(|&y| magnitude(y) as i32).max();
    f32::from_bits(largest.unwrap_or(0) as u32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The gain, then the limiter's pass, as the stage applied them before the one-pass span.
    fn gain_then_limiter(out: &mut [f32], gain: f64, ceiling: f32) -> LimiterCounts {
        let mut stage = OutputStage::new(48_000.0);
        for y in out.iter_mut() {
            *y = (*y as f64 * gain) as f32;
        }
        stage.limit(out, ceiling);
        stage.limiter
    }

    #[test]
    fn the_one_pass_span_gives_the_bits_counts_and_peak_of_gain_then_limiter() {
        let specials = [
            0.0,
            -0.0,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::MIN_POSITIVE / 2.0,
            -1e-45,
            1e-30,
            0.999,
            1.0,
            -1.5,
            f32::MAX,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -f32::NAN,
        ];
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        // Gains that make denormals of ordinary samples and infinities of large ones.
        let gains = [1.0, 0.5011872336272722, 3.98, 1e-36, 1e30];
        let ceilings = [CEILING.min as f32, 0.5, 1.0];
        let mut flushed = 0;
        for round in 0..3000 {
            let len = 1 + round % LONGEST_SPAN;
            // Ordinary samples, with a special one now and then.
            let input: Vec<f32> = (0..len)
                .map(|_| {
                    let bits = next();
                    if bits % 7 == 0 {
                        specials[(bits >> 8) as usize % specials.len()]
                    } else {
                        ((bits >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0) as f32
                    }
                })
                .collect();
            for &gain in &gains {
                for &ceiling in &ceilings {
                    let mut expected = input.clone();
                    let counts = gain_then_limiter(&mut expected, gain, ceiling);
                    let mut stage = OutputStage::new(48_000.0);
                    let mut got = input.clone();
                    let got_peak = stage.gain_and_limit(&mut got, gain, ceiling);
                    let expected_peak = expected.iter().fold(0.0f32, |m, y| m.max(y.abs()));
                    assert_eq!(got_peak.to_bits(), expected_peak.to_bits(), "{input:?}");
                    let bits = |samples: &[f32]| samples.iter().map(|y| y.to_bits()).collect();
                    let (got_bits, expected_bits): (Vec<u32>, Vec<u32>) =
                        (bits(&got), bits(&expected));
                    assert_eq!(got_bits, expected_bits, "gain {gain}, ceiling {ceiling}");
                    assert_eq!(
                        (stage.limiter.events, stage.limiter.non_finite),
                        (counts.events, counts.non_finite),
                        "gain {gain}, ceiling {ceiling}: {input:?}"
                    );
                    flushed += input
                        .iter()
                        .filter(|&&y| {
                            let gained = (y as f64 * gain) as f32;
                            gained != 0.0 && gained.abs() < f32::MIN_POSITIVE
                        })
                        .count();
                }
            }
        }
        // The denormals were there to flush.
        assert!(flushed > 100, "{flushed}");
    }

    /// Spans up to a grid period long, and a little longer (the stage takes any length).
    const LONGEST_SPAN: usize = 70;

    #[test]
    fn a_ramp_reaches_its_target_in_len_samples_in_a_straight_line() {
        let mut ramp = Ramp::settled_at(1.0, 4);
        ramp.retarget(3.0);
        let values: Vec<f64> = (0..6).map(|_| ramp.next()).collect();
        assert_eq!(values, [1.5, 2.0, 2.5, 3.0, 3.0, 3.0]);
    }

    #[test]
    fn skipping_lands_where_stepping_does() {
        let mut stepped = Ramp::settled_at(0.2, 480);
        let mut skipped = stepped;
        stepped.retarget(0.9);
        skipped.retarget(0.9);
        for _ in 0..123 {
            stepped.next();
        }
        skipped.skip(123);
        assert_eq!(stepped.value.to_bits(), skipped.value.to_bits());
    }

    #[test]
    fn a_new_target_mid_ramp_starts_from_the_value_reached() {
        let mut ramp = Ramp::settled_at(0.0, 10);
        ramp.retarget(1.0);
        for _ in 0..5 {
            ramp.next();
        }
        ramp.retarget(0.0);
        assert_eq!(ramp.next(), 0.5 - 0.05);
    }
}
