//! The glide of MODEL.md §5.2: a component's frequency may start away from its own and approach
//! it exponentially, as a real glug sweeps down into the cavity's resonance as the bubble forms,
//! or up as it rises and shrinks. With both ratios at 1 nothing of it is computed.

/// The lowest frequency a component sounds at (Hz, MODEL.md §6): below it a mode is no glug but
/// a rumble under hearing (a fitted headspace law carried far beyond its recordings can drive f1
/// there), so it is omitted as one at or above Nyquist is.
pub const LOWEST_SOUNDING_HZ: f64 = 20.0;

/// How each component's frequency glides into its own from the unit's onset.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Glide {
    /// ρ1, ρ2: the start frequency over the component's own; 1 is no glide, above 1 a glide
    /// down into the mode, below 1 a glide up.
    pub ratio: [f64; 2],
    /// τ1, τ2: the time constant of the approach (ms).
    pub time_ms: [f64; 2],
}

impl Glide {
    /// Whether component `index` glides (one that does not is computed as if there were no rule).
    #[inline]
    pub fn glides(&self, index: usize) -> bool {
        self.ratio[index] != 1.0
    }

    /// The highest frequency component `index` reaches over a unit whose own is `frequency_hz`:
    /// its start frequency if it glides down, its own otherwise (what §6 holds below Nyquist).
    #[inline]
    pub fn highest_hz(&self, index: usize, frequency_hz: f64) -> f64 {
        if self.ratio[index] > 1.0 {
            frequency_hz * self.ratio[index]
        } else {
            frequency_hz
        }
    }

    /// Whether component `index` of a unit whose own frequency is `frequency_hz` sounds at
    /// `sample_rate` (MODEL.md §6): its own frequency at or above [`LOWEST_SOUNDING_HZ`] and the
    /// highest it reaches below Nyquist.
    #[inline]
    pub fn sounds(&self, index: usize, frequency_hz: f64, sample_rate: f64) -> bool {
        frequency_hz >= LOWEST_SOUNDING_HZ
            && self.highest_hz(index, frequency_hz) < 0.5 * sample_rate
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ratio_of_1_is_no_glide_and_a_glide_down_starts_highest() {
        let glide = Glide {
            ratio: [1.0, 2.5],
            time_ms: [20.0, 5.0],
        };
        assert!(!glide.glides(0));
        assert!(glide.glides(1));
        assert_eq!(glide.highest_hz(0, 300.0), 300.0);
        assert_eq!(glide.highest_hz(1, 300.0), 750.0);
        let up = Glide {
            ratio: [0.5, 1.0],
            ..glide
        };
        assert_eq!(up.highest_hz(0, 300.0), 300.0);
    }
}
