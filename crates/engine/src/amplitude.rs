//! The amplitude law of MODEL.md §5 and §12: a(V) = max(0, (V − V0)/(C − V0)), 1 for a full
//! bottle and 0 from V0 down, V0 by default where the paper's fit at 135° reaches 0.

/// Slope of the paper's fit Asum = 0.0027·V − 0.2277 (fig. 7; V in ml of its 300 ml bottle).
const FIT_SLOPE_PER_ML: f64 = 0.0027;
const FIT_OFFSET: f64 = 0.2277;
/// The paper's bottle, in which the fit's V is measured.
const FIT_CAPACITY_ML: f64 = 300.0;
/// Asum of a full bottle, so a(C) = 1.
const FULL_BOTTLE_ASUM: f64 = FIT_SLOPE_PER_ML * FIT_CAPACITY_ML - FIT_OFFSET;

/// Where the paper's fit reaches 0 in its own bottle: 84.333… ml of 300.
pub const PAPERS_SILENT_BELOW_ML: f64 = FIT_OFFSET / FIT_SLOPE_PER_ML;

/// V0 of MODEL.md §12: the residual volume from which down a unit is silent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SilentBelow {
    /// The paper's, scaled to the capacity C (the default): [`PAPERS_SILENT_BELOW_ML`] of 300 ml.
    /// Held as such rather than as a number, so that it follows C as it changes, and so that
    /// a(V) keeps the paper's own arithmetic, which rounds differently from the general form:
    /// every render from before V0 became data stays byte-identical.
    PapersFit,
    /// A model's own V0 (ml), 0 ≤ V0 < C.
    Ml(f64),
}

impl SilentBelow {
    /// V0 in a bottle of `capacity_ml` (ml).
    pub fn ml(self, capacity_ml: f64) -> f64 {
        match self {
            Self::PapersFit => PAPERS_SILENT_BELOW_ML * (capacity_ml / FIT_CAPACITY_ML),
            Self::Ml(ml) => ml,
        }
    }

    /// Whether V0 lies within 0 ≤ V0 < C in a bottle of `capacity_ml` (false for NaN).
    pub fn fits(self, capacity_ml: f64) -> bool {
        let ml = self.ml(capacity_ml);
        ml >= 0.0 && ml < capacity_ml
    }

    /// Brought into range (MODEL.md §11) for a bottle of `capacity_ml`, itself in range: NaN
    /// becomes the default, below 0 becomes 0, C or more the largest volume below C.
    pub fn sanitized(self, capacity_ml: f64) -> Self {
        match self {
            Self::Ml(ml) if ml.is_nan() => Self::PapersFit,
            Self::Ml(ml) => Self::Ml(ml.clamp(0.0, capacity_ml.next_down())),
            Self::PapersFit => Self::PapersFit,
        }
    }

    /// a(V): a unit's summed amplitude at residual volume `volume_ml` of a `capacity_ml` bottle,
    /// before any spread; V0 must fit (see [`SilentBelow::sanitized`]).
    pub fn amplitude(self, volume_ml: f64, capacity_ml: f64) -> f64 {
        match self {
            Self::PapersFit => {
                let in_papers_bottle_ml = FIT_CAPACITY_ML * volume_ml / capacity_ml;
                (FIT_SLOPE_PER_ML * in_papers_bottle_ml - FIT_OFFSET).max(0.0) / FULL_BOTTLE_ASUM
            }
            Self::Ml(silent_ml) => ((volume_ml - silent_ml) / (capacity_ml - silent_ml)).max(0.0),
        }
    }
}

/// G = 10^(dB/20).
pub fn db_to_gain(gain_db: f64) -> f64 {
    10f64.powf(gain_db / 20.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    const PAPERS: SilentBelow = SilentBelow::PapersFit;

    #[test]
    fn full_bottle_is_unity_and_zero_crossing_is_near_84_ml() {
        assert!((PAPERS.amplitude(300.0, 300.0) - 1.0).abs() < 1e-12);
        assert!((PAPERS_SILENT_BELOW_ML - 84.333).abs() < 1e-3);
        assert_eq!(PAPERS.amplitude(84.0, 300.0), 0.0);
        assert!(PAPERS.amplitude(85.0, 300.0) > 0.0);
        assert_eq!(PAPERS.amplitude(0.0, 300.0), 0.0);
    }

    #[test]
    fn law_is_linear_above_its_zero_and_scales_with_capacity() {
        let mid = PAPERS.amplitude(200.0, 300.0);
        assert!((mid - (0.0027 * 200.0 - 0.2277) / 0.5823).abs() < 1e-12);
        assert!((PAPERS.amplitude(400.0, 600.0) - mid).abs() < 1e-12);
        assert_eq!(PAPERS.ml(600.0), 2.0 * PAPERS_SILENT_BELOW_ML);
    }

    #[test]
    fn the_default_keeps_the_arithmetic_of_every_render_before_v0_was_data() {
        // Bit for bit, so that those renders stay byte-identical (MODEL.md §5).
        let before = |volume_ml: f64, capacity_ml: f64| {
            (0.0027 * (300.0 * volume_ml / capacity_ml) - 0.2277).max(0.0)
                / (0.0027 * 300.0 - 0.2277)
        };
        for capacity_ml in [1.0, 180.0, 300.0, 720.0, 1234.5, 100_000.0] {
            for step in 0..=10_000 {
                let volume_ml = capacity_ml * step as f64 / 10_000.0;
                assert_eq!(
                    PAPERS.amplitude(volume_ml, capacity_ml).to_bits(),
                    before(volume_ml, capacity_ml).to_bits(),
                    "V {volume_ml} of {capacity_ml}"
                );
            }
        }
    }

    #[test]
    fn the_papers_arithmetic_is_the_general_law_at_the_papers_v0() {
        // The same function, to a few units in the last place: the general form is the rule.
        for capacity_ml in [1.0, 180.0, 300.0, 720.0, 1234.5, 100_000.0] {
            let silent_ml = PAPERS.ml(capacity_ml);
            let general = SilentBelow::Ml(silent_ml);
            for step in 0..=1000 {
                let volume_ml = capacity_ml * step as f64 / 1000.0;
                let (papers, ours) = (
                    PAPERS.amplitude(volume_ml, capacity_ml),
                    general.amplitude(volume_ml, capacity_ml),
                );
                assert!(
                    (papers - ours).abs() <= 1e-14,
                    "V {volume_ml} of {capacity_ml}"
                );
                assert_eq!(papers == 0.0, ours == 0.0, "V {volume_ml} of {capacity_ml}");
            }
        }
    }

    #[test]
    fn a_v0_of_its_own_is_the_general_law_and_is_brought_into_range() {
        let own = SilentBelow::Ml(100.0);
        assert_eq!(own.amplitude(300.0, 300.0), 1.0);
        assert_eq!(own.amplitude(200.0, 300.0), 0.5);
        assert_eq!(own.amplitude(100.0, 300.0), 0.0);
        assert_eq!(own.amplitude(50.0, 300.0), 0.0);
        assert!(own.fits(300.0) && !own.fits(100.0) && !SilentBelow::Ml(-1.0).fits(300.0));
        assert_eq!(SilentBelow::Ml(f64::NAN).sanitized(300.0), PAPERS);
        assert_eq!(SilentBelow::Ml(-5.0).sanitized(300.0), SilentBelow::Ml(0.0));
        let at_capacity = SilentBelow::Ml(f64::INFINITY).sanitized(300.0);
        assert!(at_capacity.fits(300.0));
        // Just below C, a full bottle still gives 1 and anything less 0: finite either way.
        assert_eq!(at_capacity.amplitude(300.0, 300.0), 1.0);
        assert_eq!(at_capacity.amplitude(299.9, 300.0), 0.0);
    }
}
