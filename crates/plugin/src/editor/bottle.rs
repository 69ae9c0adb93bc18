//! The bottle drawn at its tilt, filled to its residual volume.

use std::sync::atomic::Ordering::Relaxed;

use egui::{pos2, vec2, Color32, Pos2, Shape, Stroke, Vec2};

use crate::feed::Feed;

/// The outline of an upright tokkuri, in units of its height, mouth up, origin at the bottom centre.
const OUTLINE: [(f32, f32); 10] = [
    (0.10, 1.00),
    (0.09, 0.86),
    (0.06, 0.80),
    (0.07, 0.70),
    (0.22, 0.52),
    (0.26, 0.34),
    (0.25, 0.12),
    (0.20, 0.02),
    (0.16, 0.00),
    (0.0, 0.0),
];

pub fn show(ui: &mut egui::Ui, feed: &Feed, size: Vec2) {
    let (rect, _) = ui.allocate_exact_size(size, egui::Sense::hover());
    let painter = ui.painter_at(rect);
    let tilt_deg = feed.tilt_deg.load(Relaxed);
    let volume_ml = feed.volume_ml.load(Relaxed);
    let capacity_ml = feed.capacity_ml.load(Relaxed).max(f32::MIN_POSITIVE);
    let fraction = (volume_ml / capacity_ml).clamp(0.0, 1.0);

    let height = rect.height() * 0.8;
    let pivot = rect.center() + vec2(-rect.width() * 0.1, 0.0);
    // Tilt turns the mouth from up (0°) towards the right and down (180°); rotate about the centre.
    let angle = tilt_deg.to_radians();
    let place = |(x, y): (f32, f32)| -> Pos2 {
        let local = vec2(x * height, -(y - 0.5) * height);
        let (sin, cos) = angle.sin_cos();
        pivot + vec2(local.x * cos - local.y * sin, local.x * sin + local.y * cos)
    };
    let right: Vec<(f32, f32)> = OUTLINE[..OUTLINE.len() - 1].to_vec();
    let mut outline: Vec<Pos2> = right.iter().map(|&point| place(point)).collect();
    outline.extend(right.iter().rev().map(|&(x, y)| place((-x, y))));

    // The liquid: the inside of the outline below a level line (in screen space) chosen so that
    // the filled share of the drawing's height is the residual share of the capacity; a drawing,
    // not the bottle's geometry. Filled by scanlines, as the outline is not convex.
    let (top, bottom) = outline
        .iter()
        .fold((f32::MAX, f32::MIN), |(top, bottom), p| {
            (top.min(p.y), bottom.max(p.y))
        });
    let level_y = bottom - (bottom - top) * fraction;
    let liquid = Color32::from_rgb(200, 190, 120);
    let mut y = level_y.ceil();
    while y <= bottom {
        for span in inside_spans(&outline, y).chunks_exact(2) {
            painter.line_segment(
                [pos2(span[0], y), pos2(span[1], y)],
                Stroke::new(1.5, liquid),
            );
        }
        y += 1.0;
    }
    painter.add(Shape::closed_line(
        outline,
        Stroke::new(2.0, Color32::from_gray(220)),
    ));
    painter.text(
        rect.left_top() + vec2(6.0, 4.0),
        egui::Align2::LEFT_TOP,
        format!("tilt {tilt_deg:.1}°   {volume_ml:.1} ml of {capacity_ml:.0} ml"),
        egui::FontId::proportional(14.0),
        Color32::from_gray(230),
    );
}

/// Where a horizontal line at `y` is inside a polygon: sorted crossings, in pairs (even-odd rule).
fn inside_spans(polygon: &[Pos2], y: f32) -> Vec<f32> {
    let mut crossings: Vec<f32> = (0..polygon.len())
        .filter_map(|index| {
            let (a, b) = (polygon[index], polygon[(index + 1) % polygon.len()]);
            // Half-open in y, so a vertex on the line counts once.
            ((a.y <= y) != (b.y <= y)).then(|| a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x))
        })
        .collect();
    crossings.sort_by(f32::total_cmp);
    crossings
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_follow_a_non_convex_outline() {
        // A "U": two prongs joined at the bottom.
        let u = [
            pos2(0.0, 0.0),
            pos2(3.0, 0.0),
            pos2(3.0, 7.0),
            pos2(7.0, 7.0),
            pos2(7.0, 0.0),
            pos2(10.0, 0.0),
            pos2(10.0, 10.0),
            pos2(0.0, 10.0),
        ];
        assert_eq!(inside_spans(&u, 5.0), vec![0.0, 3.0, 7.0, 10.0]);
        assert_eq!(inside_spans(&u, 8.0), vec![0.0, 10.0]);
        assert!(inside_spans(&u, 11.0).is_empty());
    }
}
