//! `host-sim design`: from a target shape to a scenario (pure functions, no I/O except
//! reading a points file).
//!
//! * [`points`]: target point sets (CSV, TOML, or generators: polygon, lattices, strip,
//!   random disc);
//! * [`laman`]: the triangulated Laman graph (SPEC §3) with two controlled angles per
//!   triangle, built to keep every angle far from 0 and π ([`laman::construct`]);
//! * [`colouring`]: one-byte wire ids unique within two hops;
//! * [`shape`]: a formation compared with its target up to similarity and mirror, and
//!   which triangles are folded.

pub mod error;
mod geometry;
mod grow;
pub mod laman;
mod neighbours;
pub mod points;

pub use error::DesignError;
pub use laman::{
    construct, verify, Construction, ControlledAngle, DesignOptions, DesignTriangle, Figures,
};
pub use points::{Generator, Point};
