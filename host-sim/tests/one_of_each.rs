//! Issue 29's "one of each": the simulator uses the core's one implementation of what it
//! promises (continuous mode's output), and the shortcut switches follow the models'
//! one classification of their fields.

use controller_core::Status;
use host_sim::engine::ContinuousSim;
use host_sim::model::Mode;
use host_sim::scenario::strip_model;

/// Continuous mode's output is the core's `Agent::output`: an agent whose velocity is not
/// finite gets the safe command with a zero (finite) force, never a NaN (the continuous
/// simulator once computed `−safe_damping · v` itself, without the core's guard).
#[test]
fn continuous_mode_never_outputs_a_non_finite_force() {
    let mut model = strip_model(4, 1.0);
    model.mode = Mode::Continuous;
    for v in [[f64::NAN, 0.0], [0.0, f64::INFINITY]] {
        model.agents[1].velocity = v;
        let mut sim = ContinuousSim::new(&model).expect("builds");
        let out = sim.output_of(0.0, 1).expect("agent 1 exists");
        assert!(matches!(out.status, Status::Safe(_)), "{out:?}");
        assert_eq!([out.force.x, out.force.y], [0.0, 0.0], "{out:?}");
        // Its neighbours see a non-finite bearing rate: safe too, with finite forces.
        for i in [0, 2, 3] {
            let out = sim.output_of(0.0, i).expect("exists");
            assert!(
                out.force.x.is_finite() && out.force.y.is_finite(),
                "{i}: {out:?}"
            );
        }
    }
    assert!(ContinuousSim::new(&model)
        .unwrap()
        .output_of(0.0, 4)
        .is_none());
}
