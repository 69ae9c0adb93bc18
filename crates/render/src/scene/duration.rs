//! How long a scene may last: one limit, which the scene, its `[variations]` table and the
//! renderer all read.

/// Longest render a scene may ask for (and the limit on one that never falls silent).
pub const MAX_DURATION_S: f64 = 86_400.0;
