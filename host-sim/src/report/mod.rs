//! Reports (placeholder).

pub mod csv;
pub mod plot;
