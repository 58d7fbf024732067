//! The measured control step and its configurations.
//!
//! One measured step of an agent (what `insn_step_<name>` in
//! `firmware-example/budgets.toml` budgets) is exactly the work of one
//! control tick of [`ControlLoop::tick`](crate::app::ControlLoop::tick)
//! without the drivers:
//!
//! 1. decode and [`Agent::receive`] every frame its neighbours broadcast in
//!    one tick,
//! 2. [`Agent::step`] (sensing checks, finite-difference bearing rates, the
//!    control law S7–S12, the estimators S9/S10, saturation),
//! 3. [`Agent::frames`]: encode its own broadcast into frame buffers.
//!
//! The agent is the centre of a fan: agent 1 in the `k` triangles
//! `(1, r_i, r_{i+1})`, `i = 0..k`, with the rim agents `r_0 … r_k` on an
//! arc around it. In every triangle the centre and `r_i` hold the controlled
//! angles, so the centre is the apex of `k` angles (it integrates `2k`
//! estimates) and a far vertex of `k` more; it is also a leader (S11, partner
//! `r_0`) and tracks `v*` (S12): every term of the law is exercised.
//!
//! [`Bench::reset`] builds the fan deterministically: all agents move at
//! constant, distinct velocities near the desired shape; the centre and the
//! rim agents (real `controller-core` agents) run [`WARMUP_TICKS`] ticks
//! before the measured one, and the frames the rim agents broadcast in the
//! measured tick are kept. The rim agents run one at a time (keeping all
//! nine alive at once would take 8 KiB of RAM) and hear nobody, so they
//! answer with their safe output and hold their estimates at `r̂(0)`; their
//! frames are nonetheless complete (velocity, the bearings and bearing rates
//! their far vertices need, the estimates they own), which is all that the
//! centre's receive and step depend on. The centre has not heard anybody
//! before the measured tick: its step is nominal (checked by the `measure`
//! binary) because the frames it decodes first carry everything it needs.
//! The bench then holds the centre's state, the frames its neighbours
//! broadcast in the measured tick and its own measurements.

use heapless::Vec;
use ph_formation_core::{
    Agent, AgentConfig, AgentId, AngleConfig, BearingMeasurement, ConfigError, Integrity,
    LeaderConfig, LeaderRole, Measurements, Real, Schedule, Status, StepOutput, TriangleConfig,
    Vec2,
};

use crate::hal::MAX_FRAME_LEN;

/// One measured configuration of the control step.
#[derive(Clone, Copy, Debug)]
pub struct StepConfig {
    /// Short name; the budget key is `insn_step_<name>`.
    pub name: &'static str,
    /// Number of triangles (formation constraints) this robot takes part in.
    pub triangles: usize,
    /// How every agent of the bench protects its frames.
    pub integrity: Integrity,
    /// Every agent differentiates its bearings (SPEC §2) instead of running the bearing
    /// tracker (SPEC §11, the default): the `_fd` rows, the wire's own cost.
    pub finite_difference: bool,
    /// The bearing to the last rim agent is missing in the measured tick and held
    /// ([`ph_formation_core::Limits::bearing_hold`], SPEC §12): the `_held` rows.
    pub held: bool,
}

/// The `auth` configurations' key: the public placeholder (see [`crate::keys`]).
const AUTH: Integrity = Integrity::Auth(crate::keys::PLACEHOLDER_SWARM_KEY);

/// The configurations measured by the `measure` binary, in order: `crc16`
/// integrity (`triN`), `link` (`triN_link`: no trailer, the radio checks its own
/// CRC), `auth` (`triN_auth`), and `crc16` with finite-difference bearing rates
/// instead of the bearing tracker (`triN_fd`); `_held`: one bearing missing in the
/// measured tick and held or predicted (SPEC §12).
pub const STEP_CONFIGS: [StepConfig; 12] = [
    StepConfig {
        name: "tri1",
        triangles: 1,
        integrity: Integrity::Crc16,
        finite_difference: false,
        held: false,
    },
    StepConfig {
        name: "tri2",
        triangles: 2,
        integrity: Integrity::Crc16,
        finite_difference: false,
        held: false,
    },
    StepConfig {
        name: "tri4",
        triangles: 4,
        integrity: Integrity::Crc16,
        finite_difference: false,
        held: false,
    },
    StepConfig {
        name: "tri8",
        triangles: 8,
        integrity: Integrity::Crc16,
        finite_difference: false,
        held: false,
    },
    StepConfig {
        name: "tri2_link",
        triangles: 2,
        integrity: Integrity::Link,
        finite_difference: false,
        held: false,
    },
    StepConfig {
        name: "tri8_link",
        triangles: 8,
        integrity: Integrity::Link,
        finite_difference: false,
        held: false,
    },
    StepConfig {
        name: "tri2_auth",
        triangles: 2,
        integrity: AUTH,
        finite_difference: false,
        held: false,
    },
    StepConfig {
        name: "tri8_auth",
        triangles: 8,
        integrity: AUTH,
        finite_difference: false,
        held: false,
    },
    StepConfig {
        name: "tri2_fd",
        triangles: 2,
        integrity: Integrity::Crc16,
        finite_difference: true,
        held: false,
    },
    StepConfig {
        name: "tri8_fd",
        triangles: 8,
        integrity: Integrity::Crc16,
        finite_difference: true,
        held: false,
    },
    StepConfig {
        name: "tri2_held",
        triangles: 2,
        integrity: Integrity::Crc16,
        finite_difference: false,
        held: true,
    },
    StepConfig {
        name: "tri2_fd_held",
        triangles: 2,
        integrity: Integrity::Crc16,
        finite_difference: true,
        held: true,
    },
];

/// Largest number of triangles of the measured agent.
pub const MAX_TRIANGLES: usize = 8;
/// Largest number of neighbours of the measured agent (a fan of `k`
/// triangles has `k + 1` rim agents).
pub const MAX_NEIGHBOURS: usize = MAX_TRIANGLES + 1;
/// The measured agent: 8 triangles, 9 neighbours.
pub type CentreAgent = Agent<f32, MAX_TRIANGLES, MAX_NEIGHBOURS>;
/// A rim agent: in 2 triangles, 3 neighbours (centre and the two adjacent
/// rim agents).
pub type RimAgent = Agent<f32, 2, 3>;
/// Neighbour frames the bench can hold for one tick (a rim agent sends at
/// most 2).
pub const MAX_RX_FRAMES: usize = 2 * MAX_NEIGHBOURS;
/// Own frames the bench can hold for one tick (the centre of 8 triangles
/// sends 6).
pub const MAX_TX_FRAMES: usize = 8;
/// Ticks all agents run before the measured one.
pub const WARMUP_TICKS: u32 = 4;
/// Control period (s).
pub const DT: f32 = 0.01;

/// Id of the centre.
const CENTRE: AgentId = 1;
/// Radius of the arc (m).
const RADIUS: f32 = 2.0;

/// `(cos 18m°, sin 18m°)` for `m = 0..=8`: the rim directions, no
/// trigonometry on target. A fan of `k` triangles uses every `(8/k)`-th.
const UNIT_18DEG: [[f32; 2]; 9] = [
    [1.0, 0.0],
    [0.951_056_5, 0.309_017],
    [0.809_017, 0.587_785_24],
    [0.587_785_24, 0.809_017],
    [0.309_017, 0.951_056_5],
    [0.0, 1.0],
    [-0.309_017, 0.951_056_5],
    [-0.587_785_24, 0.809_017],
    [-0.809_017, 0.587_785_24],
];

/// Up to `N` frames of one tick, stored back to back (one copy per frame,
/// like a radio driver's transmit queue).
#[derive(Clone, Debug)]
pub struct FrameBuf<const N: usize> {
    bytes: [[u8; MAX_FRAME_LEN]; N],
    lens: [u8; N],
    count: usize,
    /// Frames that did not fit.
    pub overflow: u8,
}

impl<const N: usize> Default for FrameBuf<N> {
    fn default() -> Self {
        FrameBuf {
            bytes: [[0; MAX_FRAME_LEN]; N],
            lens: [0; N],
            count: 0,
            overflow: 0,
        }
    }
}

impl<const N: usize> FrameBuf<N> {
    /// Appends one frame (counted in `overflow` if full or too long).
    #[inline]
    pub fn push(&mut self, frame: &[u8]) {
        let slot = self
            .bytes
            .get_mut(self.count)
            .and_then(|b| b.get_mut(..frame.len()));
        match (slot, self.lens.get_mut(self.count)) {
            (Some(dst), Some(len)) => {
                dst.copy_from_slice(frame);
                *len = frame.len() as u8;
                self.count += 1;
            }
            _ => self.overflow = self.overflow.saturating_add(1),
        }
    }

    /// The frames, in order.
    pub fn iter(&self) -> impl Iterator<Item = &[u8]> {
        self.bytes
            .iter()
            .zip(&self.lens)
            .take(self.count)
            .map(|(b, &n)| &b[..usize::from(n)])
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.count
    }

    /// Whether there are no frames.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Total bytes.
    pub fn bytes(&self) -> usize {
        self.iter().map(<[u8]>::len).sum()
    }

    /// Removes all frames.
    pub fn clear(&mut self) {
        self.count = 0;
        self.overflow = 0;
    }
}

/// Why a bench could not be built.
#[derive(Clone, Copy, Debug, PartialEq, Eq, defmt::Format)]
pub enum BenchError {
    /// More triangles than [`MAX_TRIANGLES`] (or none).
    Triangles,
    /// An agent's configuration was refused.
    Config(ConfigError),
}

/// The centre's own measurements for the measured tick.
#[derive(Clone, Debug, Default)]
pub struct BenchInputs {
    /// Time (s).
    pub time: f32,
    /// Own velocity.
    pub velocity: Vec2<f32>,
    /// Bearings to all neighbours.
    pub bearings: Vec<BearingMeasurement<f32>, MAX_NEIGHBOURS>,
    /// The leader partner's relative position.
    pub partner_offset: Vec2<f32>,
}

impl BenchInputs {
    /// As the controller's [`Measurements`].
    pub fn measurements(&self) -> Measurements<'_, f32> {
        Measurements {
            time: self.time,
            dt: DT,
            velocity: self.velocity,
            bearings: &self.bearings,
            partner_offset: Some(self.partner_offset),
        }
    }
}

/// Everything one measured step needs: the centre's state, the frames its
/// neighbours broadcast in this tick, its own measurements, and a buffer for
/// its own frames.
///
/// Built in place ([`Bench::empty`] then [`Bench::reset`]) so that the
/// measurement firmware holds one bench, not copies of it.
#[derive(Clone, Debug, Default)]
pub struct Bench {
    /// The measured agent, as it was after the warm-up ticks (`None` before
    /// the first [`Bench::reset`]).
    pub agent: Option<CentreAgent>,
    /// Frames broadcast by its neighbours in the measured tick.
    pub rx: FrameBuf<MAX_RX_FRAMES>,
    /// Its own measurements of the measured tick.
    pub inputs: BenchInputs,
    /// Its own frames (filled by the measured step).
    pub tx: FrameBuf<MAX_TX_FRAMES>,
}

/// The parts of a [`Bench`] one measured step uses (borrowed before the
/// measured region starts).
#[derive(Debug)]
pub struct StepCtx<'a> {
    agent: &'a mut CentreAgent,
    rx: &'a FrameBuf<MAX_RX_FRAMES>,
    inputs: &'a BenchInputs,
    tx: &'a mut FrameBuf<MAX_TX_FRAMES>,
}

/// What a measured step produced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepResult {
    /// The step's output.
    pub output: StepOutput<f32>,
    /// Frames accepted by [`Agent::receive`].
    pub accepted: u8,
    /// Frames rejected by [`Agent::receive`].
    pub rejected: u8,
    /// Frames produced by [`Agent::frames`].
    pub sent: u8,
}

impl StepResult {
    /// A valid measurement: nominal output and every neighbour frame
    /// accepted.
    pub fn valid(&self) -> bool {
        self.output.status == Status::Nominal && self.rejected == 0
    }
}

/// The fan geometry of one configuration.
struct Fan {
    k: usize,
    integrity: Integrity,
    finite_difference: bool,
    held: bool,
}

impl Fan {
    fn new(cfg: &StepConfig) -> Result<Fan, BenchError> {
        match cfg.triangles {
            k @ 1..=MAX_TRIANGLES => Ok(Fan {
                k,
                integrity: cfg.integrity,
                finite_difference: cfg.finite_difference,
                held: cfg.held,
            }),
            _ => Err(BenchError::Triangles),
        }
    }

    fn rims(&self) -> usize {
        self.k + 1
    }

    /// Id of rim agent `j`.
    fn rim_id(j: usize) -> AgentId {
        CENTRE + 1 + j as AgentId
    }

    /// Agent index 0 is the centre, `1 + j` rim `j`.
    fn id(a: usize) -> AgentId {
        CENTRE + a as AgentId
    }

    /// Desired position of agent index `a`.
    fn target(&self, a: usize) -> [f32; 2] {
        if a == 0 {
            return [0.0, 0.0];
        }
        let u = UNIT_18DEG[((a - 1) * (MAX_TRIANGLES / self.k)).min(8)];
        [RADIUS * u[0], RADIUS * u[1]]
    }

    /// Actual position of agent index `a` at time `t`: near the target,
    /// moving at [`Fan::velocity`].
    fn position(&self, a: usize, t: f32) -> [f32; 2] {
        let q = self.target(a);
        let af = a as f32;
        let v = self.velocity(a);
        [
            q[0] + 0.04 * (af * 0.7 - 1.0) + v[0] * t,
            q[1] - 0.03 * (af * 0.4 - 0.5) + v[1] * t,
        ]
    }

    fn velocity(&self, a: usize) -> [f32; 2] {
        let af = a as f32;
        [0.3 + 0.02 * af, 0.1 - 0.015 * af]
    }

    /// Cosine at `u` between `v` and `w` on the target shape.
    fn cos_target(&self, u: usize, v: usize, w: usize) -> f32 {
        let (pu, pv, pw) = (self.target(u), self.target(v), self.target(w));
        let a = [pv[0] - pu[0], pv[1] - pu[1]];
        let b = [pw[0] - pu[0], pw[1] - pu[1]];
        let na = (a[0] * a[0] + a[1] * a[1]).sqrt_fast();
        let nb = (b[0] * b[0] + b[1] * b[1]).sqrt_fast();
        (a[0] * b[0] + a[1] * b[1]) / (na * nb)
    }

    /// Triangle `i` as agent indices: centre, rim `i`, rim `i + 1`.
    fn triangle(i: usize) -> [usize; 3] {
        [0, 1 + i, 2 + i]
    }

    fn config<const MT: usize>(&self, a: usize) -> AgentConfig<f32, MT> {
        let mut c = AgentConfig::new(Fan::id(a));
        c.friction = [0.5; 2];
        c.velocity_damping = [1.8; 2];
        c.velocity_reference = Schedule::constant([0.3, 0.1]);
        for i in 0..self.k {
            let tri = Fan::triangle(i);
            if !tri.contains(&a) {
                continue;
            }
            let angle = |apex: usize, v: usize, w: usize| AngleConfig {
                apex: Fan::id(apex),
                cos_desired: self.cos_target(apex, v, w),
                stiffness: 1000.0,
                damping: 10.0,
                estimator_gain: 1000.0,
            };
            let _ = c.triangles.push(TriangleConfig {
                vertices: tri.map(Fan::id),
                angles: [angle(tri[0], tri[1], tri[2]), angle(tri[1], tri[0], tri[2])],
            });
        }
        // Leader edge centre – rim 0 with its target displacement.
        let z = self.target(1);
        let leader = |role, partner| LeaderConfig {
            role,
            partner,
            stiffness: 1.0,
            damping: [0.8; 2],
            displacement: Schedule::constant([-z[0], -z[1]]),
        };
        c.leader = match a {
            0 => Some(leader(LeaderRole::A, Fan::rim_id(0))),
            1 => Some(leader(LeaderRole::B, CENTRE)),
            _ => None,
        };
        c.limits.max_force = 1.0e5;
        c.integrity = self.integrity;
        if self.finite_difference {
            c.bearing_filter = ph_formation_core::BearingFilter::FiniteDifference;
        }
        if self.held {
            // Five ticks (SPEC §12).
            c.limits.bearing_hold = 5.0 * DT;
        }
        c
    }

    /// Neighbours (agent indices) of agent index `a`.
    fn neighbours(&self, a: usize, out: &mut Vec<usize, MAX_NEIGHBOURS>) {
        out.clear();
        if a == 0 {
            for j in 0..self.rims() {
                let _ = out.push(1 + j);
            }
        } else {
            let _ = out.push(0);
            if a > 1 {
                let _ = out.push(a - 1);
            }
            if a < self.rims() {
                let _ = out.push(a + 1);
            }
        }
    }

    /// Agent index `a`'s measurements at time `t`.
    fn inputs(&self, a: usize, t: f32) -> BenchInputs {
        let mut nb = Vec::new();
        self.neighbours(a, &mut nb);
        let q = self.position(a, t);
        let mut bearings = Vec::new();
        for &n in &nb {
            let p = self.position(n, t);
            let d = [p[0] - q[0], p[1] - q[1]];
            let r = (d[0] * d[0] + d[1] * d[1]).sqrt_fast();
            let _ = bearings.push(BearingMeasurement {
                neighbour: Fan::id(n),
                bearing: Vec2::new(d[0] / r, d[1] / r),
                rate: None,
                range: None,
            });
        }
        let partner = match a {
            0 => self.position(1, t),
            _ => self.position(0, t),
        };
        let v = self.velocity(a);
        BenchInputs {
            time: t,
            velocity: Vec2::new(v[0], v[1]),
            bearings,
            partner_offset: Vec2::new(partner[0] - q[0], partner[1] - q[1]),
        }
    }
}

impl Bench {
    /// A bench without an agent; [`Bench::reset`] builds one.
    pub fn empty() -> Bench {
        Bench::default()
    }

    /// (Re)builds this bench for `cfg` in place (deterministic: the same
    /// `cfg` always gives the same bench; see the module docs).
    #[inline(never)]
    pub fn reset(&mut self, cfg: &StepConfig) -> Result<(), BenchError> {
        let fan = Fan::new(cfg)?;
        self.build_centre(&fan)?;
        self.prepare(&fan)
    }

    /// Replaces the agent by a new centre (its own stack frame: the
    /// constructor's temporaries are gone before the warm-up starts).
    #[inline(never)]
    fn build_centre(&mut self, fan: &Fan) -> Result<(), BenchError> {
        self.agent = None;
        self.agent = Some(CentreAgent::new(fan.config(0)).map_err(BenchError::Config)?);
        Ok(())
    }

    /// The parts one measured step uses (`None` before [`Bench::reset`]).
    pub fn ctx(&mut self) -> Option<StepCtx<'_>> {
        Some(StepCtx {
            agent: self.agent.as_mut()?,
            rx: &self.rx,
            inputs: &self.inputs,
            tx: &mut self.tx,
        })
    }

    /// Runs the warm-up ticks and records the measured tick's inputs.
    ///
    /// The centre runs [`WARMUP_TICKS`] ticks on its own measurements (so
    /// that its finite-difference bearing rates are non-zero). Each rim agent
    /// then runs `WARMUP_TICKS + 1` ticks, one agent at a time, and the frames
    /// it broadcasts in its last tick go to [`Bench::rx`] (see the module
    /// docs).
    #[inline(never)]
    fn prepare(&mut self, fan: &Fan) -> Result<(), BenchError> {
        let Some(centre) = self.agent.as_mut() else {
            return Ok(());
        };
        for n in 0..WARMUP_TICKS {
            let t = n as f32 * DT;
            let inp = fan.inputs(0, t);
            centre.step(&Measurements {
                dt: if n == 0 { 0.0 } else { DT },
                ..inp.measurements()
            });
        }
        self.rx.clear();
        self.tx.clear();
        for j in 0..fan.rims() {
            let mut rim = build_rim(fan, j)?;
            for n in 0..=WARMUP_TICKS {
                let t = n as f32 * DT;
                let inp = fan.inputs(1 + j, t);
                rim.step(&Measurements {
                    dt: if n == 0 { 0.0 } else { DT },
                    partner_offset: (j == 0).then_some(inp.partner_offset),
                    ..inp.measurements()
                });
                if n == WARMUP_TICKS {
                    let rx = &mut self.rx;
                    rim.frames(|bytes| rx.push(bytes));
                } else {
                    rim.frames(|_| ());
                }
            }
        }
        self.inputs = fan.inputs(0, WARMUP_TICKS as f32 * DT);
        if fan.held {
            // The camera lost the last rim agent this tick: the centre holds or
            // predicts its bearing (SPEC §12, S18) and stays nominal.
            self.inputs.bearings.pop();
        }
        Ok(())
    }
}

/// Builds rim agent `j` (its own stack frame, see [`Bench::reset`]).
#[inline(never)]
fn build_rim(fan: &Fan, j: usize) -> Result<RimAgent, BenchError> {
    RimAgent::new(fan.config(1 + j)).map_err(BenchError::Config)
}

impl StepCtx<'_> {
    /// Part 1 of the step: decode and receive the neighbours' frames.
    /// Returns (accepted, rejected).
    #[inline(always)]
    pub fn receive_all(&mut self) -> (u8, u8) {
        let (mut ok, mut bad) = (0u8, 0u8);
        for f in self.rx.iter() {
            match self.agent.receive(f) {
                Ok(()) => ok += 1,
                Err(_) => bad += 1,
            }
        }
        (ok, bad)
    }

    /// Part 2 of the step: [`Agent::step`] on the own measurements.
    #[inline(always)]
    pub fn step_only(&mut self) -> StepOutput<f32> {
        let m = self.inputs.measurements();
        self.agent.step(&m)
    }

    /// Part 3 of the step: encode the own frames into [`Bench::tx`].
    #[inline(always)]
    pub fn encode(&mut self) -> u8 {
        let tx = &mut *self.tx;
        tx.clear();
        self.agent.frames(|bytes| tx.push(bytes)) as u8
    }

    /// The frame CRCs alone: [`ph_formation_core::crc16::checksum`] of every frame the
    /// step decodes and encodes (the part of the wire cost no codec can avoid).
    #[inline(always)]
    pub fn crc_all(&self) -> u16 {
        self.rx
            .iter()
            .chain(self.tx.iter())
            .fold(0, |acc, f| acc ^ ph_formation_core::crc16::checksum(f))
    }

    /// The whole measured step: [`StepCtx::receive_all`],
    /// [`StepCtx::step_only`], [`StepCtx::encode`].
    #[inline(always)]
    pub fn control_step(&mut self) -> StepResult {
        let (accepted, rejected) = self.receive_all();
        let output = self.step_only();
        let sent = self.encode();
        StepResult {
            output,
            accepted,
            rejected,
            sent,
        }
    }
}
