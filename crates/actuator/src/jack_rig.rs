//! The measuring rig on a JACK server (feature `audio`): one output port driving the device, one
//! input port recording its accelerometer, both served by one process callback, so that sample
//! n of a recording was captured in the cycle that played sample n.
//!
//! A block to play is handed over whole, with a recording buffer as long, through a mutex the
//! callback only ever tries (it never waits: a cycle that finds it held plays silence, and
//! the main thread holds it only while no block plays). The callback neither allocates nor
//! blocks. Xruns are counted from JACK's notification; a block during which the count moved
//! is reported spoiled.

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
    /// The server shut the client down.
    shut_down: AtomicBool,
}

struct Notifications(Arc<Shared>);

impl jack::NotificationHandler for Notifications {
    fn xrun(&mut self, _: &Client) -> Control {
        self.0.xruns.fetch_add(1, Ordering::AcqRel);
        Control::Continue
    }

    unsafe fn shutdown(&mut self, _: jack::ClientStatus, _: &str) {
        self.0.shut_down.store(true, Ordering::Release);
    }
}

struct Process {
    shared: Arc<Shared>,
    output: Port<AudioOut>,
    input: Port<AudioIn>,
}

impl jack::ProcessHandler for Process {
    fn process(&mut self, _: &Client, scope: &ProcessScope) -> Control {
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
}

fn audio(what: &str, error: impl std::fmt::Display) -> MeasureError {
    MeasureError::Audio(format!("{what}: {error}"))
}

impl JackRig {
    /// Opens client `name` on `$JACK_DEFAULT_SERVER` (or the default server), its `drive` port
    /// connected to `play_to` and its `accelerometer` port to `record_from`; without them, to the
    /// server's first physical playback and capture ports.
    pub fn open(
        name: &str,
        play_to: Option<&str>,
        record_from: Option<&str>,
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
                },
            )
            .map_err(|error| audio("cannot start the JACK client", error))?;
        for (from, to) in [(&ours_out, &play_to), (&record_from, &ours_in)] {
            client
                .as_client()
                .connect_ports_by_name(from, to)
                .map_err(|error| audio(&format!("cannot connect {from} to {to}"), error))?;
        }
        Ok(Self {
            _client: client,
            shared,
            sample_rate,
            period,
        })
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
            block.armed = true;
        }
        let seconds = samples.len() as f64 / self.sample_rate as f64;
        // Far longer than the block: a server that stopped running our callback.
        let give_up = Instant::now() + Duration::from_secs_f64(2.0 * seconds + 5.0);
        while !self.shared.done.load(Ordering::Acquire) {
            if self.shared.shut_down.load(Ordering::Acquire) {
                return Err(MeasureError::Audio(
                    "the JACK server shut the client down".into(),
                ));
            }
            if Instant::now() > give_up {
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
        let spoiled = self.shared.xruns.load(Ordering::Acquire) != xruns_before;
        let recorded = std::mem::take(&mut self.block().recorded);
        Ok(Take { recorded, spoiled })
    }
}
