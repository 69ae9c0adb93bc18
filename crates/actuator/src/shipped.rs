//! The profiles shipped in `actuators/`, embedded, found by name (`--actuator lra`).

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

/// The text of the shipped profile called `name`, if there is one ([`crate::ActuatorProfile::find`]
/// reads it).
pub(crate) fn shipped_text(name: &str) -> Option<&'static str> {
    SHIPPED
        .iter()
        .find(|(shipped, _)| *shipped == name)
        .map(|(_, text)| *text)
}
