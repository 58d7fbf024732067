//! The actuator's bounds (SPEC S21c): a blocked vehicle (its measured velocity stays 0
//! while the law keeps pushing) does not let the virtual velocity run away, the safe
//! output and a stall start again from the measured velocity.

use ph_formation_core::actuate::{ActuateError, VelocityCommand, VirtualMass};

const DT: f64 = 0.01;

fn plant() -> VirtualMass<f64> {
    // No speed limit: only the gap bound can stop the wind-up.
    VirtualMass::new(1.0, [0.2; 2], f64::INFINITY)
        .and_then(|p| p.with_lead(0.2))
        .expect("valid plant")
}

fn gap(c: &VelocityCommand<f64>, measured: [f64; 2]) -> f64 {
    let v = c.command().expect("stepped");
    (v[0] - measured[0]).hypot(v[1] - measured[1])
}

/// 10 s of a constant 1 N on a vehicle that does not move: without the bound the virtual
/// velocity winds up to about U/D^r (5 m/s); with it, it stays within the bound plus one
/// step's change, and the setpoint is bounded too.
#[test]
fn a_blocked_vehicle_does_not_let_the_virtual_velocity_run_away() {
    let blocked = |p: VirtualMass<f64>| {
        let mut c = VelocityCommand::new(p);
        let mut worst_setpoint: f64 = 0.0;
        for _ in 0..1000 {
            let sp = c.step([1.0, 0.0], [0.0, 0.0], DT);
            worst_setpoint = worst_setpoint.max(sp[0].hypot(sp[1]));
        }
        (gap(&c, [0.0; 2]), worst_setpoint)
    };
    let (unbounded, _) = blocked(plant());
    assert!(unbounded > 3.0, "{unbounded}");
    let g = 0.3;
    let (bounded, setpoint) = blocked(plant().with_max_gap(g).unwrap());
    // One step of S20 from the bound: at most g + Δt/m · U.
    assert!(bounded <= g + DT * 1.0 + 1e-12, "{bounded}");
    assert!(bounded > 0.9 * g, "{bounded}");
    // The led setpoint (S21) adds τ_lead times one step's change at most.
    assert!(setpoint <= g + 0.2 * 1.0 + DT + 1e-9, "{setpoint}");
    // Released, the vehicle is at most the bound behind: no leftover wind-up.
    assert_eq!(
        plant().with_max_gap(f64::NAN),
        Err(ActuateError::MaxGap),
        "NaN gap"
    );
    assert_eq!(plant().with_max_gap(0.0), Err(ActuateError::MaxGap));
}

/// The bound moves the virtual velocity towards the measured one along their difference,
/// and not at all when within it; a non-finite measurement leaves it alone.
#[test]
fn the_gap_is_closed_along_the_difference_only_beyond_the_bound() {
    let p = VirtualMass::new(1.0, [0.0; 2], f64::INFINITY)
        .and_then(|p| p.with_max_gap(0.5))
        .unwrap();
    let mut c = VelocityCommand::resume(p, Some([1.0, 1.0]));
    let v = c.step([0.0; 2], [1.0, 0.0], DT);
    assert_eq!(v, [1.0, 0.5]);
    let mut c = VelocityCommand::resume(p, Some([1.0, 1.0]));
    assert_eq!(c.step([0.0; 2], [1.0, 0.6], DT), [1.0, 1.0]);
    let mut c = VelocityCommand::resume(p, Some([1.0, 1.0]));
    assert_eq!(c.step([0.0; 2], [f64::NAN, 0.0], DT), [1.0, 1.0]);
}

/// A step over more than the stall limit (a stalled task) starts from the measured
/// velocity, as the first step does; within the limit it goes on from the virtual one.
#[test]
fn a_stall_restarts_from_the_measured_velocity() {
    let p = VirtualMass::new(1.0, [0.0; 2], f64::INFINITY)
        .and_then(|p| p.with_max_interval(0.1))
        .unwrap();
    let mut c = VelocityCommand::resume(p, Some([1.0, 0.0]));
    assert_eq!(c.step([0.0; 2], [0.2, 0.0], 0.1), [1.0, 0.0]);
    assert_eq!(c.step([0.0; 2], [0.2, 0.0], 0.5), [0.2, 0.0]);
    assert_eq!(
        VirtualMass::new(1.0, [0.0; 2], 1.0).and_then(|p| p.with_max_interval(-1.0)),
        Err(ActuateError::MaxInterval)
    );
}

/// On the safe output the caller re-seeds the command (S21c): the next setpoint damps
/// the vehicle's own velocity instead of a virtual one that ran ahead of it.
#[test]
fn the_safe_output_restarts_from_the_measured_velocity() {
    let mut c = VelocityCommand::new(plant());
    for _ in 0..100 {
        c.step([1.0, 0.0], [0.0, 0.0], DT);
    }
    c.reseed();
    let safe_force = [-0.1 * 0.3, 0.0]; // −c v with c = 0.1 at the measured 0.3 m/s
    let v = c.command();
    assert_eq!(v, None);
    c.step(safe_force, [0.3, 0.0], DT);
    let v = c.command().unwrap();
    assert!(v[0] < 0.3 && v[0] > 0.29, "{v:?}");
}

/// The re-seed keeps the virtual acceleration of the second-order lead (S21b/S21d), so
/// the setpoint's jerk term goes on from it; a restart (a reboot, a stall) drops it and
/// the first step has no jerk term. The two differ (negative control).
#[test]
fn the_reseed_keeps_the_lead_and_the_restart_drops_it() {
    let second = plant()
        .with_second_lead(0.04)
        .and_then(|p| p.with_jerk_filter(0.03))
        .unwrap();
    let run = |reseed: bool| {
        let mut c = VelocityCommand::new(second);
        for _ in 0..50 {
            c.step([1.0, 0.0], [0.0, 0.0], DT);
        }
        let accel = c.accel();
        if reseed {
            c.reseed();
            assert_eq!(c.accel(), accel);
        } else {
            c.restart();
            assert_eq!(c.accel(), None);
        }
        assert_eq!(c.command(), None);
        c.step([0.0; 2], [0.3, 0.0], DT)
    };
    let (kept, dropped) = (run(true), run(false));
    // Without force, from 0.3 m/s: friction decelerates; the kept acceleration (about
    // 1 m/s² before) makes the filtered jerk strongly negative, the restart has none.
    assert!(dropped[0] > 0.2, "{dropped:?}");
    assert!(kept[0] < dropped[0] - 0.5, "{kept:?} vs {dropped:?}");
}
