//! The offline renderer: scene files ([`Scene`]) with their automation lanes ([`Automation`]),
//! rendered by [`render_scene`] through the engine into sinks such as [`WavFile`].

mod automation;
mod render;
mod scene;
mod wav;

pub use automation::Automation;
pub use render::{render_scene, render_scene_to_vec, RenderError, RenderSummary, BLOCK_SIZE};
pub use scene::{LaneBuffers, Scene, SceneError, DEFAULT_SCENE, MAX_DURATION_S};
pub use wav::{SampleFormat, WavError, WavFile};
