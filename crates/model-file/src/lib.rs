//! Model files (MODEL.md §12.1): a scene file that describes one bottle and one liquid, as
//! `sake-glug fit` writes it, read into a validated [`ModelFile`] that the offline renderer layers
//! under a scene ([`sake_glug_render::Scene::load_with_model`]) and the plugin loads into its
//! parameters and saved state. Compiled by both (feature `model`), so a model means the same
//! everywhere.

mod file;
mod fitted;

pub use file::{curve_points, ModelFile, ModelFileError, MAX_MODEL_BYTES};
pub use fitted::{FittedVolumes, FITTED_VOLUMES_KEY, FITTED_VOLUMES_MARGIN};
