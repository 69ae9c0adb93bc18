//! The headspace law (MODEL.md §5.1) heard in a liquid's units (§13): how each mode's frequency
//! follows the air above the liquid, H + C − V_i. For a trial H, ln f_i is a straight line in
//! ln(H + C − V_i) whose slope is −γ; H is the one whose lines leave the least residual (a
//! profile over a grid of H), written only where the data reject the default H. f_k is the
//! line's frequency one pocket below full (V_ref = C − b).

use super::stats::Line;
use sake_glug_engine::{Constant, Headspace};

/// The z of a two-sided 95 % normal interval: an exponent is heard where its line's slope lies
/// further than this many standard errors from 0.
const Z_95: f64 = 1.959_963_984_540_054;
/// χ²(1) at 95 %: the H whose residual exceeds the best's by less than this (as n·ln of their
/// ratio, the profile likelihood of a normal error) are those the data allow.
const CHI2_1_95: f64 = 3.841_458_820_694_124;
/// A mode follows the headspace only where the law moves its pitch by at least this share over
/// the units' volumes (10 %, nearly two semitones): a drift smaller than that, however
/// significant, is a fit's bias with its amplitude, not a bottle's pitch.
const MIN_PITCH_CHANGE: f64 = 0.1;
/// The grid of H, in steps of 2 % over [`GRID_DECADES`] decades around the volumes' span.
const GRID_STEPS: usize = 351;
const GRID_DECADES: f64 = 7.0;

/// One mode's line under the law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModeLaw {
    /// γ_k.
    pub exponent: f64,
    /// γ_k's standard error.
    pub exponent_error: f64,
    /// f_k: the law's frequency at a full bottle's first glug, V_ref = C − b (Hz).
    pub full_hz: f64,
    /// The units it comes from.
    pub units: usize,
    /// How far the law moves the pitch over the units' volumes: the largest air over the least.
    pub air_ratio: f64,
}

impl ModeLaw {
    /// Whether the mode's frequency moves measurably and audibly with the headspace.
    pub fn follows(&self) -> bool {
        self.exponent.abs() > Z_95 * self.exponent_error && self.pitch_change() >= MIN_PITCH_CHANGE
    }

    /// The share by which the law moves the pitch over the units' volumes.
    pub fn pitch_change(&self) -> f64 {
        (self.exponent.abs() * self.air_ratio.ln()).exp() - 1.0
    }
}

/// The law of a liquid's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadspaceLaw {
    /// H the lines are drawn at (ml): the best where the data reject the default, else the
    /// default.
    pub headspace_ml: f64,
    /// The H the data allow (ml, the 95 % profile set), where a mode follows.
    pub allowed_ml: Option<(f64, f64)>,
    /// Whether the data chose H (they reject the default).
    pub headspace_heard: bool,
    /// Each mode's line (None: fewer than 3 units with a volume).
    pub modes: [Option<ModeLaw>; 2],
}

impl HeadspaceLaw {
    /// Whether any mode follows the headspace.
    pub fn heard(&self) -> bool {
        self.modes.iter().flatten().any(ModeLaw::follows)
    }

    /// The law as written into the model, for the engine's own reading of it: an exponent of 0
    /// for a mode that does not follow.
    pub fn model(&self) -> Headspace {
        Headspace {
            headspace_ml: self.headspace_ml,
            exponent: self
                .modes
                .map(|mode| mode.filter(ModeLaw::follows).map_or(0.0, |m| m.exponent)),
        }
    }
}

/// The line of ln f against ln(H + added) and its residual sum of squares.
fn line_at(points: &[(f64, f64)], headspace_ml: f64) -> Option<(Line, f64)> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .map(|&(added_ml, hz)| ((headspace_ml + added_ml).ln(), hz.ln()))
        .collect();
    let line = Line::through(&logs)?;
    let residual = logs.iter().map(|&(x, y)| (y - line.at(x)).powi(2)).sum();
    Some((line, residual))
}

fn mode_law(points: &[(f64, f64)], headspace_ml: f64, pocket_ml: f64) -> Option<ModeLaw> {
    let (line, _) = line_at(points, headspace_ml)?;
    let (least, most) = points
        .iter()
        .fold((f64::INFINITY, 0f64), |(l, m), p| (l.min(p.0), m.max(p.0)));
    Some(ModeLaw {
        exponent: -line.slope,
        exponent_error: line.slope_error,
        full_hz: line.at((headspace_ml + pocket_ml).ln()).exp(),
        units: points.len(),
        air_ratio: (headspace_ml + most) / (headspace_ml + least),
    })
}

/// The law of units whose modes ring at `points[k]` = (C − V_i, f_i) for mode k, in a bottle
/// whose pocket is `pocket_ml`.
pub fn fit_law(points: [&[(f64, f64)]; 2], pocket_ml: f64) -> HeadspaceLaw {
    let default_ml = Constant::Headspace.range().default;
    let at_default = points.map(|p| mode_law(p, default_ml, pocket_ml));
    // H is heard in the mode that follows the air most clearly.
    let leading = (0..2)
        .filter(|&k| at_default[k].is_some_and(|m| m.exponent_error > 0.0))
        .max_by(|&a, &b| {
            let t = |k: usize| {
                let mode: ModeLaw = at_default[k].expect("filtered");
                mode.exponent.abs() / mode.exponent_error
            };
            t(a).total_cmp(&t(b))
        });
    let mut law = HeadspaceLaw {
        headspace_ml: default_ml,
        allowed_ml: None,
        headspace_heard: false,
        modes: at_default,
    };
    let Some(leading) = leading else {
        return law;
    };
    let data = points[leading];
    let (lowest, highest) = data
        .iter()
        .fold((f64::INFINITY, 0f64), |(l, h), p| (l.min(p.0), h.max(p.0)));
    let span = (highest - lowest).max(highest).max(1e-3);
    let range = Constant::Headspace.range();
    let first = (span * 10f64.powf(-0.5 * GRID_DECADES)).max(range.min);
    let grid: Vec<(f64, f64)> = (0..GRID_STEPS)
        .map(|i| first * 10f64.powf(GRID_DECADES * i as f64 / (GRID_STEPS - 1) as f64))
        .filter(|h| *h <= range.max)
        .filter_map(|h| line_at(data, h).map(|(_, residual)| (h, residual)))
        .collect();
    let Some(&(best_ml, best_residual)) = grid.iter().min_by(|a, b| a.1.total_cmp(&b.1)) else {
        return law;
    };
    let n = data.len() as f64;
    // A perfect fit (no noise at all) allows only the best H.
    let floor = best_residual.max(1e-300);
    let allowed: Vec<f64> = grid
        .iter()
        .filter(|(_, residual)| n * (residual.max(1e-300) / floor).ln() <= CHI2_1_95)
        .map(|(h, _)| *h)
        .collect();
    let allowed_ml = (allowed[0], allowed[allowed.len() - 1]);
    let default_residual = line_at(data, default_ml).map_or(f64::INFINITY, |(_, r)| r);
    let rejects_default = n * (default_residual.max(1e-300) / floor).ln() > CHI2_1_95;
    law.allowed_ml = Some(allowed_ml);
    if rejects_default && at_default[leading].is_some_and(|m| m.follows()) {
        law.headspace_ml = best_ml;
        law.headspace_heard = true;
        law.modes = points.map(|p| mode_law(p, best_ml, pocket_ml));
    }
    if law.modes[leading].is_some_and(|m| m.follows()) {
        // A mode that follows the air is a Helmholtz cavity wherever the data allow one: the
        // exponent a few glugs' scatter gives trades against H along a ridge, and ½ on it is
        // the physics, not a guess.
        let allowed = |&(_, _, residual): &(f64, f64, f64)| {
            n * (residual.max(1e-300) / floor).ln() <= CHI2_1_95
        };
        let at_half = |h: f64| helmholtz_at(data, h).map(|(intercept, r)| (h, intercept, r));
        let helmholtz = at_half(default_ml).filter(allowed).or_else(|| {
            grid.iter()
                .filter_map(|&(h, _)| at_half(h))
                .min_by(|a, b| a.2.total_cmp(&b.2))
                .filter(allowed)
        });
        if let Some((h, intercept, _)) = helmholtz {
            law.headspace_ml = h;
            law.headspace_heard = h != default_ml;
            law.modes = points.map(|p| mode_law(p, h, pocket_ml));
            if let Some(mode) = law.modes[leading].as_mut() {
                mode.exponent = HELMHOLTZ;
                mode.full_hz = (intercept - HELMHOLTZ * (h + pocket_ml).ln()).exp();
            }
        }
    }
    law
}

/// A Helmholtz cavity's exponent: f ∝ (air)^(−½).
const HELMHOLTZ: f64 = 0.5;

/// The line of ln f against ln(H + added) with its slope held at −½: its intercept and residual
/// sum of squares.
fn helmholtz_at(points: &[(f64, f64)], headspace_ml: f64) -> Option<(f64, f64)> {
    if points.is_empty() {
        return None;
    }
    let lifted: Vec<f64> = points
        .iter()
        .map(|&(added_ml, hz)| hz.ln() + HELMHOLTZ * (headspace_ml + added_ml).ln())
        .collect();
    let intercept = lifted.iter().sum::<f64>() / lifted.len() as f64;
    let residual = lifted.iter().map(|y| (y - intercept).powi(2)).sum();
    Some((intercept, residual))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each glug's (C − V, f) of one mode.
    type Points = Vec<(f64, f64)>;

    /// A Helmholtz mode (γ = ½) over a cavity of `h` ml, a pocket of 5 ml a glug, and a mode
    /// that stays put.
    fn bottle(h: f64, glugs: usize) -> (Points, Points) {
        let added: Vec<f64> = (1..=glugs).map(|i| 5.0 * i as f64).collect();
        // A small deterministic scatter, so that the lines have an error.
        let wobble = |i: usize| 1.0 + 0.004 * ((i * 7919) % 13) as f64 / 13.0 - 0.002;
        let low = added
            .iter()
            .enumerate()
            .map(|(i, &a)| (a, 200.0 * (h / (h + a)).sqrt() * wobble(i)))
            .collect();
        let high = added
            .iter()
            .enumerate()
            .map(|(i, &a)| (a, 1150.0 * wobble(i + 3)))
            .collect();
        (low, high)
    }

    #[test]
    fn a_helmholtz_cavity_gives_a_half_and_its_headspace() {
        let (low, high) = bottle(6.0, 24);
        let law = fit_law([&low, &high], 5.0);
        assert!(law.headspace_heard, "{law:?}");
        let mode = law.modes[0].unwrap();
        assert!((mode.exponent - 0.5).abs() < 0.03, "{law:?}");
        assert!((law.headspace_ml / 6.0 - 1.0).abs() < 0.15, "{law:?}");
        // The first glug, one pocket poured, at 200·√(6/11) Hz.
        let first_hz = 200.0 * (6.0f64 / 11.0).sqrt();
        assert!((mode.full_hz / first_hz - 1.0).abs() < 0.02, "{law:?}");
        assert!(!law.modes[1].unwrap().follows(), "{law:?}");
        assert_eq!(law.model().exponent[1], 0.0);
    }

    const SEED: u64 = 5;

    /// A cavity's glugs under the law with `exponent` over 40 ml of air (5 ml a pocket, 20
    /// glugs), each pitch off by a scatter of `scatter` (a fixed pseudo-random draw).
    fn cavity(exponent: f64, scatter: f64) -> Points {
        use rand::{RngExt, SeedableRng};
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(SEED);
        (1..=20)
            .map(|i| {
                let added = 5.0 * i as f64;
                let draw = rng.random::<f64>() - 0.5;
                let hz = 400.0 * (40.0 / (40.0 + added)).powf(exponent) * (1.0 + scatter * draw);
                (added, hz)
            })
            .collect()
    }

    #[test]
    fn a_cavity_the_data_allow_to_be_helmholtz_is_written_at_a_half() {
        let low = cavity(0.5, 0.2);
        let free = mode_law(&low, 40.0, 5.0).unwrap();
        // The scatter alone moves the free line's slope well off ½ ...
        assert!((free.exponent - 0.5).abs() > 0.05, "{free:?}");
        // ... and the law, which the data let be a Helmholtz cavity, is one.
        let law = fit_law([&low, &[]], 5.0);
        assert_eq!(law.modes[0].unwrap().exponent, 0.5, "{law:?}");
        assert!(law.modes[0].unwrap().follows(), "{law:?}");
    }

    #[test]
    fn a_mode_the_data_hold_off_a_half_keeps_its_own_exponent() {
        // A tube's quarter-wave mode, f ∝ 1/air.
        let law = fit_law([&cavity(1.0, 0.004), &[]], 5.0);
        let mode = law.modes[0].unwrap();
        assert!((mode.exponent - 1.0).abs() < 0.1, "{law:?}");
    }

    #[test]
    fn constant_modes_follow_nothing_and_keep_the_default_headspace() {
        let (_, high) = bottle(6.0, 24);
        let law = fit_law([&high, &high], 5.0);
        assert!(!law.heard());
        assert!(!law.headspace_heard);
        assert_eq!(law.headspace_ml, Constant::Headspace.range().default);
    }
}
