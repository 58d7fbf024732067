//! The vehicles' safety policies in the simulator (`[policy]`): the core's
//! [`ph_formation_core::policy`], the same code the Crazyflie app runs through the C API
//! (`crazyflie-app/src/flight.c`), applied to each agent's force after its tick.
//!
//! * **Fly**: the controller's force, through the minimum-separation guard against its
//!   radio neighbours' true positions.
//! * **Hold** (the controller gave its safe output: neighbours or radio lost): the safe
//!   output itself, `U = −safe_damping · v`.
//! * **Land** (lost for `hold_timeout_s`, outside the fence, or the battery
//!   (`[battery]`) below `battery_land_v` for `battery_land_s`): from then on the
//!   agent only brakes, `U = −safe_damping · v`, and counts as landed (the simulator is
//!   planar: a landed agent stays where it stopped).
//!
//! What the policies did is [`PolicyRun::counts`], per agent, on the run result
//! ([`crate::engine::RunResult::policy`]).

use crate::model::{BatteryModel, Model};
use ph_formation_core::policy::PolicyReason;
use ph_formation_core::policy::{
    separation_guard, Policy, PolicyAction, PolicyConfig, PolicyCounts, PolicyInputs,
};
use ph_formation_core::{Status, StepOutput, Vec2};

/// Every agent's policies.
#[derive(Clone, Debug)]
pub struct PolicyRun {
    config: PolicyConfig<f64>,
    policies: Vec<Policy>,
    /// The battery the low-battery policy reads (`None`: 0 V, the policy off).
    battery: Option<BatteryModel>,
    /// Each agent's flight time so far (s): the sum of its ticks' `dt`.
    flown: Vec<f64>,
}

impl PolicyRun {
    /// Policies for `n` agents, all flying, on `battery`.
    pub fn new(config: PolicyConfig<f64>, n: usize, battery: Option<BatteryModel>) -> Self {
        Self {
            config,
            policies: vec![Policy::new(); n],
            battery,
            flown: vec![0.0; n],
        }
    }

    /// Agent `i`'s force after its tick: `out` its controller's output, `dt` the time
    /// since its last tick (s), `q`, `v` every agent's position and velocity,
    /// `neighbours` its radio neighbours (indices), `safe_damping` its safe output's
    /// gain.
    #[allow(clippy::too_many_arguments)]
    pub fn force(
        &mut self,
        i: usize,
        out: &StepOutput<f64>,
        dt: f64,
        q: &[Vec2<f64>],
        v: &[Vec2<f64>],
        neighbours: &[usize],
        safe_damping: f64,
    ) -> Vec2<f64> {
        let (Some(p), Some(qi), Some(vi)) = (self.policies.get_mut(i), q.get(i), v.get(i)) else {
            return out.force;
        };
        #[allow(clippy::cast_possible_truncation, clippy::cast_sign_loss)]
        let dt_ms = (dt * 1000.0).round().clamp(0.0, f64::from(u32::MAX)) as u32;
        let flown = self.flown.get_mut(i).map_or(0.0, |t| {
            *t += dt;
            *t
        });
        let input = PolicyInputs {
            dt_ms,
            lost: !matches!(out.status, Status::Nominal),
            position: [qi.x, qi.y],
            positioning: true,
            battery: self.battery.map_or(0.0, |b| b.voltage(flown)),
        };
        match p.update(&self.config, &input).0 {
            PolicyAction::Fly => {
                let others = neighbours.iter().filter_map(|&j| q.get(j).copied());
                let (f, changed) =
                    separation_guard(out.force, *qi, others, self.config.min_separation);
                if changed {
                    p.count_guard();
                }
                f
            }
            PolicyAction::Hold => out.force,
            PolicyAction::Land => -*vi * safe_damping,
        }
    }

    /// What the policies did, per agent (agent order).
    pub fn counts(&self) -> Vec<PolicyCounts> {
        self.policies.iter().map(Policy::counts).collect()
    }
}

/// The outcome's note on the policies' landings: how many agents landed, by reason,
/// naming them (`None` when none did).
pub fn landings_note(counts: &[PolicyCounts], model: &Model) -> Option<String> {
    let reasons = [
        (
            PolicyReason::LostTimeout,
            "neighbours or radio lost past hold_timeout_s",
        ),
        (PolicyReason::Fence, "outside the fence"),
        (PolicyReason::Battery, "low battery"),
        (PolicyReason::Positioning, "positioning lost"),
    ];
    let landed = counts.iter().filter(|c| c.landings > 0).count();
    if landed == 0 {
        return None;
    }
    let parts: Vec<String> = reasons
        .iter()
        .filter_map(|(reason, what)| {
            let agents: Vec<String> = counts
                .iter()
                .zip(&model.agents)
                .filter(|(c, _)| c.landings > 0 && c.last_landing == *reason)
                .map(|(_, a)| a.id.to_string())
                .collect();
            let noun = if agents.len() == 1 { "agent" } else { "agents" };
            (!agents.is_empty()).then(|| format!("{what}: {noun} {}", agents.join(", ")))
        })
        .collect();
    Some(format!(
        "the safety policies landed {landed} of {} agents ({})",
        counts.len(),
        parts.join("; ")
    ))
}
