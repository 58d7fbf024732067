//! `host-sim design`: from a target shape to a scenario (pure functions; the only I/O is
//! [`points::read_points`]).
//!
//! * [`points`]: target point sets (CSV, TOML, or generators: polygon, lattices, strip,
//!   random disc);
//! * [`laman`]: the triangulated Laman graph (SPEC §3) with two controlled angles per
//!   triangle, built to keep every angle far from 0 and π ([`laman::construct`]);
//! * [`initial`] and [`render`]: initial positions and the scenario TOML, with the target
//!   in a `[target]` section;
//! * [`colouring`]: one-byte wire ids unique within two hops;
//! * [`shape`]: a formation compared with its target up to similarity and mirror, and
//!   which triangles are folded.
//!
//! ```
//! use ph_formation_sim::design::{construct, render_scenario, DesignOptions, Generator, ScenarioOptions};
//! let points = Generator::TriangularLattice { n: 10, spacing: 1.0 }.points().unwrap();
//! let c = construct(&points, &DesignOptions::default()).unwrap();
//! assert_eq!(c.triangles.len(), 8);
//! let toml = render_scenario(&points, &c, &DesignOptions::default(), &ScenarioOptions::default()).unwrap();
//! assert!(toml.contains("[target]"));
//! ```

/// One-byte wire ids (lives in the model layer, which the loader uses too).
pub use crate::model::wire_ids as colouring;
pub mod error;
pub mod fov;
mod geometry;
mod grow;
pub mod initial;
pub mod laman;
mod neighbours;
pub mod points;
pub mod render;
/// Shape comparison (lives in the model layer, which the run's outcome uses too).
pub use crate::model::shape;

pub use colouring::{
    adjacency_from_triangles, check_distance2, distance2_colouring, ColouringError,
};
pub use error::{DesignError, VerifyError};
pub use fov::{construct_for_camera, view_check, CameraDesign, CameraOptions};
pub use initial::{initial_positions, Initial, Perturbation, Scale};
pub use laman::{
    construct, verify, Construction, ControlledAngle, DesignOptions, DesignTriangle, Figures,
};
pub use points::{read_points, Generator, Point};
pub use render::{render_scenario, CameraView, ScenarioOptions, Template};
pub use shape::{
    compare, fit_similarity, folded_triangles, ShapeComparison, ShapeError, SimilarityFit,
};
