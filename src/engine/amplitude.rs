//! The amplitude law of MODEL.md §5 (the paper's fit at 135°), normalised to 1 for a full bottle.

/// Slope of the paper's fit Asum = 0.0027·V − 0.2277 (V in ml of its 300 ml bottle).
const FIT_SLOPE_PER_ML: f64 = 0.0027;
const FIT_OFFSET: f64 = 0.2277;
/// The paper's bottle, in which the fit's V is measured.
const FIT_CAPACITY_ML: f64 = 300.0;
/// Asum of a full bottle, so a(C) = 1.
const FULL_BOTTLE_ASUM: f64 = FIT_SLOPE_PER_ML * FIT_CAPACITY_ML - FIT_OFFSET;

/// a(V): the unit's summed amplitude at residual volume `volume_ml` of a `capacity_ml` bottle.
/// Zero below ≈ 28 % of capacity, where the fit says the last liquid pours without vibration.
pub fn unit_amplitude(volume_ml: f64, capacity_ml: f64) -> f64 {
    let scaled = FIT_CAPACITY_ML * volume_ml / capacity_ml;
    (FIT_SLOPE_PER_ML * scaled - FIT_OFFSET).max(0.0) / FULL_BOTTLE_ASUM
}

/// G = 10^(dB/20).
pub fn db_to_gain(gain_db: f64) -> f64 {
    10f64.powf(gain_db / 20.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_bottle_is_unity_and_zero_crossing_is_near_84_ml() {
        assert!((unit_amplitude(300.0, 300.0) - 1.0).abs() < 1e-12);
        let zero_at = FIT_OFFSET / FIT_SLOPE_PER_ML;
        assert!((zero_at - 84.333).abs() < 1e-3);
        assert_eq!(unit_amplitude(84.0, 300.0), 0.0);
        assert!(unit_amplitude(85.0, 300.0) > 0.0);
        assert_eq!(unit_amplitude(0.0, 300.0), 0.0);
    }

    #[test]
    fn law_is_linear_above_its_zero_and_scales_with_capacity() {
        let mid = unit_amplitude(200.0, 300.0);
        assert!((mid - (0.0027 * 200.0 - 0.2277) / 0.5823).abs() < 1e-12);
        assert!((unit_amplitude(400.0, 600.0) - mid).abs() < 1e-12);
    }
}
