//! Continuous mode, for checking the theory (S14): the controllers are evaluated at every
//! RK4 stage with exact bearing rates and no radio (neighbour data passed directly), and
//! the owned estimates are integrated as part of the ODE state.
//!
//! Per stage: write the stage's estimates into the cores (`set_estimate`), `sense` every
//! agent (time = stage time, `dt = 0`, exact rates), pass every neighbour's data with
//! `receive_direct`, then `evaluate` every agent for its force and estimate rates.

use super::error::SetupError;
use super::plant::acceleration;
use super::sensors::{quiet_bearing, Sight};
use super::simulator::Engine;
use super::slot_order::SlotOrder;
use super::stats::{ControlStats, FrameCounts};
use crate::model::{
    resolve_estimates, BearingRate, CoreAgent, EstimateInfo, Estimator, Model, SensorModel,
};
use ph_formation_core::{
    law, BearingMeasurement, Fault, LawOutput, Measurements, OwnedEstimate, StepOutput, Vec2,
};

/// `(&mut v[i], &v[j])` for `i ≠ j`.
fn pair_mut<T>(v: &mut [T], i: usize, j: usize) -> Option<(&mut T, &T)> {
    use std::cmp::Ordering::{Greater, Less};
    match i.cmp(&j) {
        Less => {
            let (a, b) = v.split_at_mut(j);
            Some((a.get_mut(i)?, b.first()?))
        }
        Greater => {
            let (a, b) = v.split_at_mut(i);
            Some((b.first_mut()?, a.get(j)?))
        }
        _ => None,
    }
}

/// The right-hand side: the cores and their scratch buffers.
struct Rhs {
    agents: Vec<CoreAgent>,
    sensors: SensorModel,
    bearings: Vec<BearingMeasurement<f64>>,
    /// Each agent's bearings go to its core in slot order ([`SlotOrder`]).
    slot_order: SlotOrder,
    partner: Vec<Option<usize>>,
    ids: Vec<u8>,
    info: Vec<EstimateInfo>,
    est_start: Vec<usize>,
    sense_fault: Vec<Option<Fault>>,
    stats: ControlStats,
}

impl Rhs {
    /// `dy = f(t, y)` with `y = [q_0, v_0, q_1, v_1, …, r̂_0, r̂_1, …]`.
    fn eval(&mut self, model: &Model, t: f64, y: &[f64], dy: &mut [f64]) {
        let n = self.agents.len();
        let pos = |i: usize| Vec2::new(y[4 * i], y[4 * i + 1]);
        let vel = |i: usize| Vec2::new(y[4 * i + 2], y[4 * i + 3]);
        for (e, info) in self.info.iter().enumerate() {
            if let Some(a) = self.agents.get_mut(info.owner) {
                a.set_estimate(&OwnedEstimate {
                    triangle: info.local_triangle,
                    angle: info.angle,
                    edge: info.edge,
                    apex: 0,
                    far: 0,
                    value: y[4 * n + e],
                });
            }
        }
        let ranged = model.estimator == Estimator::Measured;
        for i in 0..n {
            self.bearings.clear();
            let (qi, vi) = (pos(i), vel(i));
            for &j in model.graph.triangle.of(i) {
                let (qj, vj) = (pos(j), vel(j));
                let sight = Sight {
                    neighbour: self.ids[j],
                    q_self: &qi,
                    q_other: &qj,
                    v_self: &vi,
                    v_other: &vj,
                };
                if let Some(b) = quiet_bearing(&self.sensors, &sight, true, ranged) {
                    self.bearings.push(b);
                }
            }
            self.slot_order.apply(i, &mut self.bearings);
            let m = Measurements {
                time: t,
                dt: 0.0,
                velocity: vi,
                bearings: &self.bearings,
                partner_offset: self.partner[i].map(|p| pos(p) - qi),
            };
            self.sense_fault[i] = self.agents[i].sense(&m).err();
        }
        for i in 0..n {
            for &j in model.graph.radio.of(i) {
                if let Some((me, other)) = pair_mut(&mut self.agents, i, j) {
                    let _ = me.receive_direct(other);
                }
            }
        }
        for i in 0..n {
            let vi = vel(i);
            let a = &model.agents[i];
            let rates = &mut dy[4 * n + self.est_start[i]..4 * n + self.est_start[i + 1]];
            let out = self.output(i, &vi, rates);
            // Counted per stage evaluation; t > 0 makes every safe output count.
            self.stats.record(
                t.max(f64::MIN_POSITIVE),
                i,
                out.status,
                out.saturated,
                out.degenerate,
                out.force.norm(),
            );
            let force = out.force;
            let acc = acceleration(&vi, &force, a.mass, &a.friction);
            dy[4 * i] = vi.x;
            dy[4 * i + 1] = vi.y;
            dy[4 * i + 2] = acc.x;
            dy[4 * i + 3] = acc.y;
        }
    }
}

impl Rhs {
    /// Agent `i`'s output at this stage, from its sensing and `evaluate`, through the
    /// core's own [`Agent::output`](ph_formation_core::Agent::output) (saturation, and on a
    /// fault the safe command, zero for a non-finite velocity `v`), and the rates of its
    /// owned estimates into `rates` (zero on a fault: the estimates hold still).
    fn output(&mut self, i: usize, v: &Vec2<f64>, rates: &mut [f64]) -> StepOutput<f64> {
        let result = match self.sense_fault[i] {
            Some(f) => Err(f),
            None => self.agents[i].evaluate(),
        };
        let first = self.est_start[i];
        let law = match result {
            Ok(ev) => {
                for (k, rate) in rates.iter_mut().enumerate() {
                    let info = &self.info[first + k];
                    *rate = ev
                        .estimate_rates
                        .get(info.local_triangle)
                        .map_or(0.0, |r| r[info.angle][info.edge]);
                }
                Ok(LawOutput {
                    force: ev.force,
                    degenerate: ev.degenerate,
                })
            }
            Err(fault) => {
                rates.fill(0.0);
                Err(fault)
            }
        };
        self.agents[i].output(law, v)
    }
}

/// The continuous-time simulator.
pub struct ContinuousSim<'m> {
    model: &'m Model,
    rhs: Rhs,
    y: Vec<f64>,
    k: [Vec<f64>; 4],
    tmp: Vec<f64>,
    q: Vec<Vec2<f64>>,
    v: Vec<Vec2<f64>>,
    est: Vec<f64>,
}

impl<'m> ContinuousSim<'m> {
    /// Builds the cores and the initial ODE state.
    pub fn new(model: &'m Model) -> Result<Self, SetupError> {
        let n = model.n();
        let mut agents = Vec::with_capacity(n);
        let mut info = Vec::new();
        let mut est_start = Vec::with_capacity(n + 1);
        for i in 0..n {
            let a = model.core_agent(i)?;
            est_start.push(info.len());
            let owned: Vec<_> = a.owned_estimates().collect();
            info.extend(resolve_estimates(model, i, &owned)?);
            agents.push(a);
        }
        est_start.push(info.len());
        let dim = 4 * n + info.len();
        let mut y = Vec::with_capacity(dim);
        for a in &model.agents {
            y.extend_from_slice(&[a.position[0], a.position[1], a.velocity[0], a.velocity[1]]);
        }
        y.extend(info.iter().map(|_| model.initial_estimate));
        let partner = model.partners();
        let slot_order =
            SlotOrder::for_model(model, |i| agents.get(i).map(|a| a.neighbours().collect()));
        let mut sim = Self {
            model,
            rhs: Rhs {
                agents,
                sensors: SensorModel::ideal(BearingRate::Exact),
                bearings: Vec::with_capacity(model.graph.triangle.max_degree()),
                slot_order,
                partner,
                ids: model.agents.iter().map(|a| a.id).collect(),
                est_start,
                info,
                sense_fault: vec![None; n],
                stats: ControlStats::with_window(crate::analysis::steady::Window::of(model).from),
            },
            k: [
                vec![0.0; dim],
                vec![0.0; dim],
                vec![0.0; dim],
                vec![0.0; dim],
            ],
            tmp: vec![0.0; dim],
            q: vec![Vec2::zeros(); n],
            v: vec![Vec2::zeros(); n],
            est: vec![0.0; dim - 4 * n],
            y,
        };
        sim.unpack();
        Ok(sim)
    }

    /// Agent `i`'s output at time `t` on the current state, as the first RK4 stage
    /// computes it (every agent sensed and exchanged; counted in the control statistics
    /// like a stage): `None` beyond the last agent. For tests and diagnostics.
    pub fn output_of(&mut self, t: f64, i: usize) -> Option<StepOutput<f64>> {
        let n = self.q.len();
        if i >= n {
            return None;
        }
        let [k1, ..] = &mut self.k;
        self.rhs.eval(self.model, t, &self.y, k1);
        let v = Vec2::new(self.y[4 * i + 2], self.y[4 * i + 3]);
        let mut rates = vec![0.0; self.rhs.est_start[i + 1] - self.rhs.est_start[i]];
        Some(self.rhs.output(i, &v, &mut rates))
    }

    fn unpack(&mut self) {
        let n = self.q.len();
        for i in 0..n {
            self.q[i] = Vec2::new(self.y[4 * i], self.y[4 * i + 1]);
            self.v[i] = Vec2::new(self.y[4 * i + 2], self.y[4 * i + 3]);
        }
        self.est.copy_from_slice(&self.y[4 * n..]);
    }
}

impl Engine for ContinuousSim<'_> {
    fn control(&mut self, _t: f64) {}

    fn integrate(&mut self, t: f64) {
        let model = self.model;
        let h = model.dt;
        let [k1, k2, k3, k4] = &mut self.k;
        let (y, tmp) = (&self.y, &mut self.tmp);
        self.rhs.eval(model, t, y, k1);
        for ((o, a), b) in tmp.iter_mut().zip(y.iter()).zip(k1.iter()) {
            *o = a + 0.5 * h * b;
        }
        self.rhs.eval(model, t + 0.5 * h, tmp, k2);
        for ((o, a), b) in tmp.iter_mut().zip(y.iter()).zip(k2.iter()) {
            *o = a + 0.5 * h * b;
        }
        self.rhs.eval(model, t + 0.5 * h, tmp, k3);
        for ((o, a), b) in tmp.iter_mut().zip(y.iter()).zip(k3.iter()) {
            *o = a + h * b;
        }
        self.rhs.eval(model, t + h, tmp, k4);
        for (i, yi) in self.y.iter_mut().enumerate() {
            *yi += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        // S10: the projection keeps every estimate at or above r_min (the core's floor).
        let n4 = 4 * self.q.len();
        for r in self.y.iter_mut().skip(n4) {
            *r = law::estimate_floor(*r, model.min_estimate);
        }
        self.unpack();
    }

    fn view(&mut self) -> (&[Vec2<f64>], &[Vec2<f64>], &[f64]) {
        (&self.q, &self.v, &self.est)
    }

    fn estimate_info(&self) -> &[EstimateInfo] {
        &self.rhs.info
    }

    fn frame_counts(&self) -> FrameCounts {
        FrameCounts::default()
    }

    fn control_stats(&self) -> ControlStats {
        self.rhs.stats
    }
}
