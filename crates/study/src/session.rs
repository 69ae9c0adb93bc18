//! A session: each trial presented, its answer read and logged, from where the log left off.

use std::io::{BufRead, Write};
use std::time::Instant;

use super::log::{LogRow, TrialLog};
use super::spec::{Design, Spec};
use super::stimuli::Rendered;
use super::trials::{plan_practice, Trial};
use super::StudyError;
use sake_glug_io::text::printable;

/// When a trial's stimuli played.
#[derive(Debug, Clone, Copy)]
pub struct Presented {
    /// The audio interface's frames at which the first and the second stimulus started (JACK's
    /// frame time, or frames written to an ALSA device since the session started); `None` when
    /// nothing was played (a dry run).
    pub onset_frames: Option<(u64, u64)>,
    /// The moment the last sample of the second stimulus was played, from which the response
    /// time counts.
    pub ended: Instant,
}

/// What plays a trial: the first stimulus, the gap, the second; returns once it has ended.
pub trait Presenter {
    /// Plays stimuli `trial.first` and `trial.second` (indices into the rendered stimuli).
    fn present(&mut self, trial: Trial) -> Result<Presented, StudyError>;
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

    /// The row of the trial at `place` as the plan fixes it once key `pressed` (1 or 2) is
    /// answered: everything but the response time and the onset frames, which the run fills in
    /// (and [`TrialLog::resume`] checks a logged row against).
    pub fn planned_row(&self, place: Place, pressed: u8) -> LogRow {
        let trial = place.trial;
        let (first, second) = (
            &self.spec.stimuli[trial.first],
            &self.spec.stimuli[trial.second],
        );
        let chosen = if pressed == 1 {
            trial.first
        } else {
            trial.second
        };
        let (level, chose_comparison) = match self.spec.design {
            Design::Paired | Design::TwoAfc => (None, None),
            // The standard is stimulus 0; the comparison is the other one.
            Design::Constant => (first.level.or(second.level), Some(u8::from(chosen != 0))),
        };
        // 2AFC: the target is stimulus 0.
        let correct = (self.spec.design == Design::TwoAfc).then_some(u8::from(chosen == 0));
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
            correct,
        }
    }

    /// Presents the session from place `from` (0-based, practice trials first) on, once a first
    /// line (Enter) comes from `input` after the spec's instructions, reading each answer from it
    /// (a line `1` or `2`; anything else asks again) and appending it to `log` before the next
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
                format_args!("{kind} {}/{of}: listen…\n", place.number),
            );
            let presented = presenter.present(place.trial)?;
            say(
                prompt,
                format_args!("{} 1 (the first) or 2 (the second): ", self.spec.question),
            );
            let pressed = loop {
                read_line(input, &mut line, position)?;
                match line.trim() {
                    "1" => break 1u8,
                    "2" => break 2u8,
                    _ => say(prompt, format_args!("Please answer 1 or 2: ")),
                }
            };
            log.append(&LogRow {
                rt_s: presented.ended.elapsed().as_secs_f64(),
                first_onset_frame: presented.onset_frames.map(|(first, _)| first),
                second_onset_frame: presented.onset_frames.map(|(_, second)| second),
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
