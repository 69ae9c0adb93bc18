//! An automatable value of a scene: a constant, or `[time_s, value]` points joined linearly and
//! held before the first and after the last (MODEL.md §10).

use std::fmt;

use std::path::PathBuf;

use serde::de::{self, Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};

use sake_glug_engine::{sample_time_s, Lane, LinearSegment};

/// An automatable scene value: a constant or a list of `[time_s, value]` points.
#[derive(Debug, Clone, PartialEq)]
pub enum Automation {
    /// The same value at all times.
    Constant(f64),
    /// Times in seconds, non-decreasing; two points at one time make a step.
    Points(Vec<(f64, f64)>),
}

impl Automation {
    /// The value at `time_s` (s): linear between points, held before the first and after the last.
    pub fn value_at(&self, time_s: f64) -> f64 {
        match self {
            Automation::Constant(value) => *value,
            Automation::Points(points) => value_in(points, segment_at(points, time_s), time_s),
        }
    }

    /// The time of the last point: after it the value holds for ever.
    pub fn last_time_s(&self) -> f64 {
        match self {
            Automation::Constant(_) => 0.0,
            Automation::Points(points) => points.last().map_or(0.0, |point| point.0),
        }
    }

    /// Every value, in scene order, for range checks.
    pub fn values(&self) -> impl Iterator<Item = f64> + '_ {
        let (constant, points) = match self {
            Automation::Constant(value) => (Some(*value), &[][..]),
            Automation::Points(points) => (None, &points[..]),
        };
        constant
            .into_iter()
            .chain(points.iter().map(|point| point.1))
    }

    /// The lane for the samples `first_sample .. first_sample + buffer.len()`: a constant when the
    /// value cannot change over them (so the engine may skip work), else `buffer` filled with
    /// [`Automation::value_at`] of every sample's time. The points are looked up once per
    /// segment, not once per sample: the samples of one segment are filled in one pass.
    pub fn lane<'a>(&self, first_sample: u64, sample_rate: f64, buffer: &'a mut [f64]) -> Lane<'a> {
        let time_of = |index: usize| sample_time_s(first_sample + index as u64, sample_rate);
        if let Some(value) = self.constant_over(time_of(0), time_of(buffer.len().saturating_sub(1)))
        {
            return Lane::Constant(value);
        }
        let Automation::Points(points) = self else {
            unreachable!("a constant automation is constant over any samples")
        };
        let mut start = 0;
        let mut segment = segment_at(points, time_of(0));
        while start < buffer.len() {
            // The samples before the next point's time stay in this segment; times grow with
            // the sample index, so the first sample at or past it is found from a guess.
            let end = match points.get(segment) {
                Some(&(next_point_s, _)) => {
                    let guess = (next_point_s * sample_rate).ceil() - first_sample as f64;
                    let mut end = guess.clamp(start as f64, buffer.len() as f64) as usize;
                    while end > start && time_of(end - 1) >= next_point_s {
                        end -= 1;
                    }
                    while end < buffer.len() && time_of(end) < next_point_s {
                        end += 1;
                    }
                    end
                }
                None => buffer.len(),
            };
            fill_segment(points, segment, &mut buffer[start..end], |index| {
                time_of(start + index)
            });
            start = end;
            segment += 1;
        }
        Lane::Samples(buffer)
    }

    fn constant_over(&self, start_s: f64, end_s: f64) -> Option<f64> {
        match self {
            Automation::Constant(value) => Some(*value),
            Automation::Points(points) => {
                let segment = segment_at(points, start_s);
                let flat = segment == 0
                    || segment == points.len()
                    || points[segment - 1].1 == points[segment].1;
                (flat && segment == segment_at(points, end_s)).then(|| self.value_at(start_s))
            }
        }
    }
}

/// The index of the first point later than `time_s`: 0 before the first, `len` after the last.
fn segment_at(points: &[(f64, f64)], time_s: f64) -> usize {
    points.partition_point(|point| point.0 <= time_s)
}

/// The value at `time_s`, which lies in `segment` (as [`segment_at`] gives it).
#[inline]
fn value_in(points: &[(f64, f64)], segment: usize, time_s: f64) -> f64 {
    if segment == 0 {
        points[0].1
    } else if segment == points.len() {
        points[points.len() - 1].1
    } else {
        segment_line(points, segment).value_at(time_s)
    }
}

/// The line from the point before `segment` to the point that ends it.
#[inline]
fn segment_line(points: &[(f64, f64)], segment: usize) -> LinearSegment {
    LinearSegment {
        start: points[segment - 1],
        end: points[segment],
    }
}

/// Fills `values` with the value at `time_of(index)`, every time lying in `segment`: a held
/// value, or the same interpolation as [`value_in`] in a loop the compiler can vectorise (the
/// line's rise and run are the same for every sample, and computed once).
#[inline]
fn fill_segment(
    points: &[(f64, f64)],
    segment: usize,
    values: &mut [f64],
    time_of: impl Fn(usize) -> f64,
) {
    if segment == 0 || segment == points.len() {
        values.fill(value_in(points, segment, 0.0));
        return;
    }
    let line = segment_line(points, segment);
    for (index, value) in values.iter_mut().enumerate() {
        *value = line.value_at(time_of(index));
    }
}

/// An automatable value as a scene file writes it: inline, or read from a CSV take that is
/// resolved against the scene's folder once the whole scene is read.
#[derive(Debug, Clone, PartialEq)]
pub enum LaneSpec {
    /// A constant or `[time_s, value]` points.
    Inline(Automation),
    /// `{ csv = "take.csv", column = "…" }` or `{ csv = …, accel = ["ax", "ay", "az"], axis = "+z" }`.
    Csv(CsvLaneRef),
}

/// A lane read from a CSV file with a header row and a `time_s` column.
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CsvLaneRef {
    /// The file, relative to the scene file.
    pub csv: PathBuf,
    /// The column that holds the value.
    pub column: Option<String>,
    /// Or, for tilt, the columns of an accelerometer's or gravity sensor's x, y and z.
    pub accel: Option<[String; 3]>,
    /// The sensor axis from the bottle's base to its mouth (`+z` if not given).
    pub axis: Option<String>,
}

impl<'de> Deserialize<'de> for LaneSpec {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_any(LaneVisitor)
    }
}

struct LaneVisitor;

impl<'de> Visitor<'de> for LaneVisitor {
    type Value = LaneSpec;

    fn expecting(&self, formatter: &mut fmt::Formatter) -> fmt::Result {
        formatter.write_str("a number, a list of [time_s, value] points or a { csv = … } table")
    }

    fn visit_f64<E: de::Error>(self, value: f64) -> Result<LaneSpec, E> {
        Ok(LaneSpec::Inline(Automation::Constant(value)))
    }

    fn visit_i64<E: de::Error>(self, value: i64) -> Result<LaneSpec, E> {
        Ok(LaneSpec::Inline(Automation::Constant(value as f64)))
    }

    fn visit_u64<E: de::Error>(self, value: u64) -> Result<LaneSpec, E> {
        Ok(LaneSpec::Inline(Automation::Constant(value as f64)))
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<LaneSpec, A::Error> {
        CsvLaneRef::deserialize(de::value::MapAccessDeserializer::new(map)).map(LaneSpec::Csv)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<LaneSpec, A::Error> {
        let mut points = Vec::new();
        while let Some(Point(time_s, value)) = seq.next_element()? {
            points.push((time_s, value));
        }
        if points.is_empty() {
            return Err(de::Error::invalid_length(
                0,
                &"at least one [time_s, value] point",
            ));
        }
        Ok(LaneSpec::Inline(Automation::Points(points)))
    }
}

/// One `[time_s, value]` pair, numbers either integer or float, nothing more.
struct Point(f64, f64);

impl<'de> Deserialize<'de> for Point {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct PointVisitor;
        impl<'de> Visitor<'de> for PointVisitor {
            type Value = Point;
            fn expecting(&self, formatter: &mut fmt::Formatter) -> fmt::Result {
                formatter.write_str("a [time_s, value] pair of numbers")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Point, A::Error> {
                let pair_error =
                    || de::Error::custom("each point must be a [time_s, value] pair of numbers");
                let time_s: Number = seq.next_element()?.ok_or_else(pair_error)?;
                let value: Number = seq.next_element()?.ok_or_else(pair_error)?;
                if seq.next_element::<de::IgnoredAny>()?.is_some() {
                    return Err(pair_error());
                }
                Ok(Point(time_s.0, value.0))
            }
        }
        deserializer
            .deserialize_seq(PointVisitor)
            .map_err(|_: D::Error| {
                de::Error::custom("each point must be a [time_s, value] pair of numbers")
            })
    }
}

struct Number(f64);

impl<'de> Deserialize<'de> for Number {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct NumberVisitor;
        impl Visitor<'_> for NumberVisitor {
            type Value = Number;
            fn expecting(&self, formatter: &mut fmt::Formatter) -> fmt::Result {
                formatter.write_str("a number")
            }
            fn visit_f64<E: de::Error>(self, value: f64) -> Result<Number, E> {
                Ok(Number(value))
            }
            fn visit_i64<E: de::Error>(self, value: i64) -> Result<Number, E> {
                Ok(Number(value as f64))
            }
            fn visit_u64<E: de::Error>(self, value: u64) -> Result<Number, E> {
                Ok(Number(value as f64))
            }
        }
        deserializer.deserialize_any(NumberVisitor)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp() -> Automation {
        Automation::Points(vec![(0.0, 90.0), (0.5, 135.0), (1.0, 135.0), (1.0, 0.0)])
    }

    #[test]
    fn interpolates_holds_and_steps() {
        let ramp = ramp();
        assert_eq!(ramp.value_at(-1.0), 90.0);
        assert_eq!(ramp.value_at(0.25), 112.5);
        assert_eq!(ramp.value_at(0.75), 135.0);
        assert_eq!(ramp.value_at(1.0), 0.0);
        assert_eq!(ramp.value_at(9.0), 0.0);
        assert_eq!(ramp.last_time_s(), 1.0);
    }

    #[test]
    fn lanes_hold_the_value_of_every_sample_time() {
        // Steps, ramps, holds and points between samples, at sample rates whose sample times
        // are inexact, over blocks that start anywhere.
        let automation = Automation::Points(vec![
            (0.0, 90.0),
            (0.013, 135.0),
            (0.0131, 135.0),
            (0.0131, 10.0),
            (0.05, 170.0),
            (0.05, 170.0),
            (0.051, 0.0),
            (0.07, 33.3),
        ]);
        for sample_rate in [1_000.0, 44_100.0, 48_000.0, 96_000.0] {
            let mut buffer = vec![0.0; 700];
            for first_sample in [0u64, 1, 333, 571, 2_205, 4_799] {
                for len in [1, 2, 63, 700] {
                    let lane = automation.lane(first_sample, sample_rate, &mut buffer[..len]);
                    for index in 0..len {
                        let time_s = (first_sample + index as u64) as f64 / sample_rate;
                        assert_eq!(
                            lane.at(index).to_bits(),
                            automation.value_at(time_s).to_bits(),
                            "{sample_rate} Hz, sample {first_sample} + {index}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn lanes_are_constant_exactly_where_the_value_cannot_change() {
        let ramp = ramp();
        let mut buffer = [0.0; 4];
        assert!(matches!(ramp.lane(0, 8.0, &mut buffer), Lane::Samples(_)));
        assert_eq!(buffer, [90.0, 101.25, 112.5, 123.75]);
        assert_eq!(ramp.lane(4, 8.0, &mut buffer), Lane::Constant(135.0));
        assert!(matches!(ramp.lane(6, 8.0, &mut buffer), Lane::Samples(_)));
        assert_eq!(buffer, [135.0, 135.0, 0.0, 0.0]);
        assert_eq!(ramp.lane(8, 8.0, &mut buffer), Lane::Constant(0.0));
    }
}
