//! Planning a discrimination study (`sake-glug analyze plan discrimination`): how many
//! participants (of a given number of trials each) does a study need to show, with a given power,
//! that people tell the stimuli apart (d′ above zero), or that they do not tell them apart by
//! more than a bound (d′ below it: equivalence)? Studies of each size are simulated with
//! observers of a known d′ (each participant's drawn around it when `spread` is not 0), each is
//! analysed as `analyze discrimination` analyses a log, and the share of studies that show the
//! goal is the power.

use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde::Serialize;

use super::discrimination::{estimate_discrimination, DiscriminationDesign, MAX_D_PRIME};
use super::plan::{clopper_pearson, PlanError, MAX_PLAN_PARTICIPANTS, MAX_STUDIES};

/// The most trials a simulated participant answers: far past any session of people, and a bound
/// on the draws a plan makes.
pub const MAX_PLAN_TRIALS_EACH: u32 = 10_000;

/// What a study is to show.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "goal", content = "bound")]
pub enum DiscriminationGoal {
    /// The test against chance rejects at 5 %: people told the stimuli apart.
    AboveZero,
    /// The upper end of d′'s 95 % interval is below the bound: they do not tell them apart by
    /// as much as it.
    Below(f64),
}

/// A discrimination design to be sized, and the observers it is simulated with.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DiscriminationPlan {
    /// The design.
    pub design: DiscriminationDesign,
    /// What each study is to show.
    pub goal: DiscriminationGoal,
    /// The observers' d′ (their mean, with `spread`).
    pub d_prime: f64,
    /// The standard deviation of the participants' d′ around `d_prime` (each drawn once, at 0
    /// when the draw is negative): people differ, and their pooled answers vary more than one
    /// observer's would.
    pub spread: f64,
    /// Trials each participant answers.
    pub trials_each: u32,
    /// The power wanted: the share of studies that show the goal.
    pub power: f64,
    /// Studies simulated at each size tried.
    pub studies: u32,
    /// The seed: the same plan and seed give the same figures on any machine.
    pub seed: u64,
}

/// The power of one size.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PlannedSize {
    /// Participants.
    pub participants: u32,
    /// Trials in all.
    pub trials: u64,
    /// Studies that showed the goal.
    pub shown: u32,
    /// `shown` over the studies.
    pub power: f64,
    /// The 95 % Clopper–Pearson interval of that power (how well the studies know it).
    pub power_low: f64,
    /// Its upper end.
    pub power_high: f64,
}

/// A plan's outcome: every size tried, fewest participants first, and the smallest that
/// reached the power wanted.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DiscriminationPlanOutcome {
    /// The plan.
    pub plan: DiscriminationPlan,
    /// The observers' proportion correct (at `d_prime`).
    pub proportion_correct: f64,
    /// The sizes simulated.
    pub tried: Vec<PlannedSize>,
    /// The fewest participants whose studies reached the power, if any did within
    /// [`MAX_PLAN_PARTICIPANTS`].
    pub needed: Option<PlannedSize>,
}

fn refuse(argument: &'static str, message: impl Into<String>) -> PlanError {
    PlanError {
        argument,
        message: message.into(),
    }
}

impl DiscriminationPlan {
    /// The plan's arguments checked, each refused by name.
    pub fn check(&self) -> Result<(), PlanError> {
        if !(0.0..=MAX_D_PRIME).contains(&self.d_prime) {
            return Err(refuse(
                "d-prime",
                format!("{}: from 0 to {MAX_D_PRIME}", self.d_prime),
            ));
        }
        if !(0.0..=MAX_D_PRIME).contains(&self.spread) {
            return Err(refuse(
                "spread",
                format!("{}: from 0 to {MAX_D_PRIME}", self.spread),
            ));
        }
        match self.goal {
            DiscriminationGoal::AboveZero if self.d_prime == 0.0 => {
                return Err(refuse(
                    "d-prime",
                    "0: observers who cannot tell the stimuli apart show d′ above zero only as \
                     often as the test errs (5 %); give the d′ you expect",
                ))
            }
            DiscriminationGoal::Below(bound) => {
                if !(bound > 0.0 && bound <= MAX_D_PRIME) {
                    return Err(refuse(
                        "below",
                        format!("{bound}: a bound above 0 and at most {MAX_D_PRIME}"),
                    ));
                }
                if self.d_prime >= bound {
                    return Err(refuse(
                        "d-prime",
                        format!(
                            "{} is not below the bound {bound}: observers who tell the stimuli \
                             apart by that much cannot show d′ below it",
                            self.d_prime
                        ),
                    ));
                }
            }
            DiscriminationGoal::AboveZero => {}
        }
        if !(self.power > 0.0 && self.power < 1.0) {
            return Err(refuse(
                "power",
                format!("{}: a share above 0 and below 1 (0.8 is 80 %)", self.power),
            ));
        }
        for (argument, value, most) in [
            ("trials-each", self.trials_each, MAX_PLAN_TRIALS_EACH),
            ("studies", self.studies, MAX_STUDIES),
        ] {
            if !(1..=most).contains(&value) {
                return Err(refuse(argument, format!("{value}: from 1 to {most}")));
            }
        }
        Ok(())
    }

    /// Whether the pooled answers of one study (`correct` of `trials`) show the goal, as
    /// `analyze discrimination` reads them.
    fn shows(&self, correct: u32, trials: u32) -> bool {
        let estimate = estimate_discrimination(self.design, correct, trials);
        match self.goal {
            DiscriminationGoal::AboveZero => estimate.told_apart(),
            DiscriminationGoal::Below(bound) => estimate
                .d_prime_interval
                .is_some_and(|(_, high)| high < bound),
        }
    }

    /// The power of studies of `participants`: study i draws from a stream of its own (the
    /// seed's generator jumped ahead 2¹²⁸ numbers i times), participant by participant, so a
    /// larger study begins with a smaller one's participants and the powers of two sizes differ
    /// by the participants added, not by chance alone.
    fn power_of(&self, participants: u32) -> PlannedSize {
        let mut generator = Xoshiro256PlusPlus::seed_from_u64(self.seed);
        let common = self.design.proportion_correct(self.d_prime);
        let mut shown = 0;
        for _ in 0..self.studies {
            let mut stream = generator.clone();
            generator.jump();
            let mut correct = 0;
            for _ in 0..participants {
                let chance = match self.spread > 0.0 {
                    true => {
                        let deviation: f64 = StandardNormal.sample(&mut stream);
                        let d_prime = (self.d_prime + self.spread * deviation).max(0.0);
                        self.design.proportion_correct(d_prime)
                    }
                    false => common,
                };
                for _ in 0..self.trials_each {
                    correct += u32::from(stream.random::<f64>() < chance);
                }
            }
            shown += u32::from(self.shows(correct, participants * self.trials_each));
        }
        let (power_low, power_high) = clopper_pearson(shown, self.studies);
        PlannedSize {
            participants,
            trials: u64::from(participants) * u64::from(self.trials_each),
            shown,
            power: f64::from(shown) / f64::from(self.studies),
            power_low,
            power_high,
        }
    }
}

/// Simulates `plan` at growing numbers of participants (1, 2, 4, … until the power is reached,
/// then halving the step between the last size short of it and the first past it) and reports
/// the fewest that reached it.
pub fn plan_discrimination(
    plan: &DiscriminationPlan,
) -> Result<DiscriminationPlanOutcome, PlanError> {
    plan.check()?;
    let mut tried: Vec<PlannedSize> = Vec::new();
    let evaluate = |participants: u32, tried: &mut Vec<PlannedSize>| {
        let size = plan.power_of(participants);
        tried.push(size);
        size.power >= plan.power
    };
    let (mut short, mut reached) = (0, None);
    let mut participants = 1;
    loop {
        if evaluate(participants, &mut tried) {
            reached = Some(participants);
            break;
        }
        short = participants;
        if participants == MAX_PLAN_PARTICIPANTS {
            break;
        }
        participants = (participants * 2).min(MAX_PLAN_PARTICIPANTS);
    }
    if let Some(mut high) = reached {
        let mut low = short;
        while high - low > 1 {
            let middle = low + (high - low) / 2;
            if evaluate(middle, &mut tried) {
                high = middle;
            } else {
                low = middle;
            }
        }
        reached = Some(high);
    }
    tried.sort_by_key(|size| size.participants);
    let needed = reached.and_then(|participants| {
        tried
            .iter()
            .find(|size| size.participants == participants)
            .copied()
    });
    Ok(DiscriminationPlanOutcome {
        plan: plan.clone(),
        proportion_correct: plan.design.proportion_correct(plan.d_prime),
        tried,
        needed,
    })
}
