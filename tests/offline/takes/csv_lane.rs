//! CSV lanes: a column, a tilt from gravity columns, and every refusal naming file, line and
//! column.

use std::path::{Path, PathBuf};

use sake_glug_device::axis::Axis;
use sake_glug_device::csv_lane::{read_csv_lane, CsvFault, CsvLaneError, CsvLaneSpec};

fn fixtures(kind: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/takes")
        .join(kind)
}

fn read_fixture(
    kind: &str,
    name: &str,
    spec: &CsvLaneSpec,
) -> Result<Vec<(f64, f64)>, CsvLaneError> {
    let path = fixtures(kind).join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    read_csv_lane(&text, &path, spec)
}

fn gravity(axis: Axis) -> CsvLaneSpec {
    CsvLaneSpec::Gravity {
        columns: ["ax".into(), "ay".into(), "az".into()],
        axis,
    }
}

fn column(name: &str) -> CsvLaneSpec {
    CsvLaneSpec::Column(name.into())
}

/// The error for `text` read as `take.csv` with the gravity spec, as displayed.
fn refusal(text: &str) -> String {
    read_csv_lane(text, Path::new("take.csv"), &gravity(Axis::PlusZ))
        .unwrap_err()
        .to_string()
}

#[test]
fn a_column_lane_reads_trimmed_fields_past_a_byte_order_mark_and_blank_lines() {
    let name = "column_bom_crlf_spaces.csv";
    let fill = read_fixture("valid", name, &column("fill")).unwrap();
    assert_eq!(
        fill,
        [(0.0, 100.0), (0.25, 90.5), (0.25, 80.0), (10.0, 0.0)]
    );
    let viscosity = read_fixture("valid", name, &column("viscosity")).unwrap();
    assert_eq!(
        viscosity,
        [(0.0, 1.5), (0.25, 2.0), (0.25, 2.0), (10.0, 3.0)]
    );
}

#[test]
fn a_gravity_lane_is_the_tilt_of_the_chosen_axis() {
    let tilts = |axis| -> Vec<f64> {
        read_fixture("valid", "gravity.csv", &gravity(axis))
            .unwrap()
            .iter()
            .map(|(_, tilt)| (tilt * 1e9).round() / 1e9)
            .collect()
    };
    // Upright, +x gravity (on its side), upside down, on its side, half way.
    assert_eq!(tilts(Axis::PlusZ), [0.0, 90.0, 180.0, 90.0, 45.0]);
    assert_eq!(tilts(Axis::MinusY), [90.0, 90.0, 90.0, 0.0, 90.0]);
    assert_eq!(tilts(Axis::PlusX), [90.0, 0.0, 90.0, 90.0, 45.0]);
    let times: Vec<f64> = read_fixture("valid", "gravity.csv", &gravity(Axis::PlusZ))
        .unwrap()
        .iter()
        .map(|(time, _)| *time)
        .collect();
    assert_eq!(times, [0.0, 0.5, 1.0, 1.0, 1.5]);
}

#[test]
fn refusals_name_the_file_line_and_column() {
    let header = "time_s,ax,ay,az\n";
    let cases = [
        (
            "time_s,ax,ay\n0,0,0\n".to_owned(),
            r#"take.csv, line 1, column "az": no such column in the header"#,
        ),
        (
            "time_s,ax,ay,az,ay\n0,0,0,1,0\n".to_owned(),
            r#"take.csv, line 1, column "ay": named more than once in the header"#,
        ),
        (
            format!("{header}0,0,0,1\n0.1,0,0,1\n0.2,0,0,1\n0.3,0,0,1\n0.4,0,0,1\n0.5,abc,0,1\n"),
            r#"take.csv, line 7, column "ax": "abc" is not a number"#,
        ),
        (
            format!("{header}0,0,,1\n"),
            r#"take.csv, line 2, column "ay": "" is not a number"#,
        ),
        (
            format!("{header}0,0,0,inf\n"),
            r#"take.csv, line 2, column "az": "inf" is not a finite number"#,
        ),
        (
            format!("{header}0,0,0,1\n-0.5,0,0,1\n"),
            r#"take.csv, line 3, column "time_s": the time -0.5 s is negative"#,
        ),
        (
            format!("{header}0.2,0,0,1\n0.1,0,0,1\n"),
            r#"take.csv, line 3, column "time_s": the time 0.1 s is earlier than the 0.2 s of the row before"#,
        ),
        (
            format!("{header}0,0,0,0\n"),
            r#"take.csv, line 2, columns "ax", "ay", "az": the gravity vector is zero, so it has no direction"#,
        ),
        (
            format!("{header}0,0,1\n"),
            r#"take.csv, line 2, column "az": missing: the row has 3 fields but the header has 4"#,
        ),
        (
            format!("{header}0,0,0,1,5\n"),
            r#"take.csv, line 2, column "az": the row has 5 fields but the header has 4, this being the last"#,
        ),
        (
            String::new(),
            "take.csv, line 1: the file is empty: expected a header row with a time_s column",
        ),
        (
            header.to_owned(),
            "take.csv, line 2: no data rows after the header",
        ),
        (
            format!("{header}0,0,0,1\n\n\n0.5,x,0,1\n"),
            r#"take.csv, line 5, column "ax": "x" is not a number"#,
        ),
    ];
    for (text, expected) in cases {
        assert_eq!(refusal(&text), expected, "for {text:?}");
    }
}

#[test]
fn lines_are_counted_as_a_text_editor_counts_them() {
    let x_on = |line: u64| format!(r#"take.csv, line {line}, column "ax": "x" is not a number"#);
    let cases = [
        (
            "time_s,ax,ay,az\r\n0,0,0,1\r\n\r\n\r\n0.5,x,0,1\r\n",
            x_on(5),
        ),
        ("time_s,ax,ay,az\r0,0,0,1\r0.5,x,0,1\r", x_on(3)),
        ("time_s,ax,ay,az\n0,0,0,1\n   \n0.5,x,0,1\n", x_on(4)),
        (
            "time_s,ax,ay,az,note\n0,0,0,1,\"two\nlines\"\n0.5,x,0,1,c\n",
            x_on(4),
        ),
        ("\u{feff}time_s,ax,ay,az\n0.5,x,0,1", x_on(2)),
        (
            "\n\r\ntime_s,ax,ay\n0,0,0\n",
            r#"take.csv, line 3, column "az": no such column in the header"#.to_owned(),
        ),
        (
            "\n\ntime_s,ax,ay,az\n\n",
            "take.csv, line 4: no data rows after the header".to_owned(),
        ),
    ];
    for (text, expected) in cases {
        assert_eq!(refusal(text), expected, "for {text:?}");
    }
}

#[test]
fn a_column_lane_refuses_bad_values_in_its_column_only() {
    let text = "time_s,tilt,notes\n0,10,ok\n0.5,x,fine\n";
    let error = read_csv_lane(text, Path::new("t.csv"), &column("tilt")).unwrap_err();
    assert_eq!(error.line, 3);
    assert_eq!(error.columns, ["tilt"]);
    assert_eq!(error.fault, CsvFault::NotANumber("x".into()));
    let notes_ignored = "time_s,tilt,notes\n0,10,ok\n0.5,20,fine\n";
    let lane = read_csv_lane(notes_ignored, Path::new("t.csv"), &column("tilt")).unwrap();
    assert_eq!(lane, [(0.0, 10.0), (0.5, 20.0)]);
}

/// Every file in the invalid folder, named after its fault, and where that fault is.
const INVALID: [(&str, u64, &[&str]); 16] = [
    ("duplicate_column", 1, &["ax"]),
    ("empty", 1, &[]),
    ("empty_field", 2, &["ay"]),
    ("missing_column", 1, &["az"]),
    ("missing_time_column", 1, &["time_s"]),
    ("negative_time", 2, &["time_s"]),
    ("no_data_rows", 2, &[]),
    ("not_a_number", 3, &["ax"]),
    ("not_a_number_after_blank_line", 5, &["ax"]),
    ("not_finite", 3, &["az"]),
    ("number_overflows_to_infinity", 3, &["ax"]),
    ("time_goes_back", 4, &["time_s"]),
    ("time_not_a_number", 2, &["time_s"]),
    ("too_few_fields", 3, &["az"]),
    ("too_many_fields", 3, &["az"]),
    ("zero_vector", 3, &["ax", "ay", "az"]),
];

#[test]
fn every_invalid_fixture_is_refused_naming_its_file_line_and_column() {
    let folder = fixtures("invalid");
    let mut names: Vec<String> = std::fs::read_dir(&folder)
        .unwrap()
        .map(|entry| entry.unwrap().file_name().into_string().unwrap())
        .collect();
    names.sort();
    let expected_names: Vec<String> = INVALID
        .iter()
        .map(|(name, ..)| format!("{name}.csv"))
        .collect();
    assert_eq!(
        names, expected_names,
        "each invalid fixture needs its expectation here"
    );

    for (name, line, columns) in INVALID {
        let path = folder.join(format!("{name}.csv"));
        let error =
            read_fixture("invalid", &format!("{name}.csv"), &gravity(Axis::PlusZ)).expect_err(name);
        let message = error.to_string();
        assert_eq!(error.file, path);
        assert_eq!(error.line, line, "{message}");
        assert_eq!(error.columns, columns, "{message}");
        assert!(
            message.starts_with(&format!("{}, line {line}", path.display())),
            "{message}"
        );
        for column in columns {
            assert!(message.contains(&format!("{column:?}")), "{message}");
        }
        if columns.is_empty() {
            assert!(!message.contains(", column"), "{message}");
        }
        assert!(
            message.len() > format!("{}, line {line}: ", path.display()).len(),
            "{message}"
        );
    }
}
