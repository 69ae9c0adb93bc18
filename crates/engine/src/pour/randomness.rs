//! The per-unit random draws of MODEL.md §7 and §12, from one seeded generator.
//!
//! Every unit draws the same sequence of numbers whatever the spreads of §7 are, so changing one
//! spread never reshuffles the others, and a seed reproduces its output on every platform. The
//! amplitude's factor (§12), a later addition, comes from a stream of its own (the same seed,
//! 2^128 draws further on) and only while its spread is above 0: with it at 0 every render is
//! what it was before, and at any spread the onsets, f and B stay those of spread 0.

use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use rand_xoshiro::Xoshiro256PlusPlus;

use crate::config::ModelConfig;
use crate::glide::Glide;

/// The randomised constants of one wave unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitShape {
    /// f1_i, f2_i: the unit's frequencies (Hz), the headspace law's (§5.1) and the draw's.
    pub frequency_hz: [f64; 2],
    /// 1 + j_f·u of each frequency: the draw alone, without the headspace law (§7).
    pub frequency_spread: [f64; 2],
    /// B1_i, B2_i: the unit's amplitude decay rates (1/s).
    pub decay_per_s: [f64; 2],
    /// exp(σ_A·z_i): the factor on the unit's a(V_i) (§12); exactly 1 when σ_A = 0.
    pub amplitude_factor: f64,
    /// Each component's glide (§5.2): the model's, not drawn, taken at the onset like c.
    pub glide: Glide,
}

pub struct UnitDraws {
    rng: Xoshiro256PlusPlus,
    /// z_i of the amplitude's factor (§12), drawn only while σ_A > 0: `rng` jumped 2^128 draws
    /// ahead, a stream that no draw of `rng` ever reaches.
    amplitude_rng: Xoshiro256PlusPlus,
    /// u of the next unit's pocket volume, drawn ahead because the onset test needs it.
    next_pocket_u: f64,
}

impl UnitDraws {
    pub fn new(seed: u64) -> Self {
        let rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut draws = Self {
            amplitude_rng: rng.clone(),
            rng,
            next_pocket_u: 0.0,
        };
        draws.reseed(seed);
        draws
    }

    /// Restarts the sequence (MODEL.md §8, reset).
    pub fn reseed(&mut self, seed: u64) {
        self.rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        self.amplitude_rng = self.rng.clone();
        self.amplitude_rng.jump();
        self.next_pocket_u = self.uniform();
    }

    /// b_i = b·(1 + j_t·u) of the next unit.
    #[inline]
    pub fn next_pocket_ml(&self, config: &ModelConfig) -> f64 {
        config.pocket_ml * (1.0 + config.timing_jitter * self.next_pocket_u)
    }

    /// Draws the shape of the unit that is starting now at `volume_ml`, then the next unit's
    /// pocket volume, then (only while σ_A > 0) the unit's amplitude factor. Its frequencies
    /// follow the headspace law (§5.1) before the draw spreads them.
    pub fn next_unit(&mut self, config: &ModelConfig, volume_ml: f64) -> UnitShape {
        let mut shape = UnitShape {
            frequency_hz: config.frequency_hz,
            frequency_spread: [1.0; 2],
            decay_per_s: config.decay_per_s,
            amplitude_factor: 1.0,
            glide: config.glide,
        };
        // Skipped without the law, so that its frequencies are exactly the paper's.
        if config.headspace.is_active() {
            let factors = config
                .headspace
                .factors(volume_ml, config.capacity_ml, config.pocket_ml);
            for (f, factor) in shape.frequency_hz.iter_mut().zip(factors) {
                *f *= factor;
            }
        }
        for (f, spread) in shape
            .frequency_hz
            .iter_mut()
            .zip(&mut shape.frequency_spread)
        {
            *spread = 1.0 + config.freq_jitter * self.uniform();
            *f *= *spread;
        }
        for b in &mut shape.decay_per_s {
            let z: f64 = self.rng.sample(StandardNormal);
            *b *= (config.decay_sigma * z).exp();
        }
        self.next_pocket_u = self.uniform();
        if config.amplitude_spread > 0.0 {
            let z: f64 = self.amplitude_rng.sample(StandardNormal);
            shape.amplitude_factor = (config.amplitude_spread * z).exp();
        }
        shape
    }

    /// u uniform in [−1, 1].
    fn uniform(&mut self) -> f64 {
        self.rng.random_range(-1.0..=1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_spreads_give_the_nominal_constants() {
        let config = ModelConfig::default().deterministic();
        let mut draws = UnitDraws::new(7);
        assert_eq!(draws.next_pocket_ml(&config), 5.0);
        let shape = draws.next_unit(&config, 300.0);
        assert_eq!(shape.frequency_hz, [80.0, 300.0]);
        assert_eq!(shape.decay_per_s, [45.0, 40.0]);
        assert_eq!(shape.amplitude_factor, 1.0);
    }

    #[test]
    fn the_amplitude_spread_moves_no_other_draw_and_draws_nothing_at_0() {
        let still = ModelConfig::default();
        let spread = ModelConfig {
            amplitude_spread: 0.5,
            ..still
        };
        let (mut plain, mut spreading) = (UnitDraws::new(9), UnitDraws::new(9));
        let mut factors = Vec::new();
        for _ in 0..200 {
            assert_eq!(
                plain.next_pocket_ml(&still),
                spreading.next_pocket_ml(&spread)
            );
            let (a, b) = (
                plain.next_unit(&still, 300.0),
                spreading.next_unit(&spread, 300.0),
            );
            assert_eq!(
                (a.frequency_hz, a.decay_per_s),
                (b.frequency_hz, b.decay_per_s)
            );
            assert_eq!(a.amplitude_factor, 1.0);
            factors.push(b.amplitude_factor);
        }
        assert!(factors.iter().all(|&factor| factor > 0.0 && factor != 1.0));
        // Units at σ_A = 0 drew nothing from the amplitude's stream: it starts where it would.
        let mut late = UnitDraws::new(9);
        for _ in 0..50 {
            late.next_unit(&still, 300.0);
        }
        assert_eq!(late.next_unit(&spread, 300.0).amplitude_factor, factors[0]);
    }

    #[test]
    fn draws_stay_within_their_laws_and_reseeding_repeats_them() {
        let config = ModelConfig::default();
        let mut draws = UnitDraws::new(3);
        let first: Vec<_> = (0..500).map(|_| draws.next_unit(&config, 300.0)).collect();
        for shape in &first {
            assert!((76.0..=84.0).contains(&shape.frequency_hz[0]));
            assert!((285.0..=315.0).contains(&shape.frequency_hz[1]));
            assert!(shape.decay_per_s.iter().all(|b| *b > 0.0));
        }
        let log_b1: Vec<f64> = first
            .iter()
            .map(|s| (s.decay_per_s[0] / 45.0).ln())
            .collect();
        let mean = log_b1.iter().sum::<f64>() / 500.0;
        let sd = (log_b1.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 499.0).sqrt();
        assert!(mean.abs() < 0.05, "log-normal centre drifted: {mean}");
        assert!((sd - 0.35).abs() < 0.04, "log-normal spread {sd}");
        draws.reseed(3);
        assert_eq!(draws.next_unit(&config, 300.0), first[0]);
    }
}
