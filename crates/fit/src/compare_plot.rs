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
use super::listen::Heard;
use super::plot::{caption_px, draw_units_panel, waveform_chart, CHART_MARGIN_PX};
use super::session_fit::SessionFit;

const COMPARE_PLOT: Plot = Plot::new("comparison picture", (1600, 1500));
/// The shortest span of the waveforms (s).
const SHORTEST_WAVE_S: f64 = 0.05;
/// The units overlaid in (e).
const UNITS_SHOWN: usize = 4;

/// The waveforms' span (s): the whole clip (the excerpt the fit keeps), so that the time axis
/// reaches its end.
fn wave_span_s(samples: usize, sample_rate: f64) -> f64 {
    (samples as f64 / sample_rate).max(SHORTEST_WAVE_S)
}

/// Panel (e)'s caption: the units it shows are the first the fit used (rejected ones are left
/// out), so it says so.
fn units_caption(shown: usize, used: usize, detected: usize) -> String {
    let which = if shown < used {
        format!("the first {shown} of its {used} units used")
    } else {
        format!("its {used} units used")
    };
    format!("(e) {which} (of {detected} detected), with their fits")
}

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

    let span_s = wave_span_s(recording.excerpt.len(), rate);
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
    const SPECTRA_CAPTION: &str = "(c) spectra, smoothed (dB below each one's peak)";
    let mut chart = ChartBuilder::on(&panels[2])
        .margin(CHART_MARGIN_PX)
        .caption(
            SPECTRA_CAPTION,
            (FONT, caption_px(&panels[2], SPECTRA_CAPTION)),
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
            &units_caption(units.len(), recording.units.len(), recording.detected.len()),
            recording,
            &units,
            from_s..to_s,
        )?;
    }
    draw_measures_panel(&panels[5], comparison)?;
    Ok(())
}

/// The points of (d)'s pitch track of one pour: each voiced glug's onset and low pitch (a glug
/// too quiet or too short to read a pitch is left out, not drawn as a dip).
fn pitch_track(heard: &Heard) -> Vec<(f64, f64)> {
    heard
        .onsets_s
        .iter()
        .zip(&heard.pitch_hz)
        .zip(&heard.voiced)
        .filter(|&((_, hz), &voiced)| voiced && hz.is_finite())
        .map(|((&s, &hz), _)| (s, hz))
        .collect()
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
    let tracks: Vec<Vec<(f64, f64)>> = comparison.heard.iter().map(pitch_track).collect();
    let every = tracks.iter().flatten().chain(&units);
    let end_s = every.clone().map(|p| p.0).fold(0.1, f64::max) * 1.05;
    let top_hz = every.map(|p| p.1).fold(50.0, f64::max) * 1.15;
    let caption = format!(
        "(d) each glug's pitch below {:.0} Hz against time",
        comparison.split_hz
    );
    let mut chart = ChartBuilder::on(panel)
        .margin(CHART_MARGIN_PX)
        .caption(&caption, (FONT, caption_px(panel, &caption)))
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

#[cfg(test)]
mod tests {
    use super::*;
    use sake_glug_plot::plotters::style::IntoTextStyle;

    /// The caption of (b) as a recording at 44.1 kHz gives it: too wide for its panel at the
    /// full size, it is set smaller until it fits within the margins.
    #[test]
    fn a_long_caption_fits_its_panel() {
        let caption = "(b) the model of `liquid`, rendered as recorded: held at 135°, from 100 % \
                       full, for 3.13 s at 44100 Hz";
        let png = COMPARE_PLOT.png(std::path::Path::new("test.png"), |root| {
            let panels = root.split_evenly((3, 2));
            let panel = &panels[1];
            let room = panel.dim_in_pixel().0 - 2 * CHART_MARGIN_PX;
            let width = |px: u32| {
                panel
                    .estimate_text_size(caption, &(FONT, px).into_text_style(panel))
                    .unwrap()
                    .0
            };
            let px = caption_px(panel, caption);
            if width(super::super::plot::CAPTION_PX) <= room {
                return Err("the caption fits at full size: the test shows nothing".to_string());
            }
            if width(px) > room {
                return Err(format!(
                    "{} px wide at {px} px, {room} px of room",
                    width(px)
                ));
            }
            Ok(())
        });
        png.unwrap();
    }

    #[test]
    fn the_waveforms_reach_the_clips_end() {
        let rate = 44_100.0;
        let samples = (3.13 * rate) as usize;
        assert!(wave_span_s(samples, rate) >= samples as f64 / rate);
    }

    #[test]
    fn the_units_caption_says_they_are_the_ones_used() {
        let caption = units_caption(4, 4, 5);
        assert!(
            caption.contains("its 4 units used (of 5 detected)"),
            "{caption}"
        );
        let caption = units_caption(4, 9, 12);
        assert!(
            caption.contains("the first 4 of its 9 units used"),
            "{caption}"
        );
    }

    #[test]
    fn the_pitch_track_leaves_out_glugs_not_voiced() {
        let heard = Heard {
            onsets_s: vec![0.1, 0.2, 0.3, 0.4],
            rate_per_s: 10.0,
            pitch_hz: vec![200.0, 31.0, 190.0, f64::NAN],
            voiced: vec![true, false, true, true],
            high_share: 0.1,
        };
        assert_eq!(pitch_track(&heard), [(0.1, 200.0), (0.3, 190.0)]);
    }
}
