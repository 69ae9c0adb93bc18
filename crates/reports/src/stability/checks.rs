//! What a case checks ([`Property`]), the verdicts ([`Check`], [`Outcome`]), and the checks
//! every group shares, judged from a [`Run`].

use super::harness::{Run, ENERGY_SPAN_S};
use super::{Scale, StabilityCase};
use crate::timing::TimedRender;
use sake_glug_engine::synthesis::MAX_COMPONENTS;

/// Run time per sample may be at most this many times a normal case's.
pub const MAX_TIME_RATIO: f64 = 5.0;
/// Consecutive spans' energy may grow by at most this fraction (beats between components of one
/// unit move energy between spans a little; growth means instability).
pub(super) const ENERGY_TOLERANCE: f64 = 0.01;

/// A property a stability case checks; each describes itself for the report.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Property {
    /// No NaN or infinity.
    Finite,
    /// Never above the ceiling.
    Ceiling,
    /// Energy does not grow once nothing starts.
    Energy,
    /// Cost per sample bounded by a normal case's.
    Time,
    /// Components at 0 Hz or at and above Nyquist never sound.
    NotComputed,
    /// The same number of units at every sample rate.
    SameGlugs,
    /// The bank never holds more than its cap.
    ComponentsCapped,
    /// Units do start.
    Glugs,
    /// A never-decaying unit stays on the reference.
    NoDrift,
}

impl Property {
    /// Every property, in the order of the checks table.
    pub const ALL: [Property; 9] = [
        Property::Finite,
        Property::Ceiling,
        Property::Energy,
        Property::Time,
        Property::NotComputed,
        Property::SameGlugs,
        Property::ComponentsCapped,
        Property::Glugs,
        Property::NoDrift,
    ];

    /// The property's short name, as the tables show it.
    pub fn name(self) -> &'static str {
        match self {
            Property::Finite => "finite",
            Property::Ceiling => "ceiling",
            Property::Energy => "energy",
            Property::Time => "time",
            Property::NotComputed => "not computed",
            Property::SameGlugs => "same glugs",
            Property::ComponentsCapped => "components capped",
            Property::Glugs => "glugs",
            Property::NoDrift => "no drift",
        }
    }

    /// What the property asserts.
    pub fn description(self) -> String {
        match self {
            Property::Finite => "no NaN or infinity in any sample: in the output, and before \
                                 the output limiter (the engine counts the samples that were not \
                                 finite before it turned them into 0 or the ceiling)"
                .into(),
            Property::Ceiling => "|y| never exceeds the sanitised ceiling (compared in f32, as \
                                  the engine clamps), or the higher of the old and the new one \
                                  during the 10 ms ramp to a new one; the measurement says on \
                                  how many samples the limiter acted"
                .into(),
            Property::Energy => format!(
                "once no unit starts any more, the energy of consecutive {ENERGY_SPAN_S} s spans \
                 never grows by more than {} % (a never-decaying unit keeps its energy; a \
                 decaying one loses it); judged where the limiter did not act, where the output \
                 is the signal before the limiter: a judged span in which the limiter acted \
                 fails the check",
                ENERGY_TOLERANCE * 100.0
            ),
            Property::Time => format!(
                "engine run time per sample against that of a normal case measured in the same \
                 run (fastest of {} runs in the report, of {} in the tests), marked slow past \
                 {MAX_TIME_RATIO}×: points at denormal slow-downs and runaway work. A figure and \
                 a warning, never a failure, since the machine's load moves it (the work itself \
                 is bounded by the components check); never an absolute time",
                Scale::Report.repeats(),
                Scale::Test.repeats()
            ),
            Property::NotComputed => "components with f = 0 or f ≥ fs/2 never sound: no \
                                      component in the bank, output exactly 0"
                .into(),
            Property::SameGlugs => "the number of units at any sample rate equals the number \
                                    at 48 kHz (±1): onsets are sub-sample exact"
                .into(),
            Property::ComponentsCapped => format!(
                "at most {MAX_COMPONENTS} components sound, and the units beyond the caps are \
                 counted as skipped"
            ),
            Property::Glugs => "units start at all under the case's inputs".into(),
            Property::NoDrift => "the last second of the long render of a never-decaying unit \
                                  is within −100 dB of the f64 reference"
                .into(),
        }
    }
}

impl std::fmt::Display for Property {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One property checked by a case.
#[derive(Debug, Clone)]
pub struct Check {
    /// The property checked.
    pub what: Property,
    /// Whether the property held. A [`Property::Time`] check always holds: the time is a
    /// figure, and [`Check::slow`] says when it is past its bound.
    pub passed: bool,
    /// Run time past [`MAX_TIME_RATIO`]: a warning, never a failure, since a machine's load
    /// moves a time measured on it.
    pub slow: bool,
    /// The measurement behind the verdict.
    pub detail: String,
}

impl Check {
    /// The verdict as the tables show it.
    pub fn mark(&self) -> &'static str {
        match (self.passed, self.slow) {
            (false, _) => "FAILED",
            (true, true) => "slow",
            (true, false) => "ok",
        }
    }
}

/// The result of one case.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// The catalogue entry this case belongs to.
    pub group: StabilityCase,
    /// The case's name within its group.
    pub name: String,
    /// The properties checked.
    pub checks: Vec<Check>,
    /// Measurements worth reporting that are not checks.
    pub notes: String,
}

impl Outcome {
    /// Whether every check passed.
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| c.passed)
    }

    /// One line: every check with its verdict and measurement, then the notes.
    pub fn summary(&self) -> String {
        let checks: Vec<String> = self
            .checks
            .iter()
            .map(|c| format!("{} {} ({})", c.what, c.mark(), c.detail))
            .collect();
        format!("{}; {}", checks.join(", "), self.notes)
    }
}

pub(super) fn check(what: Property, passed: bool, detail: String) -> Check {
    Check {
        what,
        passed,
        slow: false,
        detail,
    }
}

pub(super) fn finite(run: &Run) -> Check {
    let hidden = run.render.non_finite_before_limiter;
    check(
        Property::Finite,
        run.render.all_finite && hidden == 0,
        if hidden == 0 {
            "every sample, before the limiter too".into()
        } else {
            format!("{hidden} samples NaN or infinite before the limiter")
        },
    )
}

pub(super) fn ceiling(run: &Run) -> Check {
    check(
        Property::Ceiling,
        // In f32, as the engine clamps: 0.001 rounds up in f32.
        run.render.all_finite && run.render.peak <= run.ceiling as f32,
        format!(
            "peak {:.3} ≤ {}, limiter acted on {} samples",
            run.render.peak, run.ceiling, run.render.limiter_events
        ),
    )
}

/// Energy of consecutive spans after the last onset never grows beyond the tolerance, and the
/// limiter did not act in those spans (there the output is the signal before the limiter).
pub(super) fn energy_not_growing(run: &Run) -> Check {
    let first = (run.render.last_onset_by / run.energy_span + 1) as usize;
    let energies = run.render.energies.get(first..).unwrap_or(&[]);
    let limited = limiter_events_in_spans(&run.render, first);
    let worst = energies
        .windows(2)
        .map(|pair| {
            if pair[0] > 0.0 {
                pair[1] / pair[0]
            } else if pair[1] > 0.0 {
                f64::INFINITY
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max);
    check(
        Property::Energy,
        worst <= 1.0 + ENERGY_TOLERANCE && energies.len() >= 2 && limited == 0,
        format!(
            "largest span-to-span ratio {worst:.4} over {} spans, limiter acted on {limited} \
             samples in them",
            energies.len()
        ),
    )
}

/// Samples the limiter changed in the energy spans from `first` on.
pub(super) fn limiter_events_in_spans(render: &TimedRender, first: usize) -> u64 {
    let counts = &render.span_limiter_events;
    match counts.last() {
        Some(&last) if first < counts.len() => {
            last - if first == 0 { 0 } else { counts[first - 1] }
        }
        _ => 0,
    }
}

/// The case's time per sample against the normal case's: a figure, with a warning past
/// [`MAX_TIME_RATIO`], never a failure.
pub(super) fn time_ratio(run: &Run, normal: &Run) -> Check {
    let ratio = run.time_per_sample() / normal.time_per_sample();
    Check {
        what: Property::Time,
        passed: true,
        slow: ratio > MAX_TIME_RATIO,
        detail: format!("{ratio:.2}× the normal case per sample"),
    }
}

pub(super) fn outcome(
    group: StabilityCase,
    name: String,
    checks: Vec<Check>,
    run: &Run,
) -> Outcome {
    Outcome {
        group,
        name,
        checks,
        notes: format!(
            "{:.0}× real time, {} units ({} skipped), {} components given up, at most {} sounding, \
             limiter acted on {} samples",
            run.times_real_time(),
            run.units_started,
            run.units_skipped,
            run.given_up,
            run.render.max_sounding,
            run.render.limiter_events
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn run_taking(engine_time: Duration) -> Run {
        Run {
            render: TimedRender {
                engine_time,
                ..TimedRender::nothing_yet(0)
            },
            sample_rate: 48_000.0,
            len: 48_000,
            energy_span: 0,
            ceiling: 1.0,
            units_started: 0,
            units_skipped: 0,
            given_up: 0,
        }
    }

    /// A busy machine can make any case as slow as it likes: the time is a warning, so the
    /// report's verdict cannot depend on the load.
    #[test]
    fn a_slow_case_is_a_warning_not_a_failure() {
        let normal = run_taking(Duration::from_millis(10));
        let slow = time_ratio(&run_taking(Duration::from_millis(1000)), &normal);
        assert!(slow.passed && slow.slow, "{slow:?}");
        assert_eq!(slow.mark(), "slow");
        let quick = time_ratio(&run_taking(Duration::from_millis(20)), &normal);
        assert!(quick.passed && !quick.slow, "{quick:?}");
        assert_eq!(quick.mark(), "ok");
    }
}
