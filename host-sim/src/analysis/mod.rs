//! Analysis of the true state (placeholder, split later).

pub mod diagnostics;
