//! The envelopes of the last units: A1·e^(−B1·τ) and A2·e^(−B2·τ) over their first 150 ms,
//! newest brightest, with a marker at each unit's current age.

use egui::{pos2, Color32, Stroke, Vec2};

use crate::feed::Feed;

const SPAN_S: f32 = 0.15;
const POINTS: usize = 60;
/// The label's line at the top of the panel (12 px text, 2 px from the top, and a gap).
const LABEL_HEIGHT: f32 = 18.0;

pub fn show(ui: &mut egui::Ui, feed: &Feed, size: Vec2) {
    let (rect, _) = ui.allocate_exact_size(size, egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, Color32::from_gray(20));
    let units: Vec<_> = feed.units().collect();
    let peak = units
        .iter()
        .flat_map(|unit| unit.amplitude)
        .fold(1e-6f32, f32::max);
    let x = |tau: f32| rect.left() + tau / SPAN_S * rect.width();
    let y = |value: f32| rect.bottom() - value / peak * rect.height() * 0.9;
    for (age_rank, unit) in units.iter().enumerate() {
        let fade = 1.0 - age_rank as f32 / units.len().max(1) as f32 * 0.8;
        let colours = [
            Color32::from_rgb(255, 170, 60),
            Color32::from_rgb(90, 200, 140),
        ];
        for (component, colour) in colours.into_iter().enumerate() {
            let points: Vec<_> = (0..=POINTS)
                .map(|step| {
                    let tau = step as f32 / POINTS as f32 * SPAN_S;
                    let value =
                        unit.amplitude[component] * (-unit.decay_per_s[component] * tau).exp();
                    pos2(x(tau), y(value))
                })
                .collect();
            painter.add(egui::Shape::line(
                points,
                Stroke::new(1.5, colour.gamma_multiply(fade)),
            ));
        }
        let age = unit.age_s as f32;
        if (0.0..SPAN_S).contains(&age) {
            // Below the label, so that no marker runs through its text.
            painter.vline(
                x(age),
                rect.top() + LABEL_HEIGHT..=rect.bottom(),
                Stroke::new(1.0, Color32::from_gray(90).gamma_multiply(fade)),
            );
        }
    }
    let label = match units.first() {
        Some(unit) => format!(
            "last units: f1 {:.0} Hz (orange), f2 {:.0} Hz (green), V {:.0} ml",
            unit.frequency_hz[0], unit.frequency_hz[1], unit.volume_ml
        ),
        None => "no unit yet: tilt the bottle past 90°".to_owned(),
    };
    painter.text(
        rect.left_top() + egui::vec2(4.0, 2.0),
        egui::Align2::LEFT_TOP,
        label,
        egui::FontId::proportional(12.0),
        Color32::from_gray(200),
    );
}
