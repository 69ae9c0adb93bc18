//! The bottle's tilt curves of MODEL.md §2–3: piecewise linear in tilt, constant outside.

/// A piecewise-linear function of tilt in degrees, given by its breakpoints.
pub struct TiltCurve {
    points: &'static [(f64, f64)],
}

/// Which piece of a [`TiltCurve`] a tilt falls in, remembered from one evaluation to the next:
/// piece 0 holds the first value (θ ≤ θ_0), piece i interpolates over (θ_(i−1), θ_i], the last
/// piece holds the last value. The piece before it is kept too, so that a tilt going back and
/// forth between two pieces finds both without a search.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CurveSegment(usize, usize);

impl TiltCurve {
    /// Linear interpolation between breakpoints, held constant beyond the ends.
    pub fn at(&self, tilt_deg: f64) -> f64 {
        self.at_in(tilt_deg, &mut CurveSegment::default())
    }

    /// [`TiltCurve::at`], looking in `segment` first and leaving there the piece `tilt_deg` fell
    /// in: the same value, without a search while the tilt stays in one piece.
    #[inline]
    pub fn at_in(&self, tilt_deg: f64, segment: &mut CurveSegment) -> f64 {
        let points = self.points;
        if !self.contains(segment.0, tilt_deg) {
            let piece = if self.contains(segment.1, tilt_deg) {
                segment.1
            } else {
                points
                    .iter()
                    .position(|&(tilt, _)| tilt_deg <= tilt)
                    .unwrap_or(points.len())
            };
            *segment = CurveSegment(piece, segment.0);
        }
        match segment.0 {
            0 => points[0].1,
            piece if piece == points.len() => points[piece - 1].1,
            piece => {
                let ((t0, v0), (t1, v1)) = (points[piece - 1], points[piece]);
                v0 + (v1 - v0) * (tilt_deg - t0) / (t1 - t0)
            }
        }
    }

    /// [`TiltCurve::at_in`] of every tilt of `tilts`, into `values`: when they all fall in one
    /// piece (a ramp of a span mostly does) the interpolation runs as one loop that vectorises.
    pub fn fill(&self, tilts: &[f64], values: &mut [f64], segment: &mut CurveSegment) {
        let Some(&first) = tilts.first() else {
            return;
        };
        self.at_in(first, segment);
        let piece = segment.0;
        let points = self.points;
        // The piece's bounds as `contains` reads them, checked for every tilt without a branch
        // (NaN fails both comparisons, as it fails `contains`).
        let above = if piece == 0 {
            f64::NEG_INFINITY
        } else {
            points[piece - 1].0
        };
        let up_to = points.get(piece).map_or(f64::INFINITY, |point| point.0);
        let inside = tilts.iter().fold(true, |inside, &tilt| {
            inside & ((tilt > above || piece == 0) & (tilt <= up_to || piece == points.len()))
        });
        if !inside {
            for (value, &tilt) in values.iter_mut().zip(tilts) {
                *value = self.at_in(tilt, segment);
            }
            return;
        }
        if piece == 0 || piece == points.len() {
            values.fill(self.at_in(first, segment));
            return;
        }
        let ((t0, v0), (t1, v1)) = (points[piece - 1], points[piece]);
        let (rise, run) = (v1 - v0, t1 - t0);
        for (value, &tilt) in values.iter_mut().zip(tilts) {
            *value = v0 + rise * (tilt - t0) / run;
        }
    }

    /// The largest value at any tilt: a breakpoint's, the curve being linear between them and
    /// held beyond them.
    pub fn max(&self) -> f64 {
        self.points
            .iter()
            .map(|&(_, value)| value)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Whether `tilt_deg` lies in piece `piece`.
    #[inline]
    fn contains(&self, piece: usize, tilt_deg: f64) -> bool {
        let points = self.points;
        let above_start = piece == 0 || tilt_deg > points[piece - 1].0;
        let below_end = piece >= points.len() || tilt_deg <= points[piece].0;
        above_start && below_end && piece <= points.len()
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
    fn a_remembered_segment_gives_the_same_values_as_a_search() {
        for curve in [&REST, &SUBMERGED, &FLOW] {
            let mut segment = CurveSegment::default();
            // Up, down, jumps, the breakpoints themselves, beyond both ends, and NaN.
            let mut tilts: Vec<f64> = (-40..=800).map(|i| i as f64 * 0.25).collect();
            tilts.extend((0..=800).rev().map(|i| i as f64 * 0.2293));
            tilts.extend(curve.points.iter().map(|p| p.0));
            tilts.extend([179.0, 0.5, 100.0, 100.0, 60.0, f64::NAN, 90.0, -0.0]);
            for tilt in tilts {
                let searched = curve.at(tilt);
                let remembered = curve.at_in(tilt, &mut segment);
                assert_eq!(searched.to_bits(), remembered.to_bits(), "at {tilt}");
                assert_eq!(
                    searched.to_bits(),
                    old_at(curve, tilt).to_bits(),
                    "at {tilt}"
                );
            }
        }
    }

    #[test]
    fn a_span_of_tilts_gets_the_values_of_one_by_one() {
        let mut tilts: Vec<f64> = (0..64).map(|i| 90.0 + i as f64 * 0.001_37).collect();
        for (start, step) in [(99.99, 0.0001), (59.0, 0.05), (134.0, 0.03), (179.0, 0.5)] {
            tilts.extend((0..64).map(|i| start + i as f64 * step));
        }
        tilts.extend([f64::NAN, 3.0, 170.0]);
        for curve in [&REST, &SUBMERGED, &FLOW] {
            for span in tilts.chunks(64) {
                let mut values = vec![0.0; span.len()];
                curve.fill(span, &mut values, &mut CurveSegment::default());
                for (value, &tilt) in values.iter().zip(span) {
                    assert_eq!(value.to_bits(), curve.at(tilt).to_bits(), "at {tilt}");
                }
            }
        }
    }

    /// The evaluation as it was before segments were remembered: the definition they follow.
    fn old_at(curve: &TiltCurve, tilt_deg: f64) -> f64 {
        let points = curve.points;
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

    #[test]
    fn curves_interpolate_linearly_between_breakpoints() {
        assert!((FLOW.at(145.0) - 1.0).abs() < 1e-15);
        assert!((FLOW.at(102.5) - (0.333 + 0.833) / 2.0).abs() < 1e-12);
        assert!((REST.at(87.0) - (0.5 + 0.333) / 2.0).abs() < 1e-12);
        assert!((SUBMERGED.at(125.0) - 0.025).abs() < 1e-12);
    }
}
