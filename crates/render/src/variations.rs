//! Sets of takes of one scene (`--variations`, MODEL.md §10.2): each take draws its seed and
//! every value the scene's `[variations]` table gives a range for, from one master seed; a
//! manifest (`NAME.variations.csv` and `.json`) lists what each take drew, and one of its rows
//! ([`Take`]) applied to the scene renders that take again, bit for bit.
//!
//! What may vary is a table ([`Varied::ALL`]): the tilt the scene's tilt lane ends at and the
//! time it gets there, each control but the tilt (a constant through the take), and each model
//! constant, by the keys and within the ranges of their own tables.

use std::collections::BTreeMap;
use std::path::Path;

use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use serde_json::value::RawValue;

use super::automation::Automation;
use super::loudness::{check_loudness, check_true_peak, HapticPeak, Loudness};
use super::scene::variations_table::known_keys;
pub use super::scene::variations_table::{
    VariationError, VariationSpec, Varied, COUNT_KEY, MAX_TAKES, VARIATIONS_KEY,
};
use super::scene::Scene;
use super::trim::check_trim_db;
use sake_glug_engine::config;
use sake_glug_io::read::{self, InputKind};
use sake_glug_io::text::printable;

/// The manifest's columns before the drawn values: the take's number, its name, its seed.
pub const TAKE_COLUMN: &str = "take";
/// The column of the take's file name (without extension).
pub const NAME_COLUMN: &str = "name";
/// The column of the take's seed.
pub const SEED_COLUMN: &str = "seed";

/// The manifest's last columns: each take's level, measured on the samples its files were
/// written from, after any level stage (MODEL.md §19). What a take measured, not what it
/// draws: a row read back ignores them, and a manifest written before them reads as well.
pub const MEASURED_COLUMNS: [MeasuredColumn; 2] = [
    ("loudness_lufs", |loudness| loudness.integrated_lufs),
    ("true_peak_dbtp", |loudness| loudness.true_peak_dbtp),
];

/// A measured column: its name, and the figure it takes of a take's [`Loudness`].
pub type MeasuredColumn = (&'static str, fn(&Loudness) -> f64);

/// Whether `column` is one of [`MEASURED_COLUMNS`].
pub fn is_measured_column(column: &str) -> bool {
    MEASURED_COLUMNS.iter().any(|&(name, _)| name == column)
}

/// The options a set was rendered with that change its takes' samples beyond the scene and each
/// take's draws (MODEL.md §10.2): recorded in every row of its manifest (empty where not
/// given), and applied to a take rendered again from its row.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TakeOptions {
    /// `--trim`'s level (dB re the file's peak).
    pub trim_db: Option<f64>,
    /// `--loudness` (LUFS).
    pub loudness_lufs: Option<f64>,
    /// `--true-peak` (dBTP).
    pub true_peak_dbtp: Option<f64>,
    /// `--haptic-peak`, as its level (above 0, at most 1).
    pub haptic_peak: Option<f64>,
}

/// A recorded option: its manifest column, the command line's option that sets it, its field
/// of [`TakeOptions`], and its check (the option's own).
pub type OptionColumn = (
    &'static str,
    &'static str,
    fn(&mut TakeOptions) -> &mut Option<f64>,
    fn(f64) -> Result<f64, String>,
);

/// The options a manifest records, each a column, between the drawn values and
/// [`MEASURED_COLUMNS`].
pub const OPTION_COLUMNS: [OptionColumn; 4] = [
    (
        "trim_db",
        "--trim",
        |options| &mut options.trim_db,
        |db| check_trim_db(db).map_err(|error| error.to_string()),
    ),
    (
        "loudness_target_lufs",
        "--loudness",
        |options| &mut options.loudness_lufs,
        check_loudness,
    ),
    (
        "true_peak_ceiling_dbtp",
        "--true-peak",
        |options| &mut options.true_peak_dbtp,
        check_true_peak,
    ),
    (
        "haptic_peak",
        "--haptic-peak",
        |options| &mut options.haptic_peak,
        |level| HapticPeak::of_level(level).map(HapticPeak::level),
    ),
];

impl TakeOptions {
    /// The options a take rendered again from its row is rendered with: the row's (`recorded`;
    /// `None` for a manifest written before they were recorded, which leaves `typed` as given).
    /// An option typed that differs from the row's is refused, naming both: the take would not
    /// be the set's.
    pub fn resolve(
        mut typed: TakeOptions,
        recorded: Option<TakeOptions>,
    ) -> Result<TakeOptions, VariationError> {
        let Some(mut recorded) = recorded else {
            return Ok(typed);
        };
        for (_, option, field, _) in OPTION_COLUMNS {
            let (now, then) = (*field(&mut typed), *field(&mut recorded));
            if let Some(now) = now.filter(|&now| Some(now) != then) {
                let set = match then {
                    Some(then) => format!("with {option} {then}"),
                    None => format!("without {option}"),
                };
                return Err(VariationError::Row(format!(
                    "{option} {now}: the set's takes were rendered {set}, which its manifest \
                     records; leave {option} out to render the take as the set did"
                )));
            }
        }
        Ok(recorded)
    }
}

/// A cell of a manifest's row.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// An option not given: empty in the CSV, `null` in the JSON, `None` in Python.
    Empty,
    /// A whole number (the take's number, its seed).
    Whole(u64),
    /// Text (the take's name).
    Text(String),
    /// A number, written as the shortest text that reads back as the same f64 (−∞ for a silent
    /// take's loudness: `-inf` in the CSV, `null` in the JSON, which has no infinity).
    Number(f64),
}

impl Cell {
    fn csv(&self) -> String {
        match self {
            Cell::Empty => String::new(),
            Cell::Whole(value) => value.to_string(),
            Cell::Text(text) => text.clone(),
            Cell::Number(value) => value.to_string(),
        }
    }

    fn json(&self) -> serde_json::Value {
        match self {
            Cell::Empty => serde_json::Value::Null,
            Cell::Whole(value) => (*value).into(),
            Cell::Text(text) => text.as_str().into(),
            // serde_json writes a non-finite number as null.
            Cell::Number(value) => (*value).into(),
        }
    }
}

/// A take's row of its set's manifest, column by column: the one list both manifests (the
/// CSV's header and cells, the JSON's keys and values) and Python's rows are written from.
/// `take`, `name`, `seed`, each drawn value by its key, the set's [`OPTION_COLUMNS`] of
/// `options`, then [`MEASURED_COLUMNS`] of `measured`.
pub fn manifest_row(
    take: &Take,
    set_name: &str,
    count: u32,
    options: &TakeOptions,
    measured: &Loudness,
) -> Vec<(&'static str, Cell)> {
    let mut row = vec![
        (TAKE_COLUMN, Cell::Whole(take.number.into())),
        (NAME_COLUMN, Cell::Text(take.name(set_name, count))),
        (SEED_COLUMN, Cell::Whole(take.seed)),
    ];
    row.extend(
        take.values
            .iter()
            .map(|&(varied, value)| (varied.key(), Cell::Number(value))),
    );
    let mut options = *options;
    row.extend(OPTION_COLUMNS.iter().map(|&(column, _, field, _)| {
        (
            column,
            field(&mut options).map_or(Cell::Empty, Cell::Number),
        )
    }));
    row.extend(
        MEASURED_COLUMNS
            .iter()
            .map(|&(column, of)| (column, Cell::Number(of(measured)))),
    );
    row
}

impl Varied {
    /// Sets `value` in `scene`; refused, naming the key, where the scene cannot take it.
    fn apply(self, scene: &mut Scene, value: f64) -> Result<(), VariationError> {
        let key = self.key();
        self.range().check(key, value)?;
        let tilt = &mut scene.lanes.tilt_deg;
        match self {
            Varied::TiltEnd => match tilt {
                Automation::Constant(end) => *end = value,
                Automation::Points(points) => {
                    if let Some(last) = points.last_mut() {
                        last.1 = value;
                    }
                }
            },
            Varied::RampTime => {
                let end_s = tilt.last_time_s();
                let Automation::Points(points) = tilt else {
                    return Err(VariationError::NoRamp { key });
                };
                if end_s <= 0.0 {
                    return Err(VariationError::NoRamp { key });
                }
                for point in points.iter_mut() {
                    point.0 *= value / end_s;
                }
            }
            Varied::Control(control) => scene.lanes[control] = Automation::Constant(value),
            Varied::Constant(constant) => {
                constant.set(&mut scene.config, value);
                scene.config.check_silent_below()?;
            }
        }
        Ok(())
    }
}

/// One take of a set: its number (from 1), its seed and what it drew. A manifest's row, and
/// all that is needed, with the scene, to render the take again.
#[derive(Debug, Clone, PartialEq)]
pub struct Take {
    /// Its number in the set, from 1 (its file's suffix).
    pub number: u32,
    /// The seed of its random draws (MODEL.md §7).
    pub seed: u64,
    /// Each drawn value, in [`Varied::all`]'s order.
    pub values: Vec<(Varied, f64)>,
    /// The set's options as its row records them; `None` for a take drawn now, or read from a
    /// manifest written before they were recorded.
    pub recorded: Option<TakeOptions>,
}

impl Take {
    /// `scene` as this take plays it: its seed and every drawn value set, each checked as a
    /// scene's; the scene's own `[variations]` table is dropped (a take is one render).
    pub fn apply(&self, mut scene: Scene) -> Result<Scene, VariationError> {
        scene.config.seed = self.seed;
        for &(varied, value) in &self.values {
            varied.apply(&mut scene, value)?;
        }
        scene.variations = None;
        Ok(scene)
    }

    /// The name of its files: the set's name and its number, `NAME_07`, at least two digits.
    pub fn name(&self, set_name: &str, count: u32) -> String {
        let width = count.to_string().len().max(2);
        format!("{set_name}_{:0width$}", self.number)
    }

    /// A take from a row's fields (column name, text): `seed`, the varied keys and the
    /// [`OPTION_COLUMNS`] (empty for an option not given; each checked as its option); `take`,
    /// `name` and the [`MEASURED_COLUMNS`] are the row's own and change nothing. Unknown columns
    /// and unreadable numbers are refused by name.
    pub fn from_fields<'a>(
        number: u32,
        fields: impl IntoIterator<Item = (&'a str, &'a str)>,
    ) -> Result<Self, VariationError> {
        let mut seed = None;
        let mut values = Vec::new();
        let mut recorded: Option<TakeOptions> = None;
        for (column, text) in fields {
            let text = text.trim();
            if let Some(&(_, option, field, check)) =
                OPTION_COLUMNS.iter().find(|(name, ..)| *name == column)
            {
                let options = recorded.get_or_insert_default();
                if !text.is_empty() && text != "null" {
                    let value = text
                        .parse::<f64>()
                        .map_err(|_| "not a number".to_owned())
                        .and_then(check)
                        .map_err(|why| {
                            VariationError::Row(format!(
                                "`{column}` = {} ({option}): {why}",
                                printable(text)
                            ))
                        })?;
                    *field(options) = Some(value);
                }
                continue;
            }
            match column {
                TAKE_COLUMN | NAME_COLUMN => {}
                column if is_measured_column(column) => {}
                SEED_COLUMN => {
                    seed = Some(text.parse::<u64>().map_err(|_| {
                        VariationError::Row(format!(
                            "`seed` = {}: not a whole number from 0 to {}",
                            printable(text),
                            u64::MAX
                        ))
                    })?)
                }
                column => {
                    let varied = Varied::of_key(column).ok_or_else(|| {
                        VariationError::Row(format!(
                            "unknown column `{}` in a take's row: use `seed` and {}",
                            printable(column),
                            known_keys()
                        ))
                    })?;
                    let value = text.parse::<f64>().map_err(|_| {
                        VariationError::Row(format!(
                            "`{column}` = {}: not a number",
                            printable(text)
                        ))
                    })?;
                    values.push((varied, value));
                }
            }
        }
        let seed =
            seed.ok_or_else(|| VariationError::Row("a take's row needs its `seed`".into()))?;
        values.sort_by_key(|(varied, _)| Varied::all().position(|other| other == *varied));
        Ok(Self {
            number,
            seed,
            values,
            recorded,
        })
    }
}

/// The name of a set whose first file is `path`: its file name up to the first dot
/// (`pour.wav` and `pour.units.csv` are of the set `pour`).
pub fn set_name_of(path: &Path) -> String {
    let file_name = path
        .file_name()
        .map_or(String::new(), |name| name.to_string_lossy().into_owned());
    let (stem, _) = split_at_first_dot(&file_name);
    stem.to_owned()
}

/// The file of a take beside `path`: the take's number after the set's name, before the
/// extensions (`pour.units.csv` → `pour_07.units.csv`).
pub fn take_path(path: &Path, take_name: &str) -> std::path::PathBuf {
    let file_name = path
        .file_name()
        .map_or(String::new(), |name| name.to_string_lossy().into_owned());
    let (_, extensions) = split_at_first_dot(&file_name);
    path.with_file_name(format!("{take_name}{extensions}"))
}

/// A file name cut before its first dot (a leading dot is part of the name).
fn split_at_first_dot(file_name: &str) -> (&str, &str) {
    match file_name.char_indices().skip(1).find(|&(_, c)| c == '.') {
        Some((index, _)) => file_name.split_at(index),
        None => (file_name, ""),
    }
}

/// The manifests of a set named `set_name` in `folder`: `NAME.variations.csv` and `.json`.
pub fn manifest_paths(folder: &Path, set_name: &str) -> [std::path::PathBuf; 2] {
    ["csv", "json"].map(|extension| folder.join(format!("{set_name}.variations.{extension}")))
}

/// `count` takes drawn from `master_seed`: take k's seed, then each of `ranges` in order,
/// uniform in [low, high]; the first takes of a larger set are the takes of a smaller one. A
/// seed lies within the range of the plugin's Seed parameter, so a take plays there too.
pub fn draw_takes(ranges: &[(Varied, [f64; 2])], count: u32, master_seed: u64) -> Vec<Take> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(master_seed);
    let seeds = config::SEED.range;
    (1..=count)
        .map(|number| {
            let seed = rng.random_range(seeds.min as u64..=seeds.max as u64);
            let values = ranges
                .iter()
                .map(|&(varied, [low, high])| {
                    let value = if low == high {
                        low
                    } else {
                        rng.random_range(low..=high)
                    };
                    (varied, value)
                })
                .collect();
            Take {
                number,
                seed,
                values,
                recorded: None,
            }
        })
        .collect()
}

/// The manifest of a set as CSV: a header ([`manifest_row`]'s columns) and a row per take,
/// each take with what it measured.
pub fn manifest_csv(set_name: &str, options: &TakeOptions, takes: &[(Take, Loudness)]) -> String {
    let count = takes.len() as u32;
    let rows: Vec<_> = takes
        .iter()
        .map(|(take, measured)| manifest_row(take, set_name, count, options, measured))
        .collect();
    let Some(first) = rows.first() else {
        return [TAKE_COLUMN, NAME_COLUMN, SEED_COLUMN].join(",") + "\n";
    };
    let header: Vec<&str> = first.iter().map(|&(column, _)| column).collect();
    let mut text = header.join(",") + "\n";
    for row in &rows {
        let cells: Vec<String> = row.iter().map(|(_, cell)| cell.csv()).collect();
        text += &(cells.join(",") + "\n");
    }
    text
}

/// The manifest of a set as JSON: the set's name, scene, master seed and ranges, and its takes,
/// each an object of the CSV row's columns.
pub fn manifest_json(
    set_name: &str,
    scene_file: Option<&Path>,
    master_seed: u64,
    ranges: &[(Varied, [f64; 2])],
    options: &TakeOptions,
    takes: &[(Take, Loudness)],
) -> String {
    let count = takes.len() as u32;
    let rows: Vec<serde_json::Value> = takes
        .iter()
        .map(|(take, measured)| {
            let row = manifest_row(take, set_name, count, options, measured)
                .into_iter()
                .map(|(column, cell)| (column.to_owned(), cell.json()))
                .collect();
            serde_json::Value::Object(row)
        })
        .collect();
    let ranges: serde_json::Map<String, serde_json::Value> = ranges
        .iter()
        .map(|&(varied, range)| (varied.key().to_owned(), serde_json::json!(range)))
        .collect();
    let manifest = serde_json::json!({
        "name": set_name,
        "scene": scene_file.map(|path| path.display().to_string()),
        "master_seed": master_seed,
        "count": count,
        "ranges": ranges,
        "takes": rows,
    });
    serde_json::to_string_pretty(&manifest).expect("a JSON value is written") + "\n"
}

/// Take `number` of the manifest at `path` (`.json`, else CSV), read as the renderer reads any
/// input file.
pub fn read_take(path: &Path, number: u32) -> Result<Take, VariationError> {
    let text = read::read_text(path, InputKind::VARIATIONS)?;
    let in_file = |message: String| {
        VariationError::Row(format!(
            "{}: {message}",
            printable(&path.display().to_string())
        ))
    };
    let is_json = path
        .extension()
        .is_some_and(|extension| extension.eq_ignore_ascii_case("json"));
    let take = if is_json {
        take_from_json(&text, number)
    } else {
        take_from_csv(&text, number)
    };
    take.map_err(|error| match error {
        VariationError::Row(message) => in_file(message),
        other => other,
    })
}

fn take_from_csv(text: &str, number: u32) -> Result<Take, VariationError> {
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let header = reader
        .headers()
        .map_err(|error| VariationError::Row(error.to_string()))?
        .clone();
    let take_index = header.iter().position(|column| column == TAKE_COLUMN);
    for (index, record) in reader.records().enumerate() {
        let record = record.map_err(|error| VariationError::Row(error.to_string()))?;
        let row_number = match take_index.and_then(|column| record.get(column)) {
            Some(text) => text.parse::<u32>().ok(),
            None => Some(index as u32 + 1),
        };
        if row_number == Some(number) {
            return Take::from_fields(number, header.iter().zip(record.iter()));
        }
    }
    Err(VariationError::Row(format!("no take {number} in it")))
}

fn take_from_json(text: &str, number: u32) -> Result<Take, VariationError> {
    // Each value is kept as the text the manifest holds and parsed as the CSV's are
    // (`str::parse`, correctly rounded), so a row reads back bit for bit without serde_json's
    // `float_roundtrip`, a feature that would change how every crate of a build parses floats.
    type Row = BTreeMap<String, Box<RawValue>>;
    let bad = |error: serde_json::Error| VariationError::Row(error.to_string());
    let manifest: BTreeMap<String, Box<RawValue>> = serde_json::from_str(text).map_err(bad)?;
    let takes = manifest
        .get("takes")
        .ok_or_else(|| VariationError::Row("no `takes` list in it".into()))?;
    let rows: Vec<Row> = serde_json::from_str(takes.get())
        .map_err(|_| VariationError::Row("its `takes` is not a list of rows".into()))?;
    let row = rows
        .iter()
        .find(|row| {
            row.get(TAKE_COLUMN)
                .and_then(|value| value.get().parse::<u64>().ok())
                == Some(number as u64)
        })
        .ok_or_else(|| VariationError::Row(format!("no take {number} in it")))?;
    let mut fields = Vec::with_capacity(row.len());
    for (column, value) in row {
        let raw = value.get();
        let text = if raw.starts_with('"') {
            serde_json::from_str::<String>(raw).map_err(bad)?
        } else {
            raw.to_owned()
        };
        fields.push((column.clone(), text));
    }
    Take::from_fields(
        number,
        fields
            .iter()
            .map(|(column, text)| (column.as_str(), text.as_str())),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(text: &str) -> Result<VariationSpec, VariationError> {
        VariationSpec::from_table(toml::from_str(text).unwrap())
    }

    #[test]
    fn ranges_are_read_by_their_tables_keys() {
        let spec = spec("count = 3\nfill_percent = [60, 100]\ntilt_end_deg = [120, 150]\nglug.f1_hz = [70.0, 90.0]\n")
            .unwrap();
        assert_eq!(spec.count, Some(3));
        let keys: Vec<&str> = spec.ranges.iter().map(|(varied, _)| varied.key()).collect();
        assert_eq!(keys, ["tilt_end_deg", "fill_percent", "glug.f1_hz"]);
    }

    #[test]
    fn a_row_written_reads_back_as_the_same_take() {
        let ranges = spec("ramp_s = [0.2, 0.9]\nviscosity_c = [0.1, 0.6]\n")
            .unwrap()
            .ranges;
        let takes = draw_takes(&ranges, 12, 99);
        let measured = Loudness {
            integrated_lufs: -23.5,
            range_lu: 4.0,
            true_peak_dbtp: -1.25,
            duration_s: 5.0,
        };
        let rows: Vec<(Take, Loudness)> =
            takes.iter().map(|take| (take.clone(), measured)).collect();
        let options = TakeOptions {
            trim_db: Some(-40.0),
            true_peak_dbtp: Some(-1.0),
            haptic_peak: Some(10f64.powf(-3.0 / 20.0)),
            ..TakeOptions::default()
        };
        let csv = manifest_csv("pour", &options, &rows);
        let json = manifest_json("pour", None, 99, &ranges, &options, &rows);
        for take in &takes {
            let read = Take {
                recorded: Some(options),
                ..take.clone()
            };
            assert_eq!(take_from_csv(&csv, take.number).unwrap(), read);
            assert_eq!(take_from_json(&json, take.number).unwrap(), read);
        }
        assert_eq!(takes[6].name("pour", 12), "pour_07");
    }
}
