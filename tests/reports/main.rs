//! The reports at test lengths: accuracy against the f64 reference and the stability catalogue.

#[path = "../support/mod.rs"]
mod support;

mod accuracy;
mod stability;
