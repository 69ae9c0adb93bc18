//! The default, real-time synthesis path ([`AnchoredF32`]): each component rendered as
//! `anchor · z^j` over a grid period of [`GRID`] samples ([`AnchoredComponent`]).
//!
//! The anchor (the component's complex state at the period's first sample) advances in f64 once
//! per period, and the powers z^j are tabled once per component in f32. Each output sample is then
//! one f32 complex product: independent across samples (so it vectorises), about two f32 ulps from
//! the exact value, and free of the drift of a per-sample recursion. Periods sit on an absolute
//! sample grid, so how a host cuts time into blocks never changes a sample.

use multiversion::multiversion;

use super::bank::{Bank, BankComponent};
use super::component::{complex_exp, complex_mul, Component};

/// Samples per grid period; the anchor advances in f64 once per period.
pub const GRID: usize = 64;
/// Powers below this are stored as zero: it is inside the error budget and keeps f32 denormals
/// out of the render loop for very fast decays.
const NEGLIGIBLE_POWER: f64 = 1e-7;
/// The f64 anchor recursion is re-evaluated from the closed form this often, so nothing can
/// drift however long a component rings (B = 0 rings for ever).
const PERIODS_PER_DIRECT_ANCHOR: u32 = 1024;
/// A glide with less phase than this left to add (rad) is over: from then on a period's powers
/// are the plain z^j, which leaves the samples within A·10⁻⁷ (−140 dB) of the closed form.
const GLIDE_SETTLED_RADIANS: f64 = 1e-7;

/// The default synthesis path: anchored components in f32, allocation-free after `new()`.
pub type AnchoredF32 = Bank<AnchoredComponent>;

/// One component on the default path: its f32 powers over a grid period and its anchor.
#[derive(Clone)]
pub struct AnchoredComponent {
    powers_re: [f32; GRID],
    powers_im: [f32; GRID],
    /// State at `anchor_sample`, the first sample of the period being rendered.
    anchor: [f32; 2],
    /// The same in f64, as it was worked out: what the level is read from.
    anchor_f64: [f64; 2],
    anchor_sample: u64,
    /// State at the first sample of the next period.
    next_anchor: [f64; 2],
    /// z^GRID in f64.
    period_step: [f64; 2],
    component: Component,
    /// The sample from which the component is silent (see [`Component::silent_from`]).
    silent_from: u64,
    periods_since_direct: u32,
    /// The powers of each period carry the glide's phase (MODEL.md §5.2), refilled every period
    /// until the glide is over.
    gliding: bool,
}

impl BankComponent for AnchoredComponent {
    fn start(component: Component) -> Self {
        let first_sample = component.first_sample();
        let grid = GRID as f64;
        let mut anchored = Self {
            powers_re: [0.0; GRID],
            powers_im: [0.0; GRID],
            anchor: [0.0; 2],
            anchor_f64: [0.0; 2],
            anchor_sample: first_sample,
            next_anchor: [0.0; 2],
            period_step: complex_exp(
                -component.decay_per_sample * grid,
                component.radians_per_sample * grid,
            ),
            component,
            silent_from: component.silent_from(),
            periods_since_direct: 0,
            gliding: component.glide.is_some(),
        };
        anchored.set_anchor(component.state_at(first_sample));
        let next_period = (first_sample / GRID as u64 + 1) * GRID as u64;
        anchored.next_anchor = component.state_at(next_period);
        anchored.fill_powers();
        anchored
    }

    /// |anchor|² rounded to f32 (squared: only the order matters, and it saves a hypot), worked
    /// out only when the bank is full and a component is to be given up, not every period.
    fn level(&self) -> f64 {
        let [re, im] = self.anchor_f64;
        (re * re + im * im) as f32 as f64
    }

    fn advance(&mut self, period_start: u64) -> bool {
        if self.anchor_sample >= period_start {
            // Started on this very boundary: its anchor already belongs to the new period.
            return true;
        }
        if period_start >= self.silent_from {
            return false;
        }
        self.set_anchor(self.next_anchor);
        self.anchor_sample = period_start;
        let following = period_start + GRID as u64;
        if self.component.glide.is_some() {
            // A glide's phase is no fixed rotation a period: each anchor is the closed form's.
            self.next_anchor = self.component.state_at(following);
            if self.gliding {
                self.fill_powers();
            }
            return true;
        }
        self.periods_since_direct += 1;
        self.next_anchor = if self.periods_since_direct == PERIODS_PER_DIRECT_ANCHOR {
            self.periods_since_direct = 0;
            self.component.state_at(following)
        } else {
            complex_mul(self.next_anchor, self.period_step)
        };
        true
    }

    type PeriodSum = PeriodSum;

    fn write_all(
        components: &mut [Self],
        period_sum: &mut PeriodSum,
        span_start: u64,
        out: &mut [f32],
    ) {
        if let Ok(period) = <&mut [f32; GRID]>::try_from(&mut *out) {
            if components
                .iter()
                .all(|component| component.anchor_sample == span_start)
            {
                sum_period(components, period);
                return;
            }
        }
        // A span shorter than a period (a host's small block), or a period in which a component
        // starts: the components that sound from the period's start are summed over the whole
        // period once, in registers, and each span of the period takes its part of that sum, then
        // adds the components that started since.
        let period_start = span_start / GRID as u64 * GRID as u64;
        if period_sum.period_start != Some(period_start) {
            // They lead the bank: a component joins at its end, and one that starts at a
            // period's first sample joined in the period before.
            let leading = components
                .iter()
                .take_while(|component| component.anchor_sample == period_start)
                .count();
            sum_period(&components[..leading], &mut period_sum.samples);
            period_sum.components = leading;
            period_sum.period_start = Some(period_start);
        }
        let offset = (span_start - period_start) as usize;
        out.copy_from_slice(&period_sum.samples[offset..offset + out.len()]);
        let started_since = &components[period_sum.components..];
        if !started_since.is_empty() {
            add_each(started_since, span_start, out);
        }
    }
}

/// The sum over one grid period of the components that sound from its first sample: see
/// [`AnchoredComponent::write_all`].
#[derive(Clone)]
pub struct PeriodSum {
    samples: [f32; GRID],
    /// The period summed; `None` before the first sum, and whenever the bank's components
    /// changed other than by one joining at the end.
    period_start: Option<u64>,
    /// How many components lead the bank in the sum.
    components: usize,
}

impl Default for PeriodSum {
    fn default() -> Self {
        Self {
            samples: [0.0; GRID],
            period_start: None,
            components: 0,
        }
    }
}

impl AnchoredComponent {
    /// Adds this component's samples for `out`, which starts at absolute sample `span_start` and
    /// lies within one grid period.
    #[inline]
    fn synthesize(&self, span_start: u64, out: &mut [f32]) {
        let first = self.anchor_sample.max(span_start);
        let offset = (first - span_start) as usize;
        if offset >= out.len() {
            return;
        }
        let out = &mut out[offset..];
        let power = (first - self.anchor_sample) as usize;
        let re = &self.powers_re[power..power + out.len()];
        let im = &self.powers_im[power..power + out.len()];
        let [anchor_re, anchor_im] = self.anchor;
        for ((y, &z_re), &z_im) in out.iter_mut().zip(re).zip(im) {
            *y += anchor_re * z_im + anchor_im * z_re;
        }
    }

    /// Adds this component's samples for the whole period `out`, when its anchor is at the
    /// period's first sample (it did not start within the period): the same sums as
    /// [`AnchoredComponent::synthesize`], with the length known to the compiler.
    #[inline]
    fn synthesize_period(&self, out: &mut [f32; GRID]) {
        let [anchor_re, anchor_im] = self.anchor;
        for ((y, &z_re), &z_im) in out.iter_mut().zip(&self.powers_re).zip(&self.powers_im) {
            *y += anchor_re * z_im + anchor_im * z_re;
        }
    }

    /// The first sample of the period being rendered, or of the component if it starts later.
    fn set_anchor(&mut self, state: [f64; 2]) {
        self.anchor = [state[0] as f32, state[1] as f32];
        self.anchor_f64 = state;
    }

    /// z^j for the period that starts at `anchor_sample`, times the glide's phase over it while
    /// the component glides: from the anchor, the glide adds K_a·(1 − r^j), K_a the phase left
    /// to add at the anchor and r = e^(−1/T).
    fn fill_powers(&mut self) {
        let step = self.component.step();
        // |z^j| = e^(−dj) falls below NEGLIGIBLE_POWER from j = ln(1/NEGLIGIBLE_POWER)/d on;
        // counted up front rather than with a hypot per power, which made starts costly.
        let audible = (-NEGLIGIBLE_POWER.ln() / self.component.decay_per_sample).ceil();
        let count = if audible < GRID as f64 {
            audible as usize
        } else {
            GRID
        };
        let glide = match self.component.glide {
            Some(glide) if self.gliding => {
                let elapsed = self.component.samples_since_onset(self.anchor_sample);
                let left = glide.phase_left_at(elapsed);
                self.gliding = left.abs() >= GLIDE_SETTLED_RADIANS;
                self.gliding
                    .then(|| (left, (-1.0 / glide.time_samples).exp()))
            }
            _ => None,
        };
        let mut power: [f64; 2] = [1.0, 0.0];
        match glide {
            None => {
                for j in 0..count {
                    self.powers_re[j] = power[0] as f32;
                    self.powers_im[j] = power[1] as f32;
                    power = complex_mul(power, step);
                }
            }
            Some((left, per_sample)) => {
                // r^j by products: j roundings of a number below 1, far inside the budget even
                // times the largest K (a few thousand radians).
                let mut remaining = 1.0;
                for j in 0..count {
                    let glided = complex_mul(power, complex_exp(0.0, left * (1.0 - remaining)));
                    self.powers_re[j] = glided[0] as f32;
                    self.powers_im[j] = glided[1] as f32;
                    power = complex_mul(power, step);
                    remaining *= per_sample;
                }
            }
        }
    }
}

/// The sum of `components` over a whole period, each anchored at its first sample, written to
/// `out`, in the bank's order from +0 (as adding each into a period of zeros would make it).
/// The loops are compiled for x86-64's baseline (SSE2: 4 f32 an instruction) and again for AVX2
/// (8) and AVX-512 (16), and the widest the processor has runs. Every lane does the same IEEE
/// multiplications and additions in the same order (Rust never fuses them), so the samples are
/// the same bits on every path.
///
/// The period is held in registers (64 f32: 8 AVX2 or 4 AVX-512 registers), so each component
/// costs its multiplications and additions and no loads and stores of the output.
#[multiversion(targets("x86_64+avx512f+avx512vl+avx2+avx", "x86_64+avx2+avx"))]
fn sum_period(components: &[AnchoredComponent], out: &mut [f32; GRID]) {
    let mut sum = [0.0; GRID];
    for component in components {
        component.synthesize_period(&mut sum);
    }
    *out = sum;
}

/// Adds each component's samples into `out`, which starts at absolute sample `span_start` and
/// lies within one grid period, in the bank's order; compiled as [`sum_period`] is.
#[multiversion(targets("x86_64+avx512f+avx512vl+avx2+avx", "x86_64+avx2+avx"))]
fn add_each(components: &[AnchoredComponent], span_start: u64, out: &mut [f32]) {
    for component in components {
        component.synthesize(span_start, out);
    }
}
