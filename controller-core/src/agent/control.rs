//! The control step: the law S7–S12 summed over the agent's angles (the apex kernels were
//! computed by [`Agent::sense`]; far vertices apply the efforts they received), the
//! estimator flows S9/S10, saturation and the safe output.

use super::estimates::owns;
use super::sensing::sense_angle;
use super::state::{AngleState, ApexPart, Neighbour, Remote, Side};
#[cfg(any(feature = "sim", test))]
use super::Evaluation;
use super::{
    finite_vec, pick, vec2, within, Agent, Fault, LawOutput, Measurements, Status, StepOutput,
};
use crate::config::{EstimatorMode, LeaderRole};
use crate::{geometry, law, Real, Vec2};

impl<T: Real, const MT: usize, const NB: usize> Agent<T, MT, NB> {
    /// Evaluates the control law S7–S12 and the estimator flows S9/S10 on the stored
    /// measurements and neighbour data, without changing the state (it only overwrites
    /// the internal scratch of the flows). [`Agent::step`] runs the same law; simulators
    /// that integrate the estimators themselves (continuous time) call [`Agent::sense`],
    /// exchange, then this. Feature `sim` only (not built for the firmware).
    #[cfg(any(feature = "sim", test))]
    pub fn evaluate(&mut self) -> Result<Evaluation<T, MT>, Fault> {
        let LawOutput { force, degenerate } = self.law_pass()?;
        let r_min = self.config.min_estimate;
        // S10, continuous form: no negative flow at r_min (zero for estimates not owned).
        let projected = |a: &AngleState<T>| {
            let rate = |e: usize| match self.owns(a, e) {
                true => law::projected_rate(pick(&a.estimate, e), pick(&a.flow, e), r_min),
                false => T::zero(),
            };
            [rate(0), rate(1)]
        };
        let estimate_rates = self
            .angles
            .iter()
            .map(|[a0, a1]| [projected(a0), projected(a1)])
            .collect();
        Ok(Evaluation {
            force,
            estimate_rates,
            degenerate,
        })
    }

    /// One control tick: sensing, the law S7–S12 with the owned estimates integrated over
    /// `dt` (sampled S10), saturation. On any fault the output
    /// is the documented safe command `U = −safe_damping · v` (no formation force) and the
    /// estimates hold still.
    ///
    /// The angles are walked once: each angle's sensing and then its law, the same
    /// per-angle functions that `sense` and `evaluate` (feature `sim`) run in two walks,
    /// in the same order on the same data (the same result bit for bit).
    pub fn step(&mut self, m: &Measurements<'_, T>) -> StepOutput<T> {
        let result = match self.sense_own(m) {
            Ok(()) => {
                let mut done = 0;
                let result = self.sense_and_law(m.dt, &mut done);
                if result.is_err() {
                    self.roll_back(done);
                }
                result
            }
            Err(fault) => Err(fault),
        };
        self.comm_due = self.comm_countdown == 0;
        self.comm_countdown = match self.comm_countdown.checked_sub(1) {
            Some(c) => c,
            None => self.config.comm_every.saturating_sub(1),
        };
        self.step_output(result, &m.velocity)
    }

    /// The output for a law result: the force saturated to `max_force`, or on a fault the
    /// safe command `U = −safe_damping · v` (zero if `v` is not finite), saturated too.
    /// (What [`Agent::step`] returns; for simulators that call [`Agent::evaluate`].)
    /// Feature `sim` only (not built for the firmware).
    #[cfg(any(feature = "sim", test))]
    pub fn output(&self, law: Result<LawOutput<T>, Fault>, velocity: &Vec2<T>) -> StepOutput<T> {
        self.step_output(law, velocity)
    }

    /// What [`Agent::step`] returns for its law result (`Agent::output`, feature `sim`).
    fn step_output(&self, law: Result<LawOutput<T>, Fault>, velocity: &Vec2<T>) -> StepOutput<T> {
        let limits = &self.config.limits;
        let (force, status, degenerate) = match law {
            Ok(LawOutput { force, degenerate }) => (force, Status::Nominal, degenerate),
            Err(fault) => {
                let v = if finite_vec(velocity) {
                    *velocity
                } else {
                    Vec2::zeros()
                };
                (v * -limits.safe_damping, Status::Safe(fault), false)
            }
        };
        let (force, saturated) = law::saturate(&force, limits.max_force);
        StepOutput {
            force,
            status,
            saturated,
            degenerate,
        }
    }

    /// Puts back the estimates of the first `done` angles from before the step (their
    /// `flow` holds them; the others are untouched).
    #[cold]
    fn roll_back(&mut self, done: usize) {
        let mode = self.config.estimator;
        for a in self
            .angles
            .as_mut_slice()
            .as_flattened_mut()
            .iter_mut()
            .take(done)
        {
            for e in 0..2 {
                if owns(mode, a, e) {
                    if let (Some(est), Some(before)) = (a.estimate.get_mut(e), a.flow.get(e)) {
                        *est = *before;
                    }
                }
            }
        }
    }

    /// What every angle's law reads of this tick.
    #[inline(always)]
    fn law_context(&self, integrate: Option<T>) -> LawContext<T> {
        let c = &self.config;
        LawContext {
            v: self.velocity,
            mode: c.estimator,
            r_min: c.min_estimate,
            timeout: c.limits.neighbour_timeout,
            integrate,
        }
    }

    /// The law S7–S12 on the stored state: the sum of the angles' S8 forces, S11 and S12,
    /// and the S9 flow of every owned estimate, left in each angle's `flow`. Returns the
    /// unsaturated force and whether a current angle (of which this agent is the apex) is
    /// degenerate. The first fault in angle order wins (after staleness).
    #[cfg(any(feature = "sim", test))]
    #[inline]
    fn law_pass(&mut self) -> Result<LawOutput<T>, Fault> {
        self.check_fresh()?;
        let cx = self.law_context(None);
        let mut sum = LawSum::new(self.velocity_force());
        let nbs = self.neighbours.as_slice();
        for a in self.angles.as_mut_slice().as_flattened_mut() {
            angle_law(&cx, nbs, a, &mut sum)?;
        }
        self.finish_law(sum)
    }

    /// [`Agent::sense`]'s walk over the angles and [`Agent::law_pass`]'s in one walk, the
    /// owned estimates integrated over `dt` (the sampled S10 step `r̂ ← max(r_min, r̂ +
    /// Δt·S9)`; the continuous projection would change nothing: it acts only when
    /// r̂ ≤ r_min and S9 < 0, and then both give r_min). Each angle is sensed, then (until
    /// the first fault, staleness first) its law runs; every angle is sensed whatever the
    /// law finds, as `sense` then the law would. `done`: the angles whose estimates were
    /// integrated (to roll back after a fault).
    #[inline]
    fn sense_and_law(&mut self, dt: T, done: &mut usize) -> Result<LawOutput<T>, Fault> {
        let mut fault = self.check_fresh().err();
        let cx = self.law_context(Some(dt));
        let mut sum = LawSum::new(self.velocity_force());
        let nbs = self.neighbours.as_slice();
        // The two arms below are `sense_angle` and `angle_law` written out so that the
        // side of each angle is tested once: on target that is 951 → 903 (tri2) and
        // 2 772 → 2 601 (tri8) instructions per step (docs/firmware.md).
        for a in self.angles.as_mut_slice().as_flattened_mut() {
            if let Side::Far { age, .. } = &mut a.side {
                // A far vertex: its data ages (sensing), then its law.
                *age += dt;
                if fault.is_none() {
                    if let Side::Far { k, remote, age } = a.side {
                        match far_law(&cx, nbs, a, k, &remote, age, &mut sum) {
                            Ok(()) => *done += 1,
                            Err(f) => fault = Some(f),
                        }
                    }
                }
                continue;
            }
            // The apex: its kernel (sensing), then its law on what sensing kept.
            sense_angle(nbs, cx.mode, &cx.v, a, dt);
            if fault.is_none() {
                if let Side::Apex { part, fault: kept } = a.side {
                    let law = match kept {
                        Some(f) => Err(f),
                        None => apex_law(&cx, nbs, a, &part, &mut sum),
                    };
                    match law {
                        Ok(()) => *done += 1,
                        Err(f) => fault = Some(f),
                    }
                }
            }
        }
        match fault {
            Some(f) => Err(f),
            None => self.finish_law(sum),
        }
    }

    /// S12: `U^v_n = D^r_n v* − D^v_n (v_n − v*)`.
    #[inline(always)]
    fn velocity_force(&self) -> Vec2<T> {
        let c = &self.config;
        let v_star = vec2(c.velocity_reference.at(self.time));
        law::velocity_force(&c.friction, &c.velocity_damping, &self.velocity, &v_star)
    }

    /// The end of the law after the angles: S11, the finiteness of the force, degeneracy.
    #[inline(always)]
    fn finish_law(&self, sum: LawSum<T>) -> Result<LawOutput<T>, Fault> {
        let c = &self.config;
        let v = self.velocity;
        let mut force = sum.force;
        if let Some(l) = &c.leader {
            // S11 with z = q_a − q_b; the partner offset p = q_partner − q_self.
            let p = self.partner_offset.ok_or(Fault::MissingPartnerOffset)?;
            let v_p = self.neighbour(self.partner_slot)?.velocity;
            let z_star = vec2(l.displacement.at(self.time));
            force += match l.role {
                LeaderRole::A => {
                    law::leader_force(l.stiffness, &l.damping, &(-p - z_star), &(v - v_p))
                }
                // Agent b receives the negation.
                LeaderRole::B => {
                    -law::leader_force(l.stiffness, &l.damping, &(p - z_star), &(v_p - v))
                }
                // S11b, the same on both ends: it is odd in (p, ṗ).
                LeaderRole::Distance => law::leader_distance_force(
                    l.stiffness,
                    &l.damping,
                    &p,
                    crate::geometry::norm(&z_star),
                    &(v_p - v),
                ),
            };
        }
        if !finite_vec(&force) {
            return Err(Fault::NonFinite);
        }
        Ok(LawOutput {
            force,
            degenerate: sum.y_max > c.limits.margin_cos,
        })
    }
}

/// What every angle's law reads of this tick ([`Agent::law_context`]).
struct LawContext<T: Real> {
    /// Own velocity.
    v: Vec2<T>,
    mode: EstimatorMode,
    r_min: T,
    timeout: T,
    /// `Some(dt)`: integrate the owned estimates (sampled S10); `None`: keep the flows.
    integrate: Option<T>,
}

/// The law's running sums over the angles.
struct LawSum<T: Real> {
    /// S12 plus the S8 forces so far.
    force: Vec2<T>,
    /// Largest `|y|` of the apex angles (NaN ignored): degenerate iff above the margin.
    y_max: T,
}

impl<T: Real> LawSum<T> {
    #[inline(always)]
    fn new(force: Vec2<T>) -> Self {
        Self {
            force,
            y_max: T::zero(),
        }
    }
}

/// One angle's law: its S8 force into `sum` and the S9 flow (stepped by S10 with
/// `integrate`) of the estimates it owns, or the angle's fault.
#[cfg(any(feature = "sim", test))]
#[inline(always)]
fn angle_law<T: Real, const MT: usize>(
    cx: &LawContext<T>,
    nbs: &[Neighbour<T, MT>],
    a: &mut AngleState<T>,
    sum: &mut LawSum<T>,
) -> Result<(), Fault> {
    match a.side {
        Side::Apex { part, fault } => {
            if let Some(fault) = fault {
                return Err(fault);
            }
            apex_law(cx, nbs, a, &part, sum)
        }
        Side::Far { k, remote, age } => far_law(cx, nbs, a, k, &remote, age, sum),
    }
}

/// The law on the apex of an angle: its S8 force (computed when sensing) and the S9 flow
/// of both estimates with S3 for `ṙ` from the far vertices' broadcast velocities.
#[inline(always)]
fn apex_law<T: Real, const MT: usize>(
    cx: &LawContext<T>,
    nbs: &[Neighbour<T, MT>],
    a: &mut AngleState<T>,
    p: &ApexPart<T>,
    sum: &mut LawSum<T>,
) -> Result<(), Fault> {
    let y_abs = p.y.abs();
    if y_abs > sum.y_max {
        sum.y_max = y_abs;
    }
    // S8 on the apex (computed when sensing).
    sum.force += p.force;
    if cx.mode != EstimatorMode::Measured {
        let nb = |slot: usize| nbs.get(slot).ok_or(Fault::Internal);
        let (nv, nw) = (nb(a.slots[1])?, nb(a.slots[2])?);
        // Broadcast velocities: every neighbour was heard (`check_fresh`).
        let (vv, vw) = (nv.velocity, nw.velocity);
        let gain = a.estimator_gain;
        // S3 with the own bearings s_uv, s_uw and the far vertices' velocities.
        let rr = [
            geometry::range_rate(&nv.s, &(vv - cx.v)),
            geometry::range_rate(&nw.s, &(vw - cx.v)),
        ];
        let [r0, r1] = a.estimate;
        let f0 = law::estimator_rate(rr[0], p.gamma, p.share[0], gain, r0);
        let f1 = law::estimator_rate(rr[1], p.gamma, p.share[1], gain, r1);
        integrate_estimate(cx, a, 0, f0);
        integrate_estimate(cx, a, 1, f1);
    }
    Ok(())
}

/// The law on far vertex `k` of an angle: S6–S8 from what the apex sent `age` seconds
/// ago ([`law::far_angle`]), and in per-agent mode the S9 flow of the own copy.
#[inline(always)]
fn far_law<T: Real, const MT: usize>(
    cx: &LawContext<T>,
    nbs: &[Neighbour<T, MT>],
    a: &mut AngleState<T>,
    k: usize,
    remote: &Remote<T>,
    age: T,
    sum: &mut LawSum<T>,
) -> Result<(), Fault> {
    let n = nbs.get(a.slots[0]).ok_or(Fault::Internal)?;
    // S19: the bearing to the apex measured or held (S18).
    let (s_ku, _) = n.bearing()?;
    if !within(age, cx.timeout) {
        return Err(Fault::MissingData(a.apex));
    }
    // SPEC §6: the apex's shared estimate, the own copy, or the range.
    let r = match cx.mode {
        EstimatorMode::Shared => remote.range,
        EstimatorMode::PerAgent => pick(&a.estimate, k),
        EstimatorMode::Measured => n.range()?,
    };
    let v = cx.v;
    // Own motion relative to the apex since it measured (taken as the tick before the
    // frame arrived): displacement at the current relative velocity, change of own
    // velocity since the frame arrived.
    let v_apex = n.velocity;
    let delta = (v - v_apex) * age;
    let dv = v - remote.v_ref;
    // S6–S8 on this far vertex.
    let (gamma_k, g_k, f) = law::far_angle(&law::FarAngle {
        gamma: remote.gamma,
        sigma_k: remote.sigma,
        r_k: r,
        s_to_apex: s_ku,
        stiffness: a.stiffness,
        damping: a.damping,
        delta,
        dv,
    });
    sum.force += f;
    if cx.mode == EstimatorMode::PerAgent {
        // S9 on the own copy r̂^k (SPEC §6): ṙ_uk = s_ukᵀ(v_k − v_u) with s_uk = −s_ku
        // (S3), and the share f^k = +g_kᵀ v_k / r̂^k.
        let rr = geometry::range_rate(&-s_ku, &(v - v_apex));
        let share = law::own_share(&g_k, &v, r, true);
        let flow = law::estimator_rate(rr, gamma_k, share, a.estimator_gain, r);
        integrate_estimate(cx, a, k, flow);
    }
    Ok(())
}

/// The S9 `flow` of estimate `e` (computed with S3 for ṙ): stepping, the estimate is
/// integrated over `Δt` (sampled S10) and its value before kept in `a.flow` (for the roll
/// back); evaluating, the flow is kept in `a.flow` and the estimate is left alone.
#[inline(always)]
fn integrate_estimate<T: Real>(cx: &LawContext<T>, a: &mut AngleState<T>, e: usize, flow: T) {
    if let (Some(est), Some(f)) = (a.estimate.get_mut(e), a.flow.get_mut(e)) {
        match cx.integrate {
            Some(dt) => {
                *f = *est;
                *est = law::estimator_step(*est, flow, dt, cx.r_min);
            }
            None => *f = flow,
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::agent::test_support::one_triangle;
    use crate::{Agent, BearingMeasurement, Fault, Measurements, Vec2};

    /// A neighbour slot that does not exist (impossible by construction) is reported as
    /// `Fault::Internal`, not as a non-finite force or a panic.
    #[test]
    fn an_impossible_neighbour_slot_is_an_internal_fault() {
        let mut c = one_triangle::<f64>(1, [2, 3], 0.0);
        c.limits.neighbour_timeout = 1e9;
        let mut a = Agent::<f64, 1, 2>::new(c).unwrap();
        for n in a.neighbours.iter_mut() {
            n.age = 0.0;
        }
        let b = |id, x: f64, y: f64| BearingMeasurement {
            neighbour: id,
            bearing: Vec2::new(x, y),
            rate: None,
            range: None,
        };
        let m = Measurements {
            time: 0.0,
            dt: 0.0,
            velocity: Vec2::zeros(),
            bearings: &[b(2, 1.0, 0.0), b(3, 0.0, 1.0)],
            partner_offset: None,
        };
        a.sense(&m).unwrap();
        if let crate::agent::state::Side::Far { age, .. } = &mut a.angles[0][0].side {
            *age = 0.0;
        }
        a.angles[0][0].slots[0] = 7;
        assert_eq!(a.evaluate().err(), Some(Fault::Internal));
    }
}
