//! A glass bottle emptying, from a physical model that is not Sake Glug's, written here from the
//! acoustics alone (no code of the engine). The bottle starts at `start_ml` of its capacity C;
//! a pocket of liquid of b ml (± a uniform jitter) pours out, and the air that replaces it enters
//! as a glug, so the liquid volume V falls by one pocket a glug, and the air above the liquid as
//! a glug sounds is V_air = H + C − V (its own pocket in), H the full bottle's headspace. Each glug strikes two modes, both e^(−Bτ)·sin(2πfτ) from its onset:
//! - the **cavity**: the air above the liquid and the neck are a Helmholtz resonator,
//!   f = (c/2π)·√(A/(V_air·L_eff)), A = πr² the neck's bore, L_eff = L + 1.7·r its length with
//!   an end correction of 0.85·r at each end; so f ∝ V_air^(−1/2) falls from glug to glug;
//! - the **bubble**: the bubble pinched off as the pocket enters rings at Minnaert's resonance
//!   f = (1/2πa)·√(3γp0/ρ) for its radius a, decaying fast; its pitch may rise from glug to glug.
//!
//! Either mode may **glide** within each glug, approaching its own frequency f from a start ρ·f
//! as f(τ) = f·(1 + (ρ − 1)·e^(−τ/τ_g)) (the cavity down into its resonance as the bubble forms,
//! ρ > 1; the bubble up as it rises and shrinks, ρ < 1), and the low mode may be **fixed**
//! instead of the Helmholtz cavity: a resonance that does not grow with the air above the liquid
//! (the paper's bottle, whose f1 it found almost constant), so that the pitch does not fall.
//!
//! The bubble takes the share `bubble_share` of each glug's amplitude and the cavity the rest;
//! the cavity is the lower mode in both presets, so its share is MODEL.md §13's c = A1/(A1 + A2)
//! (f1 the lower mode). A glug's amplitude may fall as the bottle empties. Around it: a room (the
//! dry sound convolved with decaying sparse noise), white noise and 50 Hz mains hum with its
//! harmonics, at any sample rate from 8 to 48 kHz; a mode at or above Nyquist is left out. The
//! true V(t) comes back as a weight log, so a session's log can be written from it.

use std::f64::consts::{PI, TAU};

use super::bubbles::{minnaert_hz, minnaert_radius, SOUND_M_PER_S};
/// The neck's end correction, in neck radii: 0.85·r at each of its two ends.
pub const END_CORRECTION: f64 = 1.7;
/// Quiet before the first glug (s).
pub const LEAD_IN_S: f64 = 0.05;
/// A mode is rendered until its envelope falls below this share of its amplitude (−100 dB).
const SILENT: f64 = 1e-5;
/// The room's taps: one in each cell of this length (s), at a random place in it.
const TAP_CELL_S: f64 = 0.001;

/// The Helmholtz frequency (Hz) of `air_ml` of air under a neck of radius `neck_radius_m` and
/// length `neck_length_m`: (c/2π)·√(A/(V_air·L_eff)).
pub fn helmholtz_hz(air_ml: f64, neck_radius_m: f64, neck_length_m: f64) -> f64 {
    let area = PI * neck_radius_m * neck_radius_m;
    let effective = neck_length_m + END_CORRECTION * neck_radius_m;
    SOUND_M_PER_S / TAU * (area / (air_ml * 1e-6 * effective)).sqrt()
}

/// The neck length (m) under which `air_ml` of air rings at `hz` through a neck of radius
/// `neck_radius_m`: L = A/(V_air·(2πf/c)²) − 1.7·r.
pub fn neck_length_m(hz: f64, air_ml: f64, neck_radius_m: f64) -> f64 {
    let wavenumber = TAU * hz / SOUND_M_PER_S;
    PI * neck_radius_m * neck_radius_m / (air_ml * 1e-6 * wavenumber * wavenumber)
        - END_CORRECTION * neck_radius_m
}

/// The air (ml) above the liquid at the first of `glugs` glugs of `pocket_ml` whose cavity falls
/// from `first_hz` to `last_hz`: the air grows by (glugs − 1) pockets and f ∝ V_air^(−1/2), so
/// V_air,first·((first/last)² − 1) = (glugs − 1)·b.
pub fn first_air_ml(first_hz: f64, last_hz: f64, glugs: usize, pocket_ml: f64) -> f64 {
    (glugs - 1) as f64 * pocket_ml / ((first_hz / last_hz).powi(2) - 1.0)
}

/// The energy ∫ y² dτ (amplitude² · s) of A·e^(−Bτ)·sin(2πfτ) from τ = 0:
/// A²·ω²/(4B·(B² + ω²)), ω = 2πf.
pub fn ring_energy(amplitude: f64, hz: f64, decay: f64) -> f64 {
    let omega = TAU * hz;
    amplitude * amplitude * omega * omega / (4.0 * decay * (decay * decay + omega * omega))
}

/// The bubble's share of a glug's amplitude that gives it `energy_share` of the glug's energy,
/// the bubble ringing at `bubble_hz` decaying at `bubble_decay`, the cavity at `cavity_hz` and
/// `cavity_decay`: c/(1 − c) = √(s·E_cavity/((1 − s)·E_bubble)) at unit amplitudes.
pub fn bubble_share_for_energy(
    energy_share: f64,
    (bubble_hz, bubble_decay): (f64, f64),
    (cavity_hz, cavity_decay): (f64, f64),
) -> f64 {
    let ratio = (energy_share * ring_energy(1.0, cavity_hz, cavity_decay)
        / ((1.0 - energy_share) * ring_energy(1.0, bubble_hz, bubble_decay)))
    .sqrt();
    ratio / (1.0 + ratio)
}

/// A mode's glide within a glug: f(τ) = f·(1 + (ρ − 1)·e^(−τ/τ_g)), from ρ·f at the onset to the
/// mode's own f.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Glide {
    /// ρ, the start frequency over the mode's own (1: no glide).
    pub ratio: f64,
    /// τ_g (s).
    pub time_s: f64,
}

impl Glide {
    /// The mode rings at its own frequency from its onset.
    pub const NONE: Glide = Glide {
        ratio: 1.0,
        time_s: 0.0,
    };

    /// The phase (rad) the glide adds by τ to a mode of `hz` ringing at its own frequency:
    /// 2π·f·(ρ − 1)·τ_g·(1 − e^(−τ/τ_g)), the integral of f(τ) − f.
    fn extra_phase(&self, hz: f64, tau: f64) -> f64 {
        TAU * hz * (self.ratio - 1.0) * self.time_s * (1.0 - (-tau / self.time_s).exp())
    }

    /// Its frequency over the mode's own τ after the onset.
    pub fn factor(&self, tau: f64) -> f64 {
        if self.ratio == 1.0 {
            1.0
        } else {
            1.0 + (self.ratio - 1.0) * (-tau / self.time_s).exp()
        }
    }
}

/// A bottle emptying as this simulator sees it.
#[derive(Debug, Clone, Copy)]
pub struct Params {
    /// Sample rate (Hz).
    pub sample_rate: f64,
    /// The bottle's capacity C (ml).
    pub capacity_ml: f64,
    /// The liquid at the first sample (ml).
    pub start_ml: f64,
    /// The air above the liquid of the full bottle, H (ml): the neck's and shoulder's.
    pub headspace_ml: f64,
    /// The neck's radius r (m).
    pub neck_radius_m: f64,
    /// The neck's length L (m), before its end correction.
    pub neck_length_m: f64,
    /// The glugs: fewer if the bottle empties first.
    pub glugs: usize,
    /// The air pocket b each glug lets in (ml).
    pub pocket_ml: f64,
    /// Each pocket is b·(1 + j·u), u uniform on −1…1.
    pub pocket_jitter: f64,
    /// Glugs a second.
    pub rate_per_s: f64,
    /// Each interval is (1 + j·u)/rate, u uniform on −1…1.
    pub timing_jitter: f64,
    /// The cavity mode's decay (1/s).
    pub cavity_decay: f64,
    /// `None`: the low mode is the Helmholtz cavity of the air above the liquid; `Some(f)`: a
    /// low mode fixed at f (Hz), whatever the air.
    pub fixed_cavity_hz: Option<f64>,
    /// The low mode's glide within each glug.
    pub cavity_glide: Glide,
    /// The bubble mode's glide within each glug.
    pub bubble_glide: Glide,
    /// The ringing bubble's radius a (m) at the first glug.
    pub bubble_radius_m: f64,
    /// The bubble's pitch rises linearly from glug to glug, by this share of f at the last glug.
    pub bubble_rise: f64,
    /// The bubble mode's decay (1/s), the geometric centre of its draws.
    pub bubble_decay: f64,
    /// Each glug's bubble decay is B·s^u, u uniform on −1…1 (1: every glug's the same).
    pub bubble_decay_spread: f64,
    /// The bubble's share of each glug's amplitude (the rest the cavity's).
    pub bubble_share: f64,
    /// A glug's amplitude is 1 − fall·(1 − V/C) with V before it (0: constant).
    pub amplitude_fall: f64,
    /// Each glug's amplitude is also times (1 + j·u), u uniform on −1…1.
    pub level_jitter: f64,
    /// The reverberation's level against the dry sound (in amplitude: its taps' gains have this
    /// root sum of squares), and its decay time to −60 dB (s).
    pub reverb: (f64, f64),
    /// White noise's RMS against the dry sound's peak.
    pub noise: f64,
    /// Mains hum (50 Hz and its harmonics) against the dry sound's peak.
    pub hum: f64,
    /// Quiet after the liquid stops (s): a second of it lets a weight log end at rest.
    pub tail_s: f64,
    /// The weight log's readings a second (0: no log).
    pub log_hz: f64,
    /// The seed of every draw.
    pub seed: u64,
}

impl Params {
    /// A 720 ml glass bottle poured from full to about empty: 24 glugs at 10 a second (intervals
    /// ±15 %), each pocket a 24th of the bottle (±10 %), the cavity falling from 260 Hz to about
    /// 75 Hz (the headspace and the neck's length are what give that, for a 7 mm neck), decaying
    /// at 30 /s; the bubble at 1.15 kHz decaying at 150 /s with 60 % of the amplitude; the
    /// amplitude falling by 30 % as the bottle empties.
    pub fn glass_bottle(sample_rate: f64) -> Params {
        let (capacity_ml, glugs, first_hz, last_hz) = (720.0, 24, 260.0, 75.0);
        let pocket_ml = capacity_ml / glugs as f64;
        let air_ml = first_air_ml(first_hz, last_hz, glugs, pocket_ml);
        let neck_radius_m = 0.007;
        Params {
            sample_rate,
            capacity_ml,
            start_ml: capacity_ml,
            // The first glug's air holds its own pocket.
            headspace_ml: air_ml - pocket_ml,
            neck_radius_m,
            neck_length_m: neck_length_m(first_hz, air_ml, neck_radius_m),
            glugs,
            pocket_ml,
            pocket_jitter: 0.1,
            rate_per_s: 10.0,
            timing_jitter: 0.15,
            cavity_decay: 30.0,
            fixed_cavity_hz: None,
            cavity_glide: Glide::NONE,
            bubble_glide: Glide::NONE,
            bubble_radius_m: minnaert_radius(1150.0),
            bubble_rise: 0.0,
            bubble_decay: 150.0,
            bubble_decay_spread: 1.0,
            bubble_share: 0.6,
            amplitude_fall: 0.3,
            level_jitter: 0.1,
            reverb: (0.05, 0.3),
            noise: 0.003,
            hum: 0.01,
            tail_s: 1.0,
            log_hz: 10.0,
            seed: 1,
        }
    }

    /// A short clip: 5 glugs of 40 ml from a full 300 ml bottle (the fit's default capacity) at
    /// about 8 a second, the cavity falling from 194 Hz to 90 Hz (through a 4 mm neck), decaying
    /// at 25 /s; the bubble rising from 1.1 kHz to 1.35 kHz over the glugs, ringing 30 to 60 ms
    /// to −40 dB, with the share of the amplitude that gives it 38 % of a glug's energy.
    pub fn short_clip(sample_rate: f64) -> Params {
        let (capacity_ml, glugs, pocket_ml, first_hz, last_hz): (f64, usize, f64, f64, f64) =
            (300.0, 5, 40.0, 194.0, 90.0);
        let air_ml = first_air_ml(first_hz, last_hz, glugs, pocket_ml);
        let neck_radius_m = 0.004;
        let (bubble_first_hz, bubble_last_hz) = (1100.0, 1350.0);
        // Rings of 30 to 60 ms to −40 dB: B = ln(100)/length, drawn about their geometric centre.
        let (shortest_s, longest_s): (f64, f64) = (0.03, 0.06);
        let bubble_decay = 100f64.ln() / (shortest_s * longest_s).sqrt();
        let cavity_decay = 25.0;
        Params {
            sample_rate,
            capacity_ml,
            start_ml: capacity_ml,
            headspace_ml: air_ml - pocket_ml,
            neck_radius_m,
            neck_length_m: neck_length_m(first_hz, air_ml, neck_radius_m),
            glugs,
            pocket_ml,
            pocket_jitter: 0.0,
            rate_per_s: 8.0,
            timing_jitter: 0.15,
            cavity_decay,
            fixed_cavity_hz: None,
            cavity_glide: Glide::NONE,
            bubble_glide: Glide::NONE,
            bubble_radius_m: minnaert_radius(bubble_first_hz),
            bubble_rise: bubble_last_hz / bubble_first_hz - 1.0,
            bubble_decay,
            bubble_decay_spread: (longest_s / shortest_s).sqrt(),
            bubble_share: bubble_share_for_energy(
                0.38,
                ((bubble_first_hz * bubble_last_hz).sqrt(), bubble_decay),
                ((first_hz * last_hz).sqrt(), cavity_decay),
            ),
            amplitude_fall: 0.0,
            level_jitter: 0.1,
            reverb: (0.05, 0.3),
            noise: 0.003,
            hum: 0.01,
            tail_s: 1.0,
            log_hz: 10.0,
            seed: 1,
        }
    }
}

/// What the simulator drew: the glugs and the truths the fit is judged by. Amplitudes and
/// energies are in the samples' units.
pub struct Simulated {
    /// The sound, its dry peak at 0.5.
    pub samples: Vec<f32>,
    /// The onsets (s).
    pub onsets: Vec<f64>,
    /// The liquid in the bottle as each glug sounds, its pocket of liquid poured, V_i (ml).
    pub volume_ml: Vec<f64>,
    /// Each glug's pocket (ml): V_i = V_(i−1) − b_i.
    pub pocket_ml: Vec<f64>,
    /// The air above the liquid at each glug, H + C − V_i (ml).
    pub air_ml: Vec<f64>,
    /// Each glug's cavity frequency (Hz).
    pub cavity_hz: Vec<f64>,
    /// Each glug's bubble frequency (Hz).
    pub bubble_hz: Vec<f64>,
    /// Each glug's bubble decay (1/s).
    pub bubble_decay: Vec<f64>,
    /// Each glug's amplitude, both modes' together (A1 + A2).
    pub amplitude: Vec<f64>,
    /// Each glug's cavity energy ∫ y² dτ as it rings alone (0 if left out above Nyquist).
    pub cavity_energy: Vec<f64>,
    /// Each glug's bubble energy ∫ y² dτ as it rings alone (0 if left out above Nyquist).
    pub bubble_energy: Vec<f64>,
    /// The cavity's decay (1/s).
    pub cavity_decay: f64,
    /// The cavity's glide in every glug.
    pub cavity_glide: Glide,
    /// The bubble mode's glide in every glug.
    pub bubble_glide: Glide,
    /// The exponent γ of f ∝ V_air^(−γ) for the cavity: 1/2 (0 for a fixed low mode).
    pub cavity_exponent: f64,
    /// The full bottle's headspace H (ml).
    pub headspace_ml: f64,
    /// Glugs a second (the parameter).
    pub rate_per_s: f64,
    /// The liquid's mean fall from the first glug to the last, (V_first − V_last)/(t_last −
    /// t_first) (ml/s).
    pub drain_ml_per_s: f64,
    /// The bubble's share of each glug's amplitude.
    pub bubble_share: f64,
    /// The cavity's share of each glug's amplitude (1 − bubble_share): MODEL.md's c when the
    /// cavity is the lower mode.
    pub low_mode_share: f64,
    /// The bubble's share of the glugs' energy, each mode ringing alone: ΣE_bubble/ΣE.
    pub bubble_energy_share: f64,
    /// When the liquid stops (s): at the last glug, whose pocket of liquid has then poured.
    pub flow_end_s: f64,
    /// The true liquid volume (time s, ml) at the log's rate: V falls linearly from the start
    /// volume at 0 s to the first glug's V_1 and from each glug's V_i to the next one's, then
    /// stays.
    pub weight_log: Vec<(f64, f64)>,
}

/// A small generator of its own (xorshift64*), so that the simulation shares nothing.
pub struct Draws(u64);

impl Draws {
    /// The generator of `seed`, mixed by `salt` (an odd constant of the caller's, so that two
    /// users of one seed draw apart).
    pub fn new(seed: u64, salt: u64) -> Self {
        Draws(seed.wrapping_mul(salt) | 1)
    }

    pub fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform on −1…1.
    pub fn signed(&mut self) -> f64 {
        2.0 * self.uniform() - 1.0
    }

    fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform().max(1e-300), self.uniform());
        (-2.0 * u.ln()).sqrt() * (TAU * v).cos()
    }
}

/// A glide's extra phase is taken as settled once τ passes this many τ_g (e^(−40) < 10⁻¹⁷).
const GLIDE_SETTLED: f64 = 40.0;

/// Adds A·e^(−Bτ)·sin(2πfτ + φ_g(τ)), τ = t − onset ≥ 0, to `dry` until it is silent: the phasor
/// e^((−B + iω)τ) advanced by one sample's step at a time, turned by the glide's extra phase φ_g
/// (none without a glide).
fn ring(
    dry: &mut [f64],
    fs: f64,
    onset: f64,
    (amplitude, hz, decay): (f64, f64, f64),
    glide: Glide,
) {
    if amplitude == 0.0 {
        return;
    }
    let first = ((onset * fs).ceil() as usize).min(dry.len());
    let last = (((onset + SILENT.recip().ln() / decay) * fs).ceil() as usize).min(dry.len());
    let tau = first as f64 / fs - onset;
    let (mut re, mut im) = (
        (-decay * tau).exp() * (TAU * hz * tau).cos(),
        (-decay * tau).exp() * (TAU * hz * tau).sin(),
    );
    let shrink = (-decay / fs).exp();
    let (step_re, step_im) = (
        shrink * (TAU * hz / fs).cos(),
        shrink * (TAU * hz / fs).sin(),
    );
    if glide.ratio == 1.0 {
        for sample in &mut dry[first..last] {
            *sample += amplitude * im;
            (re, im) = (re * step_re - im * step_im, re * step_im + im * step_re);
        }
        return;
    }
    let settled = (GLIDE_SETTLED * glide.time_s * fs) as usize;
    for (n, sample) in dry[first..last].iter_mut().enumerate() {
        let phase = glide.extra_phase(hz, tau + n.min(settled) as f64 / fs);
        *sample += amplitude * (im * phase.cos() + re * phase.sin());
        (re, im) = (re * step_re - im * step_im, re * step_im + im * step_re);
    }
}

/// The volume at `t` on the line through `knots` (time, volume), held before and after them.
fn volume_at(knots: &[(f64, f64)], t: f64) -> f64 {
    match knots.iter().position(|&(knot, _)| knot > t) {
        Some(0) => knots[0].1,
        None => knots[knots.len() - 1].1,
        Some(next) => {
            let ((t0, v0), (t1, v1)) = (knots[next - 1], knots[next]);
            v0 + (v1 - v0) * (t - t0) / (t1 - t0)
        }
    }
}

/// Simulates `params`.
pub fn simulate(params: &Params) -> Simulated {
    assert!(
        params.glugs >= 1 && params.pocket_ml > 0.0 && params.rate_per_s > 0.0,
        "at least one glug, of a pocket, at a rate: {params:?}"
    );
    assert!(
        params.start_ml > 0.0 && params.start_ml <= params.capacity_ml,
        "the start within the bottle: {params:?}"
    );
    let fs = params.sample_rate;
    let nyquist = fs / 2.0;
    let mut draws = Draws::new(params.seed, 0x9E37_79B9_7F4A_7C15);
    // The glugs: each draws its pocket, interval, bubble decay and amplitude, in that order.
    let (mut onsets, mut volume_ml, mut pocket_ml, mut air_ml) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut cavity_hz, mut bubble_hz, mut bubble_decay, mut level) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let (mut t, mut volume) = (LEAD_IN_S, params.start_ml);
    for glug in 0..params.glugs {
        if volume <= 0.0 {
            break;
        }
        // The last pocket can take no more than the liquid left.
        let pocket = (params.pocket_ml * (1.0 + params.pocket_jitter * draws.signed())).min(volume);
        let interval = (1.0 + params.timing_jitter * draws.signed()) / params.rate_per_s;
        let decay = params.bubble_decay * params.bubble_decay_spread.powf(draws.signed());
        let jitter = 1.0 + params.level_jitter * draws.signed();
        // The pocket's liquid has poured; its air enters as the glug.
        volume -= pocket;
        let air = params.headspace_ml + params.capacity_ml - volume;
        let along = if params.glugs > 1 {
            glug as f64 / (params.glugs - 1) as f64
        } else {
            0.0
        };
        onsets.push(t);
        volume_ml.push(volume);
        pocket_ml.push(pocket);
        air_ml.push(air);
        cavity_hz.push(
            params
                .fixed_cavity_hz
                .unwrap_or_else(|| helmholtz_hz(air, params.neck_radius_m, params.neck_length_m)),
        );
        bubble_hz.push(minnaert_hz(params.bubble_radius_m) * (1.0 + params.bubble_rise * along));
        bubble_decay.push(decay);
        level.push((1.0 - params.amplitude_fall * (1.0 - volume / params.capacity_ml)) * jitter);
        t += interval;
    }
    // The liquid stops with the last glug; then the tail.
    let flow_end = onsets.last().copied().unwrap_or(LEAD_IN_S);
    let duration = flow_end + params.tail_s;
    let len = (duration * fs) as usize;
    let mut dry = vec![0.0f64; len];
    // A mode at or above Nyquist is left out: its amplitude is 0.
    let heard = |hz: f64, amplitude: f64| if hz < nyquist { amplitude } else { 0.0 };
    let cavity_amplitude: Vec<f64> = (0..onsets.len())
        .map(|glug| heard(cavity_hz[glug], (1.0 - params.bubble_share) * level[glug]))
        .collect();
    let bubble_amplitude: Vec<f64> = (0..onsets.len())
        .map(|glug| heard(bubble_hz[glug], params.bubble_share * level[glug]))
        .collect();
    for glug in 0..onsets.len() {
        let onset = onsets[glug];
        let cavity = (cavity_amplitude[glug], cavity_hz[glug], params.cavity_decay);
        ring(&mut dry, fs, onset, cavity, params.cavity_glide);
        let bubble = (bubble_amplitude[glug], bubble_hz[glug], bubble_decay[glug]);
        ring(&mut dry, fs, onset, bubble, params.bubble_glide);
    }
    // The room: the dry sound convolved with sparse noise (one tap of random sign at a random
    // place in each millisecond) under an envelope falling 60 dB over its decay time.
    let (reverb_level, reverb_s) = params.reverb;
    let mut wet = dry.clone();
    if reverb_level > 0.0 {
        let taps: Vec<(usize, f64)> = (0..(reverb_s / TAP_CELL_S) as usize)
            .map(|cell| {
                let delay = (cell as f64 + draws.uniform()) * TAP_CELL_S;
                let sign = if draws.uniform() < 0.5 { -1.0 } else { 1.0 };
                (
                    (delay * fs) as usize,
                    sign * 10f64.powf(-3.0 * delay / reverb_s),
                )
            })
            .collect();
        let norm = taps.iter().map(|(_, g)| g * g).sum::<f64>().sqrt();
        for &(delay, gain) in &taps {
            let gain = reverb_level * gain / norm;
            for (sample, &source) in wet[delay.min(len)..].iter_mut().zip(&dry) {
                *sample += gain * source;
            }
        }
    }
    let dry_peak = dry.iter().fold(0.0f64, |p, y| p.max(y.abs())).max(1e-12);
    let scale = 0.5 / dry_peak;
    let harmonics: Vec<f64> = (1..=3)
        .map(f64::from)
        .filter(|&h| 50.0 * h < nyquist)
        .collect();
    let samples = wet
        .iter()
        .enumerate()
        .map(|(n, &y)| {
            let t = n as f64 / fs;
            let hum: f64 = harmonics
                .iter()
                .map(|&h| (TAU * 50.0 * h * t).sin() / h)
                .sum();
            let y = y + dry_peak * (params.noise * draws.normal() + params.hum * hum);
            (y * scale) as f32
        })
        .collect();
    let amplitude: Vec<f64> = level.iter().map(|l| l * scale).collect();
    let cavity_energy: Vec<f64> = (0..onsets.len())
        .map(|glug| {
            let amplitude = scale * cavity_amplitude[glug];
            ring_energy(amplitude, cavity_hz[glug], params.cavity_decay)
        })
        .collect();
    let bubble_energy: Vec<f64> = (0..onsets.len())
        .map(|glug| {
            let amplitude = scale * bubble_amplitude[glug];
            ring_energy(amplitude, bubble_hz[glug], bubble_decay[glug])
        })
        .collect();
    let bubble_total: f64 = bubble_energy.iter().sum();
    let total = bubble_total + cavity_energy.iter().sum::<f64>();
    // V(t): from the start volume through each glug's V_i.
    let knots: Vec<(f64, f64)> = std::iter::once((0.0, params.start_ml))
        .chain(onsets.iter().copied().zip(volume_ml.iter().copied()))
        .collect();
    let weight_log = if params.log_hz > 0.0 {
        (0..=(duration * params.log_hz) as usize)
            .map(|k| {
                let t = k as f64 / params.log_hz;
                (t, volume_at(&knots, t))
            })
            .collect()
    } else {
        Vec::new()
    };
    let glugs = onsets.len();
    let drain_ml_per_s = if glugs > 1 {
        (volume_ml[0] - volume_ml[glugs - 1]) / (onsets[glugs - 1] - onsets[0])
    } else {
        pocket_ml[0] / LEAD_IN_S
    };
    Simulated {
        samples,
        onsets,
        volume_ml,
        pocket_ml,
        air_ml,
        cavity_hz,
        bubble_hz,
        bubble_decay,
        amplitude,
        cavity_energy,
        bubble_energy,
        cavity_decay: params.cavity_decay,
        cavity_glide: params.cavity_glide,
        bubble_glide: params.bubble_glide,
        cavity_exponent: if params.fixed_cavity_hz.is_some() {
            0.0
        } else {
            0.5
        },
        headspace_ml: params.headspace_ml,
        rate_per_s: params.rate_per_s,
        drain_ml_per_s,
        bubble_share: params.bubble_share,
        low_mode_share: 1.0 - params.bubble_share,
        bubble_energy_share: bubble_total / total.max(1e-300),
        flow_end_s: flow_end,
        weight_log,
    }
}
