//! The control step: the law S7–S12 summed over the agent's angles (the apex kernels were
//! computed by [`Agent::sense`]; far vertices apply the efforts they received), the
//! estimator flows S9/S10, saturation and the safe output.

use super::state::Role;
use super::{
    finite_vec, pick, vec2, within, Agent, Evaluation, Fault, Measurements, Status, StepOutput,
};
use crate::config::{EstimatorMode, LeaderRole};
use crate::{geometry, law, Real, Vec2};

impl<T: Real, const MT: usize, const NB: usize> Agent<T, MT, NB> {
    /// Evaluates the control law S7–S12 and the estimator flows S9/S10 on the stored
    /// measurements and neighbour data, without changing anything. [`Agent::step`] uses
    /// the same law; simulators that integrate the estimators themselves (continuous
    /// time) call [`Agent::sense`], exchange, then this.
    pub fn evaluate(&self) -> Result<Evaluation<T, MT>, Fault> {
        let (force, degenerate) = self.law()?;
        let estimate_rates = self
            .angles
            .iter()
            .map(|[a0, a1]| [a0.rate.get(), a1.rate.get()])
            .collect();
        Ok(Evaluation {
            force,
            estimate_rates,
            degenerate,
        })
    }

    /// One control tick: [`Agent::sense`], the law ([`Agent::evaluate`]'s), the owned
    /// estimates integrated over `dt` (sampled S10), saturation. On any fault the output
    /// is the documented safe command `U = −safe_damping · v` (no formation force) and the
    /// estimates hold still.
    pub fn step(&mut self, m: &Measurements<'_, T>) -> StepOutput<T> {
        let result = self.sense(m).and_then(|()| self.law());
        if result.is_ok() {
            // The law's flows, over dt (sampled S10: `r̂ ← max(r_min, r̂ + Δt·S9)`; the
            // continuous projection the law applies first changes nothing here: it acts
            // only when r̂ ≤ r_min and S9 < 0, and then both give r_min).
            self.integrate(m.dt);
        }
        self.comm_due = self.comm_countdown == 0;
        self.comm_countdown = match self.comm_countdown.checked_sub(1) {
            Some(c) => c,
            None => self.config.comm_every.saturating_sub(1),
        };
        self.output(result, &m.velocity)
    }

    /// The output for a law result: the force saturated to `max_force`, or on a fault the
    /// safe command `U = −safe_damping · v` (zero if `v` is not finite), saturated too.
    /// (What [`Agent::step`] returns; for simulators that call [`Agent::evaluate`].)
    pub fn output(&self, law: Result<(Vec2<T>, bool), Fault>, velocity: &Vec2<T>) -> StepOutput<T> {
        let limits = &self.config.limits;
        let (force, status, degenerate) = match law {
            Ok((force, degenerate)) => (force, Status::Nominal, degenerate),
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

    /// The law S7–S12: the sum of the angles' S8 forces, S11 and S12, and the S9 flow
    /// with the S10 projection of every owned estimate (left in each angle's `rate`).
    /// Returns the unsaturated force and whether a current angle (of which this agent is
    /// the apex) is degenerate. The first fault in angle order wins (after staleness).
    #[inline]
    fn law(&self) -> Result<(Vec2<T>, bool), Fault> {
        self.check_fresh()?;
        let c = &self.config;
        let v = self.velocity;
        let v_star = vec2(c.velocity_reference.at(self.time));
        let (mode, r_min) = (c.estimator, c.min_estimate);
        let timeout = c.limits.neighbour_timeout;
        let zero = T::zero();
        // S12.
        let mut force = law::velocity_force(&c.friction, &c.velocity_damping, &v, &v_star);
        // Largest |y| (NaN ignored): degenerate iff above the margin.
        let mut y_max = zero;
        for a in self.angles.as_slice().as_flattened() {
            let rate = match a.role {
                Role::Apex => {
                    if let Some(fault) = a.fault {
                        return Err(fault);
                    }
                    let p = &a.part;
                    let y_abs = p.y.abs();
                    if y_abs > y_max {
                        y_max = y_abs;
                    }
                    // S8 on the apex (computed when sensing).
                    force += p.force;
                    if mode == EstimatorMode::Measured {
                        [zero; 2]
                    } else {
                        // S9 with S3 for ṙ_e (own bearing, the far vertex's velocity), S10.
                        let flow = |slot: usize, e: usize| -> Result<T, Fault> {
                            let n = self.neighbour(slot)?;
                            let rr = geometry::range_rate(&n.s, &(n.velocity()? - v));
                            let r_hat = pick(&a.estimate, e);
                            let share = pick(&p.share, e);
                            let f =
                                law::estimator_rate(rr, p.gamma, share, a.estimator_gain, r_hat);
                            Ok(law::projected_rate(r_hat, f, r_min))
                        };
                        [flow(a.slots[1], 0)?, flow(a.slots[2], 1)?]
                    }
                }
                Role::Far(k) => {
                    let n = self.neighbour(a.slots[0])?;
                    let (s_ku, _) = n.bearing()?;
                    if !within(a.remote_age, timeout) {
                        return Err(Fault::MissingData(a.apex));
                    }
                    let remote = &a.remote;
                    // SPEC §6: the apex's shared estimate, the own copy, or the range.
                    let r = match mode {
                        EstimatorMode::Shared => remote.rho,
                        EstimatorMode::PerAgent => pick(&a.estimate, k),
                        EstimatorMode::Measured => n.range()?,
                    };
                    let dv = match remote.v_ref {
                        Some(v_ref) => v - v_ref,
                        None => Vec2::zeros(),
                    };
                    // S6–S8 on this far vertex.
                    let (gamma_k, g_k, f) = law::far_angle(
                        remote.gamma,
                        remote.sigma,
                        k,
                        r,
                        &s_ku,
                        a.stiffness,
                        a.damping,
                        &remote.delta,
                        &dv,
                    );
                    force += f;
                    if mode == EstimatorMode::PerAgent {
                        // S9 on the own copy r̂^k (SPEC §6): ṙ_uk = s_ukᵀ(v_k − v_u) with
                        // s_uk = −s_ku (S3), and the share f^k = +g_kᵀ v_k / r̂^k.
                        let rr = geometry::range_rate(&-s_ku, &(v - n.velocity()?));
                        let share = law::own_share(&g_k, &v, r, true);
                        let flow = law::estimator_rate(rr, gamma_k, share, a.estimator_gain, r);
                        let mut rate = [zero; 2];
                        if let Some(x) = rate.get_mut(k) {
                            *x = law::projected_rate(r, flow, r_min);
                        }
                        rate
                    } else {
                        [zero; 2]
                    }
                }
            };
            a.rate.set(rate);
        }
        if let Some(l) = &c.leader {
            // S11 with z = q_a − q_b; the partner offset p = q_partner − q_self.
            let p = self.partner_offset.ok_or(Fault::MissingPartnerOffset)?;
            let v_p = self.neighbour(self.partner_slot)?.velocity()?;
            let z_star = vec2(l.displacement.at(self.time));
            force += match l.role {
                LeaderRole::A => {
                    law::leader_force(l.stiffness, &l.damping, &(-p - z_star), &(v - v_p))
                }
                // Agent b receives the negation.
                LeaderRole::B => {
                    -law::leader_force(l.stiffness, &l.damping, &(p - z_star), &(v_p - v))
                }
            };
        }
        if !finite_vec(&force) {
            return Err(Fault::NonFinite);
        }
        Ok((force, y_max > c.limits.margin_cos))
    }
}

#[cfg(test)]
mod tests {
    use crate::{
        Agent, AgentConfig, AngleConfig, BearingMeasurement, Fault, Measurements, TriangleConfig,
        Vec2,
    };

    /// A neighbour slot that does not exist (impossible by construction) is reported as
    /// `Fault::Internal`, not as a non-finite force or a panic.
    #[test]
    fn an_impossible_neighbour_slot_is_an_internal_fault() {
        let angle = |apex| AngleConfig {
            apex,
            cos_desired: 0.5,
            stiffness: 1.0,
            damping: 0.0,
            estimator_gain: 1.0,
        };
        let mut c = AgentConfig::<f64, 1>::new(1);
        c.limits.neighbour_timeout = 1e9;
        c.triangles
            .push(TriangleConfig {
                vertices: [1, 2, 3],
                angles: [angle(2), angle(3)],
            })
            .unwrap();
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
        a.angles[0][0].remote_age = 0.0;
        a.angles[0][0].slots[0] = 7;
        assert_eq!(a.evaluate().err(), Some(Fault::Internal));
    }
}
