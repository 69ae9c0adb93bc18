//! The pour plot (`.png`): the rendered waveform with its haptic envelope and glug onsets, the
//! bottle's volume and its tilt, stacked on one time axis so a glug can be traced to the pour
//! (feature `plot`; a build without it refuses a plot by name).
//!
//! [`sink`] keeps what the plot needs as the render runs, [`series`] holds its series within a
//! bound however long the render, and [`draw`] draws it through the plot crate.

#[cfg(feature = "plot")]
mod draw;
#[cfg(feature = "plot")]
mod series;
#[cfg(feature = "plot")]
mod sink;

#[cfg(feature = "plot")]
pub use draw::{draw_pour_plot, PlotData};
#[cfg(feature = "plot")]
pub use series::Waveform;
#[cfg(feature = "plot")]
use sink::open;

use super::OutputFormat;
#[cfg(not(feature = "plot"))]
use super::{OutputError, Sink, SinkContext};

/// `.png`: the pour plot; read by people, not played.
pub(super) const FORMAT: OutputFormat = OutputFormat {
    name: "png",
    extension: "png",
    by_extension: true,
    built: cfg!(feature = "plot"),
    open,
    read_back: None,
    carries_c: "—",
};

/// Without the `plot` feature a plot is refused by name, not taken for an unknown format.
#[cfg(not(feature = "plot"))]
fn open<'a>(context: SinkContext<'a>) -> Result<Box<dyn Sink + 'a>, OutputError> {
    Err(OutputError::NoPlot {
        path: context.path.to_owned(),
    })
}
