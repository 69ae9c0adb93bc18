//! The comparison picture (`sake-glug fit --compare FILE.png`): each recording beside its
//! fitted model's render, so that a user sees whether the model sounds like theirs: (a) the
//! recording's waveform, (b) the model's over the same span, (c) the smoothed spectra of the
//! recording, the model and the default bottle (with their correlations), (d) a few units of the
//! recording with their fits overlaid. The first recording is drawn.

use sake_glug_io::PendingFile;
use sake_glug_plot::plotters::prelude::*;
use sake_glug_plot::{Canvas, Plot, PlotError, FONT};

use super::compare::{render_default, render_model, smoothed_db, spectral_correlation};
use super::plot::{draw_units_panel, waveform_chart};
use super::session_fit::SessionFit;
use super::spectrum::Spectrum;

const COMPARE_PLOT: Plot = Plot::new("comparison picture", (1600, 1100));
/// The waveforms' span (s), at most.
const WAVE_S: f64 = 3.0;
/// The units overlaid in (d).
const UNITS_SHOWN: usize = 4;

/// Draws the comparison of `fit`'s first recording into `file` (a PNG).
pub fn draw_compare_plot(fit: &SessionFit, file: &PendingFile) -> Result<(), PlotError> {
    COMPARE_PLOT.draw_into(file, |root| draw(fit, root))
}

/// The drawing; the error is the renderer's or plotters' message.
fn draw(fit: &SessionFit, root: &Canvas<'_>) -> Result<(), String> {
    let e = |error: &dyn std::fmt::Display| error.to_string();
    let recording = fit
        .recordings
        .first()
        .ok_or_else(|| "no recording to compare".to_string())?;
    let liquid = fit
        .liquids
        .iter()
        .find(|l| l.liquid == recording.spec.liquid)
        .ok_or_else(|| "no model for the recording".to_string())?;
    let fs = recording.sample_rate;
    let rate = f64::from(fs);
    let model = render_model(&liquid.model_toml, fs)?;
    let default = render_default(fs)?;
    let (model_spectrum, default_spectrum) =
        (Spectrum::of(&model, rate), Spectrum::of(&default, rate));
    root.fill(&WHITE).map_err(|x| e(&x))?;
    let panels = root.split_evenly((2, 2));

    let span_s = WAVE_S.min(recording.excerpt.len() as f64 / rate).max(0.05);
    // The model's first glug comes a pocket's pour after its start: its span starts there.
    let model_from = model.iter().position(|y| y.abs() > 0.0).unwrap_or(0);
    for (panel, samples, caption) in [
        (
            &panels[0],
            &recording.excerpt[..],
            format!("(a) the recording {}", recording.name()),
        ),
        (
            &panels[1],
            &model[model_from..],
            format!("(b) the fitted model of `{}`, rendered", liquid.liquid),
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
    let curves = [
        (&recording.spectrum, BLUE, "the recording".to_string()),
        (
            &model_spectrum,
            RED,
            format!(
                "the model (r = {:.2})",
                spectral_correlation(&recording.spectrum, &model_spectrum)
            ),
        ),
        (
            &default_spectrum,
            RGBColor(120, 120, 120),
            format!(
                "the default bottle (r = {:.2})",
                spectral_correlation(&recording.spectrum, &default_spectrum)
            ),
        ),
    ];
    // Each spectrum in dB relative to its own peak in the band: their shapes are compared.
    let shapes: Vec<Vec<(f64, f64)>> = curves
        .iter()
        .map(|(spectrum, _, _)| {
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
    for (shape, (_, colour, label)) in shapes.into_iter().zip(curves) {
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

    // (d) A few units with their fits.
    let units: Vec<_> = recording.units.iter().take(UNITS_SHOWN).collect();
    if let (Some(first), Some(last)) = (units.first(), units.last()) {
        let from_s = (first.fit.onset_s - 0.005).max(0.0);
        let to_s = (last.fit.window.1 as f64 / rate).max(from_s + 0.02);
        draw_units_panel(
            &panels[3],
            &format!("(d) its first {} units and their fits", units.len()),
            recording,
            &units,
            from_s..to_s,
        )?;
    }
    Ok(())
}
