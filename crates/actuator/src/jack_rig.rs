//! The measuring rig on a JACK server (feature `audio`): one output port driving the device, one
//! input port recording its accelerometer, both served by one process callback, so that sample
//! n of a recording was captured in the cycle that played sample n.
//!
//! A block to play is handed over whole, with a recording buffer as long, through a mutex the
//! callback only ever tries (it never waits: a cycle that finds it held plays silence, and
//! the main thread holds it only while no block plays). The callback neither allocates nor
//! blocks. Xruns are counted from JACK's notification; a block during which the count moved
//! is reported spoiled.
//!
//! With `freewheel`, the rig turns JACK's freewheel on once its ports are connected and off
//! again before its client leaves: the server then runs each cycle as soon as every client has
//! finished the last, so a slow device or a busy machine delays the measurement and never drops a
//! cycle. Only then: jack2 saves the connections when freewheel starts and restores them when it
//! stops, so a client that joins, connects or leaves meanwhile leaves the server confused (a
//! cycle stalls for its 10 s timeout on a join; a client closed meanwhile is restored, jack2
//! issue 1006). Xruns still spoil a block while it freewheels: jack2 reports some as it switches
//! (a slow client still running its last real-time cycle), and a cycle can then be lost. A
//! freewheeling server also drops a cycle when it gives up on a client after
//! [`FREEWHEEL_TIMEOUT`], so a block during which two of the rig's cycles came that far apart is
//! spoiled too.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use jack::{AudioIn, AudioOut, Client, ClientOptions, Control, Port, PortFlags, ProcessScope};

use crate::measure::{MeasureError, Rig, Take};

/// The block the callback plays, and what it recorded of it.
#[derive(Default)]
struct Block {
    playing: Vec<f32>,
    recorded: Vec<f32>,
    position: usize,
    armed: bool,
}

#[derive(Default)]
struct Shared {
    block: Mutex<Block>,
    /// Set by the callback when the armed block has been played whole.
    done: AtomicBool,
    xruns: AtomicU64,
    /// The cycles the callback has run: a server that stopped running it is told from a slow one.
    cycles: AtomicU64,
    /// The longest time between two cycles of the callback since the main thread last cleared
    /// it (ns).
    longest_gap_ns: AtomicU64,
    /// What the server last said of freewheel.
    freewheeling: AtomicBool,
    /// The server shut the client down.
    shut_down: AtomicBool,
}

struct Notifications(Arc<Shared>);

impl jack::NotificationHandler for Notifications {
    fn xrun(&mut self, _: &Client) -> Control {
        self.0.xruns.fetch_add(1, Ordering::AcqRel);
        Control::Continue
    }

    fn freewheel(&mut self, _: &Client, is_freewheel_enabled: bool) {
        self.0
            .freewheeling
            .store(is_freewheel_enabled, Ordering::Release);
    }

    unsafe fn shutdown(&mut self, _: jack::ClientStatus, _: &str) {
        self.0.shut_down.store(true, Ordering::Release);
    }
}

struct Process {
    shared: Arc<Shared>,
    output: Port<AudioOut>,
    input: Port<AudioIn>,
    /// When the last cycle began.
    last_cycle: Option<Instant>,
}

impl jack::ProcessHandler for Process {
    fn process(&mut self, _: &Client, scope: &ProcessScope) -> Control {
        self.shared.cycles.fetch_add(1, Ordering::AcqRel);
        // A clock read: no lock, no allocation.
        let now = Instant::now();
        if let Some(last) = self.last_cycle.replace(now) {
            let gap = u64::try_from(now.duration_since(last).as_nanos()).unwrap_or(u64::MAX);
            self.shared.longest_gap_ns.fetch_max(gap, Ordering::AcqRel);
        }
        let output = self.output.as_mut_slice(scope);
        output.fill(0.0);
        let input = self.input.as_slice(scope);
        // Never waits: the main thread holds the lock only while nothing is armed.
        if let Ok(mut block) = self.shared.block.try_lock() {
            if block.armed {
                let Block {
                    playing,
                    recorded,
                    position,
                    armed,
                } = &mut *block;
                let count = output.len().min(playing.len() - *position);
                let range = *position..*position + count;
                output[..count].copy_from_slice(&playing[range.clone()]);
                recorded[range].copy_from_slice(&input[..count]);
                *position += count;
                if *position == playing.len() {
                    *armed = false;
                    self.shared.done.store(true, Ordering::Release);
                }
            }
        }
        Control::Continue
    }
}

/// A client on the running JACK server (never started by us), its ports connected.
pub struct JackRig {
    /// Kept only to stay active: dropping it deactivates the client and closes its ports.
    _client: jack::AsyncClient<Notifications, Process>,
    shared: Arc<Shared>,
    sample_rate: u32,
    period: u32,
    /// The rig turned freewheel on, and turns it off before its client leaves.
    freewheel: bool,
}

/// How long the server may run not one cycle of ours before the rig gives up on it: longer than
/// jack2's own limit on a freewheeling cycle (10 s), after which it goes on without the client.
const STALLED: Duration = Duration::from_secs(15);
/// How long a freewheeling jack2 server waits for a client's cycle before it goes on without it
/// (its `FREEWHEEL_DRIVER_TIMEOUT`).
const FREEWHEEL_TIMEOUT: Duration = Duration::from_secs(10);
/// How long the server may take to say it started or stopped freewheeling.
const FREEWHEEL_ANSWER: Duration = Duration::from_secs(15);

fn audio(what: &str, error: impl std::fmt::Display) -> MeasureError {
    MeasureError::Audio(format!("{what}: {error}"))
}

impl JackRig {
    /// Opens client `name` on `$JACK_DEFAULT_SERVER` (or the default server), its `drive` port
    /// connected to `play_to` and its `accelerometer` port to `record_from`; without them, to the
    /// server's first physical playback and capture ports. With `freewheel`, the server freewheels
    /// from then until the rig is dropped.
    pub fn open(
        name: &str,
        play_to: Option<&str>,
        record_from: Option<&str>,
        freewheel: bool,
    ) -> Result<Self, MeasureError> {
        let (client, _) = Client::new(name, ClientOptions::NO_START_SERVER)
            .map_err(|error| audio("cannot reach a JACK server", error))?;
        let output = client
            .register_port("drive", AudioOut::default())
            .map_err(|error| audio("cannot register a port", error))?;
        let input = client
            .register_port("accelerometer", AudioIn::default())
            .map_err(|error| audio("cannot register a port", error))?;
        let (ours_out, ours_in) = (
            output.name().map_err(|e| audio("a port", e))?,
            input.name().map_err(|e| audio("a port", e))?,
        );
        let physical = |flags: PortFlags, option: &str, what: &str| {
            client
                .ports(
                    None,
                    Some("32 bit float mono audio"),
                    flags | PortFlags::IS_PHYSICAL,
                )
                .into_iter()
                .next()
                .ok_or_else(|| {
                    MeasureError::Audio(format!(
                        "the JACK server has no physical {what} port: name one with {option}"
                    ))
                })
        };
        let play_to = match play_to {
            Some(port) => port.to_owned(),
            None => physical(PortFlags::IS_INPUT, "--play-to", "playback")?,
        };
        let record_from = match record_from {
            Some(port) => port.to_owned(),
            None => physical(PortFlags::IS_OUTPUT, "--record-from", "capture")?,
        };
        for port in [&play_to, &record_from] {
            if client.port_by_name(port).is_none() {
                return Err(MeasureError::Audio(format!(
                    "the JACK server has no port named {}",
                    sake_glug_io::text::quoted(port)
                )));
            }
        }
        let sample_rate = client.sample_rate();
        let period = client.buffer_size();
        let shared = Arc::new(Shared::default());
        let client = client
            .activate_async(
                Notifications(Arc::clone(&shared)),
                Process {
                    shared: Arc::clone(&shared),
                    output,
                    input,
                    last_cycle: None,
                },
            )
            .map_err(|error| audio("cannot start the JACK client", error))?;
        for (from, to) in [(&ours_out, &play_to), (&record_from, &ours_in)] {
            client
                .as_client()
                .connect_ports_by_name(from, to)
                .map_err(|error| audio(&format!("cannot connect {from} to {to}"), error))?;
        }
        let mut rig = Self {
            _client: client,
            shared,
            sample_rate,
            period,
            freewheel: false,
        };
        if freewheel {
            rig.request_freewheel(true)?;
            // Accepted: from here on, dropping the rig stops it.
            rig.freewheel = true;
            rig.await_freewheel(true)?;
        }
        Ok(rig)
    }

    /// Asks the server to start or stop freewheeling.
    fn request_freewheel(&self, on: bool) -> Result<(), MeasureError> {
        // SAFETY: the client is open for as long as `self` lives; jack_set_freewheel only sends
        // the server a request (the `jack` crate does not wrap it).
        let status = unsafe {
            jack::jack_sys::jack_set_freewheel(self._client.as_client().raw(), on.into())
        };
        if status == 0 {
            Ok(())
        } else {
            Err(MeasureError::Audio(format!(
                "the JACK server refused to {} freewheeling (status {status}){}",
                if on { "start" } else { "stop" },
                if on {
                    ": is it freewheeling already?"
                } else {
                    ""
                }
            )))
        }
    }

    /// Waits until the server says it started (`on`) or stopped freewheeling.
    fn await_freewheel(&self, on: bool) -> Result<(), MeasureError> {
        let answer_by = Instant::now() + FREEWHEEL_ANSWER;
        while self.shared.freewheeling.load(Ordering::Acquire) != on {
            if Instant::now() > answer_by {
                return Err(MeasureError::Audio(format!(
                    "the JACK server did not say it {} freewheeling within {} s",
                    if on { "started" } else { "stopped" },
                    FREEWHEEL_ANSWER.as_secs()
                )));
            }
            std::thread::sleep(Duration::from_millis(2));
        }
        Ok(())
    }

    /// The lock, which only this thread takes while nothing is armed.
    fn block(&self) -> std::sync::MutexGuard<'_, Block> {
        self.shared
            .block
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

impl Rig for JackRig {
    fn sample_rate_hz(&self) -> u32 {
        self.sample_rate
    }

    fn play_and_record(&mut self, samples: &[f32]) -> Result<Take, MeasureError> {
        let xruns_before = self.shared.xruns.load(Ordering::Acquire);
        {
            let mut block = self.block();
            block.playing = samples.to_vec();
            block.recorded = vec![0.0; samples.len()];
            block.position = 0;
            self.shared.done.store(false, Ordering::Release);
            self.shared.longest_gap_ns.store(0, Ordering::Release);
            block.armed = true;
        }
        // Given up on when the server stops running our callback, however slowly it runs it
        // (a freewheeling server runs as fast as its slowest client).
        let mut cycles = self.shared.cycles.load(Ordering::Acquire);
        let mut give_up = Instant::now() + STALLED;
        while !self.shared.done.load(Ordering::Acquire) {
            if self.shared.shut_down.load(Ordering::Acquire) {
                return Err(MeasureError::Audio(
                    "the JACK server shut the client down".into(),
                ));
            }
            let now_cycles = self.shared.cycles.load(Ordering::Acquire);
            if now_cycles != cycles {
                cycles = now_cycles;
                give_up = Instant::now() + STALLED;
            } else if Instant::now() > give_up {
                return Err(MeasureError::Audio(
                    "the JACK server stopped running the client".into(),
                ));
            }
            std::thread::sleep(Duration::from_millis(2));
        }
        // JACK reports an xrun after the cycle it spoiled: wait two periods for the news.
        std::thread::sleep(Duration::from_secs_f64(
            2.0 * self.period as f64 / self.sample_rate as f64,
        ));
        let gave_up_on_a_client = self.freewheel
            && Duration::from_nanos(self.shared.longest_gap_ns.load(Ordering::Acquire))
                >= FREEWHEEL_TIMEOUT;
        let spoiled =
            gave_up_on_a_client || self.shared.xruns.load(Ordering::Acquire) != xruns_before;
        let recorded = std::mem::take(&mut self.block().recorded);
        Ok(Take { recorded, spoiled })
    }
}

impl Drop for JackRig {
    /// Real time again before the client leaves: a client leaving a freewheeling server leaves it
    /// confused (above).
    fn drop(&mut self) {
        if self.freewheel {
            let stopped = self
                .request_freewheel(false)
                .and_then(|()| self.await_freewheel(false));
            if let Err(error) = stopped {
                eprintln!("warning: {error}");
            }
        }
    }
}
