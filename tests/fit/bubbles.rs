//! Glugs from a physical model that is not Sake Glug's, written here from the physics alone (no
//! code of the engine): each glug a bubble released at the neck, ringing at its Minnaert
//! resonance f = (1/2πa)·√(3γp0/ρ) with a pitch that rises as it rises, and the bottle's air
//! column (a quarter-wave tube, c/4L) struck by it; glugs overlapping, a room's reverberation,
//! noise, mains hum and clipping, sampled at 44.1 kHz or 8 kHz. The fit has to recover the
//! bubbles' and the column's frequencies, their decays, the share of the bubble, and the rate.

use std::f64::consts::{PI, TAU};

/// The adiabatic index of air.
const GAMMA: f64 = 1.4;
/// Atmospheric pressure (Pa).
const P0: f64 = 101_325.0;
/// Density of water (kg/m³).
const RHO: f64 = 1_000.0;
/// Speed of sound in air (m/s).
pub const SOUND_M_PER_S: f64 = 343.0;

/// Minnaert's resonance of a bubble of radius `a` (m), in Hz.
pub fn minnaert_hz(a: f64) -> f64 {
    (3.0 * GAMMA * P0 / RHO).sqrt() / (TAU * a)
}

/// The bubble radius (m) that rings at `hz`.
pub fn minnaert_radius(hz: f64) -> f64 {
    (3.0 * GAMMA * P0 / RHO).sqrt() / (TAU * hz)
}

/// A pour as this simulator sees it.
#[derive(Debug, Clone, Copy)]
pub struct Pour {
    /// Sample rate (Hz).
    pub sample_rate: f64,
    /// Length (s).
    pub duration_s: f64,
    /// Glugs a second.
    pub rate_per_s: f64,
    /// The median bubble's radius (m).
    pub radius_m: f64,
    /// The spread of ln(radius).
    pub radius_sigma: f64,
    /// How much the pitch rises over the first 1/B of the bubble's ring (a share of f).
    pub rise: f64,
    /// The bubble's damping: B = π·f·δ.
    pub damping: f64,
    /// The air column's length (m): its mode rings at c/4L.
    pub column_m: f64,
    /// The column's decay (1/s).
    pub column_decay: f64,
    /// The bubble's share of each glug's amplitude (the rest the column's).
    pub bubble_share: f64,
    /// The reverberation's level against the dry sound, and its decay time to −60 dB (s).
    pub reverb: (f64, f64),
    /// White noise's RMS against the glugs' peak.
    pub noise: f64,
    /// Mains hum (50 Hz and its harmonics) against the glugs' peak.
    pub hum: f64,
    /// The level the signal is clipped at, against its peak (1: no clipping).
    pub clip: f64,
    /// The seed of every draw.
    pub seed: u64,
}

/// What the simulator drew: the glugs' onsets and the truths the fit is judged by.
pub struct Simulated {
    pub samples: Vec<f32>,
    /// The onsets (s).
    pub onsets: Vec<f64>,
    /// Each glug's bubble frequency at the centre of its ring (Hz).
    pub bubble_hz: Vec<f64>,
    /// Each glug's bubble decay (1/s).
    pub bubble_decay: Vec<f64>,
    /// The column's frequency (Hz).
    pub column_hz: f64,
}

/// A small generator of its own (xorshift64*), so that the simulation shares nothing.
struct Draws(u64);

impl Draws {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }

    fn normal(&mut self) -> f64 {
        let (u, v) = (self.uniform().max(1e-300), self.uniform());
        (-2.0 * u.ln()).sqrt() * (TAU * v).cos()
    }
}

/// Simulates `pour`.
pub fn simulate(pour: &Pour) -> Simulated {
    let fs = pour.sample_rate;
    let len = (pour.duration_s * fs) as usize;
    let mut draws = Draws(pour.seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let mut dry = vec![0.0f64; len];
    let column_hz = SOUND_M_PER_S / (4.0 * pour.column_m);
    let (mut onsets, mut bubble_hz, mut bubble_decay) = (Vec::new(), Vec::new(), Vec::new());
    // Releases: a jittered clock (±20 %), starting after a quiet 50 ms.
    let mut t = 0.05;
    while t < pour.duration_s - 0.1 {
        let radius = pour.radius_m * (pour.radius_sigma * draws.normal()).exp();
        let f0 = minnaert_hz(radius);
        let decay = PI * f0 * pour.damping;
        // The pitch rises exponentially towards f0·(1 + rise) as the bubble rises.
        let rise_rate = decay;
        let level = 0.6 + 0.4 * draws.uniform();
        let first = (t * fs).ceil() as usize;
        let mut phase_bubble = 0.0f64;
        for (n, sample) in dry.iter_mut().enumerate().skip(first) {
            let tau = n as f64 / fs - t;
            let envelope_bubble = (-decay * tau).exp();
            let envelope_column = (-pour.column_decay * tau).exp();
            if envelope_bubble < 1e-5 && envelope_column < 1e-5 {
                break;
            }
            let hz = f0 * (1.0 + pour.rise * (1.0 - (-rise_rate * tau).exp()));
            *sample += level
                * (pour.bubble_share * envelope_bubble * phase_bubble.sin()
                    + (1.0 - pour.bubble_share) * envelope_column * (TAU * column_hz * tau).sin());
            phase_bubble += TAU * hz / fs;
        }
        // Its pitch at the centre of its ring's energy, 1/(2B) in.
        let centre = 0.5 / decay;
        onsets.push(t);
        bubble_hz.push(f0 * (1.0 + pour.rise * (1.0 - (-rise_rate * centre).exp())));
        bubble_decay.push(decay);
        t += (1.0 + 0.2 * (2.0 * draws.uniform() - 1.0)) / pour.rate_per_s;
    }
    // The room: the dry sound convolved with decaying noise, added at its level.
    let (reverb_level, reverb_s) = pour.reverb;
    let tail_len = (reverb_s * fs) as usize;
    let tail: Vec<f64> = (0..tail_len)
        .map(|n| draws.normal() * (-6.9 * n as f64 / (reverb_s * fs)).exp())
        .collect();
    let tail_energy = tail.iter().map(|v| v * v).sum::<f64>().sqrt().max(1e-12);
    let mut wet = dry.clone();
    if reverb_level > 0.0 {
        // Sparse taps of the tail (every 16th): a coarse room is enough, and quick.
        for (k, &tap) in tail.iter().enumerate().step_by(16) {
            let gain = reverb_level * tap / tail_energy * 4.0;
            for (n, sample) in wet.iter_mut().enumerate().skip(k) {
                *sample += gain * dry[n - k];
            }
        }
    }
    let peak = wet.iter().fold(0.0f64, |p, y| p.max(y.abs()));
    let samples = wet
        .iter()
        .enumerate()
        .map(|(n, &y)| {
            let t = n as f64 / fs;
            let hum: f64 = (1..=3)
                .map(|h| (TAU * 50.0 * h as f64 * t).sin() / h as f64)
                .sum();
            let y = y + peak * (pour.noise * draws.normal() + pour.hum * hum);
            let limit = pour.clip * peak;
            (y.clamp(-limit, limit) / peak * 0.5) as f32
        })
        .collect();
    Simulated {
        samples,
        onsets,
        bubble_hz,
        bubble_decay,
        column_hz,
    }
}
