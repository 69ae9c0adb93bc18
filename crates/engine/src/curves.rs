//! The bottle's tilt curves of MODEL.md §2–3: piecewise linear in tilt, constant outside. They
//! are data (MODEL.md §12): a scene may give its own, checked here; the defaults are below.

use std::ops::RangeInclusive;

/// The most points a curve holds (MODEL.md §12). Curves sit inline in the model's constants,
/// which the plugin hands to the engine on every `process()` call: a fixed size keeps them
/// `Copy` and free of allocation. Sixteen is more than any measured bottle needs (the default
/// rest curve has ten).
pub const MAX_CURVE_POINTS: usize = 16;

/// A piecewise-linear function of tilt in degrees, given by its breakpoints: linear between
/// them, constant outside them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TiltCurve {
    /// The first `len` hold the breakpoints; the rest are unused.
    points: [(f64, f64); MAX_CURVE_POINTS],
    len: usize,
}

/// Why a list of points is no curve (MODEL.md §12).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum CurveError {
    /// Fewer than two points, or more than [`MAX_CURVE_POINTS`].
    #[error("{count} points; a curve has {MIN_CURVE_POINTS} to {MAX_CURVE_POINTS}")]
    PointCount {
        /// The number of points given.
        count: usize,
    },
    /// A tilt outside 0…180°, or not above the one before it.
    #[error(
        "point {index} is at {tilt_deg}°; tilts must lie within 0 to 180 and increase strictly"
    )]
    Tilt {
        /// Index of the point, from 0.
        index: usize,
        /// Its tilt (°).
        tilt_deg: f64,
    },
    /// A value outside 0…1.
    #[error("point {index} has the value {value}; values must lie within 0 to 1")]
    Value {
        /// Index of the point, from 0.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A curve that must pass through a given point does not (h(135°) = 1).
    #[error("its value at {tilt_deg}° is {value}; it must be {required} there")]
    Anchor {
        /// The tilt it is held to (°).
        tilt_deg: f64,
        /// Its value there.
        value: f64,
        /// The value required there.
        required: f64,
    },
}

/// The fewest points a curve has.
const MIN_CURVE_POINTS: usize = 2;
/// The values a curve may take: fractions of the capacity, or of the rate at 135°.
const VALUES: RangeInclusive<f64> = 0.0..=1.0;

/// The tilt at which a full bottle empties in the pour time T (MODEL.md §1, §3): the drain
/// curve is 1 there.
pub const REFERENCE_TILT_DEG: f64 = 135.0;

/// The bottle's three curves (MODEL.md §2, §3): the defaults, or a model's own (§12).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BottleCurves {
    /// r(θ): the fraction of the capacity that stays in the bottle at this tilt (§2).
    pub rest: TiltCurve,
    /// s(θ): the fraction of the capacity above which the mouth is submerged and the pour
    /// glugs (§2).
    pub submerged: TiltCurve,
    /// h(θ): the outflow rate relative to the rate at [`REFERENCE_TILT_DEG`] (§3).
    pub drain: TiltCurve,
}

impl Default for BottleCurves {
    fn default() -> Self {
        Self {
            rest: REST,
            submerged: SUBMERGED,
            drain: DRAIN,
        }
    }
}

/// Which piece of a [`TiltCurve`] a tilt falls in, remembered from one evaluation to the next:
/// piece 0 holds the first value (θ ≤ θ_0), piece i interpolates over (θ_(i−1), θ_i], the last
/// piece holds the last value. The piece before it is kept too, so that a tilt going back and
/// forth between two pieces finds both without a search.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CurveSegment(usize, usize);

impl TiltCurve {
    /// The curve through `points` (tilt in degrees, value), checked as MODEL.md §12 asks: two to
    /// [`MAX_CURVE_POINTS`] points, tilts strictly increasing within `tilts` (the tilt control's
    /// range, which its table declares), values within 0…1.
    pub fn new(points: &[(f64, f64)], tilts: RangeInclusive<f64>) -> Result<Self, CurveError> {
        let count = points.len();
        if !(MIN_CURVE_POINTS..=MAX_CURVE_POINTS).contains(&count) {
            return Err(CurveError::PointCount { count });
        }
        let mut previous = f64::NEG_INFINITY;
        for (index, &(tilt_deg, value)) in points.iter().enumerate() {
            if !(tilts.contains(&tilt_deg) && tilt_deg > previous) {
                return Err(CurveError::Tilt { index, tilt_deg });
            }
            if !VALUES.contains(&value) {
                return Err(CurveError::Value { index, value });
            }
            previous = tilt_deg;
        }
        Ok(Self::from_points(points))
    }

    /// The curve through `points`, unchecked: for the defaults below.
    const fn from_points(points: &[(f64, f64)]) -> Self {
        let mut stored = [(0.0, 0.0); MAX_CURVE_POINTS];
        let mut index = 0;
        while index < points.len() {
            stored[index] = points[index];
            index += 1;
        }
        Self {
            points: stored,
            len: points.len(),
        }
    }

    /// The same curve if its value at `tilt_deg` is `required` (MODEL.md §12: h(135°) = 1).
    pub fn through(self, tilt_deg: f64, required: f64) -> Result<Self, CurveError> {
        match self.at(tilt_deg) {
            value if value == required => Ok(self),
            value => Err(CurveError::Anchor {
                tilt_deg,
                value,
                required,
            }),
        }
    }

    /// The breakpoints, in order of tilt.
    #[inline]
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points[..self.len]
    }

    /// Linear interpolation between breakpoints, held constant beyond the ends.
    pub fn at(&self, tilt_deg: f64) -> f64 {
        self.at_in(tilt_deg, &mut CurveSegment::default())
    }

    /// [`TiltCurve::at`], looking in `segment` first and leaving there the piece `tilt_deg` fell
    /// in: the same value, without a search while the tilt stays in one piece.
    #[inline]
    pub fn at_in(&self, tilt_deg: f64, segment: &mut CurveSegment) -> f64 {
        let points = self.points();
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
        let points = self.points();
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
        self.points()
            .iter()
            .map(|&(_, value)| value)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Whether `tilt_deg` lies in piece `piece`.
    #[inline]
    fn contains(&self, piece: usize, tilt_deg: f64) -> bool {
        let points = self.points();
        // A piece past the end (remembered from a curve with more points) is in no curve.
        piece <= points.len()
            && (piece == 0 || tilt_deg > points[piece - 1].0)
            && (piece == points.len() || tilt_deg <= points[piece].0)
    }
}

/// r(θ): fraction of capacity that stays in the bottle at this tilt (§2).
const REST: TiltCurve = TiltCurve::from_points(&[
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
]);

/// s(θ): fraction of capacity above which the mouth is submerged and pours glug (§2).
const SUBMERGED: TiltCurve = TiltCurve::from_points(&[
    (0.0, 1.0),
    (60.0, 1.0),
    (90.0, 0.687),
    (100.0, 0.367),
    (115.0, 0.05),
    (135.0, 0.0),
    (180.0, 0.0),
]);

/// h(θ): outflow rate relative to the rate at the 135° reference tilt (§3).
const DRAIN: TiltCurve = TiltCurve::from_points(&[
    (0.0, 0.0),
    (60.0, 0.1),
    (90.0, 0.333),
    (115.0, 0.833),
    (135.0, 1.0),
    (155.0, 1.0),
    (180.0, 0.733),
]);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curves_pass_through_their_breakpoints_and_hold_outside() {
        assert_eq!(REST.at(79.0), 0.667);
        assert_eq!(SUBMERGED.at(100.0), 0.367);
        assert_eq!(DRAIN.at(135.0), 1.0);
        assert_eq!(DRAIN.at(-10.0), 0.0);
        assert_eq!(DRAIN.at(200.0), 0.733);
        assert_eq!(REST.at(200.0), 0.0);
    }

    #[test]
    fn a_curve_is_checked_as_model_md_12_asks() {
        let curve = |points: &[(f64, f64)]| TiltCurve::new(points, 0.0..=180.0);
        assert_eq!(curve(&[(0.0, 0.5), (180.0, 1.0)]).unwrap().at(90.0), 0.75);
        assert_eq!(curve(DRAIN.points()), Ok(DRAIN));
        assert_eq!(
            curve(&[(10.0, 0.5)]),
            Err(CurveError::PointCount { count: 1 })
        );
        let many: Vec<_> = (0..=MAX_CURVE_POINTS).map(|i| (i as f64, 0.5)).collect();
        assert!(curve(&many[..MAX_CURVE_POINTS]).is_ok());
        assert_eq!(
            curve(&many),
            Err(CurveError::PointCount {
                count: MAX_CURVE_POINTS + 1
            })
        );
        for (points, index, tilt_deg) in [
            (&[(0.0, 0.5), (0.0, 0.6)][..], 1, 0.0),
            (&[(50.0, 0.5), (40.0, 0.6)], 1, 40.0),
            (&[(-1.0, 0.5), (40.0, 0.6)], 0, -1.0),
            (&[(10.0, 0.5), (180.5, 0.6)], 1, 180.5),
        ] {
            assert_eq!(curve(points), Err(CurveError::Tilt { index, tilt_deg }));
        }
        assert!(matches!(
            curve(&[(f64::NAN, 0.5), (40.0, 0.6)]),
            Err(CurveError::Tilt { index: 0, .. })
        ));
        for (value, index) in [(1.01, 1), (-0.1, 1), (f64::NAN, 1)] {
            assert!(matches!(
                curve(&[(0.0, 0.5), (40.0, value)]),
                Err(CurveError::Value { index: i, .. }) if i == index
            ));
        }
    }

    #[test]
    fn a_curve_is_held_to_its_anchor() {
        assert_eq!(DRAIN.through(REFERENCE_TILT_DEG, 1.0), Ok(DRAIN));
        let low = TiltCurve::new(&[(90.0, 0.5), (180.0, 0.9)], 0.0..=180.0).unwrap();
        assert_eq!(
            low.through(REFERENCE_TILT_DEG, 1.0),
            Err(CurveError::Anchor {
                tilt_deg: 135.0,
                value: 0.7,
                required: 1.0
            })
        );
    }

    #[test]
    fn a_remembered_segment_gives_the_same_values_as_a_search() {
        for curve in [&REST, &SUBMERGED, &DRAIN] {
            let mut segment = CurveSegment::default();
            // Up, down, jumps, the breakpoints themselves, beyond both ends, and NaN.
            let mut tilts: Vec<f64> = (-40..=800).map(|i| i as f64 * 0.25).collect();
            tilts.extend((0..=800).rev().map(|i| i as f64 * 0.2293));
            tilts.extend(curve.points().iter().map(|p| p.0));
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
        for curve in [&REST, &SUBMERGED, &DRAIN] {
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
        let points = curve.points();
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
        assert!((DRAIN.at(145.0) - 1.0).abs() < 1e-15);
        assert!((DRAIN.at(102.5) - (0.333 + 0.833) / 2.0).abs() < 1e-12);
        assert!((REST.at(87.0) - (0.5 + 0.333) / 2.0).abs() < 1e-12);
        assert!((SUBMERGED.at(125.0) - 0.025).abs() < 1e-12);
    }
}
