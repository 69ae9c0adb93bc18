//! The OSC socket: a thread that reads UDP packets, decodes them with [`decode_osc`] and stores
//! the controls in [`LiveControls`] for the audio thread. Nothing here runs on the audio thread.
//!
//! A packet that does not decode is dropped whole and counted in [`OscStats`], with its error
//! kept for display, and passed to the caller's report function at the 1st, 2nd, 4th, 8th, …
//! malformed packet (a log that a flood of garbage cannot flood); the thread carries on.

use std::io;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use crate::axis::Axis;
use crate::live::LiveControls;
use crate::osc::{decode_osc, OscControl};

/// How often the thread looks whether it should stop, while no packet comes.
const STOP_POLL: Duration = Duration::from_millis(50);

/// The largest UDP payload.
const MAX_PACKET: usize = 65_536;

/// What the listener has seen, for the editor and the log.
#[derive(Debug, Default)]
pub struct OscStats {
    /// Packets received, good or not.
    pub packets: AtomicU64,
    /// Packets dropped because they did not decode.
    pub malformed: AtomicU64,
    /// The last decoding error, in words.
    last_error: Mutex<Option<String>>,
}

impl OscStats {
    /// The last decoding error, if any packet was malformed.
    pub fn last_error(&self) -> Option<String> {
        self.last_error
            .lock()
            .map_or(None, |error| error.as_ref().cloned())
    }

    /// Counts a malformed packet; reports it if the count is a power of two.
    fn record_error(&self, error: String, report: &Report) {
        let count = self.malformed.fetch_add(1, Ordering::Relaxed) + 1;
        if count.is_power_of_two() {
            report(count, &error);
        }
        if let Ok(mut last) = self.last_error.lock() {
            *last = Some(error);
        }
    }
}

/// Told the count of malformed packets so far and the last one's error.
pub type Report = Box<dyn Fn(u64, &str) + Send>;

/// A running OSC listener; dropping it stops the thread and closes the socket.
#[derive(Debug)]
pub struct OscListener {
    local_addr: SocketAddr,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl OscListener {
    /// Binds a UDP socket to `address` and starts reading it on a thread of its own. `axis` is
    /// the sensor axis from the bottle's base to its mouth, for gravity vectors; `report` hears
    /// of malformed packets (see the module documentation).
    pub fn spawn(
        address: SocketAddr,
        axis: Axis,
        live: Arc<LiveControls>,
        stats: Arc<OscStats>,
        report: Report,
    ) -> io::Result<Self> {
        let socket = UdpSocket::bind(address)?;
        socket.set_read_timeout(Some(STOP_POLL))?;
        let local_addr = socket.local_addr()?;
        let stop = Arc::new(AtomicBool::new(false));
        let thread = std::thread::Builder::new()
            .name(format!("osc {local_addr}"))
            .spawn({
                let stop = stop.clone();
                move || listen(&socket, axis, &live, &stats, &stop, &report)
            })?;
        Ok(Self {
            local_addr,
            stop,
            thread: Some(thread),
        })
    }

    /// The address the socket is bound to (with the port the system chose, if it was 0).
    pub fn local_addr(&self) -> SocketAddr {
        self.local_addr
    }
}

impl Drop for OscListener {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

fn listen(
    socket: &UdpSocket,
    axis: Axis,
    live: &LiveControls,
    stats: &OscStats,
    stop: &AtomicBool,
    report: &Report,
) {
    let mut buffer = vec![0u8; MAX_PACKET];
    while !stop.load(Ordering::Relaxed) {
        let size = match socket.recv_from(&mut buffer) {
            Ok((size, _sender)) => size,
            Err(error)
                if matches!(
                    error.kind(),
                    io::ErrorKind::WouldBlock
                        | io::ErrorKind::TimedOut
                        | io::ErrorKind::Interrupted
                ) =>
            {
                continue
            }
            // An ICMP error from an earlier send, or a packet larger than the buffer: count it
            // and go on.
            Err(error) => {
                stats.packets.fetch_add(1, Ordering::Relaxed);
                stats.record_error(error.to_string(), report);
                continue;
            }
        };
        stats.packets.fetch_add(1, Ordering::Relaxed);
        let applied = decode_osc(&buffer[..size], axis, &mut |control| match control {
            OscControl::Set(control, value) => live.set(control, value),
            OscControl::Refill => live.refill(),
        });
        if let Err(error) = applied {
            stats.record_error(error.to_string(), report);
        }
    }
}
