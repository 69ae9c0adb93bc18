//! The bottle's tilt curves of MODEL.md §2–3: piecewise linear in tilt, constant outside.

/// A piecewise-linear function of tilt in degrees, given by its breakpoints.
pub struct TiltCurve {
    points: &'static [(f64, f64)],
}

impl TiltCurve {
    /// Linear interpolation between breakpoints, held constant beyond the ends.
    pub fn at(&self, tilt_deg: f64) -> f64 {
        let points = self.points;
        let (first_tilt, first_value) = points[0];
        if tilt_deg <= first_tilt {
            return first_value;
        }
        for pair in points.windows(2) {
            let ((t0, v0), (t1, v1)) = (pair[0], pair[1]);
            if tilt_deg <= t1 {
                return v0 + (v1 - v0) * (tilt_deg - t0) / (t1 - t0);
            }
        }
        points[points.len() - 1].1
    }
}

/// r(θ): fraction of capacity that stays in the bottle at this tilt (§2).
pub const REST: TiltCurve = TiltCurve {
    points: &[
        (0.0, 1.0),
        (60.0, 1.0),
        (74.5, 0.833),
        (79.0, 0.667),
        (84.0, 0.5),
        (90.0, 0.333),
        (96.0, 0.167),
        (100.0, 0.083),
        (115.0, 0.0),
        (180.0, 0.0),
    ],
};

/// s(θ): fraction of capacity above which the mouth is submerged and pours glug (§2).
pub const SUBMERGED: TiltCurve = TiltCurve {
    points: &[
        (0.0, 1.0),
        (60.0, 1.0),
        (90.0, 0.687),
        (100.0, 0.367),
        (115.0, 0.05),
        (135.0, 0.0),
        (180.0, 0.0),
    ],
};

/// h(θ): outflow rate relative to the rate at the 135° reference tilt (§3).
pub const FLOW: TiltCurve = TiltCurve {
    points: &[
        (0.0, 0.0),
        (60.0, 0.1),
        (90.0, 0.333),
        (115.0, 0.833),
        (135.0, 1.0),
        (155.0, 1.0),
        (180.0, 0.733),
    ],
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curves_pass_through_their_breakpoints_and_hold_outside() {
        assert_eq!(REST.at(79.0), 0.667);
        assert_eq!(SUBMERGED.at(100.0), 0.367);
        assert_eq!(FLOW.at(135.0), 1.0);
        assert_eq!(FLOW.at(-10.0), 0.0);
        assert_eq!(FLOW.at(200.0), 0.733);
        assert_eq!(REST.at(200.0), 0.0);
    }

    #[test]
    fn curves_interpolate_linearly_between_breakpoints() {
        assert!((FLOW.at(145.0) - 1.0).abs() < 1e-15);
        assert!((FLOW.at(102.5) - (0.333 + 0.833) / 2.0).abs() < 1e-12);
        assert!((REST.at(87.0) - (0.5 + 0.333) / 2.0).abs() < 1e-12);
        assert!((SUBMERGED.at(125.0) - 0.025).abs() < 1e-12);
    }
}
