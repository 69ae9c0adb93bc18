//! The actuator the plugin compensates for (MODEL.md §18): a shipped profile or a profile's
//! text, and the felt flag, kept for the state and handed to the audio thread through a
//! lock-free queue (as `loaded_model.rs` hands over a model), so `process()` neither allocates,
//! locks nor waits.

use std::collections::BTreeMap;
use std::sync::Mutex;

use crossbeam_queue::ArrayQueue;
use nice_plug::params::persist;

use sake_glug_actuator::{ActuatorProfile, ActuatorResponse, ProfileError};

/// The persisted field that holds the actuator: a shipped profile's name, or else a profile's
/// whole text (a project must load on a machine without the file). Absent without one, so a
/// state without an actuator is byte for byte what it was before actuators.
pub const ACTUATOR_KEY: &str = "actuator";
/// The persisted field that says whether the skin's threshold is equalised (`--felt`); saved
/// only with an actuator.
pub const ACTUATOR_FELT_KEY: &str = "actuator_felt";

/// Changes queued for the audio thread before it takes them; the oldest is dropped if the
/// editor makes more between two blocks (only the newest counts).
const PENDING: usize = 4;

/// The actuator chosen: its profile, whether it is a shipped one (saved by name), and the felt
/// flag.
#[derive(Debug, Clone, PartialEq)]
pub struct Actuator {
    /// The profile as read.
    pub profile: ActuatorProfile,
    /// Saved by its name: one of `actuators/`.
    pub shipped: bool,
    /// Equalises over the skin's threshold instead of the acceleration.
    pub felt: bool,
}

impl Actuator {
    /// The shipped profile called `name`, if there is one.
    pub fn shipped(name: &str, felt: bool) -> Option<Self> {
        let profile = ActuatorProfile::shipped(name)?;
        Some(Self {
            profile,
            shipped: true,
            felt,
        })
    }

    /// A shipped profile's name, or else a profile file's path (the app's `--actuator`, the
    /// editor's "Load profile…"), as `sake-glug render --actuator` finds it.
    pub fn find(name_or_path: &str, felt: bool) -> Result<Self, ProfileError> {
        if let Some(actuator) = Self::shipped(name_or_path, felt) {
            return Ok(actuator);
        }
        Ok(Self {
            profile: ActuatorProfile::find(name_or_path)?,
            shipped: false,
            felt,
        })
    }

    /// The response the engine compensates for: as `sake-glug render --actuator` reads the
    /// profile, and with the felt flag as `--felt` equalises it.
    pub fn response(&self) -> ActuatorResponse {
        self.profile.clone().felt_if(self.felt).response()
    }

    /// What the state keeps of it: the name of a shipped profile, the text of any other.
    fn saved(&self) -> &str {
        if self.shipped {
            self.profile.name()
        } else {
            self.profile.text()
        }
    }
}

/// The plugin's actuator: the chosen one, for the editor and the state, and its changes on
/// their way to the audio thread.
pub struct ActuatorSetting {
    /// Read and written off the audio thread only.
    current: Mutex<Option<Actuator>>,
    changes: ArrayQueue<Option<ActuatorResponse>>,
}

impl Default for ActuatorSetting {
    fn default() -> Self {
        Self {
            current: Mutex::new(None),
            changes: ArrayQueue::new(PENDING),
        }
    }
}

impl ActuatorSetting {
    /// Compensates for `actuator` from the next block on (`None`: plays the model's drive).
    /// Not on the audio thread: it locks.
    pub fn set(&self, actuator: Option<Actuator>) {
        self.changes
            .force_push(actuator.as_ref().map(Actuator::response));
        *self.lock() = actuator;
    }

    /// The actuator chosen, if any.
    pub fn get(&self) -> Option<Actuator> {
        self.lock().clone()
    }

    /// The newest change since the last call, if any (`Some(None)`: none chosen). Lock-free and
    /// allocation-free: for the audio thread.
    pub fn take_change(&self) -> Option<Option<ActuatorResponse>> {
        let mut newest = None;
        while let Some(change) = self.changes.pop() {
            newest = Some(change);
        }
        newest
    }

    /// The persisted fields of the actuator: none without one.
    pub fn serialize_fields(&self) -> BTreeMap<String, String> {
        let mut fields = BTreeMap::new();
        if let Some(actuator) = &*self.lock() {
            let saved = [
                (ACTUATOR_KEY, persist::serialize_field(&actuator.saved())),
                (ACTUATOR_FELT_KEY, persist::serialize_field(&actuator.felt)),
            ];
            for (key, data) in saved {
                match data {
                    Ok(data) => {
                        fields.insert(key.to_owned(), data);
                    }
                    Err(error) => {
                        nice_plug::nice_debug_assert_failure!("cannot save '{}': {}", key, error)
                    }
                }
            }
        }
        fields
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Option<Actuator>> {
        // A panic elsewhere while holding it leaves a value that is still whole.
        self.current
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

/// The actuator in a state's `fields`: `Ok(None)` without one, `Err` with the reason (the field
/// and the profile's key) if it is neither a shipped profile's name nor a valid profile.
pub fn saved_actuator(fields: &BTreeMap<String, String>) -> Result<Option<Actuator>, String> {
    let Some(saved) = fields.get(ACTUATOR_KEY) else {
        return Ok(None);
    };
    let saved: String = persist::deserialize_field(saved)
        .map_err(|error| format!("field {ACTUATOR_KEY:?} is not a string: {error}"))?;
    let felt = match fields.get(ACTUATOR_FELT_KEY) {
        None => false,
        Some(felt) => persist::deserialize_field::<bool>(felt).map_err(|error| {
            format!("field {ACTUATOR_FELT_KEY:?} is not true or false: {error}")
        })?,
    };
    if let Some(actuator) = Actuator::shipped(&saved, felt) {
        return Ok(Some(actuator));
    }
    let profile = ActuatorProfile::parse(&saved)
        .map_err(|error| format!("field {ACTUATOR_KEY:?}: {error}"))?;
    Ok(Some(Actuator {
        profile,
        shipped: false,
        felt,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shipped_name_is_kept_by_name_and_a_file_by_its_text() {
        let shipped = Actuator::find("lra", true).unwrap();
        assert!(shipped.shipped && shipped.felt);
        assert_eq!(shipped.saved(), "lra");

        let directory = tempfile::tempdir().unwrap();
        let path = directory.path().join("shaker.toml");
        let text = "name = \"shaker\"\nresponse = [[20.0, -24.0], [1000.0, 0.0]]\n\
                    band_hz = [20.0, 1000.0]\nmax_amplitude = 1.0\nsample_rate_hz = 48000\n";
        std::fs::write(&path, text).unwrap();
        let own = Actuator::find(path.to_str().unwrap(), false).unwrap();
        assert!(!own.shipped && !own.felt);
        assert_eq!(own.saved(), text);

        let error = Actuator::find("no-such-profile", false).unwrap_err();
        assert!(matches!(error, ProfileError::Unknown(_)), "{error}");
    }
}
