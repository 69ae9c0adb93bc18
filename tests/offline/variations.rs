//! Sets of takes (`render --variations`, `--take-from`, `--seed`), trimming (`--trim`) and the
//! warning of a render in which nothing sounds (MODEL.md §10.2), through the command as a user
//! runs it; the draws of a set by simulation over many seeds.

use std::collections::BTreeMap;
use std::path::Path;

use crate::command::{files_in, sake_glug};
use sake_glug_render::loudness::LoudnessMeter;
use sake_glug_render::variations::{draw_takes, VariationSpec, Varied};

/// A scene whose takes draw every kind of value: the tilt's end and ramp, controls, constants.
const SET_SCENE: &str = r#"
tilt_deg = [[0.0, 90.0], [0.5, 135.0]]

[variations]
count = 5
tilt_end_deg = [120, 150]
ramp_s = [0.3, 0.8]
fill_percent = [60, 100]
viscosity_c = [0.2, 0.5]
pour_time_s = [4, 6]
glug.f1_hz = [70, 90]
"#;

fn succeeded(output: &std::process::Output) -> String {
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// Every file of a folder with its bytes.
fn contents(directory: &Path) -> BTreeMap<String, Vec<u8>> {
    files_in(directory)
        .into_iter()
        .map(|name| {
            let bytes = std::fs::read(directory.join(&name)).unwrap();
            (name, bytes)
        })
        .collect()
}

/// Renders the set of [`SET_SCENE`] with `extra` arguments into `out/` of a new folder.
fn render_set(extra: &[&str]) -> tempfile::TempDir {
    let directory = tempfile::tempdir().unwrap();
    std::fs::write(directory.path().join("set.toml"), SET_SCENE).unwrap();
    std::fs::create_dir(directory.path().join("out")).unwrap();
    let mut args = vec![
        "render",
        "set.toml",
        "-o",
        "out/set.wav",
        "-o",
        "out/set.haptic",
        "-o",
        "units:out/set.csv",
    ];
    args.extend(extra);
    succeeded(&sake_glug(directory.path(), &args));
    directory
}

#[test]
fn the_same_command_and_seed_give_the_same_set_byte_for_byte() {
    let first = contents(&render_set(&["--seed", "11", "--trim"]).path().join("out"));
    let names: Vec<&str> = first.keys().map(String::as_str).collect();
    let mut expected = vec!["set.variations.csv", "set.variations.json"];
    let takes: Vec<String> = (1..=5)
        .flat_map(|take| {
            [
                format!("set_0{take}.csv"),
                format!("set_0{take}.haptic"),
                format!("set_0{take}.wav"),
            ]
        })
        .collect();
    expected.extend(takes.iter().map(String::as_str));
    expected.sort_unstable();
    assert_eq!(names, expected);
    let again = contents(&render_set(&["--seed", "11", "--trim"]).path().join("out"));
    assert_eq!(first, again, "the same command and seed, another set");
    // Another master seed draws another set; every take differs from its namesake.
    let other = contents(&render_set(&["--seed", "12", "--trim"]).path().join("out"));
    for take in 1..=5 {
        let name = format!("set_0{take}.wav");
        assert_ne!(first[&name], other[&name], "{name}");
    }
    // The takes differ from each other too.
    assert_ne!(first["set_01.wav"], first["set_02.wav"]);
}

/// Two outputs of one extension stay two files in every take: each keeps its own name, followed
/// by the take's number; the manifests are named after the first.
#[test]
fn each_output_of_a_set_keeps_its_own_name() {
    let directory = tempfile::tempdir().unwrap();
    std::fs::write(directory.path().join("set.toml"), SET_SCENE).unwrap();
    let args = [
        "render",
        "set.toml",
        "--variations",
        "2",
        "-o",
        "pour.wav",
        "-o",
        "dualsense:pad.wav",
    ];
    let stderr = succeeded(&sake_glug(directory.path(), &args));
    let mut names = files_in(directory.path());
    names.sort_unstable();
    assert_eq!(
        names,
        [
            "pad_01.wav",
            "pad_02.wav",
            "pour.variations.csv",
            "pour.variations.json",
            "pour_01.wav",
            "pour_02.wav",
            "set.toml"
        ],
        "{stderr}"
    );
    let pad = hound::WavReader::open(directory.path().join("pad_01.wav")).unwrap();
    assert_eq!(
        pad.spec().channels,
        4,
        "the DualSense file: two audio, two actuator channels"
    );
}

#[test]
fn a_take_renders_again_bit_for_bit_from_its_row_alone() {
    let set = render_set(&["--seed", "5", "--trim"]);
    let out = set.path().join("out");
    let manifest = std::fs::read_to_string(out.join("set.variations.csv")).unwrap();
    let mut lines = manifest.lines();
    let header = lines.next().unwrap();
    assert_eq!(
        header,
        "take,name,seed,tilt_end_deg,ramp_s,viscosity_c,fill_percent,pour_time_s,glug.f1_hz,\
         trim_db,loudness_target_lufs,true_peak_ceiling_dbtp,haptic_peak,loudness_lufs,\
         true_peak_dbtp"
    );
    let row = lines.nth(2).unwrap();
    assert!(row.starts_with("3,set_03,"), "{row}");
    // A manifest of that one row, the others gone: the take comes back from it alone, with no
    // --seed (the row's seed is the take's).
    std::fs::write(set.path().join("one.csv"), format!("{header}\n{row}\n")).unwrap();
    // The manifests as written before each take's options and level were in them: without
    // their columns (a take from them needs its options typed again).
    let without_level = |line: &str| line.rsplitn(7, ',').nth(6).unwrap().to_owned();
    std::fs::write(
        set.path().join("old.csv"),
        format!("{}\n{}\n", without_level(header), without_level(row)),
    )
    .unwrap();
    // Their lines taken out of the text (a value parsed and written again by serde_json may
    // move by an ulp): neither is a row's last key, so what is left is JSON.
    let json = std::fs::read_to_string(out.join("set.variations.json")).unwrap();
    let old_json: String = json
        .lines()
        .filter(|line| {
            ![
                "\"loudness_lufs\"",
                "\"true_peak_dbtp\"",
                "\"trim_db\"",
                "\"loudness_target_lufs\"",
                "\"true_peak_ceiling_dbtp\"",
                "\"haptic_peak\"",
            ]
            .iter()
            .any(|key| line.contains(key))
        })
        .map(|line| format!("{line}\n"))
        .collect();
    let old: serde_json::Value = serde_json::from_str(&old_json).unwrap();
    let old_row = old["takes"][2].as_object().unwrap();
    assert!(!old_row.contains_key("loudness_lufs") && !old_row.contains_key("true_peak_dbtp"));
    assert!(old_row.contains_key("seed"), "{old_json}");
    std::fs::write(set.path().join("old.json"), old_json).unwrap();
    for (manifest, name) in [
        ("one.csv:3", "again"),
        ("out/set.variations.json:3", "json"),
        ("old.csv:3", "old_csv"),
        ("old.json:3", "old_json"),
    ] {
        succeeded(&sake_glug(
            set.path(),
            &[
                "render",
                "set.toml",
                "--trim",
                "--take-from",
                manifest,
                "-o",
                &format!("{name}.wav"),
                "-o",
                &format!("{name}.haptic"),
            ],
        ));
        for extension in ["wav", "haptic"] {
            let take = std::fs::read(out.join(format!("set_03.{extension}"))).unwrap();
            let again = std::fs::read(set.path().join(format!("{name}.{extension}"))).unwrap();
            assert!(take == again, "{manifest}: the .{extension} differs");
        }
    }
    // A take that is not in the manifest is refused by its number.
    let output = sake_glug(
        set.path(),
        &[
            "render",
            "set.toml",
            "--take-from",
            "one.csv:4",
            "-o",
            "x.wav",
        ],
    );
    assert_eq!(output.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&output.stderr).contains("no take 4"));
}

/// A set rendered with `--trim`, `--loudness`, `--true-peak` and `--haptic-peak` could not be
/// remade from its manifest alone: `--take-from` without them gave other files (issue 49). Its
/// rows record them, `--take-from` applies them, and refuses one typed that differs, naming
/// both; a recorded option out of its range is refused by its column.
#[test]
fn a_take_is_remade_with_its_sets_options_from_the_manifest_alone() {
    let set = render_set(&[
        "--seed",
        "6",
        "--trim=-50",
        "--loudness",
        "-20",
        "--true-peak",
        "-2",
        "--haptic-peak",
        "-3dB",
    ]);
    let out = set.path().join("out");
    let again = |manifest: &str, extra: &[&str]| {
        let mut args = vec![
            "render",
            "set.toml",
            "--take-from",
            manifest,
            "-o",
            "again.wav",
            "-o",
            "again.haptic",
        ];
        args.extend(extra);
        sake_glug(set.path(), &args)
    };
    for manifest in ["out/set.variations.csv:2", "out/set.variations.json:2"] {
        // Alone, and with an option typed as the set had it.
        for extra in [&[][..], &["--loudness", "-20"]] {
            succeeded(&again(manifest, extra));
            for extension in ["wav", "haptic"] {
                let take = std::fs::read(out.join(format!("set_02.{extension}"))).unwrap();
                let remade = std::fs::read(set.path().join(format!("again.{extension}"))).unwrap();
                assert!(
                    take == remade,
                    "{manifest} {extra:?}: the .{extension} differs"
                );
            }
        }
    }
    for (extra, said) in [
        (
            &["--loudness", "-16"][..],
            "--loudness -16: the set's takes were rendered with --loudness -20",
        ),
        (
            &["--trim"],
            "--trim -60: the set's takes were rendered with --trim -50",
        ),
    ] {
        let output = again("out/set.variations.csv:2", extra);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(2), "{stderr}");
        assert!(stderr.contains(said), "{stderr}");
    }
    let csv = std::fs::read_to_string(out.join("set.variations.csv")).unwrap();
    let mut lines = csv.lines();
    let header = lines.next().unwrap();
    let trim = header
        .split(',')
        .position(|column| column == "trim_db")
        .unwrap();
    let mut cells: Vec<&str> = lines.next().unwrap().split(',').collect();
    cells[trim] = "5";
    std::fs::write(
        set.path().join("bad.csv"),
        format!("{header}\n{}\n", cells.join(",")),
    )
    .unwrap();
    let output = again("bad.csv:1", &[]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert_eq!(output.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("`trim_db` = 5 (--trim)"), "{stderr}");
}

/// Each take's loudness and true peak are in its manifest's row (CSV and JSON), as measured
/// on the samples its WAV holds, after the level stage brought it to `--loudness` under
/// `--true-peak`.
#[test]
fn each_takes_level_is_in_the_manifests_as_its_file_measures() {
    let set = render_set(&["--seed", "8", "--loudness", "-20", "--true-peak", "-1"]);
    let out = set.path().join("out");
    let csv_text = std::fs::read_to_string(out.join("set.variations.csv")).unwrap();
    let mut rows = csv::Reader::from_reader(csv_text.as_bytes());
    let header = rows.headers().unwrap().clone();
    let column = |name: &str| header.iter().position(|c| c == name).unwrap();
    let (lufs, peak) = (column("loudness_lufs"), column("true_peak_dbtp"));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("set.variations.json")).unwrap()).unwrap();
    let takes = json["takes"].as_array().unwrap();
    let mut count = 0;
    for (record, json_row) in rows.records().zip(takes) {
        let record = record.unwrap();
        let name = &record[1];
        let mut reader = hound::WavReader::open(out.join(format!("{name}.wav"))).unwrap();
        let rate = reader.spec().sample_rate;
        let samples: Vec<f32> = reader.samples::<f32>().map(Result::unwrap).collect();
        let mut meter = LoudnessMeter::mono(rate);
        meter.add(&samples);
        let measured = meter.loudness();
        let in_csv: [f64; 2] = [record[lufs].parse().unwrap(), record[peak].parse().unwrap()];
        let in_json = [
            json_row["loudness_lufs"].as_f64().unwrap(),
            json_row["true_peak_dbtp"].as_f64().unwrap(),
        ];
        let in_file = [measured.integrated_lufs, measured.true_peak_dbtp];
        assert_eq!(in_csv, in_file, "{name}");
        assert_eq!(in_json, in_file, "{name}");
        // At the level asked: −20 LUFS, unless the ceiling held it quieter.
        assert!(in_file[1] <= -1.0, "{name}: {in_file:?}");
        assert!(
            (in_file[0] + 20.0).abs() < 0.01 || (in_file[0] < -20.0 && in_file[1] > -1.01),
            "{name}: {in_file:?}"
        );
        count += 1;
    }
    assert_eq!(count, 5);
}

/// The ranges of [`SET_SCENE`] as the renderer reads them.
fn ranges() -> Vec<(Varied, [f64; 2])> {
    let table: toml::Table = toml::from_str(SET_SCENE).unwrap();
    let variations = table["variations"].as_table().unwrap().clone();
    VariationSpec::from_table(variations).unwrap().ranges
}

#[test]
fn drawn_values_stay_within_and_cover_their_ranges() {
    let ranges = ranges();
    const BINS: usize = 10;
    const SEEDS: u64 = 400;
    const TAKES: u32 = 25;
    let mut counts = vec![[0u32; BINS]; ranges.len()];
    let mut seeds = std::collections::HashSet::new();
    for master in 0..SEEDS {
        let takes = draw_takes(&ranges, TAKES, master);
        // The first takes of a larger set are those of a smaller one.
        assert_eq!(draw_takes(&ranges, 3, master)[..], takes[..3]);
        for take in &takes {
            assert!(take.seed <= 999_999, "a seed the plugin's Seed takes");
            seeds.insert(take.seed);
            for (index, (&(varied, [low, high]), &(drawn, value))) in
                ranges.iter().zip(&take.values).enumerate()
            {
                assert_eq!(varied, drawn);
                assert!(
                    (low..=high).contains(&value),
                    "{}: {value} outside [{low}, {high}]",
                    varied.key()
                );
                let bin = (((value - low) / (high - low)) * BINS as f64) as usize;
                counts[index][bin.min(BINS - 1)] += 1;
            }
        }
    }
    let draws = (SEEDS * TAKES as u64) as f64;
    assert!(seeds.len() as f64 > 0.99 * draws, "seeds repeat");
    // Uniform over the range: Pearson's χ² over ten bins below its 99.9 % point for 9 degrees
    // of freedom (27.88), for every range; the ends are reached (both end bins are full).
    let expected = draws / BINS as f64;
    for ((varied, _), bins) in ranges.iter().zip(&counts) {
        let chi_square: f64 = bins
            .iter()
            .map(|&count| (count as f64 - expected).powi(2) / expected)
            .sum();
        assert!(
            chi_square < 27.88,
            "{}: χ² = {chi_square:.1} over {bins:?}",
            varied.key()
        );
    }
}

/// Renders a scene holding `[variations]` `table` and checks that it is refused naming `key`,
/// with nothing written.
fn assert_refused(table: &str, expected: &[&str]) {
    let directory = tempfile::tempdir().unwrap();
    let scene = format!("tilt_deg = [[0.0, 90.0], [0.5, 135.0]]\n[variations]\n{table}\n");
    std::fs::write(directory.path().join("set.toml"), &scene).unwrap();
    let output = sake_glug(
        directory.path(),
        &["render", "set.toml", "--variations", "2", "-o", "set.wav"],
    );
    assert_eq!(output.status.code(), Some(1), "{table}");
    let message = String::from_utf8_lossy(&output.stderr);
    for part in expected {
        assert!(message.contains(part), "{table}: {message}");
    }
    assert_eq!(files_in(directory.path()), ["set.toml"], "{table}");
}

#[test]
fn bad_ranges_are_refused_naming_the_key() {
    assert_refused(
        "fill_percent = [90, 60]",
        &[
            "`variations.fill_percent`",
            "low end 90 is above its high end 60",
        ],
    );
    assert_refused(
        "viscosity_c = [0.2, 1.5]",
        &[
            "`variations.viscosity_c`",
            "1.5 lies outside `viscosity_c`'s range, 0 to 1",
        ],
    );
    assert_refused(
        "glug.f1_hz = [nan, 90]",
        &["`variations.glug.f1_hz`", "not NaN"],
    );
    assert_refused("tilt_end_deg = [120, 200]", &["`variations.tilt_end_deg`"]);
    assert_refused("ramp_s = 0.5", &["`variations.ramp_s`", "[low, high]"]);
    assert_refused(
        "fill = [60, 100]",
        &["unknown key `fill` in [variations]", "`fill_percent`"],
    );
    assert_refused("count = 0", &["`variations.count` = 0"]);
    // A range every take can draw from but the scene cannot take: a ramp on a constant tilt.
    let directory = tempfile::tempdir().unwrap();
    std::fs::write(
        directory.path().join("set.toml"),
        "tilt_deg = 135\n[variations]\ncount = 2\nramp_s = [0.2, 0.4]\n",
    )
    .unwrap();
    let output = sake_glug(directory.path(), &["render", "set.toml", "-o", "set.wav"]);
    assert_eq!(output.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&output.stderr).contains("`ramp_s`: the scene's tilt_deg"));
    assert_eq!(files_in(directory.path()), ["set.toml"]);
}

/// A units table as the command line writes it: each row's columns by name.
fn read_units(path: &Path) -> Vec<BTreeMap<String, f64>> {
    let mut reader = csv::Reader::from_path(path).unwrap();
    let header = reader.headers().unwrap().clone();
    reader
        .records()
        .map(|record| {
            let record = record.unwrap();
            header
                .iter()
                .zip(record.iter())
                .map(|(column, value)| (column.to_owned(), value.parse().unwrap()))
                .collect()
        })
        .collect()
}

fn read_wav(path: &Path) -> Vec<f32> {
    hound::WavReader::open(path)
        .unwrap()
        .into_samples::<f32>()
        .map(Result::unwrap)
        .collect()
}

/// When a unit's sounding components sum below `threshold` for good, found by stepping time in
/// 0.1 ms (the test's own reading of the units table, not the renderer's bisection).
fn unit_end_s(unit: &BTreeMap<String, f64>, threshold: f64, nyquist_hz: f64) -> Option<f64> {
    let sounding = |f: &str| unit["audible"] == 1.0 && unit[f] > 0.0 && unit[f] < nyquist_hz;
    let parts: Vec<(f64, f64)> = [("f1_hz", "a1", "b1_per_s"), ("f2_hz", "a2", "b2_per_s")]
        .into_iter()
        .filter(|(f, _, _)| sounding(f))
        .map(|(_, a, b)| (unit[a], unit[b]))
        .collect();
    let level = |tau: f64| -> f64 { parts.iter().map(|(a, b)| a * (-b * tau).exp()).sum() };
    if level(0.0) <= threshold {
        return None;
    }
    let mut tau = 0.0;
    while level(tau) > threshold {
        tau += 1e-4;
    }
    Some(unit["onset_s"] + tau)
}

#[test]
fn trim_keeps_every_audible_unit() {
    const FS: f64 = 48_000.0;
    for (preset, level_db, longest_s) in [
        ("default", "-60", 4.0),
        ("syrup", "-60", 9.5),
        ("default", "-30", 3.8),
    ] {
        let directory = tempfile::tempdir().unwrap();
        let preset_args: &[&str] = if preset == "default" {
            &[]
        } else {
            &["--preset", preset]
        };
        let render = |name: &str, extra: &[&str]| {
            let wav = format!("{name}.wav");
            let units = format!("{name}.csv");
            let mut args = vec!["render", "-o", &wav, "--units", &units];
            args.extend(preset_args);
            args.extend(extra);
            let stderr = succeeded(&sake_glug(directory.path(), &args));
            assert!(stderr.is_empty(), "{stderr}");
        };
        render("full", &[]);
        let trim = format!("--trim={level_db}");
        render("trimmed", &[&trim]);
        let full = read_wav(&directory.path().join("full.wav"));
        let trimmed = read_wav(&directory.path().join("trimmed.wav"));
        let full_units = read_units(&directory.path().join("full.csv"));
        let trimmed_units = read_units(&directory.path().join("trimmed.csv"));
        let peak = full.iter().fold(0.0f32, |peak, y| peak.max(y.abs())) as f64;
        let threshold = peak * 10f64.powf(level_db.parse::<f64>().unwrap() / 20.0);
        let end_s = trimmed.len() as f64 / FS;
        assert!(
            end_s < longest_s && trimmed.len() < full.len(),
            "{preset} {level_db}: {end_s} s of {} s",
            full.len() as f64 / FS
        );
        // The fade's 10 ms follow the point where every unit has decayed below the level.
        let fade_start = trimmed.len() - (0.010 * FS) as usize;
        let mut audible = 0;
        for unit in &full_units {
            let Some(unit_end) = unit_end_s(unit, threshold, FS / 2.0) else {
                continue;
            };
            audible += 1;
            assert!(
                unit_end <= fade_start as f64 / FS + 1e-4,
                "{preset} {level_db}: a unit at {} s sounds until {unit_end} s, past the fade at \
                 {} s",
                unit["onset_s"],
                fade_start as f64 / FS
            );
            assert!(
                trimmed_units.contains(unit),
                "{preset} {level_db}: the unit at {} s is not in the trimmed file",
                unit["onset_s"]
            );
        }
        assert!(audible > 20, "{preset}: {audible} audible units");
        // Before the fade the samples are the untrimmed render's; the fade ends at silence.
        assert!(trimmed[..fade_start] == full[..fade_start], "{preset}");
        assert_eq!(*trimmed.last().unwrap(), 0.0);
        assert!(trimmed[fade_start..]
            .iter()
            .all(|y| (y.abs() as f64) <= threshold * 1.01));
    }
}

#[test]
fn a_render_that_pours_nothing_warns_why() {
    let directory = tempfile::tempdir().unwrap();
    for (name, scene, reason) in [
        (
            "upright",
            "seed = 7\n[glug]\nf1_hz = 90\n",
            "the bottle never tilts past where it pours: `tilt_deg` stays at 0°",
        ),
        (
            "empty",
            "tilt_deg = 135\nfill_percent = 0\n",
            "the bottle is empty",
        ),
    ] {
        std::fs::write(directory.path().join(format!("{name}.toml")), scene).unwrap();
        let output = sake_glug(
            directory.path(),
            &["render", &format!("{name}.toml"), "-o", "x.wav"],
        );
        let stderr = succeeded(&output);
        assert!(
            stderr.contains(&format!("warning: {name}: nothing sounds: {reason}")),
            "{stderr}"
        );
    }
    // A pour that sounds says nothing.
    let stderr = succeeded(&sake_glug(directory.path(), &["render", "-o", "x.wav"]));
    assert!(stderr.is_empty(), "{stderr}");
}
