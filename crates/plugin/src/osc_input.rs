//! OSC in the plugin: the saved port and axis, the user's consent, and the socket thread.
//!
//! A network port opens only when the user turns OSC on in this session: in the editor, or on
//! the standalone app's command line. A port saved with a state is the project's wish: loading
//! it opens nothing; the editor shows that the project wants OSC on that port and opens it when
//! the user agrees. The socket binds to the address the user chose, loopback (this computer
//! only) unless asked for every interface.
//!
//! Real-time safety: the socket is bound, read and decoded on threads other than the audio
//! thread (the listener's own thread; [`OscInput::follow`] runs from `activate()` or the
//! editor). The audio thread only polls [`LiveControls`], whose `Arc` never changes while the
//! plugin lives: atomic loads, no lock, no allocation.

use std::net::{IpAddr, Ipv4Addr, SocketAddr};
use std::sync::atomic::{AtomicU16, AtomicU8, Ordering};
use std::sync::{Arc, Mutex};

use nice_plug::prelude::*;

use sake_glug_device::osc_listener::Report;
use sake_glug_device::{Axis, LiveControls, OscListener, OscStats};

/// The axis a new instance uses: a phone's +y runs from its bottom edge to its top, so a phone
/// held along the bottle with its top to the mouth reads upright at 0°.
pub const DEFAULT_AXIS: Axis = Axis::PlusY;

/// Where OSC listens unless the user asks for more: this computer only.
pub const DEFAULT_OSC_INTERFACE: IpAddr = IpAddr::V4(Ipv4Addr::LOCALHOST);

/// The OSC settings, saved with the plugin's state (per instance), not automatable.
#[derive(Params)]
pub struct OscSettings {
    /// UDP port to listen on; 0 is off. Saved with the project, but opened only once the user
    /// allows it in the session (see [`OscInput::allow`]).
    #[persist = "osc_port"]
    pub port: AtomicU16,
    /// Index in [`Axis::ALL`] of the sensor axis from the bottle's base to its mouth.
    #[persist = "osc_axis"]
    pub axis: AtomicU8,
}

impl Default for OscSettings {
    /// Off, unless the standalone app was started with `--osc-port`.
    fn default() -> Self {
        let (port, axis) = crate::standalone::options()
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
    /// The saved setting (a loaded project) wants this port, which the user has not opened in
    /// this session: it stays closed until [`OscInput::allow`].
    Waiting {
        /// The port the setting wants.
        port: u16,
    },
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
    address: SocketAddr,
    axis: Axis,
    listener: Option<OscListener>,
    error: Option<String>,
}

/// What this session decided about OSC; none of it is saved.
#[derive(Debug)]
struct Session {
    /// The port the user turned OSC on with, in the editor or on the command line (0: none).
    allowed_port: u16,
    /// The address the socket binds to.
    interface: IpAddr,
    /// The port the setting wants while it is not allowed (0: none).
    waiting_port: u16,
    running: Option<Running>,
}

/// The plugin's OSC input: the values for the audio thread, the counters, and the listener.
#[derive(Debug)]
pub struct OscInput {
    live: Arc<LiveControls>,
    stats: Arc<OscStats>,
    /// Only locked off the audio thread.
    session: Mutex<Session>,
}

impl Default for OscInput {
    /// Nothing allowed and loopback, unless the standalone app's command line says otherwise.
    fn default() -> Self {
        let options = crate::standalone::options();
        let session = Session {
            allowed_port: options
                .and_then(|options| options.osc)
                .map_or(0, |(port, _)| port),
            interface: options.map_or(DEFAULT_OSC_INTERFACE, |options| options.osc_interface),
            waiting_port: 0,
            running: None,
        };
        Self {
            live: Arc::default(),
            stats: Arc::default(),
            session: Mutex::new(session),
        }
    }
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

    /// The user turns OSC on at `port` in this session (the editor's port, its button for the
    /// port a project wants): a setting of that port is listened to from now on. Call
    /// [`follow`](Self::follow) to act on it.
    pub fn allow(&self, port: u16) {
        if let Ok(mut session) = self.session.lock() {
            session.allowed_port = port;
        }
    }

    /// The address the socket binds to.
    pub fn interface(&self) -> IpAddr {
        self.session
            .lock()
            .map_or(DEFAULT_OSC_INTERFACE, |session| session.interface)
    }

    /// The user picks the address to listen on (loopback, or every interface). Call
    /// [`follow`](Self::follow) to act on it.
    pub fn set_interface(&self, interface: IpAddr) {
        if let Ok(mut session) = self.session.lock() {
            session.interface = interface;
        }
    }

    /// Listens as `settings` say if the user allowed their port in this session; otherwise
    /// stops listening and waits for the user (see [`OscStatus::Waiting`]). Does nothing if
    /// that is what already runs. Binds a socket and starts a thread: never call it from the
    /// audio thread.
    pub fn follow(&self, settings: &OscSettings) {
        let Ok(mut session) = self.session.lock() else {
            return;
        };
        let (port, axis) = (settings.port(), settings.axis());
        let allowed = port != 0 && port == session.allowed_port;
        let waiting = if allowed { 0 } else { port };
        if waiting != 0 && waiting != session.waiting_port {
            nice_log!(
                "OSC: the project wants UDP port {port}; it stays closed until the editor's OSC \
                 panel opens it"
            );
        }
        session.waiting_port = waiting;
        let address = SocketAddr::new(session.interface, port);
        let wanted = allowed.then_some((address, axis));
        let running = session.running.as_ref().map(|now| (now.address, now.axis));
        if running == wanted {
            return;
        }
        // The old socket closes first, so that the same port can be bound again.
        session.running = None;
        if !allowed {
            return;
        }
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
        session.running = Some(Running {
            address,
            axis,
            listener,
            error,
        });
    }

    /// Whether and where it listens, or which port waits for the user.
    pub fn status(&self) -> OscStatus {
        let Ok(session) = self.session.lock() else {
            return OscStatus::Off;
        };
        match &session.running {
            None if session.waiting_port != 0 => OscStatus::Waiting {
                port: session.waiting_port,
            },
            None => OscStatus::Off,
            Some(Running {
                listener: Some(listener),
                ..
            }) => OscStatus::Listening(listener.local_addr()),
            Some(Running { address, error, .. }) => OscStatus::Failed {
                port: address.port(),
                error: error.clone().unwrap_or_default(),
            },
        }
    }
}
