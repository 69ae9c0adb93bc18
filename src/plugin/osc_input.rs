//! OSC in the plugin: the saved port and axis, and the socket thread they start.
//!
//! Real-time safety: the socket is bound, read and decoded on threads other than the audio
//! thread (the listener's own thread; [`OscInput::listen`] runs from `activate()` or the
//! editor). The audio thread only polls [`LiveControls`], whose `Arc` never changes while the
//! plugin lives: atomic loads, no lock, no allocation.

use std::net::{Ipv4Addr, SocketAddr};
use std::sync::atomic::{AtomicU16, AtomicU8, Ordering};
use std::sync::{Arc, Mutex};

use nice_plug::prelude::*;

use crate::device::osc_listener::Report;
use crate::device::{Axis, LiveControls, OscListener, OscStats};

/// The axis a new instance uses: a phone's +y runs from its bottom edge to its top, so a phone
/// held along the bottle with its top to the mouth reads upright at 0°.
pub const DEFAULT_AXIS: Axis = Axis::PlusY;

/// The OSC settings, saved with the plugin's state (per instance), not automatable.
#[derive(Params)]
pub struct OscSettings {
    /// UDP port to listen on, on every interface; 0 is off.
    #[persist = "osc_port"]
    pub port: AtomicU16,
    /// Index in [`Axis::ALL`] of the sensor axis from the bottle's base to its mouth.
    #[persist = "osc_axis"]
    pub axis: AtomicU8,
}

impl Default for OscSettings {
    /// Off, unless the standalone app was started with `--osc-port`.
    fn default() -> Self {
        let (port, axis) = crate::plugin::standalone::options()
            .and_then(|options| options.osc)
            .unwrap_or((0, DEFAULT_AXIS));
        let settings = Self {
            port: AtomicU16::new(0),
            axis: AtomicU8::new(0),
        };
        settings.set(port, axis);
        settings
    }
}

impl OscSettings {
    /// The port, 0 for off.
    pub fn port(&self) -> u16 {
        self.port.load(Ordering::Relaxed)
    }

    /// The sensor axis along the bottle (a saved index out of range reads as the default).
    pub fn axis(&self) -> Axis {
        Axis::ALL
            .get(self.axis.load(Ordering::Relaxed) as usize)
            .copied()
            .unwrap_or(DEFAULT_AXIS)
    }

    /// Saves `port` (0 = off) and `axis`.
    pub fn set(&self, port: u16, axis: Axis) {
        let index = Axis::ALL
            .iter()
            .position(|&known| known == axis)
            .unwrap_or(0);
        self.port.store(port, Ordering::Relaxed);
        self.axis.store(index as u8, Ordering::Relaxed);
    }
}

/// Whether the plugin is listening for OSC.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum OscStatus {
    /// No port set.
    Off,
    /// Listening on this address.
    Listening(SocketAddr),
    /// The port could not be bound (in use, or not allowed): the error in words.
    Failed {
        /// The port asked for.
        port: u16,
        /// Why it failed.
        error: String,
    },
}

#[derive(Debug)]
struct Running {
    port: u16,
    axis: Axis,
    listener: Option<OscListener>,
    error: Option<String>,
}

/// The plugin's OSC input: the values for the audio thread, the counters, and the listener.
#[derive(Debug, Default)]
pub struct OscInput {
    live: Arc<LiveControls>,
    stats: Arc<OscStats>,
    /// Only locked off the audio thread.
    running: Mutex<Option<Running>>,
}

impl OscInput {
    /// What OSC has set, for the audio thread.
    pub fn live(&self) -> &LiveControls {
        &self.live
    }

    /// Packets received and malformed.
    pub fn stats(&self) -> &OscStats {
        &self.stats
    }

    /// Listens on `port` (0: stops listening) with `axis`; does nothing if that is what already
    /// runs. Binds a socket and starts a thread: never call it from the audio thread.
    pub fn listen(&self, port: u16, axis: Axis) {
        let Ok(mut running) = self.running.lock() else {
            return;
        };
        if running
            .as_ref()
            .is_some_and(|now| now.port == port && now.axis == axis)
            || (port == 0 && running.is_none())
        {
            return;
        }
        // The old socket closes first, so that the same port can be bound again.
        *running = None;
        if port == 0 {
            return;
        }
        let address = SocketAddr::from((Ipv4Addr::UNSPECIFIED, port));
        let report: Report = Box::new(|count, error| {
            nice_log!("OSC: {count} malformed packet(s) ignored so far, the last: {error}")
        });
        let (listener, error) = match OscListener::spawn(
            address,
            axis,
            self.live.clone(),
            self.stats.clone(),
            report,
        ) {
            Ok(listener) => {
                nice_log!("OSC: listening on UDP {address}, bottle axis {axis}");
                (Some(listener), None)
            }
            Err(error) => {
                nice_error!("OSC: cannot listen on UDP {address}: {error}");
                (None, Some(error.to_string()))
            }
        };
        *running = Some(Running {
            port,
            axis,
            listener,
            error,
        });
    }

    /// Whether and where it listens.
    pub fn status(&self) -> OscStatus {
        let Ok(running) = self.running.lock() else {
            return OscStatus::Off;
        };
        match running.as_ref() {
            None => OscStatus::Off,
            Some(Running {
                listener: Some(listener),
                ..
            }) => OscStatus::Listening(listener.local_addr()),
            Some(Running { port, error, .. }) => OscStatus::Failed {
                port: *port,
                error: error.clone().unwrap_or_default(),
            },
        }
    }
}
