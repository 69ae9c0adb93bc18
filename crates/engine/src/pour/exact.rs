//! Many rounded f64 steps `x ← x − a` or `x ← x + a` taken at once, bit for bit as the per-sample
//! steps would take them: the drain of V and the accumulator g of MODEL.md §3–4 under constant
//! controls.
//!
//! Within one binade [2^e, 2^(e+1)) every f64 is an integer multiple m of the binade's unit in
//! the last place u, and a step rounds x ± a to the nearest such multiple: (m ± δ)·u, where δ is
//! a/u rounded to the nearest integer. δ is the same at every step as long as the results stay in
//! the binade, so n steps are x ± n·δ·u, a product and a sum that are both exact. Only a tie (a/u
//! exactly halfway between integers, where the rounding follows m's parity) and a step that leaves
//! the binade are left to the per-sample step.

/// Which way the steps go.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// `x ← x − a` (the drain).
    Down,
    /// `x ← x + a` (the accumulator).
    Up,
}

/// n rounded steps of `a` from one value, as one exact move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BinadeSteps {
    /// What each step moves the value by, exactly: δ·u.
    pub step: f64,
    /// How many steps from the value stay inside its binade (and so take exactly `step` each).
    pub max_steps: u64,
}

const MANTISSA_BITS: u32 = 52;
const IMPLICIT_BIT: u64 = 1 << MANTISSA_BITS;

impl BinadeSteps {
    /// The steps of `a` from `x` in `direction`, or `None` where they are left to the per-sample
    /// step: `x` or `a` not a positive normal number, a tie, or not even one step inside the
    /// binade.
    pub fn of(x: f64, a: f64, direction: Direction) -> Option<Self> {
        if !(x.is_normal() && x > 0.0 && a.is_finite() && a > 0.0) {
            return None;
        }
        let bits = x.to_bits();
        let biased_exponent = bits >> MANTISSA_BITS;
        // u = 2^(exponent − 52) must itself be a normal number to be exact below.
        if biased_exponent <= MANTISSA_BITS as u64 {
            return None;
        }
        let unit = f64::from_bits((biased_exponent - MANTISSA_BITS as u64) << MANTISSA_BITS);
        let m = (bits & (IMPLICIT_BIT - 1)) | IMPLICIT_BIT;
        // a/u is exact: a division by a power of two that neither overflows nor underflows here.
        let ratio = a / unit;
        if ratio >= IMPLICIT_BIT as f64 {
            return None;
        }
        // The floor of a positive number below 2^53 by truncation to an integer, which is
        // exact: `f64::floor` is a call into libm on x86-64's baseline (no SSE4.1 `roundsd`).
        let whole = ratio as u64;
        let fraction = ratio - whole as f64;
        if fraction == 0.5 {
            return None;
        }
        let delta = whole + u64::from(fraction > 0.5);
        // Each step's exact result must stay in the binade, where the unit is u: x − a at or above
        // 2^e, which holds while m − δ − 1 ≥ 2^52 (the exact m − a/u lies above m − δ − 1); x + a
        // below 2^(e+1), which holds while m + δ + 1 ≤ 2^53. With δ = 0 (a below half a unit)
        // every step rounds back to x, for ever.
        let room = match direction {
            Direction::Down => (m - IMPLICIT_BIT).checked_sub(1),
            Direction::Up => Some(2 * IMPLICIT_BIT - 1 - m),
        };
        let max_steps = match (room, delta) {
            (None, _) => 0,
            (Some(_), 0) => u64::MAX,
            (Some(room), delta) => room / delta,
        };
        if max_steps == 0 {
            return None;
        }
        Some(Self {
            step: delta as f64 * unit,
            max_steps,
        })
    }

    /// `x` after `count` ≤ `max_steps` steps.
    #[inline]
    pub fn after(&self, x: f64, count: u64, direction: Direction) -> f64 {
        after(x, self.step, count, direction)
    }
}

/// `x` moved by `count` steps of `step` (a [`BinadeSteps::step`] of `x`'s binade, with `count` at
/// most its `max_steps`): exact, since count·δ < 2^53 and the result is a multiple of u inside
/// the binade.
#[inline]
pub fn after(x: f64, step: f64, count: u64, direction: Direction) -> f64 {
    // Through i64, which x86-64 converts in one instruction where u64 takes several: the same
    // value, as count < 2^53 here.
    debug_assert!(count < 1 << 53);
    let moved = count as i64 as f64 * step;
    match direction {
        Direction::Down => x - moved,
        Direction::Up => x + moved,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small xorshift, so the test needs no generator crate of its own.
    fn next(state: &mut u64) -> u64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        *state
    }

    fn random_in(state: &mut u64, low: f64, high: f64) -> f64 {
        let unit = (next(state) >> 11) as f64 / (1u64 << 53) as f64;
        // Spread over decades, so that a/u takes every kind of value.
        low * (high / low).powf(unit)
    }

    #[test]
    fn closed_form_steps_match_rounded_steps_bit_for_bit() {
        let mut state = 0x9e37_79b9_7f4a_7c15;
        let mut checked = 0;
        for _ in 0..20_000 {
            let x = random_in(&mut state, 1e-6, 1e5);
            let a = random_in(&mut state, 1e-12, 1e3);
            for direction in [Direction::Down, Direction::Up] {
                let Some(steps) = BinadeSteps::of(x, a, direction) else {
                    continue;
                };
                let count = steps.max_steps.min(300);
                let mut value = x;
                for step in 1..=count {
                    value = match direction {
                        Direction::Down => value - a,
                        Direction::Up => value + a,
                    };
                    let closed = steps.after(x, step, direction);
                    assert_eq!(
                        closed.to_bits(),
                        value.to_bits(),
                        "{direction:?} x = {x:e}, a = {a:e}, step {step}"
                    );
                }
                checked += count;
            }
        }
        assert!(checked > 1_000_000, "only {checked} steps checked");
    }

    #[test]
    fn the_last_step_inside_the_binade_is_still_exact_and_the_next_leaves_it() {
        // 1.0 − 2^-20 steps: from just above 2 down to the edge of [1, 2).
        let a = 2f64.powi(-20) * 1.3;
        let x = 1.0 + 7.0 * a;
        let steps = BinadeSteps::of(x, a, Direction::Down).unwrap();
        let mut value = x;
        for _ in 0..steps.max_steps {
            value -= a;
        }
        assert_eq!(value, steps.after(x, steps.max_steps, Direction::Down));
        assert!(value >= 1.0 && value - 2.0 * a < 1.0);
    }

    #[test]
    fn ties_and_unusual_values_are_left_to_the_per_sample_step() {
        // a = 1.5 units of 1.0's binade: exactly halfway.
        let unit = f64::EPSILON;
        assert_eq!(BinadeSteps::of(1.0, 1.5 * unit, Direction::Up), None);
        assert_eq!(BinadeSteps::of(0.0, 1.0, Direction::Up), None);
        assert_eq!(BinadeSteps::of(-1.0, 1.0, Direction::Up), None);
        assert_eq!(BinadeSteps::of(1.0, 0.0, Direction::Up), None);
        assert_eq!(
            BinadeSteps::of(f64::MIN_POSITIVE / 2.0, 1e-310, Direction::Up),
            None
        );
        // Below half a unit: x never moves, except down from the binade's lowest value, where
        // the finer unit below it would catch the step.
        let tiny = BinadeSteps::of(1.5, 0.4 * unit, Direction::Down).unwrap();
        assert_eq!((tiny.step, tiny.max_steps), (0.0, u64::MAX));
        assert_eq!(1.5 - 0.4 * unit, 1.5);
        assert_eq!(BinadeSteps::of(1.0, 0.4 * unit, Direction::Down), None);
        assert_ne!(1.0 - 0.4 * unit, 1.0);
    }
}
