//! What a study's output channels carry, block by block, for every audio backend: a trial's
//! stimuli one after another with the gap between each two on the actuator channels, the masking noise on
//! the headphone channels, silence elsewhere (MODEL.md §15). The backends own the clock and the
//! hand-off; this owns the samples. It neither allocates nor locks once made.

use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

use super::spec::Channels;
use super::trials::Trial;

/// What one output channel carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Role {
    Actuator,
    Headphone,
    Unused,
}

/// Where a trial's stimuli fall, counted in frames from its onset.
#[derive(Debug, Clone)]
pub(super) struct Timeline {
    lengths: Vec<u64>,
    gap: u64,
}

/// Where a trial's stimuli fall: frames from its onset to each stimulus's onset, and to its end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Placed {
    /// Each stimulus's onset, in the order played (the first's is 0).
    pub(super) onsets: [u64; 3],
    /// The stimuli played: 2 or 3.
    pub(super) count: usize,
    /// Just after its last sample.
    pub(super) end: u64,
}

impl Timeline {
    /// Where the stimuli of `trial` fall.
    pub(super) fn of(&self, trial: Trial) -> Placed {
        let mut onsets = [0; 3];
        let mut at = 0;
        let mut count = 0;
        for (slot, stimulus) in onsets.iter_mut().zip(trial.played()) {
            if count > 0 {
                at += self.gap;
            }
            *slot = at;
            at += self.lengths[stimulus];
            count += 1;
        }
        Placed {
            onsets,
            count,
            end: at,
        }
    }
}

/// The samples of a session's output channels.
pub(super) struct Mix {
    stimuli: Vec<Vec<f32>>,
    timeline: Timeline,
    roles: Vec<Role>,
    /// Half the noise's span (0: no noise).
    noise_peak: f32,
    rng: Xoshiro256PlusPlus,
    /// The trial playing, and where its stimuli fall.
    playing: Option<(Trial, Placed)>,
}

impl Mix {
    /// The stimuli (each at the output's rate), the gap between a trial's two (frames), the
    /// channels' roles and the noise's RMS level (dBFS, uniform white noise).
    pub(super) fn new(
        stimuli: Vec<Vec<f32>>,
        gap: u64,
        channels: &Channels,
        noise_dbfs: Option<f64>,
    ) -> Self {
        let roles = (1..=channels.count())
            .map(|channel| {
                if channels.actuator.contains(&channel) {
                    Role::Actuator
                } else if channels.headphones.contains(&channel) {
                    Role::Headphone
                } else {
                    Role::Unused
                }
            })
            .collect();
        // Uniform on ±a has an RMS of a/√3.
        let noise_peak = noise_dbfs.map_or(0.0, |db| 10f64.powf(db / 20.0) * 3f64.sqrt()) as f32;
        Self {
            timeline: Timeline {
                lengths: stimuli.iter().map(|s| s.len() as u64).collect(),
                gap,
            },
            stimuli,
            roles,
            noise_peak,
            rng: Xoshiro256PlusPlus::seed_from_u64(0),
            playing: None,
        }
    }

    /// How many output channels.
    pub(super) fn channels(&self) -> usize {
        self.roles.len()
    }

    /// Where its trials' stimuli fall.
    pub(super) fn timeline(&self) -> &Timeline {
        &self.timeline
    }

    /// Whether a trial is playing.
    pub(super) fn playing(&self) -> bool {
        self.playing.is_some()
    }

    /// Starts a trial: the next [`fill`](Self::fill) counts from its onset.
    pub(super) fn begin(&mut self, trial: Trial) {
        self.playing = Some((trial, self.timeline.of(trial)));
    }

    /// Fills one block of `frames` frames, `outputs` being the channels' buffers in order (one
    /// slice of at least `frames` samples each), the block starting `into_trial` frames after
    /// the onset of the trial playing (ignored when none plays). Returns true when the trial's
    /// last sample is in this block: the trial has then ended.
    pub(super) fn fill<'a>(
        &mut self,
        into_trial: u64,
        frames: usize,
        outputs: impl IntoIterator<Item = &'a mut [f32]>,
    ) -> bool {
        for (out, role) in outputs.into_iter().zip(&self.roles) {
            let out = &mut out[..frames];
            out.fill(0.0);
            match role {
                Role::Actuator => {
                    if let Some((trial, placed)) = self.playing {
                        for (offset, sample) in out.iter_mut().enumerate() {
                            let position = into_trial + offset as u64;
                            // The stimulus whose span holds this frame, if any (else a gap).
                            *sample = trial
                                .played()
                                .zip(placed.onsets)
                                .find_map(|(stimulus, onset)| {
                                    let samples = &self.stimuli[stimulus];
                                    position
                                        .checked_sub(onset)
                                        .and_then(|into| samples.get(into as usize))
                                        .copied()
                                })
                                .unwrap_or(0.0);
                        }
                    }
                }
                Role::Headphone if self.noise_peak > 0.0 => {
                    for sample in out.iter_mut() {
                        *sample = self.noise_peak * (2.0 * self.rng.random::<f32>() - 1.0);
                    }
                }
                Role::Headphone | Role::Unused => {}
            }
        }
        let Some((_, placed)) = self.playing else {
            return false;
        };
        let ended = into_trial + frames as u64 >= placed.end;
        if ended {
            self.playing = None;
        }
        ended
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FRAMES: usize = 4;

    fn channels(actuator: &[u16], headphones: &[u16]) -> Channels {
        Channels {
            actuator: actuator.to_vec(),
            headphones: headphones.to_vec(),
        }
    }

    /// Every block of a session, each channel's samples end to end, and the block the trial
    /// ended in.
    fn play(
        mix: &mut Mix,
        trial: Trial,
        blocks: usize,
        begin_at_block: usize,
    ) -> (Vec<Vec<f32>>, Option<usize>) {
        let mut recorded = vec![Vec::new(); mix.channels()];
        let mut buffers = vec![vec![f32::NAN; FRAMES]; mix.channels()];
        let mut ended = None;
        for block in 0..blocks {
            if block == begin_at_block {
                mix.begin(trial);
            }
            let into_trial = (block.saturating_sub(begin_at_block) * FRAMES) as u64;
            if mix.fill(into_trial, FRAMES, buffers.iter_mut().map(|b| &mut b[..])) {
                ended = Some(block);
            }
            for (channel, buffer) in recorded.iter_mut().zip(&buffers) {
                channel.extend_from_slice(buffer);
            }
        }
        (recorded, ended)
    }

    #[test]
    fn the_stimuli_sit_at_the_onset_and_after_the_gap_on_the_actuator_channels() {
        let first = vec![1.0, 2.0, 3.0, 4.0, 5.0];
        let second = vec![-1.0, -2.0, -3.0];
        let mut mix = Mix::new(
            vec![first.clone(), second.clone()],
            2,
            &channels(&[1, 3], &[]),
            None,
        );
        let placed = mix.timeline().of(Trial::pair(0, 1));
        assert_eq!((placed.onsets[1], placed.end, placed.count), (7, 10, 2));
        let (recorded, ended) = play(&mut mix, Trial::pair(0, 1), 6, 1);
        let mut expected = vec![0.0; FRAMES];
        expected.extend(&first);
        expected.extend([0.0, 0.0]);
        expected.extend(&second);
        expected.resize(6 * FRAMES, 0.0);
        assert_eq!(recorded[0], expected);
        assert_eq!(recorded[2], expected);
        assert!(
            recorded[1].iter().all(|&s| s == 0.0),
            "channel 2 has no role"
        );
        // The trial's 10 frames from frame 4 end in the block of frames 12..16.
        assert_eq!(ended, Some(3));
        assert!(!mix.playing());
    }

    /// A triangle's three stimuli, each after a gap, the trial ending after the third.
    #[test]
    fn three_stimuli_follow_one_another_with_the_gap_between_each_two() {
        let a = vec![1.0, 2.0];
        let b = vec![-1.0, -2.0, -3.0];
        let mut mix = Mix::new(vec![a.clone(), b.clone()], 1, &channels(&[1], &[]), None);
        let trial = Trial::triple(0, 1, 0);
        let placed = mix.timeline().of(trial);
        assert_eq!((placed.onsets, placed.end, placed.count), ([0, 3, 7], 9, 3));
        let (recorded, ended) = play(&mut mix, trial, 3, 0);
        let mut expected = a.clone();
        expected.push(0.0);
        expected.extend(&b);
        expected.push(0.0);
        expected.extend(&a);
        expected.resize(3 * FRAMES, 0.0);
        assert_eq!(recorded[0], expected);
        assert_eq!(
            ended,
            Some(2),
            "frames 8..12 hold the trial's last, frame 8"
        );
    }

    #[test]
    fn a_trial_ending_on_a_block_boundary_ends_in_that_block() {
        let mut mix = Mix::new(
            vec![vec![1.0; 3], vec![1.0; 3]],
            2,
            &channels(&[1], &[]),
            None,
        );
        let (_, ended) = play(&mut mix, Trial::pair(0, 1), 4, 0);
        assert_eq!(ended, Some(1), "frames 0..8 hold the whole trial");
    }

    #[test]
    fn the_noise_is_on_the_headphone_channels_alone_at_its_level() {
        let noise_dbfs = -20.0;
        let stimulus = vec![0.5; 3000];
        let mut mix = Mix::new(
            vec![stimulus.clone(), stimulus],
            1000,
            &channels(&[2], &[1, 4]),
            Some(noise_dbfs),
        );
        let (recorded, ended) = play(&mut mix, Trial::pair(0, 1), 2000, 0);
        assert!(ended.is_some());
        for headphone in [&recorded[0], &recorded[3]] {
            let rms = (headphone.iter().map(|&s| (s * s) as f64).sum::<f64>()
                / headphone.len() as f64)
                .sqrt();
            let target = 10f64.powf(noise_dbfs / 20.0);
            assert!(
                (rms / target - 1.0).abs() < 0.02,
                "rms {rms}, target {target}"
            );
            assert!(
                headphone.iter().all(|&s| s != 0.5),
                "no stimulus in the noise"
            );
        }
        assert_ne!(
            recorded[0], recorded[3],
            "each headphone channel draws its own noise"
        );
        let actuator = &recorded[1];
        assert!(
            actuator.iter().all(|&s| s == 0.5 || s == 0.0),
            "no noise on the actuator"
        );
        assert!(
            recorded[2].iter().all(|&s| s == 0.0),
            "channel 3 has no role"
        );
    }

    #[test]
    fn between_trials_the_noise_plays_and_the_actuator_is_silent() {
        let mut mix = Mix::new(vec![vec![1.0; 8]], 0, &channels(&[1], &[2]), Some(-30.0));
        let (recorded, ended) = play(&mut mix, Trial::pair(0, 0), 3, usize::MAX);
        assert_eq!(ended, None);
        assert!(recorded[0].iter().all(|&s| s == 0.0));
        assert!(
            recorded[1].iter().all(|&s| s != 0.0),
            "the noise lasts the session"
        );
    }
}
