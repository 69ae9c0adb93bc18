//! Sake Glug: the glug vibration of liquid poured from a Japanese sake bottle.
//!
//! One engine, three products:
//!
//! - [`engine`]: the model of `docs/MODEL.md` (controls → pour → synthesis), shared by all;
//! - [`plugin`]: the CLAP/VST3 plugin (feature `plugin`, its egui editor with `editor`), also
//!   run as the standalone app `sake-glug-standalone` (feature `standalone`);
//! - [`offline`]: scene files, automation lanes, the offline renderer and its file writers, used
//!   by the `sake-glug` command line (feature `offline`, which `cli` brings);
//! - [`reports`]: the accuracy and stability reports the command line prints (feature `reports`,
//!   which `cli` brings).
//!
//! The plugin compiles neither `offline` nor `reports`. [`device`] holds what a tilt device sends
//! (the MIDI mapping and decoder, OSC from phones, and with `offline` recorded MIDI and CSV
//! takes), shared by the plugin and the offline renderer. Data flows one way: scene, take or
//! host → controls → pour → synthesis → sinks (WAV, clips, plot, audio out).
//!
//! [`analysis`] (feature `analysis`, which `cli` brings) reads the trial logs of the paper's two
//! studies and scales or fits them.
//! [`study`] runs the paper's listening studies on the offline renderer's stimuli (feature
//! `study`, which `cli` brings; presentation on JACK with `audio`).
//!
//! [`text::printable`] escapes the control characters of outside text echoed in any message.
#![warn(missing_docs)]

#[cfg(feature = "analysis")]
pub mod analysis;
pub mod device;
pub mod engine;
#[cfg(feature = "offline")]
mod files;
#[cfg(feature = "fit")]
pub mod fit;
#[cfg(feature = "model")]
pub mod model;
#[cfg(feature = "offline")]
pub mod offline;
#[cfg(feature = "plugin")]
pub mod plugin;
#[cfg(feature = "reports")]
pub mod reports;
#[cfg(feature = "study")]
pub mod study;
pub mod text;

/// The plugin types, at the crate's root for nice-plug's export macros.
#[cfg(feature = "plugin")]
pub use plugin::{SakeGlug, SakeGlugVst3};
