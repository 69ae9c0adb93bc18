//! The units table (`sake-glug fit --units FILE.csv`): a row per detected unit, used or not,
//! with its fit in eq. 1's terms and why it was not used.

use super::session_fit::SessionFit;

/// The table's columns, in order.
pub const UNIT_COLUMNS: [&str; 10] = [
    "recording",
    "onset_s",
    "f1_hz",
    "f2_hz",
    "b1_per_s",
    "b2_per_s",
    "a1",
    "a2",
    "used",
    "reason",
];

/// The units table of `fit` as CSV text (the csv crate quotes a field that needs it).
pub fn units_csv(fit: &SessionFit) -> String {
    let mut writer = csv::Writer::from_writer(Vec::new());
    let number = |value: f64| {
        if value.is_finite() {
            value.to_string()
        } else {
            String::new()
        }
    };
    // Writing into memory cannot fail.
    let _ = writer.write_record(UNIT_COLUMNS);
    for recording in &fit.recordings {
        let name = recording.name();
        for unit in &recording.detected {
            let (f, b, a) = match unit.fit {
                Some(fit) => (fit.frequency_hz, fit.decay_per_s, fit.amplitude),
                None => ([f64::NAN; 2], [f64::NAN; 2], [f64::NAN; 2]),
            };
            let onset_s = unit.fit.map_or(unit.onset_s, |fit| fit.onset_s);
            let _ = writer.write_record([
                name.clone(),
                number(onset_s),
                number(f[0]),
                number(f[1]),
                number(b[0]),
                number(b[1]),
                number(a[0]),
                number(a[1]),
                if unit.rejection.is_none() { "1" } else { "0" }.to_owned(),
                unit.rejection.map(|r| r.to_string()).unwrap_or_default(),
            ]);
        }
    }
    let bytes = writer.into_inner().unwrap_or_default();
    String::from_utf8(bytes).unwrap_or_default()
}
