//! The profiles shipped in `actuators/`, embedded, found by name (`--actuator lra`).

use crate::profile::ActuatorProfile;

/// Each shipped profile's name and text (the file `actuators/<name>.toml`).
pub const SHIPPED: [(&str, &str); 6] = [
    ("flat", include_str!("../../../actuators/flat.toml")),
    (
        "haptuator-mark2",
        include_str!("../../../actuators/haptuator-mark2.toml"),
    ),
    ("lra", include_str!("../../../actuators/lra.toml")),
    ("phone", include_str!("../../../actuators/phone.toml")),
    (
        "dualsense",
        include_str!("../../../actuators/dualsense.toml"),
    ),
    (
        "vr-controller",
        include_str!("../../../actuators/vr-controller.toml"),
    ),
];

/// The names of the shipped profiles.
pub fn shipped_names() -> Vec<&'static str> {
    SHIPPED.iter().map(|(name, _)| *name).collect()
}

/// The shipped profile called `name`, if there is one.
pub(crate) fn shipped(name: &str) -> Option<ActuatorProfile> {
    SHIPPED
        .iter()
        .find(|(shipped, _)| *shipped == name)
        .map(|(_, text)| ActuatorProfile::parse(text).expect("a shipped profile is valid"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shipped_profile_is_valid_and_named_as_its_file() {
        for (name, text) in SHIPPED {
            let profile =
                ActuatorProfile::parse(text).unwrap_or_else(|error| panic!("{name}: {error}"));
            assert_eq!(profile.name(), name);
        }
    }

    #[test]
    fn a_flat_profile_changes_no_gain() {
        let flat = shipped("flat").unwrap().response();
        for frequency_hz in [[80.0, 300.0], [2.0, 90_000.0], [1.0, 1.0]] {
            assert_eq!(flat.gains(frequency_hz), [1.0, 1.0]);
        }
    }
}
