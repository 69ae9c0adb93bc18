//! Offline rendering of a scene: scene → engine → a sink of sample blocks.

use std::time::{Duration, Instant};

use super::scene::{LaneBuffers, Scene, MAX_DURATION_S};
use sake_glug_device::midi::{CcDecoder, DeviceAction};
use sake_glug_device::midi_take::TimedInput;
use sake_glug_engine::synthesis::SILENT_DECAY_EXPONENT;
use sake_glug_engine::{
    Controls, DrainMode, Engine, Lane, Outflow, PerControl, UnitOnset, Voicing,
};

/// Samples per engine call offline; any size gives the same samples.
const BLOCK_SIZE: usize = 4096;

/// Why a scene could not be rendered.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The scene has no `duration_s` and cannot be seen to fall silent.
    #[error(
        "the scene never falls silent (it pours or rings for ever after its last automation \
         point, or past {MAX_DURATION_S} s), so it has no natural end; give it a duration_s"
    )]
    NeverSettles,
    /// The scene has no `duration_s` and a glug component decays too slowly to fall silent
    /// within [`MAX_DURATION_S`]: refused before anything is rendered.
    #[error(
        "`{key}` = {decay_per_s} /s: a glug needs {decay_time} to decay to −120 dB, longer than \
         the {MAX_DURATION_S} s a render may last, so the scene has no natural end; give it a \
         duration_s, or a decay rate of at least {min_decay_per_s:.6} /s"
    )]
    DecaysTooSlowly {
        /// The scene key of the decay rate.
        key: &'static str,
        /// Its value (1/s).
        decay_per_s: f64,
        /// How long e^(−Bτ) takes to reach 10⁻⁶ ("for ever" at B = 0).
        decay_time: String,
        /// The slowest decay that falls silent within the limit.
        min_decay_per_s: f64,
    },
    /// The caller stopped the render ([`RenderObserver::interrupted`]).
    #[error("interrupted")]
    Interrupted,
}

/// What a finished render did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RenderSummary {
    /// Length of the render (samples).
    pub samples: u64,
    /// Sample rate of the render (Hz).
    pub sample_rate: u32,
    /// Wave units started.
    pub units: u64,
    /// Largest |sample|.
    pub peak: f32,
    /// The lowest and highest V_i of the units started (ml), `None` without a unit.
    pub unit_volumes_ml: Option<(f64, f64)>,
    /// Wall-clock time the render took.
    pub elapsed: Duration,
}

impl RenderSummary {
    /// Length of the render (s).
    pub fn duration_s(&self) -> f64 {
        self.samples as f64 / self.sample_rate as f64
    }

    /// How many times faster than real time the render ran.
    pub fn realtime_factor(&self) -> f64 {
        self.duration_s() / self.elapsed.as_secs_f64().max(1e-9)
    }
}

/// The bottle as a block left it: what the render reports to an observer that asks for it
/// ([`RenderObserver::next_bottle_report`]), the engine's own values.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BottleReport {
    /// Samples rendered: the block's last sample is `position − 1`.
    pub position: u64,
    /// The residual volume after them (ml): V at the start of sample `position`.
    pub volume_ml: f64,
    /// What the last sample (`position − 1`) poured: V at its start, its outflow, whether the
    /// mouth was submerged.
    pub last_sample: Outflow,
    /// θ of the last sample, brought into range (°).
    pub tilt_deg: f64,
    /// The output gain G of the last sample (linear, on its ramp: MODEL.md §6).
    pub output_gain: f64,
}

/// What a render tells besides its samples; every method has a default that ignores it. A
/// closure `FnMut(u64)` is an observer of progress alone.
pub trait RenderObserver {
    /// `rendered` samples are done.
    fn progress(&mut self, _rendered: u64) {}
    /// A unit started (its onset is `(onset.sample + onset.fraction) / fs`), voiced as `voicing`
    /// says (its output gain, on its ramp: MODEL.md §6, and whether it sounds).
    fn unit_started(&mut self, _onset: &UnitOnset, _voicing: Voicing) {}
    /// The next position after `position` (samples rendered) at which a
    /// [`RenderObserver::bottle`] report is wanted, or `None` for none: the render then ends a
    /// block there, which changes no sample, and reports after every block.
    fn next_bottle_report(&self, _position: u64) -> Option<u64> {
        None
    }
    /// The bottle after a block.
    fn bottle(&mut self, _report: &BottleReport) {}
    /// Whether the render is to stop (its user interrupted it), asked after every block: the
    /// render then ends with [`RenderError::Interrupted`].
    fn interrupted(&self) -> bool {
        false
    }
}

impl<F: FnMut(u64)> RenderObserver for F {
    fn progress(&mut self, rendered: u64) {
        self(rendered)
    }
}

/// Renders `scene`, handing its samples to `sink` in blocks and telling `observer` how far it
/// got, which units started and how the bottle drained. A scene without a duration ends where
/// pouring stopped and the last unit decayed (below −120 dB), a sample fixed by the model, not
/// by how time was cut into blocks.
pub fn render_scene<E: From<RenderError>>(
    scene: &Scene,
    mut sink: impl FnMut(&[f32]) -> Result<(), E>,
    observer: &mut impl RenderObserver,
) -> Result<RenderSummary, E> {
    let started = Instant::now();
    if scene.duration_s.is_none() {
        refuse_endless_decays(scene)?;
    }
    let sample_rate = scene.sample_rate as f64;
    let mut engine = Engine::new(sample_rate, scene.config);
    engine.set_actuator(scene.actuator);
    let mut lanes = LaneBuffers::default();
    let mut block = vec![0.0f32; BLOCK_SIZE];
    let total = scene.duration_samples();
    let settle_from = (scene.last_automation_s() * sample_rate).ceil() as u64;
    let give_up_at = (MAX_DURATION_S * sample_rate) as u64;
    let mut take = TakePlayer::new(scene);
    // Trailing zeros are held back until something follows them or the end is known.
    let (mut written, mut held_zeros, mut peak) = (0u64, 0u64, 0.0f32);
    let mut unit_volumes_ml: Option<(f64, f64)> = None;

    loop {
        let position = engine.position();
        let len = match total {
            Some(total) => BLOCK_SIZE.min((total - position) as usize),
            None => BLOCK_SIZE,
        };
        if len == 0 {
            break;
        }
        take.act_at(position, &mut engine);
        let len = take.until_next(position).map_or(len, |next| len.min(next));
        let report_at = observer.next_bottle_report(position);
        // A report asked for at or before `position` (which no observer should) ends the block
        // after one sample, never at once.
        let len = report_at.map_or(len, |next| {
            len.min(next.saturating_sub(position).max(1) as usize)
        });
        let mut controls = scene.controls(position, &mut lanes, len);
        take.override_lanes(&mut controls);
        let block = &mut block[..len];
        engine.process_observed(&controls, block, &mut |onset, voicing| {
            widen(&mut unit_volumes_ml, onset.volume_ml);
            observer.unit_started(onset, voicing)
        });
        // The output stage after synthesis: a trimmed render's fade (crate::trim).
        if let Some(fade) = &scene.fade_out {
            fade.apply(position, block);
        }
        observer.progress(engine.position());
        if report_at.is_some() {
            observer.bottle(&BottleReport {
                position: engine.position(),
                volume_ml: engine.volume_ml(),
                last_sample: engine.last_outflow(),
                tilt_deg: controls.values_at(len - 1).sanitized().tilt_deg,
                output_gain: engine.gain_now(),
            });
        }
        if observer.interrupted() {
            return Err(RenderError::Interrupted.into());
        }

        match block.iter().rposition(|y| *y != 0.0) {
            None => held_zeros += len as u64,
            Some(last) => {
                write_zeros(&mut sink, held_zeros)?;
                sink(&block[..=last])?;
                // The engine's own pass knows the block's peak, unless a fade came after it.
                let block_peak = match engine.block_peak() {
                    Some(block_peak) if scene.fade_out.is_none() => block_peak,
                    _ => sake_glug_engine::peak(block),
                };
                peak = peak.max(block_peak);
                written = position + last as u64 + 1;
                held_zeros = (len - last - 1) as u64;
            }
        }
        if total.is_none() && position >= settle_from {
            if engine.is_settled() {
                break;
            }
            if endless(scene, &engine) || engine.position() >= give_up_at {
                return Err(RenderError::NeverSettles.into());
            }
        }
    }
    engine.report_deferred_units(&mut |onset, voicing| {
        widen(&mut unit_volumes_ml, onset.volume_ml);
        observer.unit_started(onset, voicing)
    });
    let end = total.unwrap_or_else(|| engine.active_until().max(written));
    write_zeros(&mut sink, end - written)?;
    Ok(RenderSummary {
        samples: end,
        sample_rate: scene.sample_rate,
        units: engine.stats().units_started,
        peak,
        unit_volumes_ml,
        elapsed: started.elapsed(),
    })
}

/// `range` widened to hold `volume_ml`.
fn widen(range: &mut Option<(f64, f64)>, volume_ml: f64) {
    *range = Some(range.map_or((volume_ml, volume_ml), |(low, high)| {
        (low.min(volume_ml), high.max(volume_ml))
    }));
}

/// A scene's MIDI take played into the engine: every message acts at its sample, before that
/// sample renders, through the decoder the plugin uses, so a take renders offline as the plugin
/// renders the same messages at the same offsets.
struct TakePlayer<'a> {
    events: &'a [TimedInput],
    next: usize,
    decoder: CcDecoder,
    map: sake_glug_device::midi::MidiMap,
    /// Tilt, viscosity and fill as the take last set them: from then on they replace the
    /// scene's lanes, as a CC overrides its parameter in the plugin.
    held: PerControl<Option<f64>>,
}

impl<'a> TakePlayer<'a> {
    fn new(scene: &'a Scene) -> Self {
        Self {
            events: scene.take.as_ref().map_or(&[], |take| &take.events),
            next: 0,
            decoder: CcDecoder::default(),
            map: scene.midi,
            held: PerControl::splat(None),
        }
    }

    /// Acts on every message due at or before `position`.
    fn act_at(&mut self, position: u64, engine: &mut Engine) {
        while let Some(event) = self.events.get(self.next).filter(|e| e.sample <= position) {
            match self.decoder.decode(&self.map, event.input) {
                Some(DeviceAction::Refill) => engine.refill(),
                Some(DeviceAction::Set(control, value)) => self.held[control] = Some(value),
                None => {}
            }
            self.next += 1;
        }
    }

    /// Samples from `position` to the next message, if one is due later.
    fn until_next(&self, position: u64) -> Option<usize> {
        let next = self.events.get(self.next)?;
        Some((next.sample - position) as usize)
    }

    fn override_lanes(&self, controls: &mut Controls) {
        for (control, held) in self.held.iter() {
            if let Some(value) = held {
                controls[control] = Lane::Constant(value);
            }
        }
    }
}

/// Refuses, before rendering, a scene without a duration whose glugs cannot fall silent within
/// [`MAX_DURATION_S`]: a component that can sound (its share of c is not always 0, and some
/// drawn frequency can lie between 0 and Nyquist) whose nominal decay takes longer than the limit
/// to reach −120 dB (MODEL.md §10). Rendering it would only end at the limit, after gigabytes.
fn refuse_endless_decays(scene: &Scene) -> Result<(), RenderError> {
    let config = &scene.config;
    let nyquist_hz = scene.sample_rate as f64 / 2.0;
    let viscosities: Vec<f64> = scene.lanes.viscosity.values().collect();
    let share_can_sound = [
        viscosities.iter().any(|&c| c > 0.0),
        viscosities.iter().any(|&c| c < 1.0),
    ];
    for (index, key) in ["glug.b1_per_s", "glug.b2_per_s"].into_iter().enumerate() {
        let frequency_hz = config.frequency_hz[index];
        // The highest it reaches: a glide down starts above it (MODEL.md §5.2).
        let lowest_draw_hz =
            config.glide.highest_hz(index, frequency_hz) * (1.0 - config.freq_jitter);
        let can_sound = share_can_sound[index] && frequency_hz > 0.0 && lowest_draw_hz < nyquist_hz;
        let decay_per_s = config.decay_per_s[index];
        let decay_s = SILENT_DECAY_EXPONENT / decay_per_s;
        if can_sound && decay_s > MAX_DURATION_S {
            return Err(RenderError::DecaysTooSlowly {
                key,
                decay_per_s,
                decay_time: if decay_s.is_finite() {
                    format!("{decay_s:.0} s")
                } else {
                    "for ever".into()
                },
                min_decay_per_s: SILENT_DECAY_EXPONENT / MAX_DURATION_S,
            });
        }
    }
    Ok(())
}

/// Whether, with the controls held still for good, the scene can be seen never to fall silent:
/// follow mode holds the volume, so a bottle still pouring pours for ever. (A decay rate too slow
/// to end, 0 included, is refused before rendering by [`refuse_endless_decays`].)
fn endless(scene: &Scene, engine: &Engine) -> bool {
    scene.config.drain == DrainMode::Follow && !engine.is_resting()
}

fn write_zeros<E>(sink: &mut impl FnMut(&[f32]) -> Result<(), E>, count: u64) -> Result<(), E> {
    const ZEROS: [f32; 1024] = [0.0; 1024];
    let mut left = count;
    while left > 0 {
        let run = left.min(ZEROS.len() as u64) as usize;
        sink(&ZEROS[..run])?;
        left -= run as u64;
    }
    Ok(())
}

/// Renders a whole scene into memory.
pub fn render_scene_to_vec(scene: &Scene) -> Result<(Vec<f32>, RenderSummary), RenderError> {
    let mut samples = Vec::new();
    let summary = render_scene(
        scene,
        |block| {
            samples.extend_from_slice(block);
            Ok::<(), RenderError>(())
        },
        &mut |_| {},
    )?;
    Ok((samples, summary))
}
