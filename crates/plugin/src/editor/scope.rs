//! A live scope of the output: the min and max of each millisecond, oldest on the left.

use egui::{pos2, Color32, Stroke, Vec2};

use crate::feed::{Feed, SCOPE_COLUMNS, SCOPE_COLUMN_S};

/// The label's line at the top of the panel (12 px text, 2 px from the top, and a gap).
const LABEL_HEIGHT: f32 = 18.0;

pub fn show(ui: &mut egui::Ui, feed: &Feed, size: Vec2) {
    let (rect, _) = ui.allocate_exact_size(size, egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, Color32::from_gray(20));
    let columns: Vec<(f32, f32)> = feed.scope().collect();
    let peak = columns
        .iter()
        .fold(1e-6f32, |peak, &(min, max)| peak.max(-min).max(max));
    let x_step = rect.width() / SCOPE_COLUMNS as f32;
    let first_x = rect.right() - columns.len() as f32 * x_step;
    // The trace keeps below the label, so that it never runs through the text.
    let plot = rect.with_min_y(rect.top() + LABEL_HEIGHT);
    let y = |value: f32| plot.center().y - value / peak * plot.height() * 0.45;
    for (index, &(min, max)) in columns.iter().enumerate() {
        let x = first_x + index as f32 * x_step;
        painter.line_segment(
            [pos2(x, y(max)), pos2(x, y(min).max(y(max) + 1.0))],
            Stroke::new(1.0, Color32::from_rgb(120, 200, 255)),
        );
    }
    painter.text(
        rect.left_top() + egui::vec2(4.0, 2.0),
        egui::Align2::LEFT_TOP,
        format!(
            "output, last {:.1} s, peak {peak:.3}",
            SCOPE_COLUMNS as f64 * SCOPE_COLUMN_S
        ),
        egui::FontId::proportional(12.0),
        Color32::from_gray(200),
    );
}
