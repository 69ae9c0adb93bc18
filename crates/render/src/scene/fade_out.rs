//! The fade that ends a trimmed render (`--trim`, MODEL.md §10.2): part of the scene, which the
//! renderer applies; where it goes is `crate::trim`'s to find.

/// A fade to silence over the samples `start..end`, where the render ends: a raised cosine
/// whose last sample is 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FadeOut {
    /// The first sample the fade lowers.
    pub start: u64,
    /// The sample after the last: the render's end.
    pub end: u64,
}

impl FadeOut {
    /// The gain of sample `sample`: 1 before the fade, 0 after it.
    pub fn gain(&self, sample: u64) -> f32 {
        if sample < self.start {
            return 1.0;
        }
        if sample >= self.end {
            return 0.0;
        }
        let step = (sample - self.start + 1) as f64 / (self.end - self.start) as f64;
        (0.5 * (1.0 + (std::f64::consts::PI * step).cos())) as f32
    }

    /// Fades the samples of `block`, whose first sample is `position`.
    pub(crate) fn apply(&self, position: u64, block: &mut [f32]) {
        let block_end = position + block.len() as u64;
        if block_end <= self.start {
            return;
        }
        let first = self.start.saturating_sub(position) as usize;
        for (index, sample) in block.iter_mut().enumerate().skip(first) {
            *sample *= self.gain(position + index as u64);
        }
    }
}
