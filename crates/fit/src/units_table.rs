//! The units table (`sake-glug fit --units FILE.csv`): a row per detected unit, used or not,
//! with its fit in eq. 1's terms and why it was not used, and for a used unit its volume and the
//! frequencies its liquid's model plays there (the headspace law of MODEL.md §5.1 beside the
//! unit's own), and each mode's glide where it glides (MODEL.md §5.2).

use super::session_fit::SessionFit;

/// The table's columns, in order.
pub const UNIT_COLUMNS: [&str; 17] = [
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
    "volume_ml",
    "f1_model_hz",
    "f2_model_hz",
    "f1_glide_ratio",
    "f1_glide_ms",
    "f2_glide_ratio",
    "f2_glide_ms",
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
        let liquid = fit
            .liquids
            .iter()
            .find(|l| l.liquid == recording.spec.liquid);
        for unit in &recording.detected {
            // A used unit's volume: the fitted unit at its onset.
            let volume_ml = unit
                .fit
                .and_then(|fitted| {
                    recording
                        .units
                        .iter()
                        .find(|u| u.fit.onset_s == fitted.onset_s)
                })
                .map_or(f64::NAN, |u| u.volume_ml);
            let model_hz = match liquid {
                Some(liquid) if volume_ml.is_finite() => {
                    liquid.model_hz(volume_ml, fit.session.capacity_ml)
                }
                _ => [f64::NAN; 2],
            };
            let (f, b, a) = match unit.fit {
                Some(fit) => (fit.frequency_hz, fit.decay_per_s, fit.amplitude),
                None => ([f64::NAN; 2], [f64::NAN; 2], [f64::NAN; 2]),
            };
            // A mode's glide: ρ and τ_g (ms), empty where it does not glide.
            let glide = |mode: usize| {
                unit.fit
                    .and_then(|fit| fit.glide[mode])
                    .map_or([f64::NAN; 2], |g| [g.ratio, 1e3 * g.time_s])
            };
            let (glide1, glide2) = (glide(0), glide(1));
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
                number(volume_ml),
                number(model_hz[0]),
                number(model_hz[1]),
                number(glide1[0]),
                number(glide1[1]),
                number(glide2[0]),
                number(glide2[1]),
            ]);
        }
    }
    let bytes = writer.into_inner().unwrap_or_default();
    String::from_utf8(bytes).unwrap_or_default()
}
