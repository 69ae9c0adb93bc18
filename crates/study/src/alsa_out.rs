//! Presentation on an ALSA device (feature `audio`, as the standalone app reaches ALSA): the
//! stimuli on the actuator's channels, the masking noise on the headphone channels from the
//! start of the session to its end.
//!
//! The device is the one named, opened as it is: interleaved, the spec's channel count, 32-bit
//! float if it takes it, else 32- or 16-bit integers converted here. No `plug:` is put in front
//! of it: `default` is usually a `plug` already, and where someone names a bare `hw:` device
//! they want its samples untouched (`plughw:` asks for ALSA's conversions by name). Nor does
//! ALSA resample: the device runs at the scenes' sample rate if it can, else at the nearest it
//! has, and the stimuli are rendered at that rate, as JACK's rate decides them.
//!
//! A thread of its own writes one period at a time with blocking writes: the [`Mix`] fills it
//! (noise always, a trial's stimuli when one was asked for). Positions are counted in frames
//! written since the session started; a trial's end is known from the device's delay (the
//! frames written but not yet played) when its last period was written.

use std::ffi::CString;
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender, TryRecvError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use alsa::pcm::{Access, Format, HwParams, IoFormat, IO, PCM};
use alsa::{Direction, ValueOr};

use super::mix::{Mix, Timeline};
use super::session::{Onsets, Presented, Presenter};
use super::spec::Channels;
use super::trials::Trial;
use super::StudyError;

/// The device's buffer and period asked for: long enough that a busy machine does not starve
/// it, short enough that a trial starts soon after it is asked for.
const BUFFER_US: u32 = 100_000;
const PERIOD_US: u32 = 25_000;

/// The sample formats taken, the first the device has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SampleFormat {
    F32,
    S32,
    S16,
}

impl SampleFormat {
    const PREFERRED: [Self; 3] = [Self::F32, Self::S32, Self::S16];

    fn alsa(self) -> Format {
        match self {
            Self::F32 => Format::float(),
            Self::S32 => Format::s32(),
            Self::S16 => Format::s16(),
        }
    }
}

/// A sample as the device takes it.
trait Sample: IoFormat + Default + Send + 'static {
    fn from_f32(sample: f32) -> Self;
}

impl Sample for f32 {
    fn from_f32(sample: f32) -> Self {
        sample
    }
}

impl Sample for i32 {
    fn from_f32(sample: f32) -> Self {
        // Through f64: f32 cannot hold i32::MAX.
        (f64::from(sample.clamp(-1.0, 1.0)) * f64::from(i32::MAX)).round() as i32
    }
}

impl Sample for i16 {
    fn from_f32(sample: f32) -> Self {
        (sample.clamp(-1.0, 1.0) * f32::from(i16::MAX)).round() as i16
    }
}

/// An ALSA device set up for a session, not yet playing: its sample rate decides the stimuli's.
pub struct AlsaOutput {
    pcm: PCM,
    device: String,
    sample_rate: u32,
    period: usize,
    format: SampleFormat,
}

/// What the writer thread tells of a trial once its last period is written.
struct Played {
    /// The trial's onset: frames written before its first sample.
    onset: u64,
    /// When its last sample leaves the device.
    ended: Instant,
    /// How much longer than its length the trial took to be heard, beyond what measuring
    /// the delay blurs: silence the device played when it ran out of samples.
    silence: Option<Duration>,
    /// The underruns ALSA reported while it played.
    xruns: u32,
}

/// The trial being written.
struct Playing {
    /// Frames written before its first sample, and before its end.
    onset: u64,
    end: u64,
    /// When its first sample leaves the device.
    onset_heard: Option<Instant>,
    xruns: u32,
}

/// `now` moved by `seconds`, either way.
fn offset(now: Instant, seconds: f64) -> Instant {
    if seconds >= 0.0 {
        now + Duration::from_secs_f64(seconds)
    } else {
        now.checked_sub(Duration::from_secs_f64(-seconds))
            .unwrap_or(now)
    }
}

/// The player: the writer thread runs until this is dropped.
pub struct AlsaPlayer {
    device: String,
    requests: Option<Sender<Trial>>,
    reports: Receiver<Result<Played, StudyError>>,
    writer: Option<JoinHandle<()>>,
    timeline: Timeline,
    sample_rate: u32,
}

impl AlsaOutput {
    /// Opens the PCM device `device` (an ALSA name: `default`, `hw:1`, `plughw:CARD=USB`, …) for
    /// playback with `channels` interleaved channels, at `sample_rate` (Hz) or the device's
    /// nearest rate.
    pub fn open(device: &str, channels: u16, sample_rate: u32) -> Result<Self, StudyError> {
        let fail = |what: &str, error: alsa::Error| {
            StudyError::Audio(format!("ALSA device `{device}`: {what}: {error}"))
        };
        let name = CString::new(device).map_err(|_| {
            StudyError::Audio(format!(
                "ALSA device `{device}`: a device name cannot hold a NUL byte"
            ))
        })?;
        let pcm = PCM::open(&name, Direction::Playback, false).map_err(|error| {
            fail(
                "cannot open it for playback (`aplay -L` lists the devices)",
                error,
            )
        })?;
        let (format, sample_rate, period, buffer) = {
            let params =
                HwParams::any(&pcm).map_err(|error| fail("cannot read its settings", error))?;
            params
                .set_access(Access::RWInterleaved)
                .map_err(|error| fail("it takes no interleaved samples", error))?;
            if params.set_channels(u32::from(channels)).is_err() {
                let range = params
                    .get_channels_min()
                    .and_then(|min| Ok((min, params.get_channels_max()?)));
                return Err(StudyError::Audio(match range {
                    Ok((min, max)) => format!(
                        "ALSA device `{device}` plays {min} to {max} channels, and the study \
                         needs {channels} (its highest actuator or headphone channel)"
                    ),
                    Err(error) => {
                        format!("ALSA device `{device}` cannot play {channels} channels: {error}")
                    }
                }));
            }
            let format = SampleFormat::PREFERRED
                .into_iter()
                .find(|format| params.test_format(format.alsa()).is_ok())
                .ok_or_else(|| {
                    StudyError::Audio(format!(
                        "ALSA device `{device}` takes none of the sample formats 32-bit float, \
                         32-bit or 16-bit integer (name a `plug` device, e.g. `plughw:…`, for \
                         ALSA's conversions)"
                    ))
                })?;
            params
                .set_format(format.alsa())
                .map_err(|error| fail("cannot set its sample format", error))?;
            params
                .set_rate_resample(false)
                .map_err(|error| fail("cannot turn its resampling off", error))?;
            let sample_rate = params
                .set_rate_near(sample_rate, ValueOr::Nearest)
                .map_err(|error| fail("cannot set its sample rate", error))?;
            // Wishes, the period first: a device whose periods come in steps (ALSA's `jack`
            // plugin: whole JACK periods) takes the nearest step, and the buffer then holds
            // whole periods; a device that refuses either keeps its own.
            let _ = params.set_period_time_near(PERIOD_US, ValueOr::Nearest);
            let _ = params.set_buffer_time_near(BUFFER_US, ValueOr::Nearest);
            pcm.hw_params(&params)
                .map_err(|error| fail("cannot be set up", error))?;
            let current = pcm
                .hw_params_current()
                .map_err(|error| fail("cannot read its settings", error))?;
            let period = current
                .get_period_size()
                .map_err(|error| fail("cannot read its period", error))?;
            let buffer = current
                .get_buffer_size()
                .map_err(|error| fail("cannot read its buffer", error))?;
            (format, sample_rate, period, buffer)
        };
        {
            // The device starts once its buffer is full, so a slow first period cannot starve
            // it; after an underrun it restarts the same way.
            let params = pcm
                .sw_params_current()
                .map_err(|error| fail("cannot read its settings", error))?;
            params
                .set_start_threshold(buffer)
                .and_then(|()| params.set_avail_min(period))
                .and_then(|()| pcm.sw_params(&params))
                .map_err(|error| fail("cannot be set up", error))?;
        }
        Ok(Self {
            pcm,
            device: device.to_owned(),
            sample_rate,
            period: period.max(1) as usize,
            format,
        })
    }

    /// The device's sample rate (Hz).
    pub fn sample_rate(&self) -> u32 {
        self.sample_rate
    }

    /// Starts playing: the noise (an RMS level in dBFS, uniform white noise) at once on the
    /// headphone channels, a trial's stimuli on the actuator channels when one is presented.
    pub fn start(
        self,
        stimuli: Vec<Vec<f32>>,
        gap_samples: u64,
        channels: &Channels,
        noise_dbfs: Option<f64>,
    ) -> Result<AlsaPlayer, StudyError> {
        let mix = Mix::new(stimuli, gap_samples, channels, noise_dbfs);
        let timeline = mix.timeline().clone();
        let (requests, requested) = mpsc::channel();
        let (report, reports) = mpsc::channel();
        let device = self.device.clone();
        let sample_rate = self.sample_rate;
        let writer = std::thread::Builder::new().name("alsa-writer".into());
        let writer = match self.format {
            SampleFormat::F32 => writer.spawn(move || self.write::<f32>(mix, requested, report)),
            SampleFormat::S32 => writer.spawn(move || self.write::<i32>(mix, requested, report)),
            SampleFormat::S16 => writer.spawn(move || self.write::<i16>(mix, requested, report)),
        }
        .map_err(|error| {
            StudyError::Audio(format!(
                "ALSA device `{device}`: cannot start its writer thread: {error}"
            ))
        })?;
        Ok(AlsaPlayer {
            device,
            requests: Some(requests),
            reports,
            writer: Some(writer),
            timeline,
            sample_rate,
        })
    }

    fn error(&self, what: &str, error: alsa::Error) -> StudyError {
        StudyError::Audio(format!("ALSA device `{}`: {what}: {error}", self.device))
    }

    /// The writer thread: period after period until the player is dropped (its requests end)
    /// or the device fails (the next trial then gets the error).
    fn write<S: Sample>(
        self,
        mix: Mix,
        requested: Receiver<Trial>,
        report: Sender<Result<Played, StudyError>>,
    ) {
        if let Err(error) = self.write_periods::<S>(mix, &requested, &report) {
            let _ = report.send(Err(error));
        }
        // Dropping the PCM closes the device (a `file` PCM then completes its header).
    }

    fn write_periods<S: Sample>(
        &self,
        mut mix: Mix,
        requested: &Receiver<Trial>,
        report: &Sender<Result<Played, StudyError>>,
    ) -> Result<(), StudyError> {
        let io = self
            .pcm
            .io_checked::<S>()
            .map_err(|error| self.error("cannot write to it", error))?;
        let channels = mix.channels();
        let mut blocks = vec![vec![0.0f32; self.period]; channels];
        let mut interleaved = vec![S::default(); self.period * channels];
        let rate = f64::from(self.sample_rate);
        // The delay is known to about a period at each end of a trial (many devices move their
        // position a period at a time).
        let blur =
            Duration::from_secs_f64(2.0 * self.period as f64 / rate) + Duration::from_millis(5);
        let started = Instant::now();
        // Frames written since the session started: the positions logged.
        let mut written = 0u64;
        let mut trial: Option<Playing> = None;
        loop {
            if !mix.playing() {
                match requested.try_recv() {
                    Ok(asked) => {
                        mix.begin(asked);
                        let length = mix.timeline().of(asked).end;
                        trial = Some(Playing {
                            onset: written,
                            end: written + length,
                            onset_heard: None,
                            xruns: 0,
                        });
                    }
                    Err(TryRecvError::Empty) => {}
                    Err(TryRecvError::Disconnected) => return Ok(()),
                }
            }
            let into_trial = trial.as_ref().map_or(0, |playing| written - playing.onset);
            let outputs = blocks.iter_mut().map(|block| &mut block[..]);
            let ended = mix.fill(into_trial, self.period, outputs);
            for (frame, samples) in interleaved.chunks_exact_mut(channels).enumerate() {
                for (sample, block) in samples.iter_mut().zip(&blocks) {
                    *sample = S::from_f32(block[frame]);
                }
            }
            let xruns = self.write_all(&io, &interleaved, channels)?;
            written += self.period as u64;
            // What is written and not yet played. An underrun since the write has played it
            // all: nothing is held.
            let delay = self.pcm.delay();
            let held = delay.unwrap_or(0).max(0) as u64;
            // A device that holds nothing right after a write does not play in real time (the
            // `file` PCM over `null` takes everything at once): the system clock stands in for
            // its clock, and paces the session so that it lasts as long as it would sound.
            let clocked = matches!(delay, Ok(frames) if frames <= 0);
            if clocked {
                let due = started + Duration::from_secs_f64(written as f64 / rate);
                if let Some(wait) = due.checked_duration_since(Instant::now()) {
                    std::thread::sleep(wait);
                }
            }
            // When position p leaves the device: once the frames held before it have played (p
            // was written `written - p` frames ago, `held` of which are still to play).
            let now = Instant::now();
            let heard = |position: u64| {
                if clocked {
                    offset(started, position as f64 / rate)
                } else {
                    offset(now, (position + held) as f64 / rate - written as f64 / rate)
                }
            };
            let Some(playing) = &mut trial else {
                continue;
            };
            playing.xruns += xruns;
            let onset_heard = *playing
                .onset_heard
                .get_or_insert_with(|| heard(playing.onset));
            if ended {
                let ended = heard(playing.end);
                let length = Duration::from_secs_f64((playing.end - playing.onset) as f64 / rate);
                let late = ended
                    .saturating_duration_since(onset_heard)
                    .saturating_sub(length);
                // A player already gone wants no report.
                let _ = report.send(Ok(Played {
                    onset: playing.onset,
                    ended,
                    silence: (late > blur).then_some(late),
                    xruns: playing.xruns,
                }));
                trial = None;
            }
        }
    }

    /// Writes a period whole, recovering from underruns; returns how many there were.
    ///
    /// An underrun (the device played everything before the next write came) or a suspend is
    /// recovered by preparing the device again; the samples go on from where they were, so the
    /// device plays a stretch of silence that the positions, counted in frames written, do not
    /// include: every onset after it is later on the device than its logged frame says. The
    /// player warns of an underrun during a trial, and of silence a device played without
    /// reporting one (ALSA's `jack` plugin does so), seen as a trial heard for longer than it
    /// lasts.
    fn write_all<S: Sample>(
        &self,
        io: &IO<'_, S>,
        mut samples: &[S],
        channels: usize,
    ) -> Result<u32, StudyError> {
        let mut xruns = 0;
        while !samples.is_empty() {
            match io.writei(samples) {
                Ok(frames) => samples = &samples[frames * channels..],
                Err(error) => {
                    if error.errno() != libc::EINTR {
                        xruns += 1;
                    }
                    self.pcm
                        .try_recover(error, true)
                        .map_err(|error| self.error("stopped playing", error))?;
                }
            }
        }
        Ok(xruns)
    }
}

impl Presenter for AlsaPlayer {
    fn present(&mut self, trial: Trial) -> Result<Presented, StudyError> {
        let stopped = || {
            StudyError::Audio(format!(
                "ALSA device `{}` stopped playing the trial",
                self.device
            ))
        };
        let requests = self.requests.as_ref().ok_or_else(stopped)?;
        requests.send(trial).map_err(|_| stopped())?;
        let placed = self.timeline.of(trial);
        let length = placed.end;
        // Far longer than the trial: a device that stopped taking samples.
        let give_up = Duration::from_secs_f64(2.0 * length as f64 / self.sample_rate as f64 + 5.0);
        let played = match self.reports.recv_timeout(give_up) {
            Ok(played) => played?,
            Err(RecvTimeoutError::Timeout | RecvTimeoutError::Disconnected) => {
                return Err(stopped())
            }
        };
        let what = match (played.silence, played.xruns) {
            (None, 0) => None,
            (None, xruns) => Some(format!("ran out of samples {xruns} time(s)")),
            (Some(silence), 0) => Some(format!(
                "played about {} ms of silence (it ran out of samples without reporting it)",
                silence.as_millis()
            )),
            (Some(silence), xruns) => Some(format!(
                "ran out of samples {xruns} time(s) and played about {} ms of silence",
                silence.as_millis()
            )),
        };
        if let Some(what) = what {
            eprintln!(
                "warning: ALSA device `{}` {what} during this trial: its stimuli were heard \
                 further apart than their logged onset frames (frames written) say",
                self.device
            );
        }
        // The answer counts from the last sample played, not from when it was written.
        if let Some(wait) = played.ended.checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
        Ok(Presented {
            onset_frames: Some(Onsets {
                first: played.onset,
                second: played.onset + placed.onsets[1],
                third: (placed.count > 2).then(|| played.onset + placed.onsets[2]),
            }),
            ended: played.ended,
        })
    }
}

impl Drop for AlsaPlayer {
    fn drop(&mut self) {
        // Ends the writer at its next period; waited for (a `file` PCM completes its header
        // when closed), but not for ever: a device stuck in a write is left behind.
        self.requests = None;
        if let Some(writer) = self.writer.take() {
            let give_up = Instant::now() + Duration::from_secs(2);
            while !writer.is_finished() && Instant::now() < give_up {
                std::thread::sleep(Duration::from_millis(5));
            }
            if writer.is_finished() {
                let _ = writer.join();
            }
        }
    }
}
