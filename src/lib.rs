//! Sake Glug: the glug vibration of liquid poured from a Japanese sake bottle, as a CLAP/VST3
//! plugin and an offline renderer that drive the same engine.

pub mod accuracy;
pub mod engine;
pub mod reference;
pub mod timed_render;
