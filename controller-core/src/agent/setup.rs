//! Building an [`Agent`] from its configuration: the checks of SPEC §3 and of every
//! parameter, the angle states and the neighbour table.

use super::state::{AngleState, ApexOf, ApexPart, Neighbour, Remote, Side, SELF_SLOT};
use super::{Agent, Fault};
use crate::config::{
    AgentConfig, AgentId, BearingFilter, ConfigError, EstimatorMode, Limits, TriangleConfig,
};
use crate::wire::{mode_byte, quant, FrameWriter};
use crate::{FrameStats, Real, Vec2};

fn finite_pair<T: Real>(v: &[T; 2], min: T) -> bool {
    v[0].finite() && v[1].finite() && v[0] >= min && v[1] >= min
}

impl<T: Real, const MT: usize, const NB: usize> Agent<T, MT, NB> {
    /// Checks `config` (SPEC §3 validity, gains, parameters, schedules, capacity) and
    /// builds the agent.
    pub fn new(config: AgentConfig<T, MT>) -> Result<Self, ConfigError> {
        check_parameters(&config)?;
        let me = config.id;
        let mut neighbours: heapless::Vec<Neighbour<T, MT>, NB> = heapless::Vec::new();
        let mut angles = heapless::Vec::new();
        for (ti, tri) in config.triangles.iter().enumerate() {
            check_triangle(me, ti, tri, &config.limits)?;
            let mut pair = [None, None];
            for ((ai, a), out) in tri.angles.iter().enumerate().zip(pair.iter_mut()) {
                let mut far = [0; 2];
                let mut k = 0;
                for &v in &tri.vertices {
                    if v != a.apex {
                        if let Some(f) = far.get_mut(k) {
                            *f = v;
                        }
                        k += 1;
                    }
                }
                let side = if a.apex == me {
                    Side::Apex {
                        part: ApexPart::default(),
                        fault: Some(Fault::MissingBearing(far[0])),
                    }
                } else {
                    Side::Far {
                        k: usize::from(far[0] != me),
                        remote: Remote::default(),
                        age: T::lit(f64::INFINITY),
                    }
                };
                let mut slots = [SELF_SLOT; 3];
                for (slot, id) in slots.iter_mut().zip([a.apex, far[0], far[1]]) {
                    if id != me {
                        *slot = add_neighbour(&mut neighbours, id)?;
                    }
                }
                // A far vertex takes this angle's items from its apex (`comm::receive`).
                if let (Side::Far { k, .. }, Some(n)) = (&side, neighbours.get_mut(slots[0])) {
                    let flat =
                        u16::try_from(2 * ti + ai).map_err(|_| ConfigError::TooManyTriangles)?;
                    let other = if *k == 0 { far[1] } else { far[0] };
                    // At most one controlled angle per triangle has this apex: ≤ MT entries.
                    n.apex_of
                        .push(ApexOf { other, flat })
                        .map_err(|_| ConfigError::TooManyTriangles)?;
                }
                *out = Some(AngleState {
                    apex: a.apex,
                    far,
                    side,
                    slots,
                    cos_desired: a.cos_desired,
                    stiffness: a.stiffness,
                    damping: a.damping,
                    estimator_gain: a.estimator_gain,
                    estimate: [config.initial_estimate; 2],
                    flow: [T::zero(); 2],
                });
            }
            if let [Some(a0), Some(a1)] = pair {
                angles
                    .push([a0, a1])
                    .map_err(|_| ConfigError::TooManyTriangles)?;
            }
        }
        let partner_slot = match &config.leader {
            Some(l) => add_neighbour(&mut neighbours, l.partner)?,
            None => SELF_SLOT,
        };
        let writer = FrameWriter::new(config.integrity);
        let mode = mode_byte(config.integrity, config.estimator);
        let range_min_code = match config.estimator {
            EstimatorMode::Measured => 1,
            EstimatorMode::Shared | EstimatorMode::PerAgent => {
                quant::encode(config.min_estimate.as_f32()).0
            }
        };
        let comm_countdown = config.comm_phase;
        Ok(Self {
            config,
            angles,
            neighbours,
            partner_slot,
            time: T::zero(),
            velocity: Vec2::zeros(),
            partner_offset: None,
            counter: [0; 2],
            sync_countdown: 0,
            oldest: None,
            comm_countdown,
            comm_due: true,
            writer,
            range_min_code,
            mode,
            next_slot: 0,
            stats: FrameStats::default(),
        })
    }
}

fn check_parameters<T: Real, const MT: usize>(c: &AgentConfig<T, MT>) -> Result<(), ConfigError> {
    let l = &c.limits;
    let zero = T::zero();
    let ok = c.min_estimate.finite()
        && c.min_estimate > zero
        && c.initial_estimate.finite()
        && c.initial_estimate >= c.min_estimate
        && finite_pair(&c.friction, zero)
        && finite_pair(&c.velocity_damping, zero)
        && l.max_force.finite()
        && l.max_force > zero
        && l.neighbour_timeout.finite()
        && l.neighbour_timeout > zero
        && l.safe_damping.finite()
        && l.safe_damping >= zero
        && l.bearing_tolerance.finite()
        && l.bearing_tolerance > zero
        && l.margin_cos.finite()
        && l.margin_cos > zero
        && l.margin_cos < T::one()
        && l.bearing_hold.finite()
        && l.bearing_hold >= zero;
    if !ok {
        return Err(ConfigError::BadParameter);
    }
    if !c.velocity_reference.is_valid() {
        return Err(ConfigError::BadSchedule);
    }
    if let BearingFilter::Tracker(t) = &c.bearing_filter {
        if !t.is_valid() {
            return Err(ConfigError::BadBearingFilter);
        }
    }
    if c.comm_every == 0 || c.comm_phase >= c.comm_every {
        return Err(ConfigError::BadCommRate);
    }
    if let Some(ld) = &c.leader {
        if ld.partner == c.id {
            return Err(ConfigError::BadLeader);
        }
        if !(ld.stiffness.finite() && ld.stiffness > zero && finite_pair(&ld.damping, zero)) {
            return Err(ConfigError::BadParameter);
        }
        if !ld.displacement.is_valid() {
            return Err(ConfigError::BadSchedule);
        }
    }
    Ok(())
}

fn check_triangle<T: Real>(
    me: AgentId,
    ti: usize,
    tri: &TriangleConfig<T>,
    limits: &Limits<T>,
) -> Result<(), ConfigError> {
    let [a, b, c] = tri.vertices;
    if a == b || b == c || a == c {
        return Err(ConfigError::RepeatedVertex { triangle: ti });
    }
    if !tri.vertices.contains(&me) {
        return Err(ConfigError::NotInTriangle { triangle: ti });
    }
    let [x, y] = &tri.angles;
    if x.apex == y.apex || !tri.vertices.contains(&x.apex) || !tri.vertices.contains(&y.apex) {
        return Err(ConfigError::BadApex { triangle: ti });
    }
    let zero = T::zero();
    for an in &tri.angles {
        if !(an.stiffness.finite()
            && an.stiffness > zero
            && an.damping.finite()
            && an.damping >= zero
            && an.estimator_gain.finite()
            && an.estimator_gain > zero)
        {
            return Err(ConfigError::BadGain { triangle: ti });
        }
        // SPEC §3: margin < α* < π − margin, i.e. |cos α*| < cos(margin).
        if !(an.cos_desired.finite() && an.cos_desired.abs() < limits.margin_cos) {
            return Err(ConfigError::InfeasibleAngles { triangle: ti });
        }
    }
    // SPEC §3: α₁ + α₂ < π  ⇔  cos α₁ > cos(π − α₂) = −cos α₂.
    if x.cos_desired + y.cos_desired <= zero {
        return Err(ConfigError::InfeasibleAngles { triangle: ti });
    }
    Ok(())
}

/// The slot of neighbour `id`, added if new. (Triangle neighbours come first, the leader
/// partner is added last: the firmware's bearings in slot order are then a prefix.)
fn add_neighbour<T: Real, const MT: usize, const NB: usize>(
    list: &mut heapless::Vec<Neighbour<T, MT>, NB>,
    id: AgentId,
) -> Result<usize, ConfigError> {
    if let Some(i) = list.iter().position(|n| n.id == id) {
        return Ok(i);
    }
    list.push(Neighbour::new(id))
        .map_err(|_| ConfigError::TooManyNeighbours)?;
    Ok(list.len() - 1)
}
