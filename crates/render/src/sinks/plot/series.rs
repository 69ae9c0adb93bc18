//! The pour plot's series, each kept within a bound however long the render: the waveform as
//! the extremes of buckets of samples, the bottle's volume thinned.

/// The rendered waveform as the plot draws it: the lowest and highest of every `per_bucket`
/// samples, one sample a bucket at first. Whenever the buckets reach [`Waveform::MAX_BUCKETS`]
/// neighbours are merged and each bucket from then on takes twice as many samples, so its
/// memory is bounded however long the render. Up to `MAX_BUCKETS` samples (43 s at 48 kHz) it
/// holds every sample and the plot is exactly that of the samples; beyond, a pixel column's
/// stroke may take in up to one bucket of its neighbours (never less than its own samples).
#[derive(Debug, Clone)]
pub struct Waveform {
    /// `(lowest, highest)` sample of each bucket.
    buckets: Vec<(f32, f32)>,
    per_bucket: u64,
    samples: u64,
}

impl Default for Waveform {
    fn default() -> Self {
        Self {
            buckets: Vec::new(),
            per_bucket: 1,
            samples: 0,
        }
    }
}

impl Waveform {
    /// The most buckets kept.
    pub const MAX_BUCKETS: usize = 1 << 21;
    /// The most bytes the buckets take.
    pub(super) const MAX_BYTES: u64 =
        (Self::MAX_BUCKETS * std::mem::size_of::<(f32, f32)>()) as u64;

    /// The waveform of `samples`.
    pub fn of(samples: &[f32]) -> Self {
        let mut waveform = Self::default();
        waveform.extend(samples);
        waveform
    }

    /// Appends the next samples.
    pub fn extend(&mut self, mut samples: &[f32]) {
        while !samples.is_empty() {
            let filled = self.samples % self.per_bucket;
            if filled == 0 {
                if self.buckets.len() == Self::MAX_BUCKETS {
                    self.merge_neighbours();
                }
                self.buckets.push((f32::INFINITY, f32::NEG_INFINITY));
            }
            let room = self.per_bucket - filled;
            let (these, rest) = samples.split_at(room.min(samples.len() as u64) as usize);
            if let Some(bucket) = self.buckets.last_mut() {
                *bucket = these
                    .iter()
                    .fold(*bucket, |(low, high), &y| (low.min(y), high.max(y)));
            }
            self.samples += these.len() as u64;
            samples = rest;
        }
    }

    /// Halves the buckets, each now of twice the samples. Called when they are all full, so a
    /// new bucket starts right after.
    fn merge_neighbours(&mut self) {
        let merged: Vec<(f32, f32)> = self
            .buckets
            .chunks(2)
            .map(|pair| {
                pair.iter().fold(
                    (f32::INFINITY, f32::NEG_INFINITY),
                    |(low, high), &(l, h)| (low.min(l), high.max(h)),
                )
            })
            .collect();
        self.buckets.clear();
        self.buckets.extend(merged);
        self.per_bucket *= 2;
    }

    /// Samples appended so far.
    pub fn len(&self) -> u64 {
        self.samples
    }

    /// Whether no sample was appended.
    pub fn is_empty(&self) -> bool {
        self.samples == 0
    }

    /// The lowest and highest sample of `first..last` (not empty), taking in the whole buckets
    /// these fall in.
    pub(super) fn range(&self, first: u64, last: u64) -> (f32, f32) {
        let buckets = (first / self.per_bucket) as usize..=((last - 1) / self.per_bucket) as usize;
        self.buckets[buckets].iter().fold(
            (f32::INFINITY, f32::NEG_INFINITY),
            |(low, high), &(l, h)| (low.min(l), high.max(h)),
        )
    }

    /// The largest |sample|.
    pub(super) fn peak(&self) -> f32 {
        self.buckets
            .iter()
            .map(|&(low, high)| low.abs().max(high.abs()))
            .fold(0.0, f32::max)
    }
}

/// `(t, V)`: the volume at the start and at every report of the bottle, thinned like
/// [`Waveform`]: past [`BottleSeries::MAX_POINTS`] every other point is dropped and only every
/// other report kept from then on (the last one always), so a day's render keeps as many points
/// as the first 3 h at 100 a second.
pub(super) struct BottleSeries {
    points: Vec<(f64, f64)>,
    /// Reports since the start, the one kept at the start counted as 0.
    reports: u64,
    keep_every: u64,
    last: (f64, f64),
}

impl BottleSeries {
    const MAX_POINTS: usize = 1 << 20;
    /// The most bytes the points take.
    pub(super) const MAX_BYTES: u64 = (Self::MAX_POINTS * std::mem::size_of::<(f64, f64)>()) as u64;

    pub(super) fn starting_at(volume_ml: f64) -> Self {
        Self {
            points: vec![(0.0, volume_ml)],
            reports: 0,
            keep_every: 1,
            last: (0.0, volume_ml),
        }
    }

    pub(super) fn push(&mut self, point: (f64, f64)) {
        self.reports += 1;
        self.last = point;
        if !self.reports.is_multiple_of(self.keep_every) {
            return;
        }
        if self.points.len() == Self::MAX_POINTS {
            let mut kept = false;
            self.points.retain(|_| {
                kept = !kept;
                kept
            });
            self.keep_every *= 2;
            if !self.reports.is_multiple_of(self.keep_every) {
                return;
            }
        }
        self.points.push(point);
    }

    pub(super) fn into_points(mut self) -> Vec<(f64, f64)> {
        if self.points.last() != Some(&self.last) {
            self.points.push(self.last);
        }
        self.points
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Past its bound the waveform merges buckets: its memory stays bounded, and every range
    /// still takes in every sample's extremes.
    #[test]
    fn the_waveform_stays_bounded_and_keeps_every_extreme() {
        let samples: Vec<f32> = (0..5 * Waveform::MAX_BUCKETS + 3)
            .map(|i| ((i as f32) * 0.001).sin() * (1.0 + i as f32 * 1e-7))
            .collect();
        let mut waveform = Waveform::default();
        for block in samples.chunks(4096) {
            waveform.extend(block);
        }
        assert_eq!(waveform.len(), samples.len() as u64);
        assert!(waveform.buckets.len() <= Waveform::MAX_BUCKETS);
        assert_eq!(waveform.per_bucket, 8);
        let exact = |range: std::ops::Range<usize>| {
            samples[range]
                .iter()
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(l, h), &y| {
                    (l.min(y), h.max(y))
                })
        };
        for (first, last) in [(0, 1), (5, 6), (1_000_000, 3_333_333), (0, samples.len())] {
            let (low, high) = waveform.range(first as u64, last as u64);
            let (exact_low, exact_high) = exact(first..last);
            assert!(low <= exact_low && high >= exact_high, "{first}..{last}");
        }
        let peak = samples.iter().fold(0.0f32, |peak, y| peak.max(y.abs()));
        assert_eq!(waveform.peak(), peak);
        // Below the bound it is exact.
        let short = Waveform::of(&samples[..1000]);
        assert_eq!(short.range(10, 500), exact(10..500));
    }

    #[test]
    fn the_bottle_series_stays_bounded_and_keeps_its_ends() {
        let mut series = BottleSeries::starting_at(300.0);
        let reports = 3 * BottleSeries::MAX_POINTS + 7;
        for report in 1..=reports {
            series.push((report as f64, 300.0 - report as f64 * 1e-4));
        }
        let points = series.into_points();
        assert!(points.len() <= BottleSeries::MAX_POINTS + 1);
        assert_eq!(points[0], (0.0, 300.0));
        assert_eq!(points.last().unwrap().0, reports as f64);
        assert!(points.windows(2).all(|pair| pair[0].0 < pair[1].0));
    }
}
