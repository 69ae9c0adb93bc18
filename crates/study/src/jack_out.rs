//! Presentation on a JACK server (feature `audio`, as the standalone app reaches JACK): the
//! stimuli on the actuator's channels, the masking noise on the headphone channels from the
//! start of the session to its end.
//!
//! The stimuli are rendered before the client is activated and handed to its process callback
//! whole, in the [`Mix`] that fills each cycle; the session then starts a trial through one atomic word, and the callback reports the
//! frame the trial started at and that it ended through two more. The callback neither
//! allocates nor locks.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use super::mix::{Mix, Timeline};
use super::session::{Onsets, Presented, Presenter};
use super::spec::Channels;
use super::trials::Trial;
use super::StudyError;
use jack::{AudioOut, Client, ClientOptions, Control, Port, PortFlags};

/// A JACK client, not yet playing: its sample rate decides the stimuli's.
pub struct JackOutput {
    client: Client,
}

/// The callback's side of the hand-off.
#[derive(Default)]
struct Shared {
    /// The trial asked: its generation and stimuli ([`encode`]).
    request: AtomicU64,
    /// Generation of the last trial that has ended.
    ended: AtomicU64,
    /// JACK frame at which the last trial started.
    onset_frame: AtomicU64,
}

/// The player, active on the server until dropped.
pub struct JackPlayer {
    client: jack::AsyncClient<(), jack::contrib::ClosureProcessHandler<(), Callback>>,
    shared: Arc<Shared>,
    generation: u64,
    timeline: Timeline,
    sample_rate: u32,
}

type Callback = Box<dyn FnMut(&Client, &jack::ProcessScope) -> Control + Send>;

/// A stimulus's index in a request: 16 bits, all ones for none (a two-interval trial's third).
/// A spec has far fewer stimuli than that (at most [`crate::MAX_TRIALS`] + 1).
const NO_STIMULUS: u64 = 0xffff;
const _: () = assert!(crate::MAX_TRIALS < NO_STIMULUS);

/// A request in one word: the generation in the high 16 bits (a session has far fewer trials
/// than 2¹⁶, practice included), then the first, second and third stimulus, 16 bits each.
fn encode(generation: u64, trial: Trial) -> u64 {
    let third = trial.third.map_or(NO_STIMULUS, |third| third as u64);
    (generation << 48) | ((trial.first as u64) << 32) | ((trial.second as u64) << 16) | third
}

/// The generation and the trial of a request.
fn decode(request: u64) -> (u64, Trial) {
    let stimulus = |shift: u32| ((request >> shift) & 0xffff) as usize;
    let third = (request & 0xffff != NO_STIMULUS).then(|| stimulus(0));
    (
        request >> 48,
        Trial {
            first: stimulus(32),
            second: stimulus(16),
            third,
        },
    )
}

fn audio_error(what: &str, error: impl std::fmt::Display) -> StudyError {
    StudyError::Audio(format!("{what}: {error}"))
}

impl JackOutput {
    /// Opens a client called `name` on the running JACK server (`$JACK_DEFAULT_SERVER` or the
    /// default one); never starts a server.
    pub fn open(name: &str) -> Result<Self, StudyError> {
        let (client, _) = Client::new(name, ClientOptions::NO_START_SERVER)
            .map_err(|error| audio_error("cannot reach a JACK server", error))?;
        Ok(Self { client })
    }

    /// The server's sample rate (Hz).
    pub fn sample_rate(&self) -> u32 {
        self.client.sample_rate()
    }

    /// Starts playing: ports `out_1` … `out_N` for the channels, each connected to the
    /// server's physical playback port of the same number where there is one; the noise (an
    /// RMS level in dBFS, uniform white noise) runs at once on the headphone channels.
    pub fn start(
        self,
        stimuli: Vec<Vec<f32>>,
        gap_samples: u64,
        channels: &Channels,
        noise_dbfs: Option<f64>,
    ) -> Result<JackPlayer, StudyError> {
        let client = self.client;
        let sample_rate = client.sample_rate();
        let mut ports: Vec<Port<AudioOut>> = Vec::new();
        for channel in 1..=channels.count() {
            ports.push(
                client
                    .register_port(&format!("out_{channel}"), AudioOut::default())
                    .map_err(|error| audio_error("cannot register a port", error))?,
            );
        }
        let names: Vec<String> = ports
            .iter()
            .map(|port| port.name().unwrap_or_default())
            .collect();
        let shared = Arc::new(Shared::default());
        let mut mix = Mix::new(stimuli, gap_samples, channels, noise_dbfs);
        let timeline = mix.timeline().clone();
        // The trial playing: its generation and its onset frame.
        let mut playing: Option<(u64, jack::Frames)> = None;
        let mut served = 0u64;
        let callback_shared = Arc::clone(&shared);
        let callback: Callback = Box::new(move |_client, scope| {
            let frames = scope.n_frames() as usize;
            let now = scope.last_frame_time();
            let (generation, trial) = decode(callback_shared.request.load(Ordering::Acquire));
            if playing.is_none() && generation > served {
                served = generation;
                mix.begin(trial);
                playing = Some((generation, now));
                callback_shared
                    .onset_frame
                    .store(now as u64, Ordering::Release);
            }
            // The position follows JACK's frame clock, so a cycle the server skips (an xrun)
            // loses its samples but moves nothing later: the logged frames stay true.
            let into_trial = playing.map_or(0, |(_, onset)| now.wrapping_sub(onset) as u64);
            let outputs = ports.iter_mut().map(|port| port.as_mut_slice(scope));
            if mix.fill(into_trial, frames, outputs) {
                if let Some((generation, _)) = playing.take() {
                    callback_shared.ended.store(generation, Ordering::Release);
                }
            }
            Control::Continue
        });
        let active = client
            .activate_async((), jack::contrib::ClosureProcessHandler::new(callback))
            .map_err(|error| audio_error("cannot start the JACK client", error))?;
        let physical = active.as_client().ports(
            None,
            Some("32 bit float mono audio"),
            PortFlags::IS_INPUT | PortFlags::IS_PHYSICAL,
        );
        for (ours, theirs) in names.iter().zip(&physical) {
            // A missing or refused connection leaves the port for the user to connect.
            let _ = active.as_client().connect_ports_by_name(ours, theirs);
        }
        Ok(JackPlayer {
            client: active,
            shared,
            generation: 0,
            timeline,
            sample_rate,
        })
    }
}

impl Presenter for JackPlayer {
    fn present(&mut self, trial: Trial) -> Result<Presented, StudyError> {
        self.generation += 1;
        self.shared
            .request
            .store(encode(self.generation, trial), Ordering::Release);
        let placed = self.timeline.of(trial);
        let length = placed.end;
        // Far longer than the trial: a server that stopped running our callback.
        let give_up = Instant::now()
            + Duration::from_secs_f64(2.0 * length as f64 / self.sample_rate as f64 + 5.0);
        while self.shared.ended.load(Ordering::Acquire) < self.generation {
            if Instant::now() > give_up {
                return Err(StudyError::Audio(
                    "the JACK server stopped playing the trial".into(),
                ));
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        let client = self.client.as_client();
        let first = self.shared.onset_frame.load(Ordering::Acquire);
        // Frame times are 32-bit and wrap (after a day at 48 kHz), as JACK's own do.
        let end = (first + length) as jack::Frames;
        // The end on JACK's clock (µs), and how long ago that was: the response time counts
        // from the last sample played, not from when this thread noticed.
        let end_us = client.frames_to_time(end);
        let now_us = client.time();
        let since = Duration::from_micros(now_us.saturating_sub(end_us));
        Ok(Presented {
            onset_frames: Some(Onsets {
                first,
                second: first + placed.onsets[1],
                third: (placed.count > 2).then(|| first + placed.onsets[2]),
            }),
            ended: Instant::now()
                .checked_sub(since)
                .unwrap_or_else(Instant::now),
        })
    }
}
