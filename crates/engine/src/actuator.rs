//! An actuator's frequency response as plain data, and the compensation that keeps the model's
//! viscosity ratio c on it (MODEL.md §18). No file is read here: the profiles and their parser
//! are `sake-glug-actuator`'s; the engine holds the numbers (`Copy`, fixed size, so handing a
//! profile to the audio thread allocates nothing) and computes each unit's gains as it starts.

/// A response holds at most this many points: enough for a measured sweep of a few per octave
/// from 10 Hz to 20 kHz, and few enough for a fixed-size, `Copy` profile.
pub const MAX_RESPONSE_POINTS: usize = 64;

/// The lowest and highest frequency a response point may name (Hz): from below the skin's
/// range to above any rate a device is driven at.
pub const RESPONSE_HZ: (f64, f64) = (1.0, 100_000.0);

/// The most a point may lie above or below 0 dB: a device's response spans far less.
pub const MAX_RESPONSE_DB: f64 = 120.0;

/// The skin's vibrotactile threshold as a displacement (dB re 1 µm) at the thenar eminence, for a
/// large contactor (2.9 cm²), after Verrillo (1963, J. Acoust. Soc. Am. 35, 1962–1966; the
/// shape as Gescheider and Verrillo summarise it): flat up to 40 Hz, falling 12 dB per octave to
/// the most sensitive point near 250 Hz, rising beyond it. The level is approximate (0.1 µm at
/// 250 Hz) and the rise above 250 Hz is taken as the mirror of the fall; only the shape counts,
/// since the felt mode uses ratios. Interpolated in log frequency, constant outside.
pub const SKIN_THRESHOLD_DISPLACEMENT_DB: [(f64, f64); 6] = [
    (40.0, 11.7),
    (80.0, -0.3),
    (160.0, -12.3),
    (250.0, -20.0),
    (500.0, -8.0),
    (1000.0, 4.0),
];

/// What the compensation makes equal to the model's ratio.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Equalise {
    /// The acceleration the device delivers at f1 and f2 (what an accelerometer measures).
    #[default]
    Acceleration,
    /// The level above the skin's threshold at f1 and f2 ([`SKIN_THRESHOLD_DISPLACEMENT_DB`]):
    /// how strongly each component is felt rather than how strongly it shakes.
    Felt,
}

/// Why a response was refused: each names the part of the profile at fault.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ResponseError {
    /// Fewer than two points, or more than [`MAX_RESPONSE_POINTS`].
    #[error("needs 2 to {MAX_RESPONSE_POINTS} [Hz, dB] points, has {0}")]
    PointCount(usize),
    /// A point's frequency or level is NaN or infinite.
    #[error("point {} is not two finite numbers", index + 1)]
    NotFinite {
        /// The point, from 0 (messages count from 1).
        index: usize,
    },
    /// A point's frequency is outside [`RESPONSE_HZ`].
    #[error("point {}: {hz} Hz is outside {} to {} Hz", index + 1, RESPONSE_HZ.0, RESPONSE_HZ.1)]
    FrequencyOutOfRange {
        /// The point, from 0 (messages count from 1).
        index: usize,
        /// Its frequency.
        hz: f64,
    },
    /// A point's level is beyond ±[`MAX_RESPONSE_DB`].
    #[error("point {}: {db} dB is beyond ±{MAX_RESPONSE_DB} dB", index + 1)]
    LevelOutOfRange {
        /// The point, from 0 (messages count from 1).
        index: usize,
        /// Its level.
        db: f64,
    },
    /// A point's frequency is not above the one before it.
    #[error(
        "point {}: {hz} Hz is not above the point before it ({before} Hz): points go up in \
         frequency",
        index + 1
    )]
    OutOfOrder {
        /// The point, from 0 (messages count from 1).
        index: usize,
        /// Its frequency.
        hz: f64,
        /// The frequency of the point before it.
        before: f64,
    },
    /// A band edge is NaN or infinite, or the low edge is not below the high one.
    #[error("[{low}, {high}] is not two finite frequencies, the lower first")]
    BandNotOrdered {
        /// The low edge.
        low: f64,
        /// The high edge.
        high: f64,
    },
    /// The band reaches outside the points, where the response is only held, not known.
    #[error("[{low}, {high}] Hz reaches outside the response's points ({first} to {last} Hz)")]
    BandOutsidePoints {
        /// The low edge.
        low: f64,
        /// The high edge.
        high: f64,
        /// The first point's frequency.
        first: f64,
        /// The last point's frequency.
        last: f64,
    },
    /// The largest drive is not within (0, 1] of full scale.
    #[error("{0} is not within 0 (excluded) to 1 of full scale")]
    MaxAmplitude(f64),
}

/// An actuator's response, its band and the largest drive it takes: plain data, checked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ActuatorResponse {
    /// `(ln Hz, dB)`, strictly increasing in frequency; the first `len` are used.
    points: [(f64, f64); MAX_RESPONSE_POINTS],
    len: usize,
    band_hz: [f64; 2],
    max_amplitude: f64,
    equalise: Equalise,
}

impl ActuatorResponse {
    /// A response from `[Hz, dB]` points, its band and its largest drive (linear, of full
    /// scale), equalising acceleration; refused as [`ResponseError`] says.
    pub fn new(
        points_hz_db: &[(f64, f64)],
        band_hz: [f64; 2],
        max_amplitude: f64,
    ) -> Result<Self, ResponseError> {
        if !(2..=MAX_RESPONSE_POINTS).contains(&points_hz_db.len()) {
            return Err(ResponseError::PointCount(points_hz_db.len()));
        }
        let mut points = [(0.0, 0.0); MAX_RESPONSE_POINTS];
        for (index, &(hz, db)) in points_hz_db.iter().enumerate() {
            if !hz.is_finite() || !db.is_finite() {
                return Err(ResponseError::NotFinite { index });
            }
            if !(RESPONSE_HZ.0..=RESPONSE_HZ.1).contains(&hz) {
                return Err(ResponseError::FrequencyOutOfRange { index, hz });
            }
            if db.abs() > MAX_RESPONSE_DB {
                return Err(ResponseError::LevelOutOfRange { index, db });
            }
            if let Some(&(before, _)) = index.checked_sub(1).map(|i| &points_hz_db[i]) {
                if hz <= before {
                    return Err(ResponseError::OutOfOrder { index, hz, before });
                }
            }
            points[index] = (hz.ln(), db);
        }
        let [low, high] = band_hz;
        if !(low.is_finite() && high.is_finite() && low < high) {
            return Err(ResponseError::BandNotOrdered { low, high });
        }
        let (first, last) = (points_hz_db[0].0, points_hz_db[points_hz_db.len() - 1].0);
        if low < first || high > last {
            return Err(ResponseError::BandOutsidePoints {
                low,
                high,
                first,
                last,
            });
        }
        if !(max_amplitude > 0.0 && max_amplitude <= 1.0) {
            return Err(ResponseError::MaxAmplitude(max_amplitude));
        }
        Ok(Self {
            points,
            len: points_hz_db.len(),
            band_hz,
            max_amplitude,
            equalise: Equalise::Acceleration,
        })
    }

    /// The same response, equalising as `equalise` says.
    pub fn equalising(self, equalise: Equalise) -> Self {
        Self { equalise, ..self }
    }

    /// What the compensation equalises.
    pub fn equalise(&self) -> Equalise {
        self.equalise
    }

    /// The band `[low, high]` (Hz) the device is rated for.
    pub fn band_hz(&self) -> [f64; 2] {
        self.band_hz
    }

    /// The largest drive the device takes (linear, of full scale): the output's ceiling with
    /// this profile is at most this.
    pub fn max_amplitude(&self) -> f64 {
        self.max_amplitude
    }

    /// The response at `hz` (dB): linear in log frequency between points, held outside them.
    pub fn response_db(&self, hz: f64) -> f64 {
        interpolate_log(&self.points[..self.len], hz)
    }

    /// The response at `hz` as a linear factor on the drive's amplitude.
    pub fn response(&self, hz: f64) -> f64 {
        db_to_linear(self.response_db(hz))
    }

    /// How strongly a component at `hz` reaches what is equalised, per unit of drive: the
    /// response (and, felt, over the skin's threshold), taken at the nearest band edge for a
    /// frequency outside the band (MODEL.md §18: the compensation stops at the band's edge).
    fn weight_db(&self, hz: f64) -> f64 {
        let [low, high] = self.band_hz;
        let hz = hz.clamp(low, high);
        match self.equalise {
            Equalise::Acceleration => self.response_db(hz),
            Equalise::Felt => self.response_db(hz) - skin_threshold_acceleration_db(hz),
        }
    }

    /// Each component's gain for a unit whose components sound at `frequency_hz`: the inverse
    /// of its weight, scaled so that the larger gain is 1 (the compensation only ever lowers a
    /// component, so it never asks more of the device than the model's drive did). A frequency
    /// that is not finite and positive (its component is omitted, MODEL.md §6) leaves both at 1.
    pub fn gains(&self, frequency_hz: [f64; 2]) -> [f64; 2] {
        if !frequency_hz.iter().all(|hz| hz.is_finite() && *hz > 0.0) {
            return [1.0, 1.0];
        }
        let weights = frequency_hz.map(|hz| self.weight_db(hz));
        let weakest = weights[0].min(weights[1]);
        weights.map(|weight| db_to_linear(weakest - weight))
    }

    /// What the device delivers of components driven at `amplitudes` and `frequency_hz`: each
    /// times the response at its own frequency (in or out of the band).
    pub fn delivered(&self, amplitudes: [f64; 2], frequency_hz: [f64; 2]) -> [f64; 2] {
        [
            amplitudes[0] * self.response(frequency_hz[0]),
            amplitudes[1] * self.response(frequency_hz[1]),
        ]
    }
}

/// The skin's threshold as an acceleration at `hz` (dB, up to a constant): the displacement
/// threshold times (2πf)².
pub fn skin_threshold_acceleration_db(hz: f64) -> f64 {
    let points = SKIN_THRESHOLD_DISPLACEMENT_DB.map(|(hz, db)| (hz.ln(), db));
    interpolate_log(&points, hz) + 40.0 * hz.log10()
}

fn db_to_linear(db: f64) -> f64 {
    10f64.powf(db / 20.0)
}

/// `points` (`(ln Hz, dB)`, increasing) at `hz`: linear in ln f between them, held outside.
fn interpolate_log(points: &[(f64, f64)], hz: f64) -> f64 {
    let x = hz.ln();
    let (first, last) = (points[0], points[points.len() - 1]);
    if x.is_nan() || x <= first.0 {
        return first.1;
    }
    if x >= last.0 {
        return last.1;
    }
    let next = points.partition_point(|point| point.0 <= x);
    let (a, b) = (points[next - 1], points[next]);
    a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn haptuator() -> ActuatorResponse {
        ActuatorResponse::new(
            &[(40.0, -18.0), (90.0, 0.0), (1000.0, 0.0)],
            [90.0, 1000.0],
            1.0,
        )
        .unwrap()
    }

    #[test]
    fn the_response_is_linear_in_log_frequency_and_held_outside() {
        let response = haptuator();
        assert_eq!(response.response_db(10.0), -18.0);
        assert_eq!(response.response_db(5000.0), 0.0);
        assert_eq!(response.response_db(90.0), 0.0);
        // 60 Hz lies at ln(60/40)/ln(90/40) of the way from 40 to 90 Hz.
        let fraction = (60f64 / 40.0).ln() / (90f64 / 40.0).ln();
        assert!((response.response_db(60.0) - (-18.0 + 18.0 * fraction)).abs() < 1e-12);
    }

    #[test]
    fn gains_invert_the_response_in_the_band_and_never_raise() {
        let response = ActuatorResponse::new(
            &[(50.0, -12.0), (100.0, 0.0), (400.0, 6.0)],
            [50.0, 400.0],
            1.0,
        )
        .unwrap();
        let frequency_hz = [80.0, 300.0];
        let gains = response.gains(frequency_hz);
        assert!(gains.iter().all(|&gain| gain > 0.0 && gain <= 1.0));
        let delivered = response.delivered(gains, frequency_hz);
        assert!((delivered[0] / delivered[1] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn a_flat_response_gives_gains_of_exactly_one() {
        let flat = ActuatorResponse::new(&[(10.0, 0.0), (1000.0, 0.0)], [10.0, 1000.0], 1.0)
            .unwrap()
            .equalising(Equalise::Acceleration);
        assert_eq!(flat.gains([80.0, 300.0]), [1.0, 1.0]);
    }

    #[test]
    fn outside_the_band_the_compensation_stops_at_its_edge() {
        let response = haptuator();
        // 80 Hz lies below the band: compensated as at 90 Hz (0 dB), so nothing changes.
        assert_eq!(response.gains([80.0, 300.0]), [1.0, 1.0]);
    }

    #[test]
    fn felt_mode_raises_the_component_the_skin_feels_less() {
        let flat = ActuatorResponse::new(&[(10.0, 0.0), (1000.0, 0.0)], [10.0, 1000.0], 1.0)
            .unwrap()
            .equalising(Equalise::Felt);
        // On a flat device the gains make the two components' levels over threshold equal.
        let gains = flat.gains([80.0, 250.0]);
        let over = |k: usize, hz: f64| 20.0 * gains[k].log10() - skin_threshold_acceleration_db(hz);
        assert!((over(0, 80.0) - over(1, 250.0)).abs() < 1e-9);
    }

    #[test]
    fn bad_responses_are_refused_with_the_reason() {
        let band = [50.0, 100.0];
        assert_eq!(
            ActuatorResponse::new(&[(50.0, 0.0)], band, 1.0),
            Err(ResponseError::PointCount(1))
        );
        assert!(matches!(
            ActuatorResponse::new(&[(100.0, 0.0), (50.0, 0.0)], band, 1.0),
            Err(ResponseError::OutOfOrder { index: 1, .. })
        ));
        assert!(matches!(
            ActuatorResponse::new(&[(50.0, f64::NAN), (100.0, 0.0)], band, 1.0),
            Err(ResponseError::NotFinite { index: 0 })
        ));
        assert!(matches!(
            ActuatorResponse::new(&[(60.0, 0.0), (100.0, 0.0)], band, 1.0),
            Err(ResponseError::BandOutsidePoints { .. })
        ));
        assert!(matches!(
            ActuatorResponse::new(&[(50.0, 0.0), (100.0, 0.0)], [100.0, 50.0], 1.0),
            Err(ResponseError::BandNotOrdered { .. })
        ));
        assert_eq!(
            ActuatorResponse::new(&[(50.0, 0.0), (100.0, 0.0)], band, 1.5),
            Err(ResponseError::MaxAmplitude(1.5))
        );
    }
}
