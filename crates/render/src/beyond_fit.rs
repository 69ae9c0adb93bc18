//! Whether a render plays a fitted model beyond the volumes its recordings were made at (MODEL.md
//! §13): one sentence for every front end (the command line's warning and Python's).

use super::render::RenderSummary;
use super::scene::Scene;

/// Why `scene`, rendered as `summary` says, plays its fitted model far beyond what was recorded,
/// or `None`: no fitted volumes, no unit, or units within the fit's volumes and their margin.
pub fn beyond_fit(scene: &Scene, summary: &RenderSummary) -> Option<String> {
    let fitted = scene.fitted_volumes?;
    let (lowest_ml, highest_ml) = summary.unit_volumes_ml?;
    fitted.exceeded_by(lowest_ml, highest_ml, scene.config.capacity_ml)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::render_scene_to_vec;

    fn warning(text: &str) -> Option<String> {
        let scene = Scene::parse(text).unwrap();
        let (_, summary) = render_scene_to_vec(&scene).unwrap();
        beyond_fit(&scene, &summary)
    }

    #[test]
    fn a_full_pour_of_a_model_fitted_near_full_warns_and_a_short_one_does_not() {
        let full = "tilt_deg = 135\n[fit]\nvolumes_ml = [275.0, 295.0]\n";
        let why = warning(full).expect("a full pour of a model fitted at 275–295 ml warns");
        assert!(why.contains("275–295 ml"), "{why}");
        // Glugs down to 250 ml only: within the fit's volumes and 30 ml.
        let short = "tilt_deg = 135\nduration_s = 0.9\n[fit]\nvolumes_ml = [275.0, 295.0]\n";
        assert_eq!(warning(short), None);
        assert_eq!(warning(crate::DEFAULT_SCENE), None);
    }
}
