//! The offline renderer: scene files ([`Scene`]) with their automation lanes ([`Automation`]),
//! rendered by [`render_scene`] through the engine into sinks: a WAV file ([`WavFile`]), and
//! from the same pass the haptic clips of [`clips`] and the pour plot ([`render_to_files`]).

mod automation;
pub mod clips;
mod outputs;
#[cfg(feature = "plot")]
pub mod plot;
mod render;
mod scene;
mod wav;

pub use automation::Automation;
pub use outputs::{render_to_files, OutputError, OutputFormat, OutputOptions, RenderReport};
pub use render::{
    render_scene, render_scene_to_vec, RenderError, RenderObserver, RenderSummary, BLOCK_SIZE,
};
pub use scene::{
    InputFile, InputFileError, LaneBuffers, Scene, SceneError, DEFAULT_SCENE, MAX_DURATION_S,
};
/// Every file the crate writes is first written as one of these, beside its target.
#[cfg(feature = "plugin")]
pub(crate) use wav::temp_file_builder;
pub use wav::{SampleFormat, WavError, WavFile};
