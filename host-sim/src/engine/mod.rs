//! The engine (placeholder).

pub mod continuous;
pub mod controller;
pub mod hil;
pub mod plant;
pub mod radio;
pub mod sampled;
pub mod sensors;
