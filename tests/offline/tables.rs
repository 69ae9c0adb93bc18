//! The glug data of a render (MODEL.md §14): the units table against the engine's own onsets
//! and the f64 reference, the state table against the engine's pour sample by sample, their
//! headers and row counts, the sample CSV's time column, and the tables in batches and on the
//! command line.

use std::fs;
use std::path::Path;

use sake_glug_engine::synthesis::reference;
use sake_glug_engine::{Pour, UnitOnset, Voicing};
use sake_glug_render::{
    csv_header, render_scene, render_tables, render_to_files, Output, OutputFormat, OutputOptions,
    RenderError, RenderObserver, Scene, StateRate, StateRow, UnitRow,
};

use crate::command::{files_in, sake_glug};
use crate::support::BUSY_SCENE;

const UNITS_HEADER: &str = "onset_s,tilt_deg,volume_ml,pocket_ml,viscosity_c,f1_hz,f2_hz,\
                            b1_per_s,b2_per_s,a1,a2,audible";
const STATE_HEADER: &str = "time_s,tilt_deg,volume_ml,outflow_ml_per_s,submerged,amplitude";

/// A pour down to the last of the liquid (below the amplitude law's zero), with the default gain.
const TO_THE_DREGS: &str = r#"
seed = 5
duration_s = 7.0
tilt_deg = [[0.0, 80.0], [0.8, 150.0]]
viscosity_c = [[0.0, 0.2], [6.0, 0.7]]
"#;

/// Every unit the engine starts, watched through the renderer's own observer.
fn engine_units(scene: &Scene) -> Vec<(UnitOnset, Voicing)> {
    struct Units(Vec<(UnitOnset, Voicing)>);
    impl RenderObserver for Units {
        fn unit_started(&mut self, onset: &UnitOnset, voicing: Voicing) {
            self.0.push((*onset, voicing));
        }
    }
    let mut units = Units(Vec::new());
    render_scene(scene, |_| Ok::<(), RenderError>(()), &mut units).unwrap();
    units.0
}

/// A CSV table: its header and its rows of numbers.
fn read_table(path: &Path) -> (String, Vec<Vec<f64>>) {
    let text = fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let head = lines.next().unwrap().to_owned();
    let rows = lines
        .map(|line| line.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (head, rows)
}

fn values<R>(columns: &[sake_glug_render::Column<R>], row: &R) -> Vec<f64> {
    columns.iter().map(|column| (column.value)(row)).collect()
}

fn bits(values: &[f64]) -> Vec<u64> {
    values.iter().map(|v| v.to_bits()).collect()
}

/// Writes the units and state tables of `scene` with `render_to_files`.
fn write_tables(scene: &Scene, directory: &Path, options: &OutputOptions) {
    let outputs = [
        Output {
            format: OutputFormat::UNITS,
            path: directory.join("units.csv"),
        },
        Output {
            format: OutputFormat::STATE,
            path: directory.join("state.csv"),
        },
    ];
    render_to_files(scene, "scene", &outputs, options, |_| {}).unwrap();
}

#[test]
fn the_units_table_is_the_engines_onsets_row_for_row() {
    for text in [BUSY_SCENE, TO_THE_DREGS] {
        let scene = Scene::parse(text).unwrap();
        let fs = scene.sample_rate as f64;
        let expected: Vec<UnitRow> = engine_units(&scene)
            .iter()
            .map(|(onset, voicing)| UnitRow::of(onset, *voicing, fs))
            .collect();
        let tables = render_tables(&scene, StateRate::default()).unwrap();
        assert_eq!(tables.units, expected);
        assert_eq!(tables.units.len() as u64, tables.summary.units);

        let directory = tempfile::tempdir().unwrap();
        write_tables(&scene, directory.path(), &OutputOptions::default());
        let (head, rows) = read_table(&directory.path().join("units.csv"));
        assert_eq!(head, UNITS_HEADER);
        assert_eq!(rows.len(), expected.len());
        for (row, unit) in rows.iter().zip(&expected) {
            // Shortest round-trip text: every value reads back bit for bit.
            assert_eq!(bits(row), bits(&values(UnitRow::COLUMNS, unit)));
        }
        for (unit, (onset, voicing)) in expected.iter().zip(engine_units(&scene)) {
            let [a1, a2] = onset.component_amplitudes();
            assert_eq!(unit.a1, voicing.output_gain * a1);
            assert_eq!(unit.a2, voicing.output_gain * a2);
            assert_eq!(
                (unit.tilt_deg, unit.pocket_ml),
                (onset.tilt_deg, onset.pocket_ml)
            );
        }
    }
}

#[test]
fn a_unit_is_inaudible_below_the_amplitude_laws_zero_and_when_given_up() {
    let scene = Scene::parse(TO_THE_DREGS).unwrap();
    let units = render_tables(&scene, StateRate::default()).unwrap().units;
    let silent_below_ml = 84.333_333_333_333_33 * scene.config.capacity_ml / 300.0;
    assert!(units.iter().any(|unit| !unit.audible));
    assert!(units.iter().any(|unit| unit.audible));
    for unit in &units {
        assert_eq!(
            unit.audible,
            unit.volume_ml > silent_below_ml + 1e-9,
            "{unit:?}"
        );
        assert_eq!(unit.audible, unit.a1 + unit.a2 > 0.0, "{unit:?}");
    }
    // Pockets so small that the start budget gives units up (MODEL.md §11): they are in the
    // table, marked inaudible, though their amplitude is not 0.
    let flood = Scene::parse(
        "duration_s = 0.2\ntilt_deg = 135.0\npour_time_s = 0.01\n[bottle]\npocket_ml = 0.01\n",
    )
    .unwrap();
    let units = render_tables(&flood, StateRate::default()).unwrap().units;
    let given_up = units
        .iter()
        .filter(|unit| !unit.audible && unit.a1 + unit.a2 > 0.0)
        .count();
    assert!(given_up > 0, "{} units, none given up", units.len());
}

#[test]
fn the_units_table_agrees_with_the_f64_reference() {
    for text in [
        TO_THE_DREGS,
        "seed = 3\ntilt_deg = 135.0\n[amplitude]\nsilent_below_ml = 30.0\n",
    ] {
        let scene = Scene::parse(text).unwrap();
        let tables = render_tables(&scene, StateRate::default()).unwrap();
        let window = reference::evaluate(
            scene.sample_rate as f64,
            scene.config,
            &scene,
            0..tables.summary.samples,
        );
        // The reference voices every glugging unit within the caps, a(V) = 0 or not; the engine's
        // inaudible units here are those of a(V) = 0.
        assert_eq!(window.units.len(), tables.units.len());
        let gain = 10f64.powf(-6.0 / 20.0);
        for (unit, reference) in tables.units.iter().zip(&window.units) {
            assert!((unit.onset_s - reference.onset_s).abs() < 1e-12, "{unit:?}");
            assert!(
                (unit.volume_ml - reference.volume_ml).abs() < 1e-9,
                "{unit:?} {reference:?}"
            );
            for (table, reference) in [unit.a1, unit.a2].iter().zip(reference.amplitudes) {
                assert!(
                    (table - gain * reference).abs() < 1e-12,
                    "{unit:?} {reference}"
                );
            }
            assert_eq!(unit.audible, reference.amplitudes.iter().sum::<f64>() > 0.0);
        }
    }
}

/// The row samples of a table at `rate` rows per second over `samples` samples at `fs`.
fn row_samples(rate: f64, fs: f64, samples: u64) -> Vec<u64> {
    (0u64..)
        .map(|k| (k as f64 * fs / rate).ceil() as u64)
        .take_while(|&n| n < samples)
        .collect()
}

#[test]
fn state_rows_are_the_engines_pour_at_their_samples() {
    for (text, rate) in [
        (BUSY_SCENE, 1000.0),
        (TO_THE_DREGS, 441.0),
        (BUSY_SCENE, 48_000.0),
    ] {
        let scene = Scene::parse(text).unwrap();
        let fs = scene.sample_rate as f64;
        let tables = render_tables(&scene, StateRate::new(rate).unwrap()).unwrap();
        let samples = row_samples(rate, fs, tables.summary.samples);
        assert_eq!(tables.states.len(), samples.len());
        // The pour stepped one sample at a time, as the contract words it.
        let mut pour = Pour::new(fs, scene.config);
        pour.reset();
        let mut rows = tables.states.iter().zip(&samples).peekable();
        for n in 0..tables.summary.samples {
            let values = scene.values_at(n);
            let outflow = pour.step(n, values, |_| {});
            let Some((row, _)) = rows.next_if(|&(_, &sample)| sample == n) else {
                continue;
            };
            assert_eq!(row.time_s, n as f64 / fs);
            assert_eq!(row.tilt_deg, values.sanitized().tilt_deg, "sample {n}");
            assert_eq!(row.volume_ml, outflow.volume_before_ml, "sample {n}");
            assert_eq!(row.outflow_ml_per_s, outflow.amount_ml * fs, "sample {n}");
            assert_eq!(row.submerged, outflow.submerged, "sample {n}");
        }
        assert!(rows.next().is_none());
        // At one row a sample, V falls by each sample's outflow (−dV/dt), but where it refills.
        if rate == fs {
            for pair in tables.states.windows(2) {
                let poured = pair[0].volume_ml - pair[1].volume_ml;
                if poured >= 0.0 {
                    assert!(
                        (poured - pair[0].outflow_ml_per_s / fs).abs() < 1e-9,
                        "{pair:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn the_state_amplitude_is_the_gain_times_the_amplitude_law() {
    // The paper's line (MODEL.md §5) at the default gain of −6 dB.
    let scene = Scene::parse(TO_THE_DREGS).unwrap();
    let states = render_tables(&scene, StateRate::default()).unwrap().states;
    let gain = 10f64.powf(-6.0 / 20.0);
    for row in &states {
        let law = (0.0027 * row.volume_ml - 0.2277).max(0.0) / 0.5823;
        assert!((row.amplitude - gain * law).abs() < 1e-12, "{row:?}");
    }
    assert!(states.iter().any(|row| row.amplitude == 0.0));
    assert!(states.iter().any(|row| row.submerged) && states.iter().any(|row| !row.submerged));
}

#[test]
fn the_files_hold_the_same_rows_as_memory_also_past_an_unknown_end() {
    // The default pour has no duration: the render runs on past its end until it sees it.
    for scene in [Scene::default(), Scene::parse(BUSY_SCENE).unwrap()] {
        let tables = render_tables(&scene, StateRate::new(300.0).unwrap()).unwrap();
        let directory = tempfile::tempdir().unwrap();
        let options = OutputOptions {
            state_rate: StateRate::new(300.0).unwrap(),
            ..OutputOptions::default()
        };
        write_tables(&scene, directory.path(), &options);
        let (head, rows) = read_table(&directory.path().join("state.csv"));
        assert_eq!(head, STATE_HEADER);
        let fs = scene.sample_rate as f64;
        assert_eq!(
            rows.len(),
            row_samples(300.0, fs, tables.summary.samples).len()
        );
        assert_eq!(rows.len(), tables.states.len());
        for (row, state) in rows.iter().zip(&tables.states) {
            assert_eq!(bits(row), bits(&values(StateRow::COLUMNS, state)));
        }
    }
}

#[test]
fn headers_are_derived_from_the_columns() {
    assert_eq!(csv_header(UnitRow::COLUMNS), UNITS_HEADER);
    assert_eq!(csv_header(StateRow::COLUMNS), STATE_HEADER);
}

#[test]
fn csv_time_adds_a_header_and_the_time_of_each_sample() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    let output = sake_glug(
        dir,
        &["render", "-o", "plain.csv", "--sample-rate", "44100"],
    );
    assert!(output.status.success());
    let output = sake_glug(
        dir,
        &[
            "render",
            "-o",
            "timed.csv",
            "--csv-time",
            "--sample-rate",
            "44100",
        ],
    );
    assert!(output.status.success());
    let plain = fs::read_to_string(dir.join("plain.csv")).unwrap();
    let timed = fs::read_to_string(dir.join("timed.csv")).unwrap();
    let mut timed = timed.lines();
    assert_eq!(timed.next(), Some("time_s,sample"));
    let mut count = 0;
    for (n, (line, sample)) in timed.zip(plain.lines()).enumerate() {
        let (time, value) = line.split_once(',').unwrap();
        assert_eq!(value, sample);
        assert_eq!(time.parse::<f64>().unwrap(), n as f64 / 44_100.0);
        count += 1;
    }
    assert_eq!(count, plain.lines().count());
}

#[test]
fn a_batch_writes_the_tables_beside_the_samples() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    fs::write(dir.join("a.toml"), TO_THE_DREGS).unwrap();
    fs::write(dir.join("b.toml"), BUSY_SCENE).unwrap();
    let args = [
        "render",
        "a.toml",
        "b.toml",
        "--out-dir",
        "out",
        "--formats",
        "wav,csv,units,state",
    ];
    let output = sake_glug(dir, &args);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let names = [
        "a.csv",
        "a.state.csv",
        "a.units.csv",
        "a.wav",
        "b.csv",
        "b.state.csv",
        "b.units.csv",
        "b.wav",
    ];
    assert_eq!(files_in(&dir.join("out")), names);
    // The same tables as one scene's render with --units and --state.
    let output = sake_glug(
        dir,
        &[
            "render", "a.toml", "-o", "a.wav", "--units", "u.csv", "--state", "s.csv",
        ],
    );
    assert!(output.status.success());
    for (batch, single) in [("out/a.units.csv", "u.csv"), ("out/a.state.csv", "s.csv")] {
        assert_eq!(
            fs::read(dir.join(batch)).unwrap(),
            fs::read(dir.join(single)).unwrap()
        );
    }
    assert_eq!(
        fs::read(dir.join("out/a.wav")).unwrap(),
        fs::read(dir.join("a.wav")).unwrap()
    );
}

#[test]
fn a_bad_state_rate_is_refused_by_name() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    for rate in ["0", "-1", "nan", "inf", "fast"] {
        let output = sake_glug(dir, &["render", "--state", "s.csv", "--state-rate", rate]);
        assert_eq!(output.status.code(), Some(2), "{rate}");
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains("--state-rate"), "{rate}: {stderr}");
    }
    let output = sake_glug(
        dir,
        &[
            "render",
            "--state",
            "s.csv",
            "--state-rate",
            "48000",
            "--sample-rate",
            "44100",
        ],
    );
    assert_eq!(output.status.code(), Some(2));
    // Above the scene's own sample rate: the scene fails, and no file of it is written.
    let output = sake_glug(
        dir,
        &[
            "render",
            "-o",
            "p.wav",
            "--state",
            "s.csv",
            "--state-rate",
            "96000",
        ],
    );
    assert_eq!(output.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("state rate 96000 Hz") && stderr.contains("48000 Hz"),
        "{stderr}"
    );
    assert!(files_in(dir).is_empty(), "{:?}", files_in(dir));
}

#[test]
fn the_tables_are_written_all_or_nothing_with_the_other_files() {
    let directory = tempfile::tempdir().unwrap();
    let dir = directory.path();
    fs::write(dir.join("keep.wav"), "old").unwrap();
    fs::write(dir.join("units.csv"), "old").unwrap();
    fs::create_dir(dir.join("isdir.csv")).unwrap();
    let output = sake_glug(
        dir,
        &[
            "render",
            "-o",
            "keep.wav",
            "--units",
            "units.csv",
            "--state",
            "isdir.csv",
        ],
    );
    assert_eq!(output.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("isdir.csv"), "{stderr}");
    assert_eq!(fs::read_to_string(dir.join("keep.wav")).unwrap(), "old");
    assert_eq!(fs::read_to_string(dir.join("units.csv")).unwrap(), "old");
    assert_eq!(files_in(dir), ["isdir.csv", "keep.wav", "units.csv"]);
}
