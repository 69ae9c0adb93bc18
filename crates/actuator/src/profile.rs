//! An actuator profile file, read and checked key by key (MODEL.md §18), and written.

use std::path::Path;

use sake_glug_engine::config::SAMPLE_RATE_HZ;
use sake_glug_engine::{ActuatorResponse, Equalise, ResponseError};
use sake_glug_io::keys::KeyedTable;
use sake_glug_io::read::{self, InputKind, ReadError, ReadFailure};
use sake_glug_io::text::{printable, quoted};

use crate::shipped;

/// The keys of a profile, each declared once.
mod key {
    pub const NAME: &str = "name";
    pub const RESPONSE: &str = "response";
    pub const BAND_HZ: &str = "band_hz";
    pub const MAX_AMPLITUDE: &str = "max_amplitude";
    pub const SAMPLE_RATE_HZ: &str = "sample_rate_hz";
    pub const EQUALISE: &str = "equalise";
    pub const SPREAD_DB: &str = "spread_db";
}

/// The words of `equalise`.
const EQUALISE_WORDS: [(&str, Equalise); 2] = [
    ("acceleration", Equalise::Acceleration),
    ("felt", Equalise::Felt),
];

/// Why a profile was refused: the file, and the key at fault. Text from the file is printable.
#[derive(Debug, thiserror::Error)]
pub enum ProfileError {
    /// The file could not be read: missing, not a regular file, too large, not UTF-8.
    #[error(transparent)]
    Read(#[from] ReadError),
    /// Neither a shipped profile's name nor a file.
    #[error(
        "no actuator profile {}: not a shipped one ({}) and no such file",
        quoted(.0),
        shipped::shipped_names().join(", ")
    )]
    Unknown(String),
    /// Not TOML, a value of the wrong type or an unknown key: the parser's message, which
    /// names the key.
    #[error("invalid actuator profile: {0}")]
    Syntax(String),
    /// A profile file refused for the reason given: the file named.
    #[error("{file}: {error}")]
    InFile {
        /// The file, printable.
        file: String,
        /// Why it was refused.
        error: Box<ProfileError>,
    },
    /// A key every profile gives is missing.
    #[error("invalid actuator profile: `{0}` is missing")]
    Missing(&'static str),
    /// A key's value is refused, for the reason given.
    #[error("invalid actuator profile: `{key}`: {reason}")]
    Value {
        /// The key.
        key: &'static str,
        /// Why.
        reason: String,
    },
}

/// A checked actuator profile: its name and text as written (what a plugin state keeps), and
/// the response the engine compensates for.
#[derive(Debug, Clone, PartialEq)]
pub struct ActuatorProfile {
    name: String,
    text: String,
    points: Vec<(f64, f64)>,
    response: ActuatorResponse,
    sample_rate_hz: u32,
    spread_db: Option<Vec<f64>>,
}

impl ActuatorProfile {
    /// The shipped profile called `name` (one of `actuators/`), if there is one.
    pub fn shipped(name: &str) -> Option<Self> {
        shipped::shipped_text(name)
            .map(|text| Self::parse(text).expect("a shipped profile is valid"))
    }

    /// A shipped profile's name, or else the path of a profile file.
    pub fn find(name_or_path: &str) -> Result<Self, ProfileError> {
        if let Some(profile) = Self::shipped(name_or_path) {
            return Ok(profile);
        }
        Self::load(Path::new(name_or_path)).map_err(|error| match error {
            ProfileError::Read(ReadError {
                failure: ReadFailure::Io(ref io),
                ..
            }) if io.kind() == std::io::ErrorKind::NotFound => {
                ProfileError::Unknown(name_or_path.to_owned())
            }
            error => error,
        })
    }

    /// Reads the profile file at `path`.
    pub fn load(path: &Path) -> Result<Self, ProfileError> {
        let text = read::read_text(path, InputKind::ACTUATOR)?;
        Self::parse(&text).map_err(|error| ProfileError::InFile {
            file: quoted(&path.display().to_string()),
            error: Box::new(error),
        })
    }

    /// Parses and checks a profile's `text`.
    pub fn parse(text: &str) -> Result<Self, ProfileError> {
        let mut table = KeyedTable::parse(text).map_err(ProfileError::Syntax)?;
        let mut take = |key: &'static str| -> Result<Option<toml::Value>, ProfileError> {
            table.take(key).map_err(ProfileError::Syntax)
        };
        let name = take(key::NAME)?;
        let response = take(key::RESPONSE)?;
        let band = take(key::BAND_HZ)?;
        let max_amplitude = take(key::MAX_AMPLITUDE)?;
        let sample_rate = take(key::SAMPLE_RATE_HZ)?;
        let equalise = take(key::EQUALISE)?;
        let spread = take(key::SPREAD_DB)?;
        table.refuse_unknown().map_err(ProfileError::Syntax)?;

        let name = required(key::NAME, name)?;
        let name = name
            .as_str()
            .filter(|name| !name.trim().is_empty())
            .ok_or_else(|| value(key::NAME, "expected a name (text that is not empty)"))?
            .to_owned();
        let points = pairs(key::RESPONSE, &required(key::RESPONSE, response)?)?;
        let band = numbers(key::BAND_HZ, &required(key::BAND_HZ, band)?)?;
        let band: [f64; 2] = band
            .try_into()
            .map_err(|_| value(key::BAND_HZ, "expected [low, high] in Hz"))?;
        let max_amplitude = number(
            key::MAX_AMPLITUDE,
            &required(key::MAX_AMPLITUDE, max_amplitude)?,
        )?;
        let sample_rate = required(key::SAMPLE_RATE_HZ, sample_rate)?;
        let sample_rate_hz = sample_rate
            .as_integer()
            .filter(|&rate| SAMPLE_RATE_HZ.contains(rate as f64))
            .ok_or_else(|| {
                value(
                    key::SAMPLE_RATE_HZ,
                    &format!(
                        "expected a whole number of Hz from {} to {}",
                        SAMPLE_RATE_HZ.min, SAMPLE_RATE_HZ.max
                    ),
                )
            })? as u32;
        let equalise = match equalise {
            None => Equalise::Acceleration,
            Some(word) => {
                let words: Vec<&str> = EQUALISE_WORDS.iter().map(|(word, _)| *word).collect();
                word.as_str()
                    .and_then(|word| EQUALISE_WORDS.iter().find(|(known, _)| *known == word))
                    .map(|(_, equalise)| *equalise)
                    .ok_or_else(|| {
                        value(
                            key::EQUALISE,
                            &format!("expected one of {}", words.join(", ")),
                        )
                    })?
            }
        };
        let spread_db = spread
            .map(|spread| numbers(key::SPREAD_DB, &spread))
            .transpose()?;
        if let Some(spread) = &spread_db {
            if spread.len() != points.len() {
                return Err(value(
                    key::SPREAD_DB,
                    &format!(
                        "has {} values for {} points of `{}`: one each",
                        spread.len(),
                        points.len(),
                        key::RESPONSE
                    ),
                ));
            }
            if let Some(bad) = spread.iter().position(|db| !(db.is_finite() && *db >= 0.0)) {
                return Err(value(
                    key::SPREAD_DB,
                    &format!(
                        "value {} is not a finite number of dB at or above 0",
                        bad + 1
                    ),
                ));
            }
        }
        let response = ActuatorResponse::new(&points, band, max_amplitude)
            .map_err(|error| value(key_of(&error), &error.to_string()))?
            .equalising(equalise);
        Ok(Self {
            name,
            text: text.to_owned(),
            points,
            response,
            sample_rate_hz,
            spread_db,
        })
    }

    /// Its name, as the file gives it.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The file's text, as read.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The response the engine compensates for (and its equalisation).
    pub fn response(&self) -> ActuatorResponse {
        self.response
    }

    /// The same profile equalising as `equalise` says (the command line's `--felt`); its text
    /// is unchanged.
    pub fn equalising(self, equalise: Equalise) -> Self {
        Self {
            response: self.response.equalising(equalise),
            ..self
        }
    }

    /// With `felt` (the command line's `--felt`, the editor's "felt"), the same profile
    /// equalising over the skin's threshold; without, equalising as the file says.
    pub fn felt_if(self, felt: bool) -> Self {
        if felt {
            self.equalising(Equalise::Felt)
        } else {
            self
        }
    }

    /// The `[Hz, dB]` points as written.
    pub fn points(&self) -> &[(f64, f64)] {
        &self.points
    }

    /// The rate (Hz) the device is driven at.
    pub fn sample_rate_hz(&self) -> u32 {
        self.sample_rate_hz
    }

    /// Each point's spread (dB) over a measurement's repeats, if the file gives it.
    pub fn spread_db(&self) -> Option<&[f64]> {
        self.spread_db.as_deref()
    }
}

/// The key of the profile a response's refusal is about.
fn key_of(error: &ResponseError) -> &'static str {
    match error {
        ResponseError::PointCount(_)
        | ResponseError::NotFinite { .. }
        | ResponseError::FrequencyOutOfRange { .. }
        | ResponseError::LevelOutOfRange { .. }
        | ResponseError::OutOfOrder { .. } => key::RESPONSE,
        ResponseError::BandNotOrdered { .. } | ResponseError::BandOutsidePoints { .. } => {
            key::BAND_HZ
        }
        ResponseError::MaxAmplitude(_) => key::MAX_AMPLITUDE,
    }
}

fn value(key: &'static str, reason: &str) -> ProfileError {
    ProfileError::Value {
        key,
        reason: printable(reason).into_owned(),
    }
}

fn required(key: &'static str, value: Option<toml::Value>) -> Result<toml::Value, ProfileError> {
    value.ok_or(ProfileError::Missing(key))
}

/// A number as TOML writes it: a float or an integer (NaN and infinities pass, for the
/// response's own check to name).
fn as_number(value: &toml::Value) -> Option<f64> {
    value
        .as_float()
        .or_else(|| value.as_integer().map(|integer| integer as f64))
}

fn number(key: &'static str, value: &toml::Value) -> Result<f64, ProfileError> {
    as_number(value).ok_or_else(|| self::value(key, "expected a number"))
}

fn numbers(key: &'static str, value: &toml::Value) -> Result<Vec<f64>, ProfileError> {
    let list = value
        .as_array()
        .ok_or_else(|| self::value(key, "expected a list of numbers"))?;
    list.iter()
        .enumerate()
        .map(|(index, item)| {
            as_number(item)
                .ok_or_else(|| self::value(key, &format!("value {} is not a number", index + 1)))
        })
        .collect()
}

fn pairs(key: &'static str, value: &toml::Value) -> Result<Vec<(f64, f64)>, ProfileError> {
    let list = value
        .as_array()
        .ok_or_else(|| self::value(key, "expected a list of [Hz, dB] points"))?;
    list.iter()
        .enumerate()
        .map(|(index, point)| {
            match point.as_array().map(Vec::as_slice) {
                Some([hz, db]) => as_number(hz).zip(as_number(db)),
                _ => None,
            }
            .ok_or_else(|| {
                self::value(
                    key,
                    &format!("point {} is not a [Hz, dB] pair of numbers", index + 1),
                )
            })
        })
        .collect()
}

/// A profile to write (a measured response), as TOML that
/// [`ActuatorProfile::parse`] reads back.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileText {
    /// The profile's name.
    pub name: String,
    /// Comment lines written at the top (where the numbers come from).
    pub comments: Vec<String>,
    /// The `[Hz, dB]` points.
    pub points: Vec<(f64, f64)>,
    /// The band (Hz).
    pub band_hz: [f64; 2],
    /// The largest drive (linear, of full scale).
    pub max_amplitude: f64,
    /// The rate the device is driven at (Hz).
    pub sample_rate_hz: u32,
    /// Each point's spread (dB), if measured more than once.
    pub spread_db: Option<Vec<f64>>,
}

impl ProfileText {
    /// The profile as TOML, numbers as the shortest text that reads back the same.
    pub fn to_toml(&self) -> String {
        let mut text = String::new();
        for line in &self.comments {
            text.push_str(&format!("# {}\n", printable(line)));
        }
        let name = toml::Value::String(self.name.clone());
        text.push_str(&format!("{} = {name}\n", key::NAME));
        let points: Vec<String> = self
            .points
            .iter()
            .map(|(hz, db)| format!("  [{}, {}],\n", float(*hz), float(*db)))
            .collect();
        text.push_str(&format!("{} = [\n{}]\n", key::RESPONSE, points.concat()));
        text.push_str(&format!(
            "{} = [{}, {}]\n",
            key::BAND_HZ,
            float(self.band_hz[0]),
            float(self.band_hz[1])
        ));
        text.push_str(&format!(
            "{} = {}\n",
            key::MAX_AMPLITUDE,
            float(self.max_amplitude)
        ));
        text.push_str(&format!(
            "{} = {}\n",
            key::SAMPLE_RATE_HZ,
            self.sample_rate_hz
        ));
        if let Some(spread) = &self.spread_db {
            let spread: Vec<String> = spread.iter().map(|db| float(*db)).collect();
            text.push_str(&format!("{} = [{}]\n", key::SPREAD_DB, spread.join(", ")));
        }
        text
    }
}

/// A float as TOML text that reads back as the same f64 (always with a point or exponent).
fn float(value: f64) -> String {
    toml::Value::Float(value).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shipped_profile_is_valid_and_named_as_its_file() {
        for (name, text) in shipped::SHIPPED {
            let profile =
                ActuatorProfile::parse(text).unwrap_or_else(|error| panic!("{name}: {error}"));
            assert_eq!(profile.name(), name);
        }
    }

    #[test]
    fn a_flat_profile_changes_no_gain() {
        let flat = ActuatorProfile::find("flat").unwrap().response();
        for frequency_hz in [[80.0, 300.0], [2.0, 90_000.0], [1.0, 1.0]] {
            assert_eq!(flat.gains(frequency_hz), [1.0, 1.0]);
        }
    }

    const GOOD: &str = r#"
name = "test"
response = [[40, -18.0], [90.0, 0.0], [1000.0, 0.0]]
band_hz = [90.0, 1000.0]
max_amplitude = 1.0
sample_rate_hz = 48000
"#;

    fn refusal(text: &str) -> String {
        ActuatorProfile::parse(text).unwrap_err().to_string()
    }

    #[test]
    fn a_profile_reads_and_writes_back() {
        let profile = ActuatorProfile::parse(GOOD).unwrap();
        assert_eq!(profile.name(), "test");
        assert_eq!(profile.response().response_db(60.0).signum(), -1.0);
        let text = ProfileText {
            name: "again".into(),
            comments: vec!["measured".into()],
            points: profile.points().to_vec(),
            band_hz: [90.0, 1000.0],
            max_amplitude: 0.5,
            sample_rate_hz: 44100,
            spread_db: Some(vec![0.1, 0.0, 0.25]),
        };
        let again = ActuatorProfile::parse(&text.to_toml()).unwrap();
        assert_eq!(again.points(), profile.points());
        assert_eq!(again.spread_db(), Some(&[0.1, 0.0, 0.25][..]));
        assert_eq!(again.response().max_amplitude(), 0.5);
    }

    #[test]
    fn bad_profiles_are_refused_with_the_key_named() {
        let cases = [
            (
                GOOD.replace("[40, -18.0], [90.0", "[90.0, -18.0], [40.0"),
                "`response`: point 2",
            ),
            (
                GOOD.replace("-18.0", "nan"),
                "`response`: point 1 is not two finite",
            ),
            (
                GOOD.replace("[90.0, 1000.0]\n", "[30.0, 1000.0]\n"),
                "`band_hz`",
            ),
            (
                GOOD.replace("[90.0, 1000.0]\n", "[900.0, 100.0]\n"),
                "`band_hz`",
            ),
            (
                GOOD.replace("max_amplitude = 1.0", "max_amplitude = 0"),
                "`max_amplitude`",
            ),
            (
                GOOD.replace("sample_rate_hz = 48000", "sample_rate_hz = 48000.5"),
                "`sample_rate_hz`",
            ),
            (GOOD.replace("name = \"test\"\n", ""), "`name` is missing"),
            (format!("{GOOD}colour = 1\n"), "unknown field `colour`"),
            (format!("{GOOD}equalise = \"loud\"\n"), "`equalise`"),
            (format!("{GOOD}spread_db = [0.1]\n"), "`spread_db`"),
            (
                GOOD.replace("[40, -18.0]", "[40, \"x\"]"),
                "`response`: point 1 is not a [Hz, dB]",
            ),
        ];
        for (text, expected) in cases {
            let message = refusal(&text);
            assert!(message.contains(expected), "{message:?} lacks {expected:?}");
        }
    }
}
