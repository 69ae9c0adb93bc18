//! The offline renderer: scene files ([`Scene`]) with their automation lanes ([`Automation`]),
//! rendered by [`render_scene`] through the engine; [`render_to_files`] feeds one render to the
//! [`sinks`] of every file asked for (WAV, CSV, the haptic clips written from the glugs of
//! [`clips`], the pour plot, the tables of units and of the bottle's state), all or nothing,
//! refused up front if it cannot fit in memory; [`render_tables`] gives the tables in memory.

mod automation;
pub mod beyond_fit;
pub mod clips;
pub mod fidelity;
pub mod loudness;
mod memory;
mod outputs;
mod render;
mod resample;
mod scene;
pub mod silence;
pub mod sinks;
pub mod steps;
mod tables;
pub mod trim;
pub mod variations;

pub use automation::Automation;
pub use memory::{available_bytes, human_bytes};
pub use outputs::{remove_temporary_files, render_to_files, RenderReport};
pub use render::{
    render_scene, render_scene_to_vec, BottleReport, RenderError, RenderObserver, RenderSummary,
};
pub use resample::Resample;
pub use scene::{
    InputFile, LaneBuffers, Scene, SceneError, DEFAULT_SCENE, MAX_DURATION_S, MAX_SCENE_BYTES,
};
pub use sinks::{
    Clipped, Output, OutputError, OutputFormat, OutputOptions, PlatformOptions, SampleFormat,
    WavError,
};
pub use tables::{
    csv_header, render_tables, render_tables_until, Column, StateRate, StateRateError, StateRow,
    Tables, TablesError, UnitRow,
};
