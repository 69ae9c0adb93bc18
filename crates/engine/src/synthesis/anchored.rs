//! The default, real-time synthesis path ([`AnchoredF32`]): each component rendered as
//! `anchor · z^j` over a grid period of [`GRID`] samples ([`AnchoredComponent`]).
//!
//! The anchor (the component's complex state at the period's first sample) advances in f64 once
//! per period, and the powers z^j are tabled once per component in f32. Each output sample is then
//! one f32 complex product: independent across samples (so it vectorises), about two f32 ulps from
//! the exact value, and free of the drift of a per-sample recursion. Periods sit on an absolute
//! sample grid, so how a host cuts time into blocks never changes a sample.

use multiversion::multiversion;

use super::bank::{Bank, BankComponent, MAX_COMPONENTS};
use super::component::{complex_exp, complex_mul, Component};

/// Samples per grid period; the anchor advances in f64 once per period.
pub const GRID: usize = 64;
/// Powers below this are stored as zero: it is inside the error budget and keeps f32 denormals
/// out of the render loop for very fast decays.
const NEGLIGIBLE_POWER: f64 = 1e-7;
/// The f64 anchor recursion is re-evaluated from the closed form this often, so nothing can
/// drift however long a component rings (B = 0 rings for ever).
const PERIODS_PER_DIRECT_ANCHOR: u64 = 1024;
/// A glide with less phase than this left to add (rad) is over: from then on a period's powers
/// are the plain z^j, which leaves the samples within A·10⁻⁷ (−140 dB) of the closed form.
const GLIDE_SETTLED_RADIANS: f64 = 1e-7;

/// The default synthesis path: anchored components in f32, allocation-free after `new()`.
pub type AnchoredF32 = Bank<AnchoredComponent>;

/// One component on the default path: its f32 powers over a grid period, and what the bank's
/// arrays ([`Anchors`]) take of it when it joins; the bank steps it from then on in its arrays.
#[derive(Clone)]
pub struct AnchoredComponent {
    powers_re: [f32; GRID],
    powers_im: [f32; GRID],
    /// State at the component's first sample.
    first_anchor: [f64; 2],
    /// State at the first sample of the period after the one it starts in.
    first_next_anchor: [f64; 2],
    /// z^GRID in f64.
    period_step: [f64; 2],
    component: Component,
    /// The sample from which the component is silent (see [`Component::silent_from`]).
    silent_from: u64,
    /// The powers of each period carry the glide's phase (MODEL.md §5.2), refilled every period
    /// until the glide is over.
    gliding: bool,
}

/// Components a SIMD group of the anchors' step holds: AVX2's 4 f64 (two SSE2 pairs).
const LANES: usize = 4;

/// The anchored bank's per-period state, one entry per component in the bank's order, kept as
/// arrays of [`LANES`] entries ([`Group`]), so that a period's step of every component is one
/// loop over plain f64 arrays, a SIMD group of components at a time ([`step_anchors`]). Entry `i`
/// is lane `i % LANES` of group `i / LANES`. Entries from `len` on are not components; the step
/// runs over them to the end of the last group, harmlessly.
pub struct Anchors {
    len: usize,
    /// One allocation; a bank of n components touches only the first ⌈n / LANES⌉ groups, one
    /// contiguous run of memory.
    groups: Box<[Group; GROUPS]>,
    /// The earliest `event_at`: before it, a period's step is the array loop alone.
    first_event_at: u64,
    /// A sample at which every entry is anchored ([`NOT_ALL_ANCHORED`] if none is known): the
    /// period start the bank last stepped to, until an entry is set anchored elsewhere. It spares
    /// [`Anchors::leading_at`] its walk over the bank in nearly every period.
    all_anchored_at: u64,
    period_sum: PeriodSum,
}

/// [`Anchors::all_anchored_at`] when no sample is known at which every entry is anchored.
const NOT_ALL_ANCHORED: u64 = u64::MAX;

/// Groups of [`LANES`] entries in [`Anchors`].
const GROUPS: usize = MAX_COMPONENTS / LANES;

/// The state of [`LANES`] entries of [`Anchors`], each field an array of one SIMD group (structure
/// of arrays within the group, the groups one after another: a group is 5 cache lines, where
/// whole arrays of [`MAX_COMPONENTS`] put a few components' state on some 20 lines over 5 pages,
/// which a thousand C-library handles in 64-frame calls paid for in cache and TLB misses).
#[derive(Clone, Copy, Default)]
#[repr(C, align(64))]
struct Group {
    /// State at the first sample of the period being rendered (or of the component, if it
    /// starts later), in f32 for the synthesis.
    anchor_re: [f32; LANES],
    anchor_im: [f32; LANES],
    /// The same in f64, as it was worked out: what the level is read from.
    level_re: [f64; LANES],
    level_im: [f64; LANES],
    /// State at the first sample of the next period.
    next_re: [f64; LANES],
    next_im: [f64; LANES],
    /// z^GRID.
    step_re: [f64; LANES],
    step_im: [f64; LANES],
    anchor_sample: [u64; LANES],
    /// The first period start at which the component needs more than the plain step
    /// ([`AnchoredComponent::at_event`]): its silence, its next direct anchor, every period of a
    /// glide, and the boundary it starts on.
    event_at: [u64; LANES],
    /// The period start at which the anchor is next worked out from the closed form.
    direct_at: [u64; LANES],
}

const _: () = assert!(MAX_COMPONENTS.is_multiple_of(LANES));

impl Default for Anchors {
    /// Allocates, once: the bank never holds more than [`MAX_COMPONENTS`].
    fn default() -> Self {
        Self {
            len: 0,
            groups: Box::new([Group::default(); GROUPS]),
            first_event_at: u64::MAX,
            all_anchored_at: NOT_ALL_ANCHORED,
            period_sum: PeriodSum::default(),
        }
    }
}

impl Anchors {
    /// Appends `component`'s state at its start.
    fn push(&mut self, component: &AnchoredComponent) {
        self.len += 1;
        self.set(self.len - 1, component);
    }

    /// Entry `index` from `component`'s state at its start.
    fn set(&mut self, index: usize, component: &AnchoredComponent) {
        let first_sample = component.component.first_sample();
        if first_sample != self.all_anchored_at {
            self.all_anchored_at = NOT_ALL_ANCHORED;
        }
        self.set_anchor(index, component.first_anchor);
        let (group, lane) = self.entry_mut(index);
        [group.next_re[lane], group.next_im[lane]] = component.first_next_anchor;
        [group.step_re[lane], group.step_im[lane]] = component.period_step;
        group.anchor_sample[lane] = first_sample;
        // The counter it replaces counted the periods stepped after the one it starts in: the
        // 1024th is worked out from the closed form.
        let first_period = (first_sample / GRID as u64 + 1) * GRID as u64;
        group.direct_at[lane] = first_period + (PERIODS_PER_DIRECT_ANCHOR - 1) * GRID as u64;
        group.event_at[lane] = if first_sample.is_multiple_of(GRID as u64) {
            first_sample
        } else {
            component.next_event(group.direct_at[lane])
        };
        let event_at = group.event_at[lane];
        self.first_event_at = self.first_event_at.min(event_at);
    }

    fn set_anchor(&mut self, index: usize, state: [f64; 2]) {
        let (group, lane) = self.entry_mut(index);
        [group.level_re[lane], group.level_im[lane]] = state;
        group.anchor_re[lane] = state[0] as f32;
        group.anchor_im[lane] = state[1] as f32;
    }

    /// Entry `index`: its group, and its lane in the group.
    #[inline]
    fn entry(&self, index: usize) -> (&Group, usize) {
        (&self.groups[index / LANES], index % LANES)
    }

    /// The same, to change.
    #[inline]
    fn entry_mut(&mut self, index: usize) -> (&mut Group, usize) {
        (&mut self.groups[index / LANES], index % LANES)
    }

    /// Moves entry `from` to `to` (`to` < `from`, dropping what was there).
    fn move_entry(&mut self, from: usize, to: usize) {
        let groups = &mut *self.groups;
        let (from_group, from) = (from / LANES, from % LANES);
        let (to_group, to) = (to / LANES, to % LANES);
        macro_rules! move_fields {
            ($($field:ident),*) => {
                $(groups[to_group].$field[to] = groups[from_group].$field[from];)*
            };
        }
        move_fields!(
            anchor_re,
            anchor_im,
            level_re,
            level_im,
            next_re,
            next_im,
            step_re,
            step_im,
            anchor_sample,
            event_at,
            direct_at
        );
    }

    /// How many entries from the first are anchored at `sample`.
    #[inline]
    fn leading_at(&self, sample: u64) -> usize {
        if sample == self.all_anchored_at {
            return self.len;
        }
        (0..self.len)
            .take_while(|&index| {
                let (group, lane) = self.entry(index);
                group.anchor_sample[lane] == sample
            })
            .count()
    }
}

impl BankComponent for AnchoredComponent {
    fn start(component: Component) -> Self {
        let first_sample = component.first_sample();
        let grid = GRID as f64;
        let next_period = (first_sample / GRID as u64 + 1) * GRID as u64;
        let mut anchored = Self {
            powers_re: [0.0; GRID],
            powers_im: [0.0; GRID],
            first_anchor: component.state_at(first_sample),
            first_next_anchor: component.state_at(next_period),
            period_step: complex_exp(
                -component.decay_per_sample * grid,
                component.radians_per_sample * grid,
            ),
            component,
            silent_from: component.silent_from(),
            gliding: component.glide.is_some(),
        };
        anchored.fill_powers(first_sample);
        anchored
    }

    /// |anchor|² rounded to f32 (squared: only the order matters, and it saves a hypot), worked
    /// out only when the bank is full and a component is to be given up, not every period.
    fn level(&self) -> f64 {
        squared_level(self.first_anchor)
    }

    fn level_in(_: &[Self], anchors: &Anchors, index: usize) -> f64 {
        let (group, lane) = anchors.entry(index);
        squared_level([group.level_re[lane], group.level_im[lane]])
    }

    fn joined(anchors: &mut Anchors, components: &[Self]) {
        anchors.push(components.last().expect("a component joined"));
    }

    fn replaced(anchors: &mut Anchors, components: &[Self], index: usize) {
        anchors.set(index, &components[index]);
        // A component replaced in the middle of the bank: the period's sum is not its own.
        anchors.period_sum.period_start = None;
    }

    fn cleared(anchors: &mut Anchors) {
        anchors.len = 0;
        anchors.first_event_at = u64::MAX;
        anchors.all_anchored_at = NOT_ALL_ANCHORED;
        anchors.period_sum.period_start = None;
    }

    fn advance_all(components: &mut Vec<Self>, anchors: &mut Anchors, period_start: u64) {
        step_anchors(anchors, period_start);
        // The step anchors every entry there, and no event moves an anchor's sample.
        anchors.all_anchored_at = period_start;
        if period_start < anchors.first_event_at {
            return;
        }
        // Some component needs more than the plain step just taken: each one that does puts it
        // right, and the silent ones are dropped, the others keeping their order (`retain_mut`
        // visits them in order, once each).
        let mut first_event_at = u64::MAX;
        let mut index = 0;
        let mut kept = 0;
        components.retain_mut(|component| {
            let (group, lane) = anchors.entry(index);
            let sounds = period_start < group.event_at[lane]
                || component.at_event(anchors, index, period_start);
            if sounds {
                if kept != index {
                    anchors.move_entry(index, kept);
                }
                let (group, lane) = anchors.entry(kept);
                first_event_at = first_event_at.min(group.event_at[lane]);
                kept += 1;
            }
            index += 1;
            sounds
        });
        anchors.len = kept;
        anchors.first_event_at = first_event_at;
    }

    type Shared = Anchors;

    fn write_all(components: &mut [Self], anchors: &mut Anchors, span_start: u64, out: &mut [f32]) {
        if let Ok(period) = <&mut [f32; GRID]>::try_from(&mut *out) {
            if anchors.leading_at(span_start) == anchors.len {
                sum_period(components, &anchors.groups[..], period);
                return;
            }
        }
        // A span shorter than a period (a host's small block), or a period in which a component
        // starts: the components that sound from the period's start are summed over the whole
        // period once, in registers, and each span of the period takes its part of that sum, then
        // adds the components that started since.
        let period_start = anchors.sum_period_from(components, span_start);
        let period_sum = &anchors.period_sum;
        let offset = (span_start - period_start) as usize;
        out.copy_from_slice(&period_sum.samples[offset..offset + out.len()]);
        let since = period_sum.components;
        if since < components.len() {
            add_each(
                &components[since..anchors.len],
                anchors,
                since,
                span_start,
                out,
            );
        }
    }

    #[inline(always)]
    fn period_sum<'a>(
        components: &'a [Self],
        anchors: &'a mut Anchors,
        span_start: u64,
    ) -> Option<(&'a [f32; GRID], u64)> {
        anchors.sum_period_from(components, span_start);
        let period_sum = &anchors.period_sum;
        (period_sum.components == anchors.len)
            .then_some((&period_sum.samples, period_sum.generation))
    }
}

impl Anchors {
    /// Works out [`PeriodSum`] for the period `span_start` lies in, unless it holds it; that
    /// period's first sample.
    #[inline(always)]
    fn sum_period_from(&mut self, components: &[AnchoredComponent], span_start: u64) -> u64 {
        let period_start = span_start / GRID as u64 * GRID as u64;
        // The check in line: every call of a short block makes it, one a period does the sum.
        if self.period_sum.period_start != Some(period_start) {
            self.sum_period_anew(components, period_start);
        }
        period_start
    }

    /// [`Anchors::sum_period_from`] of a period not yet summed.
    #[inline(never)]
    fn sum_period_anew(&mut self, components: &[AnchoredComponent], period_start: u64) {
        // They lead the bank: a component joins at its end, and one that starts at a period's
        // first sample joined in the period before.
        let leading = self.leading_at(period_start);
        let period_sum = &mut self.period_sum;
        sum_period(
            &components[..leading],
            &self.groups[..],
            &mut period_sum.samples,
        );
        period_sum.components = leading;
        period_sum.period_start = Some(period_start);
        period_sum.generation = period_sum.generation.wrapping_add(1);
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
    /// Counts the sums worked out: tells a sum from the one before (see
    /// [`Synthesis::period_sum`](super::Synthesis::period_sum)).
    generation: u64,
}

impl Default for PeriodSum {
    fn default() -> Self {
        Self {
            samples: [0.0; GRID],
            period_start: None,
            components: 0,
            generation: 0,
        }
    }
}

/// |state|² rounded to f32: see [`AnchoredComponent::level`].
fn squared_level([re, im]: [f64; 2]) -> f64 {
    (re * re + im * im) as f32 as f64
}

/// Every component of the bank to the period starting at `period_start` by the plain step: the
/// anchor becomes the next one, and the next one is multiplied by z^GRID (the f64 products and
/// sums of `complex_mul`, in its order). The arrays are taken [`LANES`] components at a time,
/// each group a few SIMD instructions: SSE2 pairs on x86-64's baseline, AVX2 where the processor
/// has it. Each lane does the same IEEE operations (Rust never fuses a product into a sum), so
/// the anchors are the same bits on every path and as one component at a time. A component
/// that needs more puts its entry right afterwards ([`AnchoredComponent::at_event`]).
#[multiversion(targets("x86_64+avx512f+avx512vl+avx2+avx", "x86_64+avx2+avx"))]
fn step_anchors(anchors: &mut Anchors, period_start: u64) {
    let groups = anchors.len.div_ceil(LANES);
    for group in &mut anchors.groups[..groups] {
        let (re, im) = (group.next_re, group.next_im);
        let (z_re, z_im) = (group.step_re, group.step_im);
        group.anchor_re = re.map(|re| re as f32);
        group.anchor_im = im.map(|im| im as f32);
        group.level_re = re;
        group.level_im = im;
        group.next_re = std::array::from_fn(|k| re[k] * z_re[k] - im[k] * z_im[k]);
        group.next_im = std::array::from_fn(|k| re[k] * z_im[k] + im[k] * z_re[k]);
        group.anchor_sample = [period_start; LANES];
    }
}

impl AnchoredComponent {
    /// Adds this component's samples for `out`, which starts at absolute sample `span_start` and
    /// lies within one grid period.
    #[inline]
    fn synthesize(&self, anchor: [f32; 2], anchor_sample: u64, span_start: u64, out: &mut [f32]) {
        let first = anchor_sample.max(span_start);
        let offset = (first - span_start) as usize;
        if offset >= out.len() {
            return;
        }
        let out = &mut out[offset..];
        let power = (first - anchor_sample) as usize;
        let re = &self.powers_re[power..power + out.len()];
        let im = &self.powers_im[power..power + out.len()];
        let [anchor_re, anchor_im] = anchor;
        for ((y, &z_re), &z_im) in out.iter_mut().zip(re).zip(im) {
            *y += anchor_re * z_im + anchor_im * z_re;
        }
    }

    /// Adds this component's samples for the whole period `out`, when its anchor is at the
    /// period's first sample (it did not start within the period): the same sums as
    /// [`AnchoredComponent::synthesize`], with the length known to the compiler.
    #[inline]
    fn synthesize_period(&self, [anchor_re, anchor_im]: [f32; 2], out: &mut [f32; GRID]) {
        for ((y, &z_re), &z_im) in out.iter_mut().zip(&self.powers_re).zip(&self.powers_im) {
            *y += anchor_re * z_im + anchor_im * z_re;
        }
    }

    /// The period start from which this component, past its first boundary, needs more than the
    /// plain step: every period while it has a glide, else its silence or its next direct anchor.
    fn next_event(&self, direct_at: u64) -> u64 {
        if self.component.glide.is_some() {
            0
        } else {
            self.silent_from.min(direct_at)
        }
    }

    /// Puts entry `index` right after the plain step to the period starting at `period_start`,
    /// which reached its `event_at`; false once the component is silent.
    fn at_event(&mut self, anchors: &mut Anchors, index: usize, period_start: u64) -> bool {
        let following = period_start + GRID as u64;
        if self.component.first_sample() == period_start {
            // Started on this very boundary: its anchor already belonged to the new period.
            anchors.set_anchor(index, self.first_anchor);
            let (group, lane) = anchors.entry_mut(index);
            [group.next_re[lane], group.next_im[lane]] = self.first_next_anchor;
            group.event_at[lane] = self.next_event(group.direct_at[lane]);
            return true;
        }
        if period_start >= self.silent_from {
            return false;
        }
        let (group, lane) = anchors.entry_mut(index);
        if self.component.glide.is_some() {
            // A glide's phase is no fixed rotation a period: each anchor is the closed form's.
            [group.next_re[lane], group.next_im[lane]] = self.component.state_at(following);
            if self.gliding {
                self.fill_powers(period_start);
            }
            return true;
        }
        if period_start >= group.direct_at[lane] {
            [group.next_re[lane], group.next_im[lane]] = self.component.state_at(following);
            group.direct_at[lane] += PERIODS_PER_DIRECT_ANCHOR * GRID as u64;
        }
        group.event_at[lane] = self.next_event(group.direct_at[lane]);
        true
    }

    /// z^j for the period that starts at `anchor_sample`, times the glide's phase over it while
    /// the component glides: from the anchor, the glide adds K_a·(1 − r^j), K_a the phase left
    /// to add at the anchor and r = e^(−1/T).
    fn fill_powers(&mut self, anchor_sample: u64) {
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
                let elapsed = self.component.samples_since_onset(anchor_sample);
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
fn sum_period(components: &[AnchoredComponent], groups: &[Group], out: &mut [f32; GRID]) {
    let mut sum = [0.0; GRID];
    // Whole groups in a loop of a known length, which the compiler unrolls (a loop over a
    // chunk of unknown length was unrolled or not as the build's partition fell), then the
    // rest: the same components in the same order.
    let whole = components.chunks_exact(LANES);
    let rest = whole.remainder();
    for (components, group) in whole.zip(groups) {
        for (lane, component) in components.iter().enumerate() {
            component.synthesize_period([group.anchor_re[lane], group.anchor_im[lane]], &mut sum);
        }
    }
    if let Some(group) = groups.get(components.len() / LANES) {
        for (lane, component) in rest.iter().enumerate() {
            component.synthesize_period([group.anchor_re[lane], group.anchor_im[lane]], &mut sum);
        }
    }
    *out = sum;
}

/// Adds each component's samples into `out`, which starts at absolute sample `span_start` and
/// lies within one grid period, in the bank's order; compiled as [`sum_period`] is.
#[multiversion(targets("x86_64+avx512f+avx512vl+avx2+avx", "x86_64+avx2+avx"))]
fn add_each(
    components: &[AnchoredComponent],
    anchors: &Anchors,
    first: usize,
    span_start: u64,
    out: &mut [f32],
) {
    for (index, component) in (first..).zip(components) {
        let (group, lane) = anchors.entry(index);
        component.synthesize(
            [group.anchor_re[lane], group.anchor_im[lane]],
            group.anchor_sample[lane],
            span_start,
            out,
        );
    }
}
