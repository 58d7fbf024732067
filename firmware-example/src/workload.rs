//! The measured control step and its configurations.
//!
//! **Swap point.** [`control_step`] is the one function that the
//! measurements (and the demo) call once per control step. Today its body is
//! a stand-in: a small f32 computation with the shape of a triangle-based
//! formation controller (per triangle: a signed area, its error and its
//! gradient with respect to this robot's position). When the controller API
//! of `controller-core` is ready, replace [`Scenario`] by the controller's
//! state/inputs and the body of [`control_step`] by the controller's step;
//! keep [`STEP_CONFIGS`] (names are the budget keys `insn_step_<name>` in
//! `firmware-example/budgets.toml`) and [`Scenario::new`] (builds the inputs
//! of one configuration deterministically).

use crate::hal::Vec2;

/// One measured configuration of the control step.
#[derive(Clone, Copy, Debug)]
pub struct StepConfig {
    /// Short name; the budget key is `insn_step_<name>`.
    pub name: &'static str,
    /// Number of triangles (formation constraints) this robot takes part in.
    pub triangles: usize,
}

/// The configurations measured by the `measure` binary, in order. Region id
/// `i + 1` measures `STEP_CONFIGS[i]` (id 0 is the empty calibration region).
pub const STEP_CONFIGS: [StepConfig; 4] = [
    StepConfig {
        name: "tri1",
        triangles: 1,
    },
    StepConfig {
        name: "tri2",
        triangles: 2,
    },
    StepConfig {
        name: "tri4",
        triangles: 4,
    },
    StepConfig {
        name: "tri8",
        triangles: 8,
    },
];

/// Largest number of triangles a [`Scenario`] holds.
pub const MAX_TRIANGLES: usize = 8;

/// Force magnitude limit per axis of the stand-in step, in newtons.
pub const MAX_FORCE: f32 = 0.5;

/// Inputs of one control step of the stand-in workload.
#[derive(Clone, Debug)]
pub struct Scenario {
    /// This robot's position.
    pub own: Vec2,
    /// For each triangle, the positions of the two other robots in it.
    pub others: [[Vec2; 2]; MAX_TRIANGLES],
    /// Number of triangles in use (`<= MAX_TRIANGLES`).
    pub triangles: usize,
    /// Desired signed area of every triangle, in m².
    pub target_area: f32,
    /// Proportional gain, N/m³.
    pub gain: f32,
}

impl Scenario {
    /// Deterministic inputs for `cfg`: the other robots sit on a ring around
    /// this one, slightly off the desired shape so that every term is
    /// non-zero.
    pub fn new(cfg: &StepConfig) -> Self {
        let mut others = [[[0.0; 2]; 2]; MAX_TRIANGLES];
        for (k, pair) in others.iter_mut().enumerate() {
            let a = k as f32;
            pair[0] = [1.0 + 0.10 * a, 0.2 * a - 0.5];
            pair[1] = [0.3 * a - 1.0, 1.2 - 0.05 * a];
        }
        Scenario {
            own: [0.05, -0.02],
            others,
            triangles: cfg.triangles.min(MAX_TRIANGLES),
            target_area: 0.8,
            gain: 0.6,
        }
    }
}

/// One control step: returns the force this robot should apply.
///
/// Stand-in body (f32 only, no library calls): for each triangle
/// `(p, q, r)` with `p` this robot, the signed area
/// `A = ((q - p) × (r - p)) / 2` is driven towards the target, i.e.
/// `F -= k · (A - A*) · ∂A/∂p` with `∂A/∂p = perp(q - r) / 2`; the sum is
/// clamped per axis to [`MAX_FORCE`].
#[inline(never)]
pub fn control_step(s: &Scenario) -> Vec2 {
    let [px, py] = s.own;
    let mut f = [0.0f32; 2];
    for [q, r] in &s.others[..s.triangles.min(MAX_TRIANGLES)] {
        let (ux, uy) = (q[0] - px, q[1] - py);
        let (vx, vy) = (r[0] - px, r[1] - py);
        let area = 0.5 * (ux * vy - uy * vx);
        let err = area - s.target_area;
        // ∂A/∂p = 0.5 * (q_y - r_y, r_x - q_x)
        let (gx, gy) = (0.5 * (q[1] - r[1]), 0.5 * (r[0] - q[0]));
        f[0] -= s.gain * err * gx;
        f[1] -= s.gain * err * gy;
    }
    [
        f[0].clamp(-MAX_FORCE, MAX_FORCE),
        f[1].clamp(-MAX_FORCE, MAX_FORCE),
    ]
}
