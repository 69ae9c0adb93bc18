//! Controls from OSC packets (UDP payloads): Sake Glug's own addresses, and the gravity vectors
//! that phone sensor apps send, turned into tilt.
//!
//! Phone apps disagree on which way their vector points: iOS apps pass on Core Motion, whose
//! gravity points down, to the earth (a phone lying face up reads z = −1 g), while Android's
//! sensors report the reaction, pointing up (+9.81 m/s² on z face up). [`GRAVITY_SOURCES`] names
//! the convention of each address, and a reading that points down is turned round before its
//! tilt is taken, so one [`Axis`] (the phone axis from the bottle's base to its mouth) means the
//! same for every app.
//!
//! Bundles are opened here rather than by rosc, so that their depth is bounded (rosc recurses
//! without a limit, and a 64 KiB packet could nest thousands deep) and so that a bad element
//! deep inside is an error rather than silently dropped, as rosc does. Time tags are ignored:
//! a control applies when it arrives.

use rosc::{OscMessage, OscPacket, OscType};
use thiserror::Error;

use super::axis::{tilt_from_gravity, Axis};
use sake_glug_engine::Control;

/// How deep bundles may nest: a bundle directly in the packet is at depth 1.
pub const MAX_BUNDLE_DEPTH: usize = 8;

/// How deep OSC arrays (`[` … `]` type tags) may nest in a message. No address here takes
/// arrays; the bound keeps rosc from building (and recursively dropping) a value nested
/// tens of thousands deep.
pub const MAX_ARRAY_DEPTH: usize = 8;

/// Refill the bottle, whatever the arguments.
pub const REFILL_ADDRESS: &str = "/sakeglug/refill";
/// Which way a sensor app's vector points when the phone is at rest.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pointing {
    /// Away from the earth, as MEMS accelerometers and Android report it.
    Up,
    /// To the earth, as iOS's Core Motion reports gravity.
    Down,
}

/// Gravity-vector addresses and the way each points: GyrOSC (iOS, Core Motion's gravity),
/// TouchOSC's accelerometer (iOS values, in g), and Sensors2OSC's gravity and accelerometer
/// (Android, m/s²). Only the direction matters, so the units do not.
pub const GRAVITY_SOURCES: [(&str, Pointing); 4] = [
    ("/gyrosc/grav", Pointing::Down),
    ("/accxyz", Pointing::Down),
    ("/gravity", Pointing::Up),
    ("/acceleration", Pointing::Up),
];

/// The bundle tag that starts a bundle, with its terminating NUL.
const BUNDLE_TAG: &[u8; 8] = b"#bundle\0";

/// A control set over OSC.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OscControl {
    /// A control set to a value in its own unit: at its own address (the control table's
    /// `osc_address`), or the tilt worked out from a gravity vector.
    Set(Control, f64),
    /// Refill the bottle.
    Refill,
}

/// A packet that is not valid OSC, or a message to a known address with the wrong arguments.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum OscError {
    /// rosc could not decode a message.
    #[error("malformed OSC packet: {0}")]
    Malformed(String),
    /// Bytes after the end of a message.
    #[error("{count} stray bytes after the OSC message {address:?}")]
    TrailingBytes {
        /// The message's address.
        address: String,
        /// How many bytes follow it.
        count: usize,
    },
    /// A bundle too short for its tag and time tag.
    #[error("an OSC bundle of {0} bytes, too short for its header of 16")]
    ShortBundle(usize),
    /// A bundle element whose size runs past the end of its bundle.
    #[error("an OSC bundle element declares {declared} bytes but only {remaining} remain")]
    BundleElement {
        /// The size the element declares.
        declared: u32,
        /// The bytes left in the bundle after the size.
        remaining: usize,
    },
    /// Bundles nested deeper than [`MAX_BUNDLE_DEPTH`].
    #[error("OSC bundles nested deeper than {MAX_BUNDLE_DEPTH}")]
    BundlesTooDeep,
    /// Arrays nested deeper than [`MAX_ARRAY_DEPTH`].
    #[error("OSC arrays nested deeper than {MAX_ARRAY_DEPTH}")]
    ArraysTooDeep,
    /// A known address with too few or too many arguments.
    #[error("{address} takes {expected}, not {found} arguments")]
    ArgumentCount {
        /// The address.
        address: String,
        /// What it takes, in words.
        expected: &'static str,
        /// How many came.
        found: usize,
    },
    /// A known address with an argument that is not a number.
    #[error("{address}: argument {position} is {found}, not a number")]
    NotANumber {
        /// The address.
        address: String,
        /// The argument, from 1.
        position: usize,
        /// The OSC type that came, in words.
        found: &'static str,
    },
    /// A known address with an infinite or NaN argument.
    #[error("{address}: argument {position} is {value}, not a finite number")]
    NotFinite {
        /// The address.
        address: String,
        /// The argument, from 1.
        position: usize,
        /// The value that came.
        value: f64,
    },
    /// A gravity vector of zero length, which gives no tilt.
    #[error("{address}: the gravity vector is zero, so it has no direction")]
    ZeroVector {
        /// The address.
        address: String,
    },
}

/// Decodes one OSC packet and passes each control it sets to `out`, in packet order.
///
/// `axis` is the sensor axis along the bottle, for gravity vectors. Numbers may come as OSC
/// floats, doubles or 32/64-bit ints. Unknown addresses are ignored. A packet with any error
/// passes nothing to `out`: a bundle applies whole or not at all.
pub fn decode_osc(
    packet: &[u8],
    axis: Axis,
    out: &mut impl FnMut(OscControl),
) -> Result<(), OscError> {
    let mut controls = Vec::new();
    decode_element(packet, axis, 0, &mut controls)?;
    controls.into_iter().for_each(out);
    Ok(())
}

/// Decodes a packet or bundle element found at bundle depth `depth` into `controls`.
fn decode_element(
    bytes: &[u8],
    axis: Axis,
    depth: usize,
    controls: &mut Vec<OscControl>,
) -> Result<(), OscError> {
    let Some(after_tag) = bytes.strip_prefix(BUNDLE_TAG) else {
        check_array_depth(bytes)?;
        let message = decode_message(bytes)?;
        if let Some(control) = control_from(&message, axis)? {
            controls.push(control);
        }
        return Ok(());
    };
    if depth + 1 > MAX_BUNDLE_DEPTH {
        return Err(OscError::BundlesTooDeep);
    }
    // The time tag is not used: controls apply on arrival.
    let Some(mut rest) = after_tag.get(8..) else {
        return Err(OscError::ShortBundle(bytes.len()));
    };
    while !rest.is_empty() {
        let Some((size, after_size)) = rest.split_first_chunk::<4>() else {
            return Err(OscError::BundleElement {
                declared: 0,
                remaining: rest.len(),
            });
        };
        let declared = u32::from_be_bytes(*size);
        let Some(element) = usize::try_from(declared)
            .ok()
            .and_then(|size| after_size.get(..size))
        else {
            return Err(OscError::BundleElement {
                declared,
                remaining: after_size.len(),
            });
        };
        decode_element(element, axis, depth + 1, controls)?;
        rest = &after_size[element.len()..];
    }
    Ok(())
}

/// A single message, refusing bytes after it.
fn decode_message(bytes: &[u8]) -> Result<OscMessage, OscError> {
    let (rest, packet) =
        rosc::decoder::decode_udp(bytes).map_err(|error| OscError::Malformed(error.to_string()))?;
    match packet {
        OscPacket::Message(message) if rest.is_empty() => Ok(message),
        OscPacket::Message(message) => Err(OscError::TrailingBytes {
            address: message.addr,
            count: rest.len(),
        }),
        // Only bytes starting with the bundle tag decode as a bundle, and those are opened in
        // decode_element.
        OscPacket::Bundle(_) => Err(OscError::Malformed("unexpected bundle".to_owned())),
    }
}

/// Refuses a message whose type tags nest arrays deeper than [`MAX_ARRAY_DEPTH`], before rosc
/// builds them. Anything else odd about the message is left for rosc to find.
fn check_array_depth(message: &[u8]) -> Result<(), OscError> {
    // The address, NUL-terminated and padded to 4 bytes, then the type tags.
    let Some(address_end) = message.iter().position(|&byte| byte == 0) else {
        return Ok(());
    };
    let Some(type_tags) = message.get((address_end / 4 + 1) * 4..) else {
        return Ok(());
    };
    let mut depth = 0_usize;
    for &tag in type_tags.iter().take_while(|&&byte| byte != 0) {
        match tag {
            b'[' => depth += 1,
            b']' => depth = depth.saturating_sub(1),
            _ => {}
        }
        if depth > MAX_ARRAY_DEPTH {
            return Err(OscError::ArraysTooDeep);
        }
    }
    Ok(())
}

/// The control a message sets, if its address is known.
fn control_from(message: &OscMessage, axis: Axis) -> Result<Option<OscControl>, OscError> {
    let address = message.addr.as_str();
    if let Some((control, _)) =
        Control::device_inputs().find(|(_, device)| device.osc_address == address)
    {
        return Ok(Some(OscControl::Set(control, single_number(message)?)));
    }
    let control = match (address, gravity_pointing(address)) {
        (REFILL_ADDRESS, _) => OscControl::Refill,
        (_, Some(pointing)) => {
            let [x, y, z] = message.args.as_slice() else {
                return Err(count_error(message, "3 numbers"));
            };
            let reading = [
                number(message, 1, x)?,
                number(message, 2, y)?,
                number(message, 3, z)?,
            ];
            // tilt_from_gravity takes a reading that points up.
            let reading = match pointing {
                Pointing::Up => reading,
                Pointing::Down => reading.map(|component| -component),
            };
            let tilt = tilt_from_gravity(reading, axis).ok_or_else(|| OscError::ZeroVector {
                address: address.to_owned(),
            })?;
            OscControl::Set(Control::Tilt, tilt)
        }
        _ => return Ok(None),
    };
    Ok(Some(control))
}

/// The way the vector of a gravity address points, if `address` is one.
fn gravity_pointing(address: &str) -> Option<Pointing> {
    GRAVITY_SOURCES
        .iter()
        .find(|(known, _)| *known == address)
        .map(|&(_, pointing)| pointing)
}

/// The one numeric argument of `message`.
fn single_number(message: &OscMessage) -> Result<f64, OscError> {
    match message.args.as_slice() {
        [argument] => number(message, 1, argument),
        _ => Err(count_error(message, "1 number")),
    }
}

fn count_error(message: &OscMessage, expected: &'static str) -> OscError {
    OscError::ArgumentCount {
        address: message.addr.clone(),
        expected,
        found: message.args.len(),
    }
}

/// Argument `position` (from 1) of `message` as a finite number.
fn number(message: &OscMessage, position: usize, argument: &OscType) -> Result<f64, OscError> {
    let value = match argument {
        OscType::Float(value) => f64::from(*value),
        OscType::Double(value) => *value,
        OscType::Int(value) => f64::from(*value),
        OscType::Long(value) => *value as f64,
        other => {
            return Err(OscError::NotANumber {
                address: message.addr.clone(),
                position,
                found: type_name(other),
            })
        }
    };
    if !value.is_finite() {
        return Err(OscError::NotFinite {
            address: message.addr.clone(),
            position,
            value,
        });
    }
    Ok(value)
}

/// An OSC type in words, for errors.
fn type_name(argument: &OscType) -> &'static str {
    match argument {
        OscType::Int(_) => "an int",
        OscType::Float(_) => "a float",
        OscType::String(_) => "a string",
        OscType::Blob(_) => "a blob",
        OscType::Time(_) => "a time tag",
        OscType::Long(_) => "a 64-bit int",
        OscType::Double(_) => "a double",
        OscType::Char(_) => "a char",
        OscType::Color(_) => "a colour",
        OscType::Midi(_) => "a MIDI message",
        OscType::Bool(_) => "a boolean",
        OscType::Array(_) => "an array",
        OscType::Nil => "nil",
        OscType::Inf => "infinitum",
    }
}
