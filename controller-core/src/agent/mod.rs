//! The stateful controller of one agent: configuration, owned estimates (S9, S10), the
//! table of what it last heard from each neighbour, and the control step.

use crate::config::{AgentConfig, AgentId, ConfigError, EstimatorMode, LeaderRole, Schedule};
use crate::geometry::AngleGeometry;
use crate::law;
use crate::wire::FrameWriter;
use crate::{FrameStats, Real, Vec2};

mod comm;

/// No neighbour slot (the vertex is this agent itself).
const SELF_SLOT: usize = usize::MAX;

/// One bearing measured by this agent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BearingMeasurement<T: Real> {
    /// The neighbour it points to.
    pub neighbour: AgentId,
    /// Unit bearing `s_{n,neighbour}` in the shared world frame (S2).
    pub bearing: Vec2<T>,
    /// Measured bearing rate `ṡ`, if the sensor gives one. Without it the agent uses the
    /// finite difference of successive bearings (zero on the first step).
    pub rate: Option<Vec2<T>>,
    /// Measured distance, for [`EstimatorMode::Measured`].
    pub range: Option<T>,
}

/// What one agent's own sensors give it at one control tick.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Measurements<'a, T: Real> {
    /// Time in seconds (for the `v*`, `z*` schedules).
    pub time: T,
    /// Seconds since the previous step (the estimator's `Δt`, finite differences and
    /// neighbour ages). Zero is allowed (no time passes).
    pub dt: T,
    /// Own velocity `v_n` (world frame).
    pub velocity: Vec2<T>,
    /// Bearings to the neighbours (every triangle neighbour, every tick).
    pub bearings: &'a [BearingMeasurement<T>],
    /// Leaders only: the partner's position minus this agent's (relative-position sensor).
    pub partner_offset: Option<Vec2<T>>,
}

/// A measurement the agent refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum MeasurementError {
    /// Time, `Δt` (negative), velocity or partner offset is NaN or infinite.
    NonFinite,
    /// The bearing to this neighbour is not a finite unit vector (or its rate is not finite).
    BadBearing(AgentId),
    /// The bearing's neighbour is not a neighbour of this agent.
    UnknownNeighbour(AgentId),
    /// Two bearings to the same neighbour.
    DuplicateBearing(AgentId),
    /// A range that is not finite and positive.
    BadRange(AgentId),
}

/// Why a step produced the safe output instead of the control law.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Fault {
    /// The measurements were refused.
    Measurement(MeasurementError),
    /// No bearing to this triangle neighbour this tick.
    MissingBearing(AgentId),
    /// Nothing heard from this neighbour for longer than the timeout (or ever).
    Stale(AgentId),
    /// This neighbour's frames lacked something the step needs (its velocity, its
    /// bearing to a common neighbour, or the estimate it owns).
    MissingData(AgentId),
    /// A leader without the partner's relative position.
    MissingPartnerOffset,
    /// [`EstimatorMode::Measured`] without a range to this neighbour.
    MissingRange(AgentId),
    /// The computed force was not finite.
    NonFinite,
}

impl core::fmt::Display for MeasurementError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::NonFinite => write!(
                f,
                "time, dt, velocity or partner offset is not finite (or dt < 0)"
            ),
            Self::BadBearing(id) => write!(
                f,
                "bearing to agent {id} is not a finite unit vector (or its rate is not finite)"
            ),
            Self::UnknownNeighbour(id) => {
                write!(f, "bearing to agent {id}, which is not a neighbour")
            }
            Self::DuplicateBearing(id) => write!(f, "two bearings to agent {id}"),
            Self::BadRange(id) => write!(f, "range to agent {id} is not finite and positive"),
        }
    }
}

impl core::fmt::Display for Fault {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Measurement(e) => write!(f, "measurement refused: {e}"),
            Self::MissingBearing(id) => write!(f, "no bearing to agent {id} this tick"),
            Self::Stale(id) => write!(f, "agent {id} not heard within the timeout"),
            Self::MissingData(id) => write!(f, "agent {id}'s frames lack data this step needs"),
            Self::MissingPartnerOffset => {
                write!(f, "leader without the partner's relative position")
            }
            Self::MissingRange(id) => write!(f, "no range to agent {id} (measured-distance mode)"),
            Self::NonFinite => write!(f, "the computed force is not finite"),
        }
    }
}

/// The kind of output of a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Status {
    /// The control law S7–S12 (saturated to `max_force`).
    Nominal,
    /// The safe output `U = −safe_damping · v` (no formation force), and why.
    Safe(Fault),
}

/// The result of [`Agent::step`]. `force` is always finite and at most `max_force` long.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepOutput<T: Real> {
    /// The force command `U_n`.
    pub force: Vec2<T>,
    /// Control law or safe output.
    pub status: Status,
    /// The force was scaled down to `max_force`.
    pub saturated: bool,
    /// A current angle is within the configured margin of 0 or π (SPEC §3).
    pub degenerate: bool,
}

#[cfg(feature = "defmt")]
impl<T: Real> defmt::Format for StepOutput<T> {
    fn format(&self, f: defmt::Formatter) {
        defmt::write!(
            f,
            "StepOutput {{ force: ({}, {}), status: {}, saturated: {}, degenerate: {} }}",
            self.force.x,
            self.force.y,
            self.status,
            self.saturated,
            self.degenerate
        )
    }
}

/// The control law evaluated without changing any state (see [`Agent::evaluate`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluation<T: Real, const MT: usize> {
    /// `U_n` before saturation.
    pub force: Vec2<T>,
    /// S9 with the S10 projection for every estimate this agent owns, indexed
    /// `[triangle][angle][edge]` (zero where it owns none).
    pub estimate_rates: heapless::Vec<[[T; 2]; 2], MT>,
    /// A current angle is within the configured margin of 0 or π.
    pub degenerate: bool,
}

/// One estimate owned by this agent (see [`Agent::owned_estimates`]).
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct OwnedEstimate<T> {
    /// Triangle index in the configuration.
    pub triangle: usize,
    /// Controlled angle index (0 or 1) in the triangle.
    pub angle: usize,
    /// Edge index: 0 is apex → first far vertex, 1 is apex → second far vertex.
    pub edge: usize,
    /// The angle's apex.
    pub apex: AgentId,
    /// The far vertex of the edge.
    pub far: AgentId,
    /// `r̂`.
    pub value: T,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Role {
    Apex,
    Far(usize),
}

#[derive(Clone, Copy, Debug)]
struct AngleState<T: Real> {
    apex: AgentId,
    far: [AgentId; 2],
    role: Role,
    /// Neighbour slots of `[apex, far0, far1]` (`SELF_SLOT` for this agent).
    slots: [usize; 3],
    cos_desired: T,
    stiffness: T,
    damping: T,
    estimator_gain: T,
    /// Own estimates for edges `[apex–far0, apex–far1]` (only the owned ones are used).
    estimate: [T; 2],
    /// Far vertex only: the apex's bearing and rate to the other far vertex.
    remote_bearing: Option<(Vec2<T>, Vec2<T>)>,
    /// Far vertex, shared mode only: the apex's estimate for this agent's edge.
    remote_estimate: Option<T>,
    /// `estimate` before the fast step changed it (restored if that step fails).
    estimate_before: [T; 2],
}

#[derive(Clone, Debug)]
struct Neighbour<T: Real, const MT: usize> {
    id: AgentId,
    /// Angles (flat index `2·triangle + angle`) whose apex is this neighbour and of which
    /// this agent is a far vertex: where its bearing and estimate items go.
    apex_of: heapless::Vec<u8, MT>,
    /// Is in a triangle with this agent (needs a bearing every tick).
    in_triangle: bool,
    heard: bool,
    age: T,
    last_seq: Option<u16>,
    velocity: Option<Vec2<T>>,
    bearing: Option<Vec2<T>>,
    /// The last bearing (`bearing` without the `Option`; zero before the first one).
    s: Vec2<T>,
    /// Seconds since `bearing` was measured (finite-difference interval); −∞ while there
    /// is none.
    bearing_age: T,
    rate: Vec2<T>,
    range: Option<T>,
    fresh: bool,
}

/// One agent's controller: `MT` triangles at most, `NB` neighbours at most.
///
/// Per control tick: [`Agent::receive`] each frame heard since the last tick, then
/// [`Agent::step`] with the own measurements, then [`Agent::frames`] to broadcast.
/// Nothing here allocates or panics.
#[derive(Clone, Debug)]
pub struct Agent<T: Real, const MT: usize, const NB: usize> {
    config: AgentConfig<T, MT>,
    angles: heapless::Vec<[AngleState<T>; 2], MT>,
    neighbours: heapless::Vec<Neighbour<T, MT>, NB>,
    partner_slot: usize,
    /// Neighbour slots `0..bearings_needed` hold every triangle neighbour (they come
    /// first): the bearings each tick must cover.
    bearings_needed: usize,
    time: T,
    velocity: Vec2<T>,
    partner_offset: Option<Vec2<T>>,
    seq: u16,
    /// Frame buffer reused by [`Agent::frames`] (no zeroing per tick).
    writer: FrameWriter,
    stats: FrameStats,
}

/// Neither NaN nor infinite, in two float operations: `x − x` is 0 exactly for finite `x`
/// and NaN otherwise (cheaper on the FPU than the bit tests of `is_finite`).
#[inline(always)]
#[allow(clippy::eq_op)] // `x − x` on purpose: NaN for NaN and ±∞.
fn finite<T: Real>(x: T) -> bool {
    x - x == T::zero()
}

/// Both components finite (see [`finite`]): `(x − x) + (y − y)` is 0 or NaN.
#[inline(always)]
#[allow(clippy::eq_op)] // See `finite`.
fn finite_vec<T: Real>(v: &Vec2<T>) -> bool {
    (v.x - v.x) + (v.y - v.y) == T::zero()
}

fn finite_pair<T: Real>(v: &[T; 2], min: T) -> bool {
    v[0].finite() && v[1].finite() && v[0] >= min && v[1] >= min
}

/// `x[k]` for `k ∈ {0, 1}` (any other `k` reads index 1): panic-free pair indexing.
#[inline]
fn pick<X: Copy>(x: &[X; 2], k: usize) -> X {
    if k == 0 {
        x[0]
    } else {
        x[1]
    }
}

/// Apex bearings `[s_uv, s_uw]` and their rates, as seen by one agent.
type ApexBearings<T> = ([Vec2<T>; 2], [Vec2<T>; 2]);

fn vec2<T: Real>(a: [T; 2]) -> Vec2<T> {
    Vec2::new(a[0], a[1])
}

fn schedule_ok<T: Real>(s: &Schedule<T>) -> bool {
    s.steps
        .iter()
        .all(|st| st.from.finite() && st.value[0].finite() && st.value[1].finite())
}

impl<T: Real, const MT: usize, const NB: usize> Agent<T, MT, NB> {
    /// Checks `config` (SPEC §3 validity, gains, capacity) and builds the agent.
    pub fn new(config: AgentConfig<T, MT>) -> Result<Self, ConfigError> {
        Self::check_parameters(&config)?;
        let me = config.id;
        let mut neighbours: heapless::Vec<Neighbour<T, MT>, NB> = heapless::Vec::new();
        let mut angles = heapless::Vec::new();
        for (ti, tri) in config.triangles.iter().enumerate() {
            Self::check_triangle(me, ti, tri, &config.limits)?;
            let mut pair = [None, None];
            for (ai, a) in tri.angles.iter().enumerate() {
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
                let role = if a.apex == me {
                    Role::Apex
                } else if far[0] == me {
                    Role::Far(0)
                } else {
                    Role::Far(1)
                };
                let mut slots = [SELF_SLOT; 3];
                for (slot, id) in slots.iter_mut().zip([a.apex, far[0], far[1]]) {
                    if id != me {
                        *slot = Self::add_neighbour(&mut neighbours, id, true)?;
                    }
                }
                // A far vertex takes this angle's items from its apex (`comm::receive`).
                if let (Role::Far(_), Some(n)) = (role, neighbours.get_mut(slots[0])) {
                    // At most one controlled angle per triangle has this apex: ≤ MT entries.
                    let flat =
                        u8::try_from(2 * ti + ai).map_err(|_| ConfigError::TooManyNeighbours)?;
                    n.apex_of
                        .push(flat)
                        .map_err(|_| ConfigError::TooManyNeighbours)?;
                }
                if let Some(p) = pair.get_mut(ai) {
                    *p = Some(AngleState {
                        apex: a.apex,
                        far,
                        role,
                        slots,
                        cos_desired: a.cos_desired,
                        stiffness: a.stiffness,
                        damping: a.damping,
                        estimator_gain: a.estimator_gain,
                        estimate: [config.initial_estimate; 2],
                        remote_bearing: None,
                        remote_estimate: None,
                        estimate_before: [config.initial_estimate; 2],
                    });
                }
            }
            if let [Some(a0), Some(a1)] = pair {
                angles
                    .push([a0, a1])
                    .map_err(|_| ConfigError::TooManyNeighbours)?;
            }
        }
        let partner_slot = match &config.leader {
            Some(l) => Self::add_neighbour(&mut neighbours, l.partner, false)?,
            None => SELF_SLOT,
        };
        let bearings_needed = neighbours
            .iter()
            .rposition(|n| n.in_triangle)
            .map_or(0, |i| i + 1);
        Ok(Self {
            config,
            angles,
            neighbours,
            partner_slot,
            bearings_needed,
            time: T::zero(),
            velocity: Vec2::zeros(),
            partner_offset: None,
            seq: 0,
            writer: FrameWriter::new(me, 0),
            stats: FrameStats::default(),
        })
    }

    fn check_parameters(c: &AgentConfig<T, MT>) -> Result<(), ConfigError> {
        let l = &c.limits;
        let zero = T::zero();
        let ok = c.min_estimate.finite()
            && c.min_estimate > zero
            && c.initial_estimate.finite()
            && c.initial_estimate >= c.min_estimate
            && finite_pair(&c.friction, zero)
            && finite_pair(&c.velocity_damping, zero)
            && schedule_ok(&c.velocity_reference)
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
            && l.margin_cos < T::one();
        if !ok {
            return Err(ConfigError::BadParameter);
        }
        if let Some(ld) = &c.leader {
            if ld.partner == c.id {
                return Err(ConfigError::BadLeader);
            }
            if !(ld.stiffness.finite()
                && ld.stiffness > zero
                && finite_pair(&ld.damping, zero)
                && schedule_ok(&ld.displacement))
            {
                return Err(ConfigError::BadParameter);
            }
        }
        Ok(())
    }

    fn check_triangle(
        me: AgentId,
        ti: usize,
        tri: &crate::TriangleConfig<T>,
        limits: &crate::Limits<T>,
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

    fn add_neighbour(
        list: &mut heapless::Vec<Neighbour<T, MT>, NB>,
        id: AgentId,
        in_triangle: bool,
    ) -> Result<usize, ConfigError> {
        if let Some(i) = list.iter().position(|n| n.id == id) {
            if let Some(n) = list.get_mut(i) {
                n.in_triangle |= in_triangle;
            }
            return Ok(i);
        }
        list.push(Neighbour {
            id,
            apex_of: heapless::Vec::new(),
            in_triangle,
            heard: false,
            // Never heard: infinitely old (so `age <= timeout` alone means heard recently).
            age: T::lit(f64::INFINITY),
            last_seq: None,
            velocity: None,
            bearing: None,
            s: Vec2::zeros(),
            bearing_age: T::lit(f64::NEG_INFINITY),
            rate: Vec2::zeros(),
            range: None,
            fresh: false,
        })
        .map_err(|_| ConfigError::TooManyNeighbours)?;
        Ok(list.len() - 1)
    }

    /// This agent's id.
    pub fn id(&self) -> AgentId {
        self.config.id
    }

    /// The configuration it was built with.
    pub fn config(&self) -> &AgentConfig<T, MT> {
        &self.config
    }

    /// Ids of all neighbours (triangle neighbours and leader partner).
    pub fn neighbours(&self) -> impl Iterator<Item = AgentId> + '_ {
        self.neighbours.iter().map(|n| n.id)
    }

    /// Counters of accepted and rejected frames.
    pub fn stats(&self) -> &FrameStats {
        &self.stats
    }

    fn slot(&self, id: AgentId) -> Option<usize> {
        self.neighbours.iter().position(|n| n.id == id)
    }

    // ---------------------------------------------------------------- sensing

    /// Ages the neighbour table by `dt` (when `dt` is finite and ≥ 0, even if the rest is
    /// refused), then checks and stores the own measurements (bearings, rates, velocity,
    /// time). Nothing else changes if they are refused.
    pub fn sense(&mut self, m: &Measurements<'_, T>) -> Result<(), Fault> {
        self.sense_ready(m).map(|_| ())
    }

    /// [`Agent::sense`], also telling whether every neighbour was heard within the timeout
    /// (see [`Agent::check_fresh`]) and there is a bearing to every triangle neighbour this
    /// tick (what the shared-mode step needs from sensing).
    fn sense_ready(&mut self, m: &Measurements<'_, T>) -> Result<bool, Fault> {
        let dt = m.dt;
        if !(finite(dt) && dt >= T::zero()) {
            return Err(Fault::Measurement(MeasurementError::NonFinite));
        }
        // The checks read nothing that aging changes: age after them.
        let in_order = match self.check_measurements(m) {
            Ok(in_order) => in_order,
            Err(e) => {
                for n in self.neighbours.iter_mut() {
                    n.age += dt;
                    n.bearing_age += dt;
                }
                return Err(Fault::Measurement(e));
            }
        };
        self.time = m.time;
        self.velocity = m.velocity;
        self.partner_offset = m.partner_offset;
        // The oldest neighbour (NaN ignored, as in `check_fresh`).
        let mut age_max = T::zero();
        let ready;
        if in_order {
            // Bearing i is to slot i: one pass. Triangle neighbours are the first slots.
            ready = m.bearings.len() >= self.bearings_needed;
            let mut bearings = m.bearings.iter();
            for n in self.neighbours.iter_mut() {
                n.age += dt;
                if n.age > age_max {
                    age_max = n.age;
                }
                match bearings.next() {
                    Some(b) => Self::take_bearing(n, b, dt),
                    None => {
                        n.bearing_age += dt;
                        n.fresh = false;
                        n.range = None;
                    }
                }
            }
        } else {
            (ready, age_max) = self.take_bearings_searched(m.bearings, dt);
        }
        // `age` is ∞ until first heard: no need to read `heard`. (`age_max` is not NaN.)
        Ok(ready && age_max <= self.config.limits.neighbour_timeout)
    }

    /// Checks the own measurements (the faults of [`Agent::sense`] after `dt`, in the same
    /// order). Returns whether bearing `i` is to neighbour slot `i` for every `i`.
    fn check_measurements(&self, m: &Measurements<'_, T>) -> Result<bool, MeasurementError> {
        if !(finite(m.time) && finite_vec(&m.velocity)) {
            return Err(MeasurementError::NonFinite);
        }
        if let Some(p) = &m.partner_offset {
            if !finite_vec(p) {
                return Err(MeasurementError::NonFinite);
            }
        }
        let tol = self.config.limits.bearing_tolerance;
        // Usual case (what the firmware sends): bearing i is to slot i, so the bearings are
        // known and distinct without searching (neighbour ids are unique), and all valid.
        if m.bearings.len() <= self.neighbours.len()
            && m.bearings
                .iter()
                .zip(&self.neighbours)
                .all(|(b, n)| b.neighbour == n.id && Self::bearing_error(b, tol).is_none())
        {
            return Ok(true);
        }
        self.check_bearings_in_order(m.bearings, tol)
    }

    /// The bearing checks in general (any order): the first error in order, as the search
    /// finds it, or whether bearing `i` is to slot `i` for every `i`.
    #[cold]
    #[inline(never)]
    fn check_bearings_in_order(
        &self,
        bearings: &[BearingMeasurement<T>],
        tol: T,
    ) -> Result<bool, MeasurementError> {
        let mut in_order = true;
        let mut slots = self.neighbours.iter();
        for (i, b) in bearings.iter().enumerate() {
            let id = b.neighbour;
            in_order = in_order && slots.next().is_some_and(|n| n.id == id);
            if !in_order {
                if self.slot(id).is_none() {
                    return Err(MeasurementError::UnknownNeighbour(id));
                }
                if bearings.iter().take(i).any(|o| o.neighbour == id) {
                    return Err(MeasurementError::DuplicateBearing(id));
                }
            }
            if let Some(e) = Self::bearing_error(b, tol) {
                return Err(e);
            }
        }
        Ok(in_order)
    }

    /// What is wrong with one bearing measurement itself, if anything (neighbour aside).
    #[inline(always)]
    fn bearing_error(b: &BearingMeasurement<T>, tol: T) -> Option<MeasurementError> {
        // A unit vector within a finite tolerance is finite (NaN and ∞ fail the
        // comparison): no separate finiteness check.
        let s = &b.bearing;
        let unit = (s.dot(s) - T::one()).abs() <= tol;
        if !unit || !b.rate.as_ref().is_none_or(finite_vec) {
            return Some(MeasurementError::BadBearing(b.neighbour));
        }
        match b.range {
            Some(r) if !(finite(r) && r > T::zero()) => {
                Some(MeasurementError::BadRange(b.neighbour))
            }
            _ => None,
        }
    }

    /// Ages the neighbour table and stores checked bearings in any order (at most one per
    /// neighbour, so taking each slot's bearing is taking each bearing in turn). Returns
    /// whether every triangle neighbour got a bearing, and the largest age.
    #[cold]
    #[inline(never)]
    fn take_bearings_searched(&mut self, bearings: &[BearingMeasurement<T>], dt: T) -> (bool, T) {
        let mut covered = true;
        let mut age_max = T::zero();
        for n in self.neighbours.iter_mut() {
            n.age += dt;
            if n.age > age_max {
                age_max = n.age;
            }
            match Self::bearing_to(bearings, n.id) {
                Some(b) => Self::take_bearing(n, b, dt),
                None => {
                    n.bearing_age += dt;
                    n.fresh = false;
                    n.range = None;
                    covered &= !n.in_triangle;
                }
            }
        }
        (covered, age_max)
    }

    /// The bearing to neighbour `id`, if any.
    #[inline(never)]
    fn bearing_to(
        bearings: &[BearingMeasurement<T>],
        id: AgentId,
    ) -> Option<&BearingMeasurement<T>> {
        bearings.iter().find(|b| b.neighbour == id)
    }

    /// Stores a checked bearing of this tick and its rate; `dt` is the time since the last
    /// aging of `bearing_age` (zero if already aged).
    #[inline(always)]
    fn take_bearing(n: &mut Neighbour<T, MT>, b: &BearingMeasurement<T>, dt: T) {
        let interval = n.bearing_age + dt;
        n.rate = match b.rate {
            Some(rate) => rate,
            // Finite difference of successive bearings (SPEC §2), over the time since the
            // previous bearing (a missed tick widens the interval). Without a previous
            // bearing the interval is −∞.
            None if interval > T::zero() => (b.bearing - n.s) / interval,
            None => Vec2::zeros(),
        };
        n.bearing = Some(b.bearing);
        n.s = b.bearing;
        n.bearing_age = T::zero();
        n.range = b.range;
        n.fresh = true;
    }

    // ---------------------------------------------------------------- control law

    fn neighbour(&self, slot: usize) -> Option<&Neighbour<T, MT>> {
        self.neighbours.get(slot)
    }

    fn neighbour_velocity(&self, slot: usize) -> Result<Vec2<T>, Fault> {
        match self.neighbour(slot) {
            None => Ok(self.velocity),
            Some(n) => n.velocity.ok_or(Fault::MissingData(n.id)),
        }
    }

    /// Own measured bearing and rate to the neighbour in `slot`.
    fn own_bearing(&self, slot: usize) -> Result<(Vec2<T>, Vec2<T>), Fault> {
        let n = self.neighbour(slot).ok_or(Fault::NonFinite)?;
        match (n.fresh, n.bearing) {
            (true, Some(s)) => Ok((s, n.rate)),
            _ => Err(Fault::MissingBearing(n.id)),
        }
    }

    /// The apex bearings `[s_uv, s_uw]` and rates of an angle, seen by this agent.
    fn angle_bearings(&self, a: &AngleState<T>) -> Result<ApexBearings<T>, Fault> {
        match a.role {
            Role::Apex => {
                let (s0, d0) = self.own_bearing(a.slots[1])?;
                let (s1, d1) = self.own_bearing(a.slots[2])?;
                Ok(([s0, s1], [d0, d1]))
            }
            Role::Far(k) => {
                // s_uk = −s_ku: own bearing to the apex, reversed (SPEC §2).
                let (s_k, d_k) = self.own_bearing(a.slots[0])?;
                let (s_j, d_j) = a.remote_bearing.ok_or(Fault::MissingData(a.apex))?;
                Ok(if k == 0 {
                    ([-s_k, s_j], [-d_k, d_j])
                } else {
                    ([s_j, -s_k], [d_j, -d_k])
                })
            }
        }
    }

    /// Distances `[r_uv, r_uw]` used in S8 (only the ones this agent's force needs).
    fn angle_distances(&self, a: &AngleState<T>) -> Result<[T; 2], Fault> {
        match (self.config.estimator, a.role) {
            (EstimatorMode::Shared, Role::Far(k)) => {
                let r = a.remote_estimate.ok_or(Fault::MissingData(a.apex))?;
                let mut out = a.estimate;
                if let Some(o) = out.get_mut(k) {
                    *o = r;
                }
                Ok(out)
            }
            (EstimatorMode::Shared | EstimatorMode::PerAgent, _) => Ok(a.estimate),
            (EstimatorMode::Measured, Role::Apex) => {
                Ok([self.range(a.slots[1])?, self.range(a.slots[2])?])
            }
            (EstimatorMode::Measured, Role::Far(k)) => {
                let mut out = [T::one(); 2];
                if let Some(o) = out.get_mut(k) {
                    *o = self.range(a.slots[0])?;
                }
                Ok(out)
            }
        }
    }

    fn range(&self, slot: usize) -> Result<T, Fault> {
        let n = self.neighbour(slot).ok_or(Fault::NonFinite)?;
        n.range.ok_or(Fault::MissingRange(n.id))
    }

    /// Whether this agent owns (integrates) the estimate of `edge` of angle `a`.
    fn owns(&self, a: &AngleState<T>, edge: usize) -> bool {
        match (self.config.estimator, a.role) {
            (EstimatorMode::Measured, _) => false,
            (_, Role::Apex) => true,
            (EstimatorMode::PerAgent, Role::Far(k)) => k == edge,
            (EstimatorMode::Shared, Role::Far(_)) => false,
        }
    }

    /// Checks that every neighbour has been heard recently (or reports the stale one).
    fn check_fresh(&self) -> Result<(), Fault> {
        let timeout = self.config.limits.neighbour_timeout;
        for n in &self.neighbours {
            if !n.heard || n.age > timeout {
                return Err(Fault::Stale(n.id));
            }
        }
        Ok(())
    }

    /// Evaluates the control law S7–S12 and the estimator flows S9/S10 on the stored
    /// measurements and neighbour data, without changing anything. Used by [`Agent::step`]
    /// and by simulators that integrate the estimators themselves (continuous time).
    /// (`step`'s shared-mode fast path repeats this arithmetic: change both together.)
    pub fn evaluate(&self) -> Result<Evaluation<T, MT>, Fault> {
        self.check_fresh()?;
        let c = &self.config;
        let v = self.velocity;
        let v_star = vec2(c.velocity_reference.at(self.time));
        // S12.
        let mut force = law::velocity_force(&c.friction, &c.velocity_damping, &v, &v_star);
        let mut rates = heapless::Vec::new();
        let mut degenerate = false;
        let r_min = c.min_estimate;
        for tri in &self.angles {
            let mut tri_rates = [[T::zero(); 2]; 2];
            for (a, out) in tri.iter().zip(tri_rates.iter_mut()) {
                let (s, s_dot) = self.angle_bearings(a)?;
                // S4–S6.
                let geo = AngleGeometry::new(&s, &s_dot);
                degenerate |= geo.y.abs() > c.limits.margin_cos;
                // S7.
                let gamma =
                    law::port_effort(a.stiffness, a.damping, geo.y - a.cos_desired, geo.y_dot);
                let r = self.angle_distances(a)?;
                // S8.
                force += match a.role {
                    Role::Apex => law::apex_force(gamma, &geo.g, r),
                    Role::Far(k) => law::far_vertex_force(gamma, &pick(&geo.g, k), pick(&r, k)),
                };
                // S9/S10 for the estimates this agent owns.
                for (e, rate) in out.iter_mut().enumerate() {
                    if !self.owns(a, e) {
                        continue;
                    }
                    let r_hat = pick(&a.estimate, e);
                    let (s_e, g_e) = (pick(&s, e), pick(&geo.g, e));
                    let (range_rate, share) = match a.role {
                        Role::Apex => {
                            let v_far =
                                self.neighbour_velocity(pick(&[a.slots[1], a.slots[2]], e))?;
                            let rr = crate::geometry::range_rate(&s_e, &(v_far - v));
                            let share = match c.estimator {
                                EstimatorMode::PerAgent => law::own_share(&g_e, &v, r_hat, false),
                                _ => pick(&geo.t, e),
                            };
                            (rr, share)
                        }
                        Role::Far(_) => {
                            let v_apex = self.neighbour_velocity(a.slots[0])?;
                            let rr = crate::geometry::range_rate(&s_e, &(v - v_apex));
                            (rr, law::own_share(&g_e, &v, r_hat, true))
                        }
                    };
                    let flow =
                        law::estimator_rate(range_rate, gamma, share, a.estimator_gain, r_hat);
                    *rate = law::projected_rate(r_hat, flow, r_min);
                }
            }
            // Capacity equals the number of triangles: cannot fail.
            let _ = rates.push(tri_rates);
        }
        if let Some(l) = &c.leader {
            // S11 with z = q_a − q_b.
            let p = self.partner_offset.ok_or(Fault::MissingPartnerOffset)?;
            let v_p = self.neighbour_velocity(self.partner_slot)?;
            let z_star = vec2(l.displacement.at(self.time));
            let (z, z_dot, sign) = match l.role {
                LeaderRole::A => (-p, v - v_p, T::one()),
                LeaderRole::B => (p, v_p - v, -T::one()),
            };
            force += law::leader_force(l.stiffness, &l.damping, &(z - z_star), &z_dot) * sign;
        }
        if !finite_vec(&force) {
            return Err(Fault::NonFinite);
        }
        Ok(Evaluation {
            force,
            estimate_rates: rates,
            degenerate,
        })
    }

    /// One control tick: [`Agent::sense`], [`Agent::evaluate`], integrate the owned
    /// estimates (sampled S10), saturate. On any fault the output is the documented safe
    /// command `U = −safe_damping · v` (no formation force) and the estimates hold still.
    ///
    /// In shared mode with everything present (the usual tick) this runs a fused version
    /// of evaluate-and-integrate (`control_shared`, same arithmetic); anything else, and
    /// every fault, goes through [`Agent::evaluate`], which names the fault.
    pub fn step(&mut self, m: &Measurements<'_, T>) -> StepOutput<T> {
        let limit = self.config.limits.max_force;
        let result = match self.sense_ready(m) {
            Err(fault) => Err(fault),
            Ok(ready) => match ready.then(|| self.control_shared(m.dt)).flatten() {
                Some(out) => Ok(out),
                None => self.control_reference(m.dt),
            },
        };
        match result {
            Ok((force, degenerate)) => {
                let (force, saturated) = law::saturate(&force, limit);
                StepOutput {
                    force,
                    status: Status::Nominal,
                    saturated,
                    degenerate,
                }
            }
            Err(fault) => {
                let v = if finite_vec(&m.velocity) {
                    m.velocity
                } else {
                    Vec2::zeros()
                };
                let (force, saturated) =
                    law::saturate(&(v * -self.config.limits.safe_damping), limit);
                StepOutput {
                    force,
                    status: Status::Safe(fault),
                    saturated,
                    degenerate: false,
                }
            }
        }
    }

    /// [`Agent::evaluate`], then the owned estimates integrated over `dt` (sampled S10).
    /// Returns the unsaturated force and `degenerate`.
    fn control_reference(&mut self, dt: T) -> Result<(Vec2<T>, bool), Fault> {
        let ev = self.evaluate()?;
        let r_min = self.config.min_estimate;
        for (tri, rates) in self.angles.iter_mut().zip(ev.estimate_rates.iter()) {
            for (a, ar) in tri.iter_mut().zip(rates.iter()) {
                for (est, rate) in a.estimate.iter_mut().zip(ar.iter()) {
                    *est = law::estimator_step(*est, *rate, dt, r_min);
                }
            }
        }
        Ok((ev.force, ev.degenerate))
    }

    /// Shared mode: the control law S4–S12 and the sampled estimators S9/S10 in one pass,
    /// with the same arithmetic as [`Agent::evaluate`] followed by the integration of
    /// `control_reference`. Call only when `sense_ready` said ready (every neighbour heard
    /// within the timeout, a bearing to every triangle neighbour). Returns the unsaturated
    /// force and `degenerate`; `None`, with the estimates unchanged, when something else is
    /// missing (a velocity, the apex's bearing or estimate, the partner offset) or the
    /// force is not finite: the caller then takes the reference path, which reports the
    /// fault.
    ///
    /// A second implementation of the law: change it together with [`Agent::evaluate`].
    /// `tests/tests/step_fast.rs` checks that both agree bit for bit.
    fn control_shared(&mut self, dt: T) -> Option<(Vec2<T>, bool)> {
        let c = &self.config;
        if c.estimator != EstimatorMode::Shared {
            return None;
        }
        let v = self.velocity;
        let v_star = vec2(c.velocity_reference.at(self.time));
        // S12.
        let mut force = law::velocity_force(&c.friction, &c.velocity_damping, &v, &v_star);
        let r_min = c.min_estimate;
        let nbs = self.neighbours.as_slice();
        let mut ok = true;
        // Largest |y| (NaN ignored, as in `|y| > margin`): degenerate iff above the margin.
        let mut y_max = T::zero();
        for a in self.angles.as_mut_slice().as_flattened_mut() {
            if a.role == Role::Apex {
                a.estimate_before = a.estimate;
                let (Some(nv), Some(nw)) = (nbs.get(a.slots[1]), nbs.get(a.slots[2])) else {
                    ok = false;
                    continue;
                };
                let s = [nv.s, nw.s];
                // S4–S6 from the own bearings and rates.
                let geo = AngleGeometry::new(&s, &[nv.rate, nw.rate]);
                let y_abs = geo.y.abs();
                if y_abs > y_max {
                    y_max = y_abs;
                }
                // S7.
                let gamma =
                    law::port_effort(a.stiffness, a.damping, geo.y - a.cos_desired, geo.y_dot);
                let r = a.estimate;
                // S8 on the apex.
                force += law::apex_force(gamma, &geo.g, r);
                // S9 (S3 for ṙ, share t_{α,e}), then the sampled S10
                // `max(r_min, r̂ + Δt·S9)`. The continuous S10 projection that
                // `evaluate` applies first changes nothing here: it only acts when
                // r̂ ≤ r_min and S9 < 0, and then (Δt ≥ 0) both give r_min.
                let gain = a.estimator_gain;
                let mut next = |s_e: &Vec2<T>, v_far: &Option<Vec2<T>>, t_e: T, r_e: T| {
                    let Some(v_far) = v_far else {
                        ok = false;
                        return r_e;
                    };
                    let rr = crate::geometry::range_rate(s_e, &(v_far - v));
                    let flow = law::estimator_rate(rr, gamma, t_e, gain, r_e);
                    law::estimator_step(r_e, flow, dt, r_min)
                };
                a.estimate = [
                    next(&s[0], &nv.velocity, geo.t[0], r[0]),
                    next(&s[1], &nw.velocity, geo.t[1], r[1]),
                ];
            } else {
                let (Some(nu), Some((s_j, d_j)), Some(r_k)) =
                    (nbs.get(a.slots[0]), a.remote_bearing, a.remote_estimate)
                else {
                    ok = false;
                    continue;
                };
                // s_uk = −s_ku, ṡ_uk = −ṡ_ku (SPEC §2); S4–S6 with this agent's edge
                // first (the order of the two edges does not change y, ẏ or g_k).
                let geo = AngleGeometry::new(&[-nu.s, s_j], &[-nu.rate, d_j]);
                let y_abs = geo.y.abs();
                if y_abs > y_max {
                    y_max = y_abs;
                }
                // S7.
                let gamma =
                    law::port_effort(a.stiffness, a.damping, geo.y - a.cos_desired, geo.y_dot);
                // S8 on this far vertex, with the apex's estimate of its edge.
                force += law::far_vertex_force(gamma, &geo.g[0], r_k);
            }
        }
        if let Some(l) = &c.leader {
            // S11 with z = q_a − q_b.
            match (
                self.partner_offset,
                self.neighbour_velocity(self.partner_slot),
            ) {
                (Some(p), Ok(v_p)) => {
                    let z_star = vec2(l.displacement.at(self.time));
                    // Agent b gets the negation (exactly what `evaluate`'s `* −1` gives).
                    match l.role {
                        LeaderRole::A => {
                            force += law::leader_force(
                                l.stiffness,
                                &l.damping,
                                &(-p - z_star),
                                &(v - v_p),
                            );
                        }
                        LeaderRole::B => {
                            force -= law::leader_force(
                                l.stiffness,
                                &l.damping,
                                &(p - z_star),
                                &(v_p - v),
                            );
                        }
                    }
                }
                _ => ok = false,
            }
        }
        if ok && finite_vec(&force) {
            return Some((force, y_max > c.limits.margin_cos));
        }
        for a in self.angles.as_mut_slice().as_flattened_mut() {
            if a.role == Role::Apex {
                a.estimate = a.estimate_before;
            }
        }
        None
    }

    // ---------------------------------------------------------------- estimates

    /// The estimates this agent owns and integrates, with where they belong.
    pub fn owned_estimates(&self) -> impl Iterator<Item = OwnedEstimate<T>> + '_ {
        self.angles.iter().enumerate().flat_map(move |(ti, tri)| {
            tri.iter().enumerate().flat_map(move |(ai, a)| {
                (0..2usize)
                    .filter(move |&e| self.owns(a, e))
                    .map(move |e| OwnedEstimate {
                        triangle: ti,
                        angle: ai,
                        edge: e,
                        apex: a.apex,
                        far: pick(&a.far, e),
                        value: pick(&a.estimate, e),
                    })
            })
        })
    }

    /// Overwrites an owned estimate (for simulators integrating S9 in continuous time).
    /// Values are clamped to `r_min`; returns `false` for an estimate this agent does not own
    /// or a non-finite value.
    pub fn set_estimate(&mut self, triangle: usize, angle: usize, edge: usize, value: T) -> bool {
        let owned = match self.angles.get(triangle).and_then(|t| t.get(angle)) {
            Some(a) => self.owns(a, edge),
            None => false,
        };
        let r_min = self.config.min_estimate;
        let slot = self
            .angles
            .get_mut(triangle)
            .and_then(|t| t.get_mut(angle))
            .and_then(|a| a.estimate.get_mut(edge));
        match slot {
            Some(s) if owned && value.finite() => {
                *s = if value > r_min { value } else { r_min };
                true
            }
            _ => false,
        }
    }
}
