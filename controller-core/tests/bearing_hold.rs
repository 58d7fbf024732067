//! A bearing missing for some ticks (SPEC §12, S18–S19): held by the finite difference,
//! predicted by the bearing tracker while younger than `Limits::bearing_hold`, the output
//! nominal meanwhile; past the hold the safe output with `MissingBearing`; the bearing
//! back, the law on it at once. Three agents of one triangle move at constant velocities
//! (closed-form positions); they step on exact bearings and exchange their data directly.

mod testkit;

use ph_formation_core::geometry::bearing_rate;
use ph_formation_core::{
    BearingFilter, ConfigError, Fault, Measurements, Status, StepOutput, TrackerConfig, Vec2,
};
use testkit::{bearings, id, Formation, HostAgent};

const DT: f64 = 0.01;

/// The triangle 0, 1, 2 with angles at 0 and 1; the agents' positions `q0 + v t`.
struct World {
    f: Formation,
    q0: [Vec2<f64>; 3],
    v: [Vec2<f64>; 3],
    agents: Vec<HostAgent<f64>>,
    /// The tick about to run.
    k: usize,
}

impl World {
    fn new(filter: BearingFilter<f64>, hold: f64) -> Self {
        let q0 = [
            Vec2::new(0.0, 0.0),
            Vec2::new(1.2, 0.1),
            Vec2::new(0.5, 1.0),
        ];
        // Distinct velocities: every bearing turns (about 0.3–0.6 rad/s).
        let v = [
            Vec2::new(0.1, -0.2),
            Vec2::new(-0.2, 0.4),
            Vec2::new(0.3, 0.1),
        ];
        let f = Formation::random(3, vec![[0, 1, 2]], &q0, &mut testkit::rng(7)).formation_only();
        let agents = (0..3)
            .map(|i| {
                let mut c = f.config::<f64>(i);
                c.bearing_filter = filter;
                c.limits.bearing_hold = hold;
                HostAgent::new(c).expect("valid configuration")
            })
            .collect();
        Self {
            f,
            q0,
            v,
            agents,
            k: 0,
        }
    }

    /// The same world with neighbour timeout `timeout` (s) instead of the testkit's
    /// (none to speak of), before the first tick.
    fn with_timeout(mut self, timeout: f64) -> Self {
        for a in &mut self.agents {
            let mut c = a.config().clone();
            c.limits.neighbour_timeout = timeout;
            *a = HostAgent::new(c).expect("valid configuration");
        }
        self
    }

    fn t(&self) -> f64 {
        self.k as f64 * DT
    }

    fn q(&self, i: usize, t: f64) -> Vec2<f64> {
        self.q0[i] + self.v[i] * t
    }

    /// The exact bearing from `i` to `j` at `t` and its rate (S2), in closed form.
    fn truth(&self, i: usize, j: usize, t: f64) -> (Vec2<f64>, Vec2<f64>) {
        let d = self.q(j, t) - self.q(i, t);
        let s = d / d.norm();
        (s, bearing_rate(&s, &(self.v[j] - self.v[i]), d.norm()))
    }

    /// One tick: every agent steps on its exact bearings, less those in `missing`
    /// (`(agent, neighbour)`), then they exchange. Returns the outputs.
    fn tick(&mut self, missing: &[(usize, usize)]) -> Vec<StepOutput<f64>> {
        let t = self.t();
        let s = testkit::State {
            q: (0..3).map(|i| self.q(i, t)).collect(),
            v: self.v.to_vec(),
        };
        let mut out = Vec::new();
        for i in 0..3 {
            let b: Vec<_> = bearings::<f64>(&self.f, &s, i, false)
                .into_iter()
                .filter(|b| !missing.contains(&(i, usize::from(b.neighbour) - 1)))
                .collect();
            let m = Measurements {
                time: t,
                dt: if self.k == 0 { 0.0 } else { DT },
                velocity: self.v[i],
                bearings: &b,
                partner_offset: None,
            };
            out.push(self.agents[i].step(&m));
        }
        for i in 0..3 {
            for j in 0..3 {
                if i != j {
                    let src = self.agents[j].clone();
                    self.agents[i].receive_direct(&src).expect("neighbour");
                }
            }
        }
        self.k += 1;
        out
    }

    /// Ticks with every bearing (nominal once the agents have heard each other: from the
    /// second tick).
    fn run(&mut self, ticks: usize) {
        for _ in 0..ticks {
            let first = self.k == 0;
            let out = self.tick(&[]);
            assert!(
                first || out.iter().all(|o| o.status == Status::Nominal),
                "{out:?}"
            );
        }
    }

    /// Agent `i`'s bearing and rate to `j` this tick (`None`: missing).
    fn used(&self, i: usize, j: usize) -> Option<(Vec2<f64>, Vec2<f64>)> {
        self.agents[i].bearing(id(j))
    }
}

/// The angle between two unit vectors (rad).
fn angle(a: &Vec2<f64>, b: &Vec2<f64>) -> f64 {
    (a.x * b.y - a.y * b.x).atan2(a.dot(b)).abs()
}

/// Agent 0 loses its bearing to 1 (an apex's bearing to a far vertex) and agent 2 its
/// bearing to 0 (a far vertex's bearing to the apex).
const GAP: [(usize, usize); 2] = [(0, 1), (2, 0)];

#[test]
fn the_tracker_predicts_a_missing_bearing_along_the_true_motion_until_the_hold() {
    let hold = 9.5 * DT; // off the tick boundaries (sums of DT are not exact)
    let mut w = World::new(BearingFilter::Tracker(TrackerConfig::default()), hold);
    // Exact bearings: the tracks' inverse distances converge under the relative motion.
    w.run(200);
    let last = w.used(0, 1).expect("measured").0;
    let mut worst_pred = 0.0f64;
    let mut worst_rate = 0.0f64;
    let mut held_error = 0.0f64;
    // Nine ticks without the bearings (τ = 0.01 … 0.09 s < T_h): nominal, predicted.
    for _ in 0..9 {
        let t = w.t();
        let out = w.tick(&GAP);
        assert!(out.iter().all(|o| o.status == Status::Nominal), "{out:?}");
        for (i, j) in GAP {
            let (s, rate) = w.used(i, j).expect("predicted within the hold");
            let (s_true, rate_true) = w.truth(i, j, t);
            worst_pred = worst_pred.max(angle(&s, &s_true));
            worst_rate = worst_rate.max((rate - rate_true).norm() / rate_true.norm());
        }
        held_error = angle(&last, &w.truth(0, 1, t).0);
    }
    // The true bearing moved by `held_error` (what holding it would miss); the
    // prediction follows it to within a small fraction of that (what is left comes from
    // the track's inverse distance, still converging: 0.03 rad moved, 2·10⁻⁴ rad off).
    assert!(held_error > 0.02, "the bearing moved {held_error} rad");
    assert!(
        worst_pred < held_error / 50.0,
        "prediction error {worst_pred} rad against {held_error} rad of motion"
    );
    assert!(worst_rate < 1e-2, "relative rate error {worst_rate}");
    // τ = 0.10 s > T_h: missing, the safe output naming it.
    let out = w.tick(&GAP);
    assert_eq!(out[0].status, Status::Safe(Fault::MissingBearing(id(1))));
    assert_eq!(out[2].status, Status::Safe(Fault::MissingBearing(id(0))));
    assert!(w.used(0, 1).is_none());
    assert_eq!(
        out[0].force,
        w.v[0] * -w.agents[0].config().limits.safe_damping
    );
    let out = w.tick(&GAP);
    assert_eq!(out[0].status, Status::Safe(Fault::MissingBearing(id(1))));
    // Back: the update predicts over the part of the gap not yet predicted only (no
    // double prediction), and the law runs at once.
    for _ in 0..3 {
        let t = w.t();
        let out = w.tick(&[]);
        assert!(out.iter().all(|o| o.status == Status::Nominal), "{out:?}");
        for (i, j) in GAP {
            let e = angle(&w.used(i, j).expect("measured").0, &w.truth(i, j, t).0);
            // Predicting the gap twice would be off by about `held_error`.
            assert!(
                e < held_error / 20.0,
                "bearing error {e} rad after the gap ({held_error} rad moved in it)"
            );
        }
    }
}

#[test]
fn the_finite_difference_holds_a_missing_bearing_and_its_rate_until_the_hold() {
    let hold = 4.5 * DT;
    let mut w = World::new(BearingFilter::FiniteDifference, hold);
    w.run(50);
    let (s_last, rate_last) = w.used(0, 1).expect("measured");
    let t_last = w.t() - DT;
    let max_rate = (0..10)
        .map(|n| w.truth(0, 1, t_last + n as f64 * DT).1.norm())
        .fold(0.0, f64::max);
    // Four ticks without it (τ up to 0.04 s < T_h): nominal on the held bearing and rate,
    // within τ·max|ṡ| of the truth.
    for n in 1..=4 {
        let t = w.t();
        let out = w.tick(&GAP);
        assert!(out.iter().all(|o| o.status == Status::Nominal), "{out:?}");
        let (s, rate) = w.used(0, 1).expect("held within the hold");
        assert_eq!((s, rate), (s_last, rate_last), "held as last measured");
        let tau = n as f64 * DT;
        let e = (s - w.truth(0, 1, t).0).norm();
        assert!(e <= tau * max_rate * 1.01, "held error {e} at τ = {tau}");
    }
    // τ = 0.05 s > T_h: missing.
    let out = w.tick(&GAP);
    assert_eq!(out[0].status, Status::Safe(Fault::MissingBearing(id(1))));
    assert_eq!(out[2].status, Status::Safe(Fault::MissingBearing(id(0))));
    // Back after six ticks: the difference spans the whole gap (SPEC §2).
    let t = w.t();
    let out = w.tick(&[]);
    assert!(out.iter().all(|o| o.status == Status::Nominal), "{out:?}");
    let (s, rate) = w.used(0, 1).expect("measured");
    let s_true = w.truth(0, 1, t).0;
    assert!((s - s_true).norm() < 1e-12);
    let mean = (s_true - s_last) / (t - t_last);
    assert!((rate - mean).norm() < 1e-9, "{rate:?} against {mean:?}");
}

#[test]
fn without_a_hold_a_bearing_missing_for_one_tick_is_missing() {
    // The default (0): what the agent did before the hold existed.
    assert_eq!(
        ph_formation_core::Limits::<f64>::default().bearing_hold,
        0.0
    );
    for filter in [
        BearingFilter::FiniteDifference,
        BearingFilter::Tracker(TrackerConfig::default()),
    ] {
        let mut w = World::new(filter, 0.0);
        w.run(20);
        let out = w.tick(&GAP);
        assert_eq!(out[0].status, Status::Safe(Fault::MissingBearing(id(1))));
        assert_eq!(out[1].status, Status::Nominal);
        // With a hold of one tick and a little more, the same gap is bridged.
        let mut w = World::new(filter, 1.5 * DT);
        w.run(20);
        let out = w.tick(&GAP);
        assert!(out.iter().all(|o| o.status == Status::Nominal), "{out:?}");
    }
}

/// S15c through the agent: a bearing back after a gap longer than the neighbour timeout
/// (0.1 s) and the hold restarts that track, and the agent's reset counter of that
/// neighbour (and only of it) says so; a gap within the hold does not.
#[test]
fn a_bearing_back_after_a_long_gap_restarts_its_track_and_is_counted() {
    let resets =
        |w: &World, i: usize| -> Vec<u32> { w.agents[i].track_resets().map(|(_, r)| r).collect() };
    let mut w =
        World::new(BearingFilter::Tracker(TrackerConfig::default()), 0.05).with_timeout(0.1);
    w.run(20);
    for _ in 0..4 {
        w.tick(&GAP); // 0.04 s: within the hold
    }
    for _ in 0..5 {
        w.tick(&[]);
    }
    assert_eq!(resets(&w, 0), [0, 0]);
    for _ in 0..20 {
        w.tick(&GAP); // 0.2 s: beyond the hold and the timeout
    }
    w.tick(&[]);
    let (t, v) = (w.t() - DT, w.agents[0].neighbours().collect::<Vec<_>>());
    assert_eq!(v, [id(1), id(2)]);
    assert_eq!(resets(&w, 0), [1, 0]);
    assert_eq!(resets(&w, 1), [0, 0]);
    assert_eq!(resets(&w, 2)[0], 1, "{:?}", resets(&w, 2));
    // Restarted at the measured bearing.
    let (s, _) = w.used(0, 1).expect("measured");
    assert!(angle(&s, &w.truth(0, 1, t).0) < 1e-9);
    // The finite difference has no track to restart.
    let mut w = World::new(BearingFilter::FiniteDifference, 0.05).with_timeout(0.1);
    w.run(20);
    for _ in 0..20 {
        w.tick(&GAP);
    }
    w.tick(&[]);
    assert_eq!(resets(&w, 0), [0, 0]);
}

#[test]
fn a_neighbour_never_measured_is_missing_whatever_the_hold() {
    let mut w = World::new(BearingFilter::FiniteDifference, 1.0);
    w.tick(&[(0, 1)]); // nobody heard yet: stale
    let out = w.tick(&[(0, 1)]);
    assert_eq!(out[0].status, Status::Safe(Fault::MissingBearing(id(1))));
    assert!(w.used(0, 1).is_none());
}

#[test]
fn a_negative_or_non_finite_hold_is_refused() {
    let f = World::new(BearingFilter::FiniteDifference, 0.0).f;
    for hold in [-0.01, f64::NAN, f64::INFINITY] {
        let mut c = f.config::<f64>(0);
        c.limits.bearing_hold = hold;
        assert_eq!(
            HostAgent::new(c).err(),
            Some(ConfigError::BadParameter),
            "hold {hold}"
        );
    }
}
