//! Decides when the host's transport asks for a MODEL.md §8 reset: the transport starting, or the
//! playhead jumping (a locate, a loop wrapping). Plain Rust, fed with what the host reports.

/// Positions closer than this to the expected one are not a jump: hosts that report seconds or
/// beats lose a sample to rounding.
const JUMP_TOLERANCE_SAMPLES: i64 = 2;

/// Watches the host's transport and tells when a MODEL.md §8 reset is due.
#[derive(Debug, Clone, Copy, Default)]
pub struct TransportWatch {
    was_playing: bool,
    /// The last position the host reported that differed from the one before, and the samples
    /// processed since. nice-plug may split one host block into several `process()` calls that
    /// all carry the block's start position; those are not jumps.
    anchor: Option<(i64, i64)>,
}

impl TransportWatch {
    /// Forgets the transport's state, as after activation.
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// Call at the start of every `process()`; true when the bottle must be reset before it.
    pub fn observe(&mut self, playing: bool, position: Option<i64>) -> bool {
        let started = playing && !self.was_playing;
        self.was_playing = playing;
        if !playing {
            self.anchor = None;
            return started;
        }
        let Some(position) = position else {
            self.anchor = None;
            return started;
        };
        let jumped = match self.anchor {
            Some((anchor, _)) if anchor == position => false,
            Some((anchor, since)) => (position - (anchor + since)).abs() > JUMP_TOLERANCE_SAMPLES,
            None => false,
        };
        if self.anchor.is_none_or(|(anchor, _)| anchor != position) {
            self.anchor = Some((position, 0));
        }
        started || jumped
    }

    /// Call after rendering `samples` samples.
    pub fn advance(&mut self, samples: usize) {
        if let Some((_, since)) = &mut self.anchor {
            *since += samples as i64;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn start_resets_and_continuous_play_does_not() {
        let mut watch = TransportWatch::default();
        assert!(!watch.observe(false, Some(0)));
        watch.advance(512);
        assert!(watch.observe(true, Some(1000)));
        watch.advance(512);
        assert!(!watch.observe(true, Some(1512)));
        watch.advance(512);
        assert!(!watch.observe(true, Some(2024)));
    }

    #[test]
    fn jump_resets_but_split_blocks_and_rounding_do_not() {
        let mut watch = TransportWatch::default();
        assert!(watch.observe(true, Some(0)));
        watch.advance(100);
        // A split block that still carries the host block's start.
        assert!(!watch.observe(true, Some(0)));
        watch.advance(412);
        assert!(!watch.observe(true, Some(513)));
        watch.advance(512);
        assert!(watch.observe(true, Some(48_000)), "a locate is a jump");
        watch.advance(512);
        assert!(watch.observe(true, Some(0)), "a loop wrapping is a jump");
    }

    #[test]
    fn stopping_and_restarting_resets_again() {
        let mut watch = TransportWatch::default();
        assert!(watch.observe(true, Some(0)));
        watch.advance(64);
        assert!(!watch.observe(false, Some(64)));
        assert!(watch.observe(true, Some(64)));
    }
}
