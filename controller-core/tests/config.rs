//! Configuration checks of `Agent::new` and the mends of issue 14: unsorted schedules,
//! triangle-index overflow, link counts that do not fit.

mod testkit;

use ph_formation_core::link::{link_estimates, LinkError, LinkOutput, MAX_LINK_ESTIMATES};
use ph_formation_core::{
    Agent, AgentConfig, AngleConfig, ConfigError, EstimatorMode, Fault, Schedule, ScheduleStep,
    Status, StepOutput, TriangleConfig, Vec2,
};
use testkit::{rng, strip, strip_positions, Formation, HostAgent};

fn angle(apex: u8, cos: f64) -> AngleConfig<f64> {
    AngleConfig {
        apex,
        cos_desired: cos,
        stiffness: 1.0,
        damping: 0.0,
        estimator_gain: 1.0,
    }
}

/// A fan of `k` triangles `(1, r, r + 1)`, `r = 2 … k + 1`, with agent 1 the apex of one
/// angle in each.
fn fan_config<const MT: usize>(k: usize) -> AgentConfig<f64, MT> {
    let mut c = AgentConfig::<f64, MT>::new(1);
    for r in 0..k {
        let (v, w) = (2 + r as u8, 3 + r as u8);
        let _ = c.triangles.push(TriangleConfig {
            vertices: [1, v, w],
            angles: [angle(1, 0.9), angle(v, 0.1)],
        });
    }
    c
}

fn step(at: f64, value: [f64; 2]) -> ScheduleStep<f64> {
    ScheduleStep { from: at, value }
}

#[test]
fn schedules_must_strictly_increase_and_be_finite() {
    let mut r = rng(1);
    let f = Formation::random(4, strip(4), &strip_positions(4, 0.1, &mut r), &mut r);
    let good = f.config::<f64>(0);
    for steps in [
        vec![step(1.0, [0.0; 2]), step(0.5, [1.0; 2])],
        vec![step(1.0, [0.0; 2]), step(1.0, [1.0; 2])],
        vec![step(f64::NAN, [0.0; 2])],
        vec![step(0.0, [f64::INFINITY, 0.0])],
    ] {
        let schedule = Schedule {
            steps: steps.iter().copied().collect(),
        };
        let mut c = good.clone();
        c.velocity_reference = schedule.clone();
        assert_eq!(
            HostAgent::new(c).err(),
            Some(ConfigError::BadSchedule),
            "v* {steps:?}"
        );
        let mut c = good.clone();
        if let Some(l) = c.leader.as_mut() {
            l.displacement = schedule;
        }
        assert_eq!(
            HostAgent::new(c).err(),
            Some(ConfigError::BadSchedule),
            "z* {steps:?}"
        );
    }
    let mut c = good;
    c.velocity_reference = Schedule {
        steps: [step(0.0, [1.0; 2]), step(2.0, [0.0; 2])]
            .into_iter()
            .collect(),
    };
    assert!(HostAgent::new(c).is_ok());
}

#[test]
fn communication_divisor_and_phase_are_checked() {
    let c = |every, phase| {
        let mut c = fan_config::<2>(2);
        c.comm_every = every;
        c.comm_phase = phase;
        Agent::<f64, 2, 4>::new(c).err()
    };
    assert_eq!(c(0, 0), Some(ConfigError::BadCommRate));
    assert_eq!(c(4, 4), Some(ConfigError::BadCommRate));
    assert_eq!(c(4, 3), None);
}

/// Angle indices used to be one byte: an agent in more than 127 triangles was refused as
/// having too many neighbours. Now any `MT` up to `MAX_MT` is indexed.
#[test]
fn agents_in_more_than_127_triangles_are_indexed() {
    let config = fan_config::<140>(130);
    let agent = Agent::<f64, 140, 140>::new(config).expect("130 triangles fit");
    assert_eq!(agent.neighbours().count(), 131);
    // Capacity of neighbours, not of indices, limits a fan with NB = 100.
    let err = Agent::<f64, 140, 100>::new(fan_config::<140>(130)).err();
    assert_eq!(err, Some(ConfigError::TooManyNeighbours));
}

/// The link never truncates or saturates a count silently.
#[test]
fn link_counts_are_never_truncated() {
    // 13 triangles with agent 1 the apex in each: 26 owned estimates > 24.
    let mut c = AgentConfig::<f32, 16>::new(1);
    for r in 0..13u8 {
        let _ = c.triangles.push(TriangleConfig {
            vertices: [1, 2 + r, 3 + r],
            angles: [
                AngleConfig {
                    apex: 1,
                    cos_desired: 0.9,
                    stiffness: 1.0,
                    damping: 0.0,
                    estimator_gain: 1.0,
                },
                AngleConfig {
                    apex: 2 + r,
                    cos_desired: 0.1,
                    stiffness: 1.0,
                    damping: 0.0,
                    estimator_gain: 1.0,
                },
            ],
        });
    }
    let agent = Agent::<f32, 16, 16>::new(c).expect("valid");
    assert!(agent.owned_estimates().count() > MAX_LINK_ESTIMATES);
    assert_eq!(
        link_estimates(&agent).err(),
        Some(LinkError::TooManyEstimates)
    );
    let small = Agent::<f32, 16, 16>::new({
        let mut c = AgentConfig::<f32, 16>::new(1);
        let _ = c.triangles.push(TriangleConfig {
            vertices: [1, 2, 3],
            angles: [
                AngleConfig {
                    apex: 1,
                    cos_desired: 0.9,
                    stiffness: 1.0,
                    damping: 0.0,
                    estimator_gain: 1.0,
                },
                AngleConfig {
                    apex: 2,
                    cos_desired: 0.1,
                    stiffness: 1.0,
                    damping: 0.0,
                    estimator_gain: 1.0,
                },
            ],
        });
        c
    })
    .expect("valid");
    assert_eq!(link_estimates(&small).map(|e| e.len()), Ok(2));
    // Frame counts beyond 255 keep their value.
    let out = StepOutput {
        force: Vec2::new(1.0f32, 0.0),
        status: Status::Safe(Fault::Stale(7)),
        saturated: false,
        degenerate: false,
    };
    let link = LinkOutput::new(&out, 300, 5);
    assert_eq!(link.frames, 300);
    assert_eq!(link.status, Status::Safe(Fault::Stale(7)));
    assert_eq!(link.fault_neighbour(), Some(7));
}

/// `copy_estimates` writes the values `owned_estimates` lists, in its order, in every
/// estimator mode (the measured mode owns none), and stops at the end of a short buffer.
#[test]
fn copy_estimates_is_owned_estimates_values() {
    use rand::Rng;
    for mode in [
        EstimatorMode::Shared,
        EstimatorMode::PerAgent,
        EstimatorMode::Measured,
    ] {
        let mut r = rng(7);
        let q = testkit::fan_positions(4, 0.05, &mut r);
        let mut f = Formation::random(q.len(), testkit::fan(4), &q, &mut r);
        f.mode = mode;
        for mut a in f.agents::<f64>() {
            let owned: Vec<_> = a.owned_estimates().collect();
            for e in &owned {
                assert!(a.set_estimate(&ph_formation_core::OwnedEstimate {
                    value: r.random_range(0.3..3.0),
                    ..*e
                }));
            }
            let values: Vec<f64> = a.owned_estimates().map(|e| e.value).collect();
            let mut out = vec![f64::NAN; values.len() + 2];
            assert_eq!(a.copy_estimates(&mut out), values.len(), "{mode:?}");
            assert_eq!(&out[..values.len()], &values[..], "{mode:?}");
            assert!(out[values.len()..].iter().all(|x| x.is_nan()));
            if mode == EstimatorMode::Measured {
                assert!(values.is_empty());
            }
            if let Some(short) = values.len().checked_sub(1) {
                let mut out = vec![0.0; short];
                assert_eq!(a.copy_estimates(&mut out), short);
                assert_eq!(&out[..], &values[..short]);
            }
        }
    }
}
