//! Which sensor axis runs along the bottle, and the bottle's tilt from a gravity reading.

use std::fmt;
use std::str::FromStr;

use thiserror::Error;

/// A signed sensor axis: the one that points from the bottle's base to its mouth.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Axis {
    /// The sensor's +x.
    PlusX,
    /// The sensor's −x.
    MinusX,
    /// The sensor's +y.
    PlusY,
    /// The sensor's −y.
    MinusY,
    /// The sensor's +z.
    PlusZ,
    /// The sensor's −z.
    MinusZ,
}

impl Axis {
    /// Every axis, in the order they are listed to users.
    pub const ALL: [Axis; 6] = [
        Axis::PlusX,
        Axis::MinusX,
        Axis::PlusY,
        Axis::MinusY,
        Axis::PlusZ,
        Axis::MinusZ,
    ];

    /// The unit vector of this axis in sensor coordinates.
    pub fn unit(self) -> [f64; 3] {
        match self {
            Axis::PlusX => [1.0, 0.0, 0.0],
            Axis::MinusX => [-1.0, 0.0, 0.0],
            Axis::PlusY => [0.0, 1.0, 0.0],
            Axis::MinusY => [0.0, -1.0, 0.0],
            Axis::PlusZ => [0.0, 0.0, 1.0],
            Axis::MinusZ => [0.0, 0.0, -1.0],
        }
    }
}

impl fmt::Display for Axis {
    /// The canonical spelling, which [`Axis::from_str`] reads back.
    fn fmt(&self, formatter: &mut fmt::Formatter) -> fmt::Result {
        formatter.write_str(match self {
            Axis::PlusX => "+x",
            Axis::MinusX => "-x",
            Axis::PlusY => "+y",
            Axis::MinusY => "-y",
            Axis::PlusZ => "+z",
            Axis::MinusZ => "-z",
        })
    }
}

/// Text that names no axis.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("{text:?} is not an axis: expected +x, -x, +y, -y, +z or -z (a bare x means +x)")]
pub struct AxisParseError {
    /// The text as given.
    pub text: String,
}

impl FromStr for Axis {
    type Err = AxisParseError;

    /// `+x`, `-z`, or a bare `z` for `+z`; letters in either case, surrounding spaces ignored
    /// (settings files and command lines both end up here).
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let trimmed = text.trim();
        let (negative, letter) = match trimmed.as_bytes() {
            [b'+', letter] => (false, *letter),
            [b'-', letter] => (true, *letter),
            [letter] => (false, *letter),
            _ => (false, 0),
        };
        let axis = match (letter.to_ascii_lowercase(), negative) {
            (b'x', false) => Axis::PlusX,
            (b'x', true) => Axis::MinusX,
            (b'y', false) => Axis::PlusY,
            (b'y', true) => Axis::MinusY,
            (b'z', false) => Axis::PlusZ,
            (b'z', true) => Axis::MinusZ,
            _ => {
                return Err(AxisParseError {
                    text: text.to_owned(),
                })
            }
        };
        Ok(axis)
    }
}

/// The bottle's tilt in degrees (0 upright, 90 horizontal, 180 upside down) from an
/// accelerometer or gravity reading, or `None` when the reading has no direction (zero, or not
/// finite).
///
/// The reading must point up when the sensor is at rest, as MEMS accelerometers report it (+1 g
/// away from the earth); `axis` is the sensor axis from the bottle's base to its mouth.
pub fn tilt_from_gravity(reading: [f64; 3], axis: Axis) -> Option<f64> {
    // Scaling by the largest component first keeps the length finite for huge readings and
    // non-zero for tiny ones, so only a true zero or a non-finite reading has no direction.
    let largest = reading.iter().fold(0.0_f64, |max, c| max.max(c.abs()));
    if !largest.is_finite() || largest == 0.0 || reading.iter().any(|c| !c.is_finite()) {
        return None;
    }
    let scaled = reading.map(|component| component / largest);
    let length = scaled.iter().map(|c| c * c).sum::<f64>().sqrt();
    let along: f64 = scaled.iter().zip(axis.unit()).map(|(a, u)| a * u).sum();
    // Rounding can push the cosine a hair past ±1, where acos is NaN.
    let cosine = (along / length).clamp(-1.0, 1.0);
    Some(cosine.acos().to_degrees())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_every_spelling_and_round_trips() {
        for axis in Axis::ALL {
            assert_eq!(axis.to_string().parse::<Axis>(), Ok(axis));
        }
        assert_eq!("z".parse::<Axis>(), Ok(Axis::PlusZ));
        assert_eq!(" -Y ".parse::<Axis>(), Ok(Axis::MinusY));
        for bad in ["", "+", "w", "+xx", "x+", "--x", "1"] {
            let error = bad.parse::<Axis>().unwrap_err();
            assert!(error.to_string().contains(&format!("{bad:?}")), "{error}");
        }
    }

    #[test]
    fn tilt_is_the_angle_between_the_reading_and_the_bottle_axis() {
        let tilt = |reading, axis| tilt_from_gravity(reading, axis).unwrap();
        assert_eq!(tilt([0.0, 0.0, 9.81], Axis::PlusZ), 0.0);
        assert!((tilt([9.81, 0.0, 0.0], Axis::PlusZ) - 90.0).abs() < 1e-12);
        assert_eq!(tilt([0.0, 0.0, -1.0], Axis::PlusZ), 180.0);
        assert_eq!(tilt([0.0, -2.0, 0.0], Axis::MinusY), 0.0);
        assert!((tilt([1.0, 0.0, 1.0], Axis::PlusX) - 45.0).abs() < 1e-12);
        assert_eq!(tilt([1e300, 0.0, 1e300], Axis::PlusZ).round(), 45.0);
        assert_eq!(tilt([0.0, 0.0, 1e-310], Axis::PlusZ), 0.0);
    }

    #[test]
    fn directionless_readings_have_no_tilt() {
        for reading in [
            [0.0, 0.0, 0.0],
            [0.0, -0.0, 0.0],
            [f64::NAN, 0.0, 1.0],
            [f64::INFINITY, 0.0, 1.0],
            [0.0, f64::NEG_INFINITY, 0.0],
        ] {
            assert_eq!(tilt_from_gravity(reading, Axis::PlusZ), None, "{reading:?}");
        }
    }
}
