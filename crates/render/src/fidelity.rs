//! What each format keeps of the model, measured: one render written in every format played,
//! each file read back as its format declares ([`ReadBack`], in the format's own file) and held
//! against the model's own glugs: where its onsets fall, how far its envelope strays from the
//! felt envelope, what carries the viscosity c, how big it is, and which platform limits it
//! met. `sake-glug render --fidelity` prints it; the guide's table (docs/guide/haptic-designer.md) is its output. Nothing here
//! knows a format by name: the table of formats says everything. With an actuator profile
//! (`--actuator`, MODEL.md §18) it adds the c the device delivers, with and without the
//! compensation.

use std::path::Path;

use super::clips::{clip_onsets, ClipSource, Glug};
use super::loudness::Loudness;
use super::render::{RenderObserver, RenderSummary};
use super::scene::Scene;
use super::sinks::read_back::{ReadBack, Reading, WrittenClip};
use super::sinks::{Output, OutputError, OutputFormat, OutputOptions};
use super::steps::ComponentEnvelopes;
use sake_glug_engine::{ActuatorResponse, UnitOnset, Voicing};
use sake_glug_io::read::{self, InputKind};

/// The envelope is compared where the model's is within this of its loudest (−40 dB): the
/// glugging part, where a difference can be felt; below it every format is near silence.
const GLUGGING_FLOOR: f64 = 0.01;

/// A format's level is floored here (−60 dB) before it is compared in dB, so a step to 0
/// counts as a fall to −60 dB, not as an infinite error.
const LEVEL_FLOOR: f64 = 1e-3;

/// The envelope is compared every millisecond.
const COMPARE_EVERY_S: f64 = 0.001;

/// What one format keeps of a render.
#[derive(Debug, Clone, PartialEq)]
pub struct Fidelity {
    /// The format.
    pub format: OutputFormat,
    /// Mean and worst distance (ms) from the model's audible onsets to the format's, or `None`
    /// for a waveform, which holds the onsets to the sample.
    pub onset_error_ms: Option<(f64, f64)>,
    /// Mean |dB| between the format's envelope and the model's felt envelope over the
    /// glugging part, or `None` for a waveform.
    pub envelope_error_db: Option<f64>,
    /// What carries the viscosity c.
    pub carries_c: &'static str,
    /// Size of the file (bytes).
    pub bytes: u64,
    /// The platform limits the file met, measured on this render.
    pub limits: String,
    /// With an actuator profile, the c its device delivers of this format (`None` without one).
    pub delivered_c: Option<DeliveredC>,
    /// Its level: a waveform's loudness, a clip's peak drive.
    pub level: Level,
}

/// The level of a format's file (MODEL.md §19).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Level {
    /// A waveform: its integrated loudness, loudness range and true peak.
    Loudness(Loudness),
    /// A clip: the strongest drive it carries (0..1 of full scale), read back.
    PeakDrive(f64),
    /// A waveform with a haptic channel beside its audio: the loudness of the render's
    /// samples, and the haptic channel's strongest drive (0..1 of full scale), read back.
    LoudnessAndDrive(Loudness, f64),
    /// Not measured.
    None,
}

/// The c a device delivers of a format, against the model's (MODEL.md §18).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DeliveredC {
    /// The format carries the two components as they are (a waveform): each unit's delivered c
    /// is A1·R(f1) / (A1·R(f1) + A2·R(f2)), R the device's response, driven without and with
    /// the compensation.
    Measured {
        /// Delivered c less the model's c over the audible units, driven as the model says.
        without: CShift,
        /// The same, driven as compensated.
        with: CShift,
        /// The compensation equalises what is felt (`--felt`), while this c measures the
        /// shaking the device delivers.
        felt: bool,
    },
    /// The format carries c as something the platform plays on its own (a felt frequency, a
    /// sharpness, a motor balance), not as the two components: the model's c, without the
    /// compensation (MODEL.md §19), which the platform maps to its own actuator; the profile
    /// changes only the level it plays.
    AsCarried,
}

/// How far delivered c lies from the model's over a render's units.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CShift {
    /// Mean of delivered c − model c (below 0: the device plays the liquid thinner).
    pub mean: f64,
    /// The largest |delivered c − model c|.
    pub worst: f64,
}

impl CShift {
    /// Over `(delivered, model)` pairs; 0 for none.
    fn of(pairs: impl Iterator<Item = (f64, f64)>) -> Self {
        let (mut sum, mut worst, mut count) = (0.0, 0.0f64, 0usize);
        for (delivered, model) in pairs {
            sum += delivered - model;
            worst = worst.max((delivered - model).abs());
            count += 1;
        }
        Self {
            mean: sum / count.max(1) as f64,
            worst,
        }
    }
}

/// A unit as the device receives it: its glug (driven as compensated) and its compensation
/// gains (1 without a profile).
struct DrivenUnit {
    glug: Glug,
    gains: [f64; 2],
}

/// The c `actuator` delivers of each audible unit, driven without and with the compensation.
fn delivered_c(actuator: &ActuatorResponse, units: &[DrivenUnit]) -> DeliveredC {
    let c_of = |amplitudes: [f64; 2], unit: &DrivenUnit| {
        let [d1, d2] = actuator.delivered(amplitudes, unit.glug.frequency_hz);
        d1 / (d1 + d2)
    };
    let audible = || {
        units
            .iter()
            .filter(|unit| unit.glug.amplitudes.iter().sum::<f64>() > 0.0)
    };
    let without = CShift::of(audible().map(|unit| {
        let [a1, a2] = unit.glug.amplitudes;
        let model = [a1 / unit.gains[0], a2 / unit.gains[1]];
        (c_of(model, unit), unit.glug.viscosity)
    }));
    let with =
        CShift::of(audible().map(|unit| (c_of(unit.glug.amplitudes, unit), unit.glug.viscosity)));
    DeliveredC::Measured {
        without,
        with,
        felt: actuator.equalise() == sake_glug_engine::Equalise::Felt,
    }
}

/// The formats measured: every one played that this build writes.
fn measured_formats() -> impl Iterator<Item = (OutputFormat, ReadBack)> {
    OutputFormat::ALL
        .iter()
        .copied()
        .filter(|format| format.is_built())
        .filter_map(|format| Some((format, format.read_back()?)))
}

/// Renders `scene` once into every format (in a temporary folder) and measures each file.
pub fn measure(
    scene: &Scene,
    scene_name: &str,
    options: &OutputOptions,
) -> Result<Vec<Fidelity>, OutputError> {
    let folder = tempfile::tempdir().map_err(OutputError::io(Path::new("a temporary folder")))?;
    let formats: Vec<(OutputFormat, ReadBack)> = measured_formats().collect();
    let outputs: Vec<Output> = formats
        .iter()
        .map(|&(format, _)| Output {
            format,
            path: folder.path().join(format.file_name("measured")),
        })
        .collect();
    struct Glugs {
        glugs: Vec<Glug>,
        driven: Vec<DrivenUnit>,
        sample_rate: u32,
    }
    impl RenderObserver for &mut Glugs {
        fn unit_started(&mut self, onset: &UnitOnset, voicing: Voicing) {
            let glug = Glug::of_unit(onset, voicing.output_gain, self.sample_rate);
            self.glugs.push(glug);
            if voicing.audible {
                self.driven.push(DrivenUnit {
                    glug,
                    gains: onset.actuator_gain,
                });
            }
        }
    }
    let mut glugs = Glugs {
        glugs: Vec::new(),
        driven: Vec::new(),
        sample_rate: scene.sample_rate,
    };
    let options = &OutputOptions {
        measure_loudness: true,
        ..*options
    };
    let report = super::render_to_files(scene, scene_name, &outputs, options, &mut glugs)?;
    let source = ClipSource {
        duration_s: report.summary.duration_s(),
        glugs: &glugs.glugs,
        ceiling: scene.output_ceiling(),
        scene_name,
        seed: scene.config.seed,
    };
    outputs
        .iter()
        .zip(&formats)
        .zip(&report.files)
        .map(|((output, &(format, read_back)), (_, bytes))| {
            let delivered = |waveform: bool| {
                scene.actuator.as_ref().map(|actuator| {
                    if waveform {
                        delivered_c(actuator, &glugs.driven)
                    } else {
                        DeliveredC::AsCarried
                    }
                })
            };
            let fidelity = |onset_error_ms, envelope_error_db, limits, delivered_c| Fidelity {
                format,
                onset_error_ms,
                envelope_error_db,
                carries_c: format.carries_c(),
                bytes: *bytes,
                limits,
                delivered_c,
                level: Level::None,
            };
            Ok(match read_back {
                ReadBack::Waveform { limits, haptic } => {
                    let drive = haptic
                        .map(|channel| (channel.read_peak)(&output.path))
                        .transpose()?;
                    let level = match (report.levelled, drive) {
                        (Some(levelled), Some(drive)) => {
                            Level::LoudnessAndDrive(levelled.after, drive)
                        }
                        (Some(levelled), None) => Level::Loudness(levelled.after),
                        (None, Some(drive)) => Level::PeakDrive(drive),
                        (None, None) => Level::None,
                    };
                    Fidelity {
                        level,
                        ..fidelity(None, None, limits(scene), delivered(true))
                    }
                }
                ReadBack::Clip(read, _) => {
                    let path = &output.path;
                    let text = read::read_text(path, InputKind::WRITTEN)?;
                    // The model's glugs at the drive the clip was written at (--haptic-peak),
                    // found as its sink found it, so the envelope is compared shape to shape.
                    let drive = format.clip_drive_gain(path, &source, options)?;
                    let glugs = drive.glugs(&glugs.glugs);
                    let source = drive.source(&source, &glugs);
                    let clip = WrittenClip {
                        path,
                        text: &text,
                        source: &source,
                    };
                    let reading = read(&clip)?;
                    Fidelity {
                        level: Level::PeakDrive(reading.peak_drive(source.duration_s)),
                        ..fidelity(
                            onset_error_ms(&source, &reading),
                            envelope_error_db(&source, &report.summary, &*reading.envelope),
                            reading.limits,
                            delivered(false),
                        )
                    }
                }
            })
        })
        .collect()
}

/// Mean and worst distance (ms) from the model's audible onsets to the format's marks.
fn onset_error_ms(source: &ClipSource, reading: &Reading) -> Option<(f64, f64)> {
    let onsets: Vec<f64> = clip_onsets(source)
        .into_iter()
        .map(|i| source.glugs[i].onset_s)
        .collect();
    (!onsets.is_empty()).then(|| {
        let distances: Vec<f64> = onsets
            .iter()
            .map(|&onset| distance(reading, onset) * 1000.0)
            .collect();
        let mean = distances.iter().sum::<f64>() / distances.len() as f64;
        (mean, distances.iter().copied().fold(0.0, f64::max))
    })
}

/// How far (s) the format puts `onset`: from the nearest mark, or from the last mark before it.
fn distance(reading: &Reading, onset: f64) -> f64 {
    let marks = reading.onsets.iter();
    if reading.from_mark_before {
        marks
            .filter(|&&mark| mark <= onset + 1e-12)
            .map(|mark| onset - mark)
            .fold(f64::INFINITY, f64::min)
    } else {
        marks
            .map(|mark| (mark - onset).abs())
            .fold(f64::INFINITY, f64::min)
    }
}

/// Mean |20·log10(format / model)| every millisecond where the model's felt envelope is
/// within [`GLUGGING_FLOOR`] of its loudest.
fn envelope_error_db(
    source: &ClipSource,
    summary: &RenderSummary,
    envelope: &dyn Fn(f64) -> f64,
) -> Option<f64> {
    let model = ComponentEnvelopes::new(source);
    let times: Vec<f64> = (0..(summary.duration_s() / COMPARE_EVERY_S) as usize)
        .map(|n| n as f64 * COMPARE_EVERY_S)
        .collect();
    let levels: Vec<f64> = times.iter().map(|&t| model.felt_at(t)).collect();
    let loudest = levels.iter().copied().fold(0.0, f64::max);
    let errors: Vec<f64> = times
        .iter()
        .zip(&levels)
        .filter(|(_, &level)| level > 0.0 && level >= GLUGGING_FLOOR * loudest)
        .map(|(&t, &level)| (20.0 * (envelope(t).max(LEVEL_FLOOR) / level).log10()).abs())
        .collect();
    (!errors.is_empty()).then(|| errors.iter().sum::<f64>() / errors.len() as f64)
}

/// The measurements as the Markdown table the guide shows, each column explained under it;
/// with an actuator profile, two more columns: the c its device delivers without and with the
/// compensation.
pub fn fidelity_table(rows: &[Fidelity]) -> String {
    let on_device = rows.iter().any(|row| row.delivered_c.is_some());
    let felt = rows.iter().any(|row| {
        matches!(
            row.delivered_c,
            Some(DeliveredC::Measured { felt: true, .. })
        )
    });
    let mut lines = vec![
        "| format | onset error, mean / worst (ms) | envelope error (dB) | what carries c | size | limits met | level |".to_owned(),
        "|---|---|---|---|---|---|---|".to_owned(),
    ];
    if on_device {
        lines[0] += " delivered c − model c, mean / worst: uncompensated | compensated |";
        lines[1] += "---|---|";
    }
    for row in rows {
        let onset = row
            .onset_error_ms
            .map_or("exact (the samples)".to_owned(), |(mean, worst)| {
                format!("{mean:.2} / {worst:.2}")
            });
        let envelope = row
            .envelope_error_db
            .map_or("— (the waveform)".to_owned(), |db| format!("{db:.1}"));
        let level = match row.level {
            Level::Loudness(loudness) => loudness.to_string(),
            Level::PeakDrive(drive) => format!("peak drive {:.1} %", drive * 100.0),
            Level::LoudnessAndDrive(loudness, drive) => {
                format!(
                    "{loudness}; haptic channel: peak drive {:.1} %",
                    drive * 100.0
                )
            }
            Level::None => "—".to_owned(),
        };
        let mut line = format!(
            "| `{}` | {onset} | {envelope} | {} | {} | {} | {level} |",
            row.format.name(),
            row.carries_c,
            super::human_bytes(row.bytes),
            row.limits
        );
        let shift = |shift: CShift| format!("{:+.3} / {:.3}", shift.mean, shift.worst);
        match row.delivered_c {
            Some(DeliveredC::Measured { without, with, .. }) => {
                line += &format!(" {} | {} |", shift(without), shift(with));
            }
            Some(DeliveredC::AsCarried) => line += " model c, as carried | model c, as carried |",
            None if on_device => line += " — | — |",
            None => {}
        }
        lines.push(line);
    }
    lines.push(String::new());
    lines.extend(COLUMN_NOTES.iter().map(|note| format!("- {note}")));
    if on_device {
        lines.extend(DEVICE_NOTES.iter().map(|note| format!("- {note}")));
    }
    if felt {
        lines.push(format!("- {FELT_NOTE}"));
    }
    lines.join("\n") + "\n"
}

/// What each column of the table means, printed under it.
const COLUMN_NOTES: &[&str] = &[
    "**onset error**: how far (ms) the format puts each audible glug's onset from the model's: \
     the mean over the glugs, then the worst; to the nearest mark, or for rumble to the start \
     of the frame that carries it. A waveform holds the onsets to the sample.",
    "**envelope error**: the mean of |20·log10(format / model)| (dB, unsigned: a step above \
     and one below both count), every millisecond where the model's felt envelope is within \
     40 dB of its loudest; the format floored at −60 dB.",
    "**what carries c**: where the viscosity c lives in the file.",
    "**limits met**: what the platform's limits made of this render (for Android, the entries \
     lifted to amplitude 1, the lowest that vibrates, rather than rounded to 0, which stops \
     some motors with a click).",
    "**level**: a waveform's integrated loudness (LUFS, BS.1770-4 gated as EBU R128), its \
     loudness range (LU) and true peak (dBTP, 4× oversampled); a clip's strongest drive as \
     the file carries it (100 % = the motor's full drive; `--haptic-peak` sets it), and so \
     a waveform's haptic channel (`dualsense`'s actuators, `android-ogg`'s haptic channel, \
     decoded), its largest sample.",
];

/// The columns an actuator profile adds.
const DEVICE_NOTES: &[&str] = &[
    "**delivered c − model c**: the c the device's response makes of each audible unit, less \
     the model's: the signed mean (below 0, the device plays the liquid thinner), then the \
     unsigned worst; uncompensated = driven as the model says, compensated = with the \
     profile's gains.",
    "**model c, as carried**: a clip carries c as a parameter the platform plays on its own \
     actuator (a sharpness, a frequency, a motors' balance); it carries the model's c, not \
     compensated, as the platform maps it to its own hardware (iOS would compensate a second \
     time). The profile changes only the clip's level.",
];

/// With `--felt`.
const FELT_NOTE: &str = "**with --felt**: the compensation equalises the level above the \
     skin's threshold, while both c columns measure the shaking the device delivers \
     (acceleration), not what is felt: the compensated column departs from the model's c by \
     design.";
