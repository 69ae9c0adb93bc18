//! The headspace law of MODEL.md §5.1: a component's frequency may follow the air above the
//! liquid, as a real bottle's glug falls in pitch while it empties (a Helmholtz cavity whose air
//! grows). With both exponents at 0, the paper's constant frequencies, it changes nothing.

/// The air above the liquid and how each component's frequency follows it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Headspace {
    /// H: the air above a full bottle's liquid, in its neck and shoulder (ml).
    pub headspace_ml: f64,
    /// γ1, γ2: f_k,i = f_k · ((H + b) / (H + C − V_i))^γ_k; ½ for a Helmholtz cavity, 0 for the
    /// paper's constant frequency, negative for a mode that rises as the bottle empties.
    pub exponent: [f64; 2],
}

impl Headspace {
    /// Whether any component follows the headspace (a render without it skips the law).
    #[inline]
    pub fn is_active(&self) -> bool {
        self.exponent != [0.0, 0.0]
    }

    /// Each component's factor on its quoted frequency for a unit that starts at `volume_ml` in a
    /// bottle of `capacity_ml` whose pocket is `pocket_ml`: 1 for an exponent of 0, whatever the
    /// volume. The frequencies are quoted at a full bottle's first glug, one pocket poured
    /// (V_ref = C − b), where the factor is 1.
    #[inline]
    pub fn factors(&self, volume_ml: f64, capacity_ml: f64, pocket_ml: f64) -> [f64; 2] {
        // V ≤ C always; held there so that no input makes the air less than H (and H > 0).
        let air_ml = self.headspace_ml + (capacity_ml - volume_ml).max(0.0);
        let ratio = (self.headspace_ml + pocket_ml) / air_ml;
        self.exponent.map(|exponent| {
            if exponent == 0.0 {
                1.0
            } else {
                ratio.powf(exponent)
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_helmholtz_cavity_falls_as_the_square_root_of_its_air() {
        let law = Headspace {
            headspace_ml: 20.0,
            exponent: [0.5, -0.1],
        };
        let [low, high] = law.factors(220.0, 300.0, 5.0);
        assert!((low - (25.0f64 / 100.0).sqrt()).abs() < 1e-15);
        assert!((high - (25.0f64 / 100.0).powf(-0.1)).abs() < 1e-15);
        assert_eq!(law.factors(295.0, 300.0, 5.0), [1.0, 1.0]);
    }

    #[test]
    fn an_exponent_of_0_is_exactly_1() {
        let law = Headspace {
            headspace_ml: 0.001,
            exponent: [0.0, 0.0],
        };
        assert!(!law.is_active());
        assert_eq!(law.factors(0.0, 100_000.0, 1_000.0), [1.0, 1.0]);
    }
}
