//! Stability on stiff and extreme cases, shared by `sake-glug stability` (long renders) and
//! `tests/reports/stability.rs` (short ones): the catalogue of case groups ([`StabilityCase`]),
//! each described and run by its own file, the one way a case renders ([`harness`]) and what it
//! checks ([`checks`]).
//!
//! Every case renders through the engine's public API, on any synthesis path (the report uses
//! the default one), and checks some of:
//! - **finite**: no NaN or infinity in any sample, before the output limiter as well as after;
//! - **ceiling**: |y| never exceeds the (sanitised) ceiling, or the higher of the old and the new
//!   one while it ramps to a new one (MODEL.md §6), and how often the limiter acted;
//! - **energy**: once no unit starts any more, the energy of consecutive spans never grows, judged
//!   only where the limiter did not act (so the output is the signal before the limiter);
//! - **time**: engine run time per sample against a normal case measured in the same run,
//!   marked slow past a factor (points at denormal slow-downs and runaway work); a ratio,
//!   never an absolute time, and a warning, never a failure: a machine's load moves it;
//! - case-specific properties (components capped, nothing computed above Nyquist, no drift...).

mod checks;
mod harness;

mod decay;
mod flood;
mod frequency;
mod hostile_inputs;
mod long_render;
mod sample_rate;
mod tilt_flip;

pub use checks::{Check, Outcome, Property, MAX_TIME_RATIO};

use sake_glug_engine::{AnchoredF32, Synthesis};

/// How long the cases render.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scale {
    /// Seconds to minutes, for the test suite (dev profile).
    Test,
    /// Up to 24 hours, for the report (release build).
    Report,
}

impl Scale {
    /// Length of the sweeps' renders, seconds.
    fn sweep_s(self) -> f64 {
        match self {
            Scale::Test => 3.0,
            Scale::Report => 30.0,
        }
    }

    /// Length of the long renders, seconds.
    fn long_s(self) -> f64 {
        match self {
            Scale::Test => 600.0,
            Scale::Report => 24.0 * 3600.0,
        }
    }

    /// Repetitions of a timed render; the fastest counts, so a busy machine does not fail a case.
    fn repeats(self) -> usize {
        match self {
            Scale::Test => 3,
            Scale::Report => 2,
        }
    }
}

/// A group of cases, described and run by its own file.
trait CaseGroup {
    /// The group's short name, as the tables show it.
    const NAME: &'static str;
    /// What the group renders.
    const DESCRIPTION: &'static str;
    /// What the group's time check compares with.
    const TIME_REFERENCE: &'static str;
    /// Runs every case of the group at `scale` on synthesis path `S`.
    fn run<S: Synthesis>(scale: Scale) -> Vec<Outcome>;
}

/// Declares [`StabilityCase`] from the list of groups: each variant is the [`CaseGroup`] of the
/// same name in the file named beside it, which says everything else about it.
macro_rules! catalogue {
    ($($(#[doc = $doc:literal])* $case:ident in $file:ident,)*) => {
        /// The stability catalogue: every group of cases, each describing what it renders and
        /// what its time check compares with. `sake-glug stability --catalogue` prints it as the
        /// case table of `docs/stability.md`.
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub enum StabilityCase {
            $($(#[doc = $doc])* $case,)*
        }

        impl StabilityCase {
            /// Every group, in the report's order.
            pub const ALL: [StabilityCase; [$(stringify!($case)),*].len()] =
                [$(StabilityCase::$case),*];

            /// The group's short name, as the tables show it.
            pub fn name(self) -> &'static str {
                match self {
                    $(StabilityCase::$case => <$file::$case as CaseGroup>::NAME,)*
                }
            }

            /// What the group renders.
            pub fn description(self) -> &'static str {
                match self {
                    $(StabilityCase::$case => <$file::$case as CaseGroup>::DESCRIPTION,)*
                }
            }

            /// What the group's time check compares with.
            pub fn time_reference(self) -> &'static str {
                match self {
                    $(StabilityCase::$case => <$file::$case as CaseGroup>::TIME_REFERENCE,)*
                }
            }

            /// Runs every case of the group at `scale` on synthesis path `S`: a test runs them
            /// on a path it has broken on purpose.
            pub fn run_on<S: Synthesis>(self, scale: Scale) -> Vec<Outcome> {
                match self {
                    $(StabilityCase::$case => <$file::$case as CaseGroup>::run::<S>(scale),)*
                }
            }
        }
    };
}

catalogue! {
    /// Decay rates from 0 to 10⁹ s⁻¹.
    DecaySweep in decay,
    /// Frequencies from 0 to far above Nyquist.
    FrequencySweep in frequency,
    /// Sample rates from 1 kHz to 768 kHz, and out-of-range ones.
    SampleRateSweep in sample_rate,
    /// Hundreds of units due per sample.
    Flood in flood,
    /// Tilt jumping 0° ↔ 180° every sample.
    TiltFlip in tilt_flip,
    /// NaN, infinities and absurd values for every input.
    HostileInputs in hostile_inputs,
    /// Hours of rendering.
    LongRender in long_render,
}

impl StabilityCase {
    /// Runs every case of the group at `scale` on the default synthesis path.
    pub fn run(self, scale: Scale) -> Vec<Outcome> {
        self.run_on::<AnchoredF32>(scale)
    }
}

impl std::fmt::Display for StabilityCase {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The catalogue as Markdown: the checks table and the case table of `docs/stability.md`.
pub fn catalogue() -> String {
    let mut text = String::from("| check | what it asserts |\n|---|---|\n");
    for property in Property::ALL {
        text += &format!(
            "| {} | {} |\n",
            property,
            property.description().replace('|', "\\|")
        );
    }
    text += "\n| group | cases | normal case for the time check |\n|---|---|---|\n";
    for case in StabilityCase::ALL {
        text += &format!(
            "| {} | {} | {} |\n",
            case,
            case.description(),
            case.time_reference()
        );
    }
    text
}

/// Every group of cases, in the report's order, on the default path.
pub fn run_all(scale: Scale, mut progress: impl FnMut(&Outcome)) -> Vec<Outcome> {
    let mut all = Vec::new();
    for case in StabilityCase::ALL {
        for outcome in case.run(scale) {
            progress(&outcome);
            all.push(outcome);
        }
    }
    all
}

/// The outcomes as a Markdown table.
pub fn report(outcomes: &[Outcome]) -> String {
    let mut text =
        String::from("| group | case | result | checks | measured |\n|---|---|---|---|---|\n");
    for o in outcomes {
        let checks: Vec<String> = o
            .checks
            .iter()
            .map(|c| {
                let mark = match c.mark() {
                    "ok" => "",
                    "slow" => "**slow** ",
                    _ => "**FAILED** ",
                };
                format!("{mark}{}: {}", c.what, c.detail)
            })
            .collect();
        text += &format!(
            "| {} | {} | {} | {} | {} |\n",
            o.group,
            o.name,
            if o.passed() { "pass" } else { "**FAIL**" },
            checks.join("; "),
            o.notes
        );
    }
    let failed = outcomes.iter().filter(|o| !o.passed()).count();
    let slow = outcomes
        .iter()
        .filter(|o| o.checks.iter().any(|c| c.slow))
        .count();
    text += &format!(
        "\n{} cases, {} failed, {} slow (a time, not a verdict: see `time`).\n",
        outcomes.len(),
        failed,
        slow
    );
    text
}
