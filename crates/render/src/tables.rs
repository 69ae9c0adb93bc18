//! The glug data of a render as tables (MODEL.md §14): one row per unit ([`UnitRow`]) and the
//! bottle's state at a fixed rate ([`StateRow`]), each with its columns declared once
//! ([`UnitRow::COLUMNS`], [`StateRow::COLUMNS`]), the CSV header derived from them. The `units`
//! and `state` sinks write them from a render's single pass; [`render_tables`] collects them in
//! memory for another front end.

use std::fmt::Write as _;

use super::render::{render_scene, BottleReport, RenderError, RenderObserver, RenderSummary};
use super::scene::Scene;
use sake_glug_engine::{ModelConfig, UnitOnset, Voicing};

/// One column of a table: its name in the header, and how a row gives its value. Every value
/// is a number (a flag is 1 or 0), written as the shortest text that reads back as the same
/// f64.
pub struct Column<R> {
    /// The column's name.
    pub name: &'static str,
    /// Its value in a row.
    pub value: fn(&R) -> f64,
}

/// The header line of a table (without its line end): the columns' names, comma-separated.
pub fn csv_header<R>(columns: &[Column<R>]) -> String {
    columns
        .iter()
        .map(|column| column.name)
        .collect::<Vec<_>>()
        .join(",")
}

/// Appends `row` to `line` as a CSV line (with its line end).
pub(crate) fn write_row<R>(columns: &[Column<R>], row: &R, line: &mut String) {
    for (index, column) in columns.iter().enumerate() {
        let separator = if index == 0 { "" } else { "," };
        write!(line, "{separator}{}", (column.value)(row))
            .expect("writing to a String cannot fail");
    }
    line.push('\n');
}

fn flag(value: bool) -> f64 {
    if value {
        1.0
    } else {
        0.0
    }
}

/// One glug unit as the engine started it (MODEL.md §4, §5, §14).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UnitRow {
    /// t_i = (n + x) / fs (s).
    pub onset_s: f64,
    /// θ of the onset's sample (°).
    pub tilt_deg: f64,
    /// V_i (ml).
    pub volume_ml: f64,
    /// b_i (ml).
    pub pocket_ml: f64,
    /// c_i.
    pub viscosity_c: f64,
    /// f1_i (Hz).
    pub f1_hz: f64,
    /// f2_i (Hz).
    pub f2_hz: f64,
    /// B1_i (1/s).
    pub b1_per_s: f64,
    /// B2_i (1/s).
    pub b2_per_s: f64,
    /// A1 in output units: G·Asum_i·c_i.
    pub a1: f64,
    /// A2 in output units: G·Asum_i·(1 − c_i).
    pub a2: f64,
    /// Whether any of its components sounds ([`Voicing::audible`]).
    pub audible: bool,
}

impl UnitRow {
    /// The columns of a units table, in order.
    pub const COLUMNS: &'static [Column<Self>] = &[
        Column {
            name: "onset_s",
            value: |row| row.onset_s,
        },
        Column {
            name: "tilt_deg",
            value: |row| row.tilt_deg,
        },
        Column {
            name: "volume_ml",
            value: |row| row.volume_ml,
        },
        Column {
            name: "pocket_ml",
            value: |row| row.pocket_ml,
        },
        Column {
            name: "viscosity_c",
            value: |row| row.viscosity_c,
        },
        Column {
            name: "f1_hz",
            value: |row| row.f1_hz,
        },
        Column {
            name: "f2_hz",
            value: |row| row.f2_hz,
        },
        Column {
            name: "b1_per_s",
            value: |row| row.b1_per_s,
        },
        Column {
            name: "b2_per_s",
            value: |row| row.b2_per_s,
        },
        Column {
            name: "a1",
            value: |row| row.a1,
        },
        Column {
            name: "a2",
            value: |row| row.a2,
        },
        Column {
            name: "audible",
            value: |row| flag(row.audible),
        },
    ];

    /// The row of a unit that started at `sample_rate` (Hz), voiced as `voicing` says.
    pub fn of(onset: &UnitOnset, voicing: Voicing, sample_rate: f64) -> Self {
        let [a1, a2] = onset.component_amplitudes();
        Self {
            onset_s: (onset.sample as f64 + onset.fraction) / sample_rate,
            tilt_deg: onset.tilt_deg,
            volume_ml: onset.volume_ml,
            pocket_ml: onset.pocket_ml,
            viscosity_c: onset.viscosity,
            f1_hz: onset.shape.frequency_hz[0],
            f2_hz: onset.shape.frequency_hz[1],
            b1_per_s: onset.shape.decay_per_s[0],
            b2_per_s: onset.shape.decay_per_s[1],
            a1: voicing.output_gain * a1,
            a2: voicing.output_gain * a2,
            audible: voicing.audible,
        }
    }
}

/// The bottle at one sample n of the render (MODEL.md §14): the engine's values as it rendered
/// that sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StateRow {
    /// t_n = n / fs (s).
    pub time_s: f64,
    /// θ_n (°).
    pub tilt_deg: f64,
    /// V at the start of the sample (ml).
    pub volume_ml: f64,
    /// The sample's outflow times fs (ml/s).
    pub outflow_ml_per_s: f64,
    /// Whether the mouth was submerged at the start of the sample (V > s(θ_n)·C).
    pub submerged: bool,
    /// G·a(V): the output gain of the sample times the amplitude law at V.
    pub amplitude: f64,
}

impl StateRow {
    /// The columns of a state table, in order.
    pub const COLUMNS: &'static [Column<Self>] = &[
        Column {
            name: "time_s",
            value: |row| row.time_s,
        },
        Column {
            name: "tilt_deg",
            value: |row| row.tilt_deg,
        },
        Column {
            name: "volume_ml",
            value: |row| row.volume_ml,
        },
        Column {
            name: "outflow_ml_per_s",
            value: |row| row.outflow_ml_per_s,
        },
        Column {
            name: "submerged",
            value: |row| flag(row.submerged),
        },
        Column {
            name: "amplitude",
            value: |row| row.amplitude,
        },
    ];
}

/// How many state rows a second of render gets: finite, above 0 and at most the sample rate
/// (a row is one sample). Default 1000.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StateRate(f64);

impl StateRate {
    /// Rows per second unless asked otherwise.
    pub const DEFAULT_HZ: f64 = 1000.0;

    /// A rate of `hz` rows per second, refused unless finite and above 0 (whether it fits a
    /// render's sample rate is checked against each scene).
    pub fn new(hz: f64) -> Result<Self, StateRateError> {
        if hz.is_finite() && hz > 0.0 {
            Ok(Self(hz))
        } else {
            Err(StateRateError::NotPositive { rate_hz: hz })
        }
    }

    /// Rows per second.
    pub fn hz(self) -> f64 {
        self.0
    }
}

impl Default for StateRate {
    fn default() -> Self {
        Self(Self::DEFAULT_HZ)
    }
}

/// Why a state rate cannot be used.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum StateRateError {
    /// Not a finite number above 0.
    #[error("state rate {rate_hz} Hz: it must be a finite number of rows per second above 0")]
    NotPositive {
        /// The rate asked for.
        rate_hz: f64,
    },
    /// Above the render's sample rate: two rows would be the same sample.
    #[error(
        "state rate {rate_hz} Hz: above the sample rate ({sample_rate} Hz); a state row is one \
         sample, so at most {sample_rate} rows per second"
    )]
    AboveSampleRate {
        /// The rate asked for.
        rate_hz: f64,
        /// The render's sample rate.
        sample_rate: u32,
    },
}

/// Why a render's tables could not be made in memory.
#[derive(Debug, thiserror::Error)]
pub enum TablesError {
    /// The state rate does not fit the scene.
    #[error(transparent)]
    StateRate(#[from] StateRateError),
    /// The render itself failed, or was stopped.
    #[error(transparent)]
    Render(#[from] RenderError),
}

/// The samples a state table shows (MODEL.md §14): row k is sample n_k = ⌈k·fs/R⌉, the first
/// sample at or after k/R; it is read from the report the render makes after that sample.
pub(crate) struct StateSchedule {
    sample_rate: f64,
    rate_hz: f64,
    config: ModelConfig,
    /// k of the next row.
    next_row: u64,
    /// n_k of the next row.
    next_sample: u64,
}

impl StateSchedule {
    /// The schedule of `scene` at `rate`, refused if the rate is above its sample rate.
    pub fn new(scene: &Scene, rate: StateRate) -> Result<Self, StateRateError> {
        if rate.hz() > scene.sample_rate as f64 {
            return Err(StateRateError::AboveSampleRate {
                rate_hz: rate.hz(),
                sample_rate: scene.sample_rate,
            });
        }
        Ok(Self {
            sample_rate: scene.sample_rate as f64,
            rate_hz: rate.hz(),
            // As the engine holds it, so that a(V) is the engine's.
            config: scene.config.sanitized(),
            next_row: 0,
            next_sample: 0,
        })
    }

    /// The report wanted next: after the next row's sample.
    pub fn next_report(&self) -> u64 {
        self.next_sample + 1
    }

    /// The row a report gives, with its sample, if it is the one after the next row's sample.
    pub fn row(&mut self, report: &BottleReport) -> Option<(u64, StateRow)> {
        if report.position != self.next_report() {
            return None;
        }
        let sample = self.next_sample;
        let step = report.last_sample;
        let (capacity_ml, silent_below) = (self.config.capacity_ml, self.config.silent_below);
        let row = StateRow {
            time_s: sample as f64 / self.sample_rate,
            tilt_deg: report.tilt_deg,
            volume_ml: step.volume_before_ml,
            outflow_ml_per_s: step.amount_ml * self.sample_rate,
            submerged: step.submerged,
            amplitude: report.output_gain
                * silent_below.amplitude(step.volume_before_ml, capacity_ml),
        };
        self.next_row += 1;
        // At most one row a sample (R ≤ fs), so n_k grows with k.
        self.next_sample = (self.next_row as f64 * self.sample_rate / self.rate_hz).ceil() as u64;
        Some((sample, row))
    }
}

/// A render's samples and its tables, in memory ([`render_tables`]).
#[derive(Debug, Clone)]
pub struct Tables {
    /// The samples, as a WAV or CSV of the render has them.
    pub samples: Vec<f32>,
    /// Every unit that started, in order.
    pub units: Vec<UnitRow>,
    /// The bottle at `state_rate` over the render.
    pub states: Vec<StateRow>,
    /// The render itself.
    pub summary: RenderSummary,
}

/// Renders `scene` once into memory: its samples, its units and its state at `state_rate`, the
/// same rows the `units` and `state` files of the render get.
pub fn render_tables(scene: &Scene, state_rate: StateRate) -> Result<Tables, TablesError> {
    render_tables_until(scene, state_rate, || false)
}

/// [`render_tables`], asking `interrupted` after every block whether to stop (then the render
/// ends with [`super::RenderError::Interrupted`]): for a front end whose user may stop it.
pub fn render_tables_until(
    scene: &Scene,
    state_rate: StateRate,
    interrupted: impl Fn() -> bool,
) -> Result<Tables, TablesError> {
    struct Collector<I> {
        sample_rate: f64,
        schedule: StateSchedule,
        units: Vec<UnitRow>,
        states: Vec<(u64, StateRow)>,
        interrupted: I,
    }
    impl<I: Fn() -> bool> RenderObserver for Collector<I> {
        fn interrupted(&self) -> bool {
            (self.interrupted)()
        }
        fn unit_started(&mut self, onset: &UnitOnset, voicing: Voicing) {
            self.units
                .push(UnitRow::of(onset, voicing, self.sample_rate));
        }
        fn next_bottle_report(&self, _position: u64) -> Option<u64> {
            Some(self.schedule.next_report())
        }
        fn bottle(&mut self, report: &BottleReport) {
            self.states.extend(self.schedule.row(report));
        }
    }
    let mut collector = Collector {
        sample_rate: scene.sample_rate as f64,
        schedule: StateSchedule::new(scene, state_rate)?,
        units: Vec::new(),
        states: Vec::new(),
        interrupted,
    };
    let mut samples = Vec::new();
    let summary = render_scene(
        scene,
        |block: &[f32]| {
            samples.extend_from_slice(block);
            Ok::<(), RenderError>(())
        },
        &mut collector,
    )?;
    // A render without a duration runs on past its end until it sees it.
    let states = collector
        .states
        .into_iter()
        .take_while(|&(sample, _)| sample < summary.samples)
        .map(|(_, row)| row)
        .collect();
    Ok(Tables {
        samples,
        units: collector.units,
        states,
        summary,
    })
}
