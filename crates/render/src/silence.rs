//! Why a render poured nothing audible: one sentence for every front end (the command line's
//! warning and Python's), so that both say the same.

use super::render::RenderSummary;
use super::scene::Scene;
use sake_glug_engine::{Constant, Control};

/// Steps of the tilt searched for where a bottle starts to pour (°).
const TILT_STEP_DEG: f64 = 0.1;

/// Why `scene`, rendered as `summary` says, is silent (`nothing sounds: …`), or `None` if
/// something sounded. The reason is the first that holds: the bottle is empty, it never tilts
/// past where its liquid pours, it pours without a glug, every glug it makes is silent.
pub fn why_silent(scene: &Scene, summary: &RenderSummary) -> Option<String> {
    if summary.peak > 0.0 {
        return None;
    }
    reason(scene, summary).map(|reason| format!("nothing sounds: {reason}"))
}

fn reason(scene: &Scene, summary: &RenderSummary) -> Option<String> {
    let fill_key = Control::Fill.quantity().scene_key;
    let tilt_key = Control::Tilt.quantity().scene_key;
    let fills: Vec<f64> = scene.lanes.fill_percent.values().collect();
    let most_fill = fills.iter().copied().fold(0.0, f64::max);
    // A take moves the controls where the lanes do not say: only its own sentence holds then.
    if scene.take.is_none() {
        if most_fill <= 0.0 {
            return Some(format!(
                "the bottle is empty: `{fill_key}` is 0 throughout, so nothing pours"
            ));
        }
        let tilts: Vec<f64> = scene.lanes.tilt_deg.values().collect();
        let lowest = tilts.iter().copied().fold(f64::INFINITY, f64::min);
        let highest = tilts.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let fraction = most_fill / 100.0;
        let rest = &scene.config.curves.rest;
        // Lanes are linear between their points: the tilts reached are [lowest, highest].
        let pours_at = |tilt: f64| fraction > rest.at(tilt);
        let reached = tilt_grid(lowest, highest);
        if !reached.into_iter().any(pours_at) {
            let first_pouring = tilt_grid(0.0, 180.0)
                .into_iter()
                .find(|&tilt| pours_at(tilt));
            let tilt_range = if lowest == highest {
                format!("stays at {lowest}°")
            } else {
                format!("stays within {lowest}°–{highest}°")
            };
            return Some(match first_pouring {
                Some(tilt) => format!(
                    "the bottle never tilts past where it pours: `{tilt_key}` {tilt_range}, and a \
                     bottle filled to {most_fill} % starts to pour past {tilt:.1}°"
                ),
                None => format!(
                    "the bottle never pours: filled to {most_fill} %, its rest curve holds the \
                     liquid at every tilt"
                ),
            });
        }
    }
    if summary.units == 0 {
        return Some(if summary.samples == 0 {
            "nothing pours and no glug sounds (0 samples)".to_owned()
        } else {
            format!(
                "no glug: the bottle lets in no air pocket within the scene's {:.3} s (a glug \
                 comes only while the mouth is under the liquid, MODEL.md §2, §4)",
                summary.duration_s()
            )
        });
    }
    Some(format!(
        "its {} glugs are all silent: each came below `{}` (the amplitude law is 0 there, \
         MODEL.md §12), at an output gain too low, or with both components below 20 Hz or at \
         or above Nyquist ({} Hz)",
        summary.units,
        Constant::SilentBelow.quantity().scene_key,
        scene.sample_rate as f64 / 2.0
    ))
}

/// Tilts from `low` to `high` (°) in steps of [`TILT_STEP_DEG`], both ends included.
fn tilt_grid(low: f64, high: f64) -> Vec<f64> {
    // NaN or an empty range (no tilt reached) gives no tilt.
    if low.partial_cmp(&high).is_none_or(|order| order.is_gt()) {
        return Vec::new();
    }
    let steps = ((high - low) / TILT_STEP_DEG).floor() as usize;
    (0..=steps)
        .map(|step| low + step as f64 * TILT_STEP_DEG)
        .chain(std::iter::once(high))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::render_scene_to_vec;

    fn reason(text: &str) -> Option<String> {
        let scene = Scene::parse(text).unwrap();
        let (_, summary) = render_scene_to_vec(&scene).unwrap();
        why_silent(&scene, &summary)
    }

    #[test]
    fn an_upright_bottle_never_tilts_past_where_it_pours() {
        let why = reason("seed = 7\n[glug]\nf1_hz = 90\n").unwrap();
        assert!(why.contains("never tilts past where it pours"), "{why}");
        assert!(why.contains("stays at 0°"), "{why}");
    }

    #[test]
    fn an_empty_bottle_is_named_empty() {
        let why = reason("tilt_deg = 135\nfill_percent = 0\n").unwrap();
        assert!(why.contains("the bottle is empty"), "{why}");
    }

    #[test]
    fn glugs_below_the_silent_volume_are_named() {
        let why = reason("tilt_deg = 135\nfill_percent = 25\n").unwrap();
        assert!(why.contains("all silent"), "{why}");
    }

    #[test]
    fn the_default_pour_is_not_silent() {
        assert_eq!(reason(crate::DEFAULT_SCENE), None);
    }
}
