//! The engine against the model of MODEL.md: the drain and onsets (§2–4), the units (§5, the
//! glide of §5.2), the f64 reference (§9), the bottle as data (§12) and the work it skips.

#[path = "../support/mod.rs"]
mod support;

mod amplitude;
mod drain;
mod glide;
mod headspace;
mod onsets;
mod output_ramps;
mod pour_spans;
mod reference_match;
mod unchanged_blocks;
mod units;
mod work_skipped;
