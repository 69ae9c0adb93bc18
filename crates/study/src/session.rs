//! A session: each trial presented, its answer read and logged, from where the log left off.
//! The session plans its rows and checks a resumed log's against them; the log ([`TrialLog`])
//! only stores rows.

use std::io::{BufRead, Write};
use std::path::Path;
use std::time::Instant;

use super::log::{LogRow, TrialLog};
use super::spec::{Design, Spec};
use super::stimuli::Rendered;
use super::trials::{plan_practice, Trial};
use super::StudyError;
use sake_glug_io::text::{printable, quoted};

/// The audio interface's frames at which a trial's stimuli started (JACK's frame time, or
/// frames written to an ALSA device since the session started).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Onsets {
    /// The first stimulus's.
    pub first: u64,
    /// The second's.
    pub second: u64,
    /// The third's, in the three-interval designs.
    pub third: Option<u64>,
}

/// When a trial's stimuli played.
#[derive(Debug, Clone, Copy)]
pub struct Presented {
    /// Where its stimuli started; `None` when nothing was played (a dry run).
    pub onset_frames: Option<Onsets>,
    /// The moment the last sample of its last stimulus was played, from which the response time
    /// counts.
    pub ended: Instant,
}

/// What plays a trial: its stimuli in order with the gap between each two; returns once it has
/// ended.
pub trait Presenter {
    /// Plays the stimuli of `trial` (indices into the rendered stimuli).
    fn present(&mut self, trial: Trial) -> Result<Presented, StudyError>;

    /// What the prompt tells the participant before the trial at `place`: to listen, where the
    /// presenter plays it.
    fn cue(&self, _place: Place) -> String {
        "listen…".into()
    }
}

/// Plays nothing: the dry run's answers count from the prompt.
#[derive(Debug, Default)]
pub struct Silent;

impl Presenter for Silent {
    fn present(&mut self, _trial: Trial) -> Result<Presented, StudyError> {
        Ok(Presented {
            onset_frames: None,
            ended: Instant::now(),
        })
    }
}

/// Everything a session needs, prepared before the first trial.
#[derive(Debug)]
pub struct StudySession<'a> {
    /// The spec.
    pub spec: &'a Spec,
    /// The participant's ID.
    pub participant: &'a str,
    /// The seed of the order.
    pub seed: u64,
    /// The order.
    pub trials: &'a [Trial],
    /// The stimuli, level-matched.
    pub rendered: &'a [Rendered],
    /// Whether it is a dry run (nothing played): every row it logs is marked so.
    pub dry_run: bool,
}

/// A place in a session: its practice trials first, then the study's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Place {
    /// The trial played there.
    pub trial: Trial,
    /// Whether it is a practice trial (logged as practice, not data).
    pub practice: bool,
    /// Its number among its kind's trials, from 1 (practice and study counted apart).
    pub number: usize,
}

impl StudySession<'_> {
    /// The spec's practice trials for this participant, played before [`Self::trials`].
    pub fn practice(&self) -> Vec<Trial> {
        plan_practice(self.spec, self.seed)
    }

    /// Every place of the session in order: the practice trials, then the study's.
    pub fn places(&self) -> Vec<Place> {
        let practice = self
            .practice()
            .into_iter()
            .enumerate()
            .map(|(index, trial)| Place {
                trial,
                practice: true,
                number: index + 1,
            });
        let study = self.trials.iter().enumerate().map(|(index, &trial)| Place {
            trial,
            practice: false,
            number: index + 1,
        });
        practice.chain(study).collect()
    }

    /// The row of the trial at `place` as the plan fixes it once key `pressed` (1 to the
    /// design's [`Design::answers`]) is answered: everything but the response time and the onset
    /// frames, which the run fills in (and a resumed log's rows are checked against).
    pub fn planned_row(&self, place: Place, pressed: u8) -> LogRow {
        let trial = place.trial;
        let (first, second) = (
            &self.spec.stimuli[trial.first],
            &self.spec.stimuli[trial.second],
        );
        let third = trial.third.map(|third| &self.spec.stimuli[third]);
        let chosen = trial.at(pressed).expect("a key the design's answers allow");
        let (level, chose_comparison) = match self.spec.design {
            Design::Paired | Design::TwoAfc | Design::Triangle | Design::Abx => (None, None),
            // The standard is stimulus 0; the comparison is the other one.
            Design::Constant => (first.level.or(second.level), Some(u8::from(chosen != 0))),
        };
        let right = match self.spec.design {
            Design::Paired | Design::Constant => None,
            // The target is stimulus 0.
            Design::TwoAfc => Some(chosen == 0),
            // The odd one is the stimulus played once.
            Design::Triangle => Some(trial.played().filter(|&s| s == chosen).count() == 1),
            // X is the third; key 1 names A, key 2 B.
            Design::Abx => Some(trial.third == Some(chosen)),
        };
        LogRow {
            participant: self.participant.to_owned(),
            trial: place.number,
            design: self.spec.design.name().to_owned(),
            first: first.name.clone(),
            second: second.name.clone(),
            answer: self.spec.stimuli[chosen].name.clone(),
            pressed,
            rt_s: 0.0,
            seed: self.seed,
            level,
            chose_comparison,
            first_gain_db: self.rendered[trial.first].gain_db,
            second_gain_db: self.rendered[trial.second].gain_db,
            first_onset_frame: None,
            second_onset_frame: None,
            first_params: first.params.clone(),
            second_params: second.params.clone(),
            practice: u8::from(place.practice),
            correct: right.map(u8::from),
            third: third.map(|third| third.name.clone()),
            third_gain_db: trial.third.map(|third| self.rendered[third].gain_db),
            third_onset_frame: None,
            third_params: third.map(|third| third.params.clone()),
            dry_run: u8::from(self.dry_run),
        }
    }

    /// The log at `path` reopened to continue this session, every row checked against the plan
    /// ([`TrialLog::resume`]); with how many trials it holds.
    pub fn resume_log(&self, path: &Path) -> Result<(TrialLog, usize), StudyError> {
        let places = self.places();
        // The rows still to come, as they may be written (any key fills the same columns).
        let planned: Vec<LogRow> = places
            .iter()
            .map(|&place| self.planned_row(place, 1))
            .collect();
        TrialLog::resume(path, &planned, |index, row| {
            self.check_row(row, index, &places)
        })
    }

    /// Whether `row` is what this session plans at its place `index` (0-based, of `places`),
    /// with one of its answers; else what differs, for the message.
    fn check_row(&self, row: &LogRow, index: usize, places: &[Place]) -> Result<(), String> {
        let shown = |text: &str| format!("`{}`", quoted(text));
        if row.participant != self.participant {
            return Err(format!("participant {}", shown(&row.participant)));
        }
        let design = self.spec.design.name();
        if row.design != design || row.seed != self.seed {
            return Err(format!(
                "design {}, seed {} (this session: `{design}`, seed {})",
                shown(&row.design),
                row.seed,
                self.seed
            ));
        }
        let Some(&place) = places.get(index) else {
            return Err(format!("trial {}, past the session's last", row.trial));
        };
        if row.practice != u8::from(place.practice) {
            return Err(format!(
                "row {}: practice {}, where this session plans {}",
                index + 1,
                row.practice,
                if place.practice {
                    "a practice trial (1)"
                } else {
                    "a trial of the study (0)"
                }
            ));
        }
        if row.dry_run != u8::from(self.dry_run) {
            return Err(format!(
                "row {}: dry_run {}, where this session {}",
                index + 1,
                row.dry_run,
                if self.dry_run {
                    "is a dry run (1)"
                } else {
                    "plays its stimuli (0)"
                }
            ));
        }
        let answers = self.spec.design.answers();
        if !(1..=answers).contains(&row.pressed) {
            return Err(format!(
                "trial {}: key {} pressed, not one of 1 to {answers}",
                row.trial, row.pressed
            ));
        }
        let pressed = row.pressed;
        let planned = self.planned_row(place, pressed);
        let same_trial = row.trial == planned.trial
            && row.first == planned.first
            && row.second == planned.second
            && row.third == planned.third
            && row.first_params == planned.first_params
            && row.second_params == planned.second_params
            && row.third_params == planned.third_params;
        if !same_trial {
            let order = |row: &LogRow| {
                [Some(&row.first), Some(&row.second), row.third.as_ref()]
                    .into_iter()
                    .flatten()
                    .map(|name| shown(name))
                    .collect::<Vec<_>>()
                    .join(" then ")
            };
            return Err(format!(
                "trial {} is {}; this spec plans trial {} as {}",
                row.trial,
                order(row),
                planned.trial,
                order(&planned)
            ));
        }
        // Compared as written: a level is the spec's number, read back exactly.
        let same_answer = row.answer == planned.answer
            && row.level == planned.level
            && row.chose_comparison == planned.chose_comparison
            && row.correct == planned.correct;
        if !same_answer {
            return Err(format!(
                "trial {}: answer {}, key {pressed}, level {:?}, chose_comparison {:?}, correct \
                 {:?}; key {pressed} of this trial chooses {} (level {:?}, chose_comparison \
                 {:?}, correct {:?})",
                row.trial,
                shown(&row.answer),
                row.level,
                row.chose_comparison,
                row.correct,
                shown(&planned.answer),
                planned.level,
                planned.chose_comparison,
                planned.correct
            ));
        }
        if !(row.rt_s.is_finite() && row.rt_s >= 0.0) {
            return Err(format!(
                "trial {}: response time {} s is not a time",
                row.trial, row.rt_s
            ));
        }
        Ok(())
    }

    /// Presents the session from place `from` (0-based, practice trials first) on, once a first
    /// line (Enter) comes from `input` after the spec's instructions, reading each answer from it
    /// (a line `1` or `2`, in the triangle also `3`; anything else asks again) and appending it to `log` before the next
    /// trial. After every `break_every` of the study's trials (not after the last) a pause waits
    /// for a line. Prompts go to `prompt`. Ends with [`StudyError::InputClosed`] if `input` ends
    /// first.
    pub fn run(
        &self,
        from: usize,
        presenter: &mut dyn Presenter,
        log: &mut TrialLog,
        input: &mut impl BufRead,
        prompt: &mut impl Write,
    ) -> Result<(), StudyError> {
        let places = self.places();
        let total = places.len();
        let (practice, study) = (total - self.trials.len(), self.trials.len());
        let say = |prompt: &mut dyn Write, text: std::fmt::Arguments| {
            // A prompt that cannot be shown is no reason to lose the session.
            let _ = prompt.write_fmt(text).and_then(|()| prompt.flush());
        };
        let read_line = |input: &mut dyn BufRead, line: &mut String, answered: usize| {
            line.clear();
            match input.read_line(line) {
                Ok(0) => Err(StudyError::InputClosed { answered, total }),
                Ok(_) => Ok(()),
                Err(source) => Err(StudyError::Io {
                    path: "stdin".into(),
                    source,
                }),
            }
        };
        let answers = self.spec.design.answers();
        let (keys, choices) = match self.spec.design {
            Design::Triangle => ("1, 2 or 3 (the first, second or third)", "1, 2 or 3"),
            _ => ("1 (the first) or 2 (the second)", "1 or 2"),
        };
        let mut line = String::new();
        if from < total {
            if let Some(instructions) = &self.spec.instructions {
                // The spec's text, its control characters shown escaped, line by line.
                for text in instructions.lines() {
                    say(prompt, format_args!("{}\n", printable(text)));
                }
            }
            // The participant (and whoever connects the audio) starts the session.
            say(prompt, format_args!("Press Enter to begin.\n"));
            read_line(input, &mut line, from)?;
        }
        for (position, place) in places.iter().enumerate().skip(from) {
            if !place.practice && place.number == 1 && practice > 0 {
                say(prompt, format_args!("Practice over: the study begins.\n"));
            }
            let kind = if place.practice {
                "Practice trial"
            } else {
                "Trial"
            };
            let of = if place.practice { practice } else { study };
            say(
                prompt,
                format_args!("{kind} {}/{of}: {}\n", place.number, presenter.cue(*place)),
            );
            let presented = presenter.present(place.trial)?;
            say(prompt, format_args!("{} {keys}: ", self.spec.question));
            let pressed = loop {
                read_line(input, &mut line, position)?;
                match line.trim().parse::<u8>() {
                    Ok(key) if (1..=answers).contains(&key) => break key,
                    _ => say(prompt, format_args!("Please answer {choices}: ")),
                }
            };
            let onsets = presented.onset_frames;
            log.append(&LogRow {
                rt_s: presented.ended.elapsed().as_secs_f64(),
                first_onset_frame: onsets.map(|onsets| onsets.first),
                second_onset_frame: onsets.map(|onsets| onsets.second),
                third_onset_frame: onsets.and_then(|onsets| onsets.third),
                ..self.planned_row(*place, pressed)
            })?;
            let pause = self.spec.break_every.is_some_and(|every| {
                !place.practice && place.number % every as usize == 0 && place.number < study
            });
            if pause {
                say(
                    prompt,
                    format_args!(
                        "Break ({} of {study} trials done): press Enter when you are ready to go \
                         on.\n",
                        place.number
                    ),
                );
                read_line(input, &mut line, position + 1)?;
            }
        }
        say(prompt, format_args!("Done: {study} trials. Thank you.\n"));
        Ok(())
    }
}
