//! The comparison picture (`sake-glug fit --compare FILE.png`): each recording beside its
//! fitted model's render, the model rendered as the recording was made (the captions say how), so
//! that a user sees whether the model sounds like theirs: (a) the recording's waveform, (b) the
//! model's over the same span, (c) the smoothed spectra of the recording, the model and the
//! default bottle (with their correlations), (d) each glug's low pitch against time in the three,
//! with the fitted units' frequencies, (e) a few units of the recording with their fits
//! overlaid, (f) the measures a listener would recognise. The first recording is drawn.

use sake_glug_io::PendingFile;
use sake_glug_plot::plotters::prelude::*;
use sake_glug_plot::{Canvas, Plot, PlotError, FONT};

use super::compare::{smoothed_db, Comparison};
use super::comparisons::compare_recording;
use super::plot::{draw_units_panel, waveform_chart};
use super::session_fit::SessionFit;

const COMPARE_PLOT: Plot = Plot::new("comparison picture", (1600, 1500));
/// The waveforms' span (s), at most.
const WAVE_S: f64 = 3.0;
/// The units overlaid in (d).
const UNITS_SHOWN: usize = 4;

/// Draws the comparison of `fit`'s first recording into `file` (a PNG).
pub fn draw_compare_plot(fit: &SessionFit, file: &PendingFile) -> Result<(), PlotError> {
    COMPARE_PLOT.draw_into(file, |root| draw(fit, root))
}

/// The colours of the recording, the model and the default bottle.
const COLOURS: [RGBColor; 3] = [BLUE, RED, RGBColor(120, 120, 120)];

/// The drawing; the error is the renderer's or plotters' message.
fn draw(fit: &SessionFit, root: &Canvas<'_>) -> Result<(), String> {
    let e = |error: &dyn std::fmt::Display| error.to_string();
    let recording = fit
        .recordings
        .first()
        .ok_or_else(|| "no recording to compare".to_string())?;
    let compared = compare_recording(fit, recording)?
        .ok_or_else(|| "no model for the recording".to_string())?;
    let comparison = &compared.comparison;
    let liquid = &recording.spec.liquid;
    let fs = recording.sample_rate;
    let rate = f64::from(fs);
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let panels = root.split_evenly((3, 2));

    let span_s = WAVE_S.min(recording.excerpt.len() as f64 / rate).max(0.05);
    for (panel, samples, caption) in [
        (
            &panels[0],
            &recording.excerpt[..],
            format!("(a) the recording {}", recording.name()),
        ),
        (
            &panels[1],
            &compared.renders[0][..],
            format!("(b) the model of `{liquid}`, {}", comparison.rendered),
        ),
    ] {
        let len = ((span_s * rate) as usize).min(samples.len());
        let mut chart = waveform_chart(panel, &caption, 0.0..span_s, &samples[..len])?;
        chart
            .draw_series(LineSeries::new(
                (0..len).map(|n| (n as f64 / rate, f64::from(samples[n]))),
                BLUE,
            ))
            .map_err(|x| e(&x))?;
    }

    // (c) The spectra.
    let labels = [
        "the recording".to_string(),
        format!("the model (r = {:.2})", comparison.fitted),
        format!("the default bottle (r = {:.2})", comparison.default),
    ];
    let spectra = [
        &recording.spectrum,
        &compared.spectra[0],
        &compared.spectra[1],
    ];
    // Each spectrum in dB relative to its own peak in the band: their shapes are compared.
    let shapes: Vec<Vec<(f64, f64)>> = spectra
        .iter()
        .map(|spectrum| {
            let db = smoothed_db(spectrum);
            let top = db.iter().map(|p| p.1).fold(f64::MIN, f64::max);
            db.into_iter().map(|(hz, v)| (hz, v - top)).collect()
        })
        .collect();
    let (low_hz, high_hz) = super::compare::COMPARED_BAND_HZ;
    let mut chart = ChartBuilder::on(&panels[2])
        .margin(12)
        .caption(
            "(c) spectra, smoothed (dB below each one's peak)",
            (FONT, 22),
        )
        .x_label_area_size(35)
        .y_label_area_size(70)
        .build_cartesian_2d(low_hz..high_hz, -60.0..3.0)
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc("frequency (Hz)")
        .y_desc("dB")
        .draw()
        .map_err(|x| e(&x))?;
    for ((shape, colour), label) in shapes.into_iter().zip(COLOURS).zip(labels) {
        chart
            .draw_series(LineSeries::new(
                shape.into_iter().map(|(hz, db)| (hz, db.max(-60.0))),
                colour.stroke_width(2),
            ))
            .map_err(|x| e(&x))?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|x| e(&x))?;

    draw_pitch_panel(&panels[3], fit, comparison)?;

    // (e) A few units with their fits.
    let units: Vec<_> = recording.units.iter().take(UNITS_SHOWN).collect();
    if let (Some(first), Some(last)) = (units.first(), units.last()) {
        let from_s = (first.fit.onset_s - 0.005).max(0.0);
        let to_s = (last.fit.window.1 as f64 / rate).max(from_s + 0.02);
        draw_units_panel(
            &panels[4],
            &format!("(e) its first {} units and their fits", units.len()),
            recording,
            &units,
            from_s..to_s,
        )?;
    }
    draw_measures_panel(&panels[5], comparison)?;
    Ok(())
}

/// (d) Each glug's low pitch against time, heard in the recording, the model and the default
/// bottle alike, and the fitted units' f1 (crosses).
fn draw_pitch_panel(
    panel: &Canvas<'_>,
    fit: &SessionFit,
    comparison: &Comparison,
) -> Result<(), String> {
    let e = |error: &dyn std::fmt::Display| error.to_string();
    let units: Vec<(f64, f64)> = fit.recordings[0]
        .units
        .iter()
        .map(|u| (u.fit.onset_s, u.fit.frequency_hz[0]))
        .filter(|(_, hz)| hz.is_finite())
        .collect();
    let tracks: Vec<Vec<(f64, f64)>> = comparison
        .heard
        .iter()
        .map(|heard| {
            heard
                .onsets_s
                .iter()
                .copied()
                .zip(heard.pitch_hz.iter().copied())
                .filter(|(_, hz)| hz.is_finite())
                .collect()
        })
        .collect();
    let every = tracks.iter().flatten().chain(&units);
    let end_s = every.clone().map(|p| p.0).fold(0.1, f64::max) * 1.05;
    let top_hz = every.map(|p| p.1).fold(50.0, f64::max) * 1.15;
    let mut chart = ChartBuilder::on(panel)
        .margin(12)
        .caption(
            format!(
                "(d) each glug's pitch below {:.0} Hz against time",
                comparison.split_hz
            ),
            (FONT, 22),
        )
        .x_label_area_size(35)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..end_s, 0.0..top_hz)
        .map_err(|x| e(&x))?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc("Hz")
        .draw()
        .map_err(|x| e(&x))?;
    let labels = ["the recording", "the model", "the default bottle"];
    for ((track, colour), label) in tracks.into_iter().zip(COLOURS).zip(labels) {
        chart
            .draw_series(LineSeries::new(track.clone(), colour.stroke_width(2)))
            .map_err(|x| e(&x))?
            .label(label)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        chart
            .draw_series(
                track
                    .into_iter()
                    .map(|p| Circle::new(p, 4, colour.filled())),
            )
            .map_err(|x| e(&x))?;
    }
    chart
        .draw_series(units.into_iter().map(|p| Cross::new(p, 6, BLACK)))
        .map_err(|x| e(&x))?
        .label("the fitted units' f1")
        .legend(|(x, y)| Cross::new((x + 10, y), 6, BLACK));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|x| e(&x))?;
    Ok(())
}

/// (f) The measures of [`Comparison`], as a table of text: a row each, the recording's, the
/// model's and the default bottle's value in columns.
fn draw_measures_panel(panel: &Canvas<'_>, comparison: &Comparison) -> Result<(), String> {
    let e = |error: &dyn std::fmt::Display| error.to_string();
    let glugs = comparison.glugs();
    let heard = &comparison.heard;
    let each = |value: &dyn Fn(&super::listen::Heard) -> String| heard.each_ref().map(value);
    let rows: Vec<(String, [String; 3])> = vec![
        (
            String::new(),
            ["recording", "model", "default"].map(str::to_owned),
        ),
        (
            "audible glug units".into(),
            each(&|h| h.onsets_s.len().to_string()),
        ),
        (
            "glugs a second".into(),
            each(&|h| format!("{:.1}", h.rate_per_s)),
        ),
        (
            format!("pitch fall over {glugs} units"),
            each(&|h| format!("{:.2}×", h.fall_over(glugs))),
        ),
        (
            format!("energy above {:.0} Hz", comparison.split_hz),
            each(&|h| format!("{:.0} %", 100.0 * h.high_share)),
        ),
        (
            "spectral correlation".into(),
            [
                String::new(),
                format!("{:.2}", comparison.fitted),
                format!("{:.2}", comparison.default),
            ],
        ),
        (
            "log-spectral distance".into(),
            [
                String::new(),
                format!("{:.1} dB", comparison.distance[0]),
                format!("{:.1} dB", comparison.distance[1]),
            ],
        ),
    ];
    let text = |line: &str, at: (i32, i32), size: i32| {
        panel
            .draw_text(line, &(FONT, size).into_font().color(&BLACK), at)
            .map_err(|x| e(&x))
    };
    text("(f) what a listener hears", (12, 12), 22)?;
    text(&comparison.rendered, (12, 46), 19)?;
    for (i, (name, cells)) in rows.iter().enumerate() {
        let y = 100 + 34 * i as i32;
        text(name, (12, y), 19)?;
        for (column, cell) in cells.iter().enumerate() {
            text(cell, (330 + 150 * column as i32, y), 19)?;
        }
    }
    Ok(())
}
