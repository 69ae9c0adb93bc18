//! The reports: how exact the synthesis paths are against the f64 reference ([`accuracy`]), how
//! the engine behaves on stiff and extreme cases ([`stability`]), and the timed renders both
//! measure with ([`timing`]). The `sake-glug accuracy` and `stability` commands print them.

pub mod accuracy;
#[cfg(feature = "plot")]
mod accuracy_plot;
pub mod stability;
pub mod timing;

#[cfg(feature = "plot")]
pub use accuracy_plot::draw_accuracy_plot;
