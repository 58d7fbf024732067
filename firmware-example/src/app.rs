//! The application: one agent's control loop over the [`hal`](crate::hal)
//! traits.
//!
//! Every control tick ([`ControlLoop::tick`]):
//!
//! 1. drain the [`Radio`] into [`Agent::receive`] (frames heard since the
//!    last tick; rejected frames are counted by the agent);
//! 2. read the [`BearingSensor`] (bearings, and for a leader the partner
//!    offset), the [`VelocitySource`] and the [`Clock`];
//! 3. [`Agent::step`] → force and status;
//! 4. [`Actuator::apply_force`];
//! 5. [`Agent::frames`] → [`Radio::send`] (this tick's broadcast).
//!
//! [`run_agent`] calls it at a fixed rate, waiting on the [`Clock`]; a board
//! that simulates several robots (the QEMU demo) or that is driven by a host
//! (the UART board) calls [`ControlLoop::tick`] itself.
//!
//! Driver errors never stop the loop: a failed bearing read gives the step no
//! bearings and a failed velocity read a non-finite velocity, so the
//! controller answers with its documented safe output (`Status::Safe`); every
//! error is reported in [`TickReport::errors`].

use core::ops::ControlFlow;

use ph_formation_core::{Agent, BearingMeasurement, Measurements, Status, StepOutput, Vec2};

use crate::hal::{Actuator, Bearing, BearingSensor, Clock, Radio, VelocitySource, MAX_FRAME_LEN};

/// Most frames taken from the radio in one tick (a bound on the work of a
/// tick if the radio keeps delivering).
pub const MAX_RX_FRAMES_PER_TICK: usize = 32;

/// The five drivers one agent runs on.
#[derive(Debug)]
pub struct Board<B, V, R, A, C> {
    /// Bearings to neighbours (and the leader partner offset).
    pub bearings: B,
    /// Own velocity.
    pub velocity: V,
    /// Broadcast radio.
    pub radio: R,
    /// Force output.
    pub actuator: A,
    /// Time.
    pub clock: C,
}

/// Driver errors seen during one tick (the tick still completes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, defmt::Format)]
pub struct HalErrors {
    /// [`BearingSensor::read_bearings`] or [`BearingSensor::partner_offset`]
    /// failed.
    pub bearing_sensor: bool,
    /// [`VelocitySource::velocity`] failed.
    pub velocity: bool,
    /// [`Radio::receive`] failed (draining stopped for this tick).
    pub radio_receive: bool,
    /// [`Radio::send`] failed for at least one frame.
    pub radio_send: bool,
    /// [`Actuator::apply_force`] failed.
    pub actuator: bool,
}

impl HalErrors {
    /// Whether any driver failed.
    pub fn any(&self) -> bool {
        self.bearing_sensor
            || self.velocity
            || self.radio_receive
            || self.radio_send
            || self.actuator
    }
}

/// What one tick did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TickReport {
    /// The controller's output (already applied to the actuator).
    pub output: StepOutput<f32>,
    /// Time of the tick, s (from the clock).
    pub time: f32,
    /// `Δt` used by the step, s (0 on the first tick).
    pub dt: f32,
    /// Frames taken from the radio and accepted by the agent.
    pub frames_accepted: u16,
    /// Frames taken from the radio and rejected by the agent (corrupt,
    /// stale, or from a robot that is not a neighbour).
    pub frames_rejected: u16,
    /// Frames broadcast.
    pub frames_sent: u8,
    /// Bearings the sensor reported to robots that are not neighbours
    /// (ignored).
    pub bearings_ignored: u8,
    /// Driver errors.
    pub errors: HalErrors,
}

impl TickReport {
    /// `true` when the output is the control law (not the safe output).
    pub fn nominal(&self) -> bool {
        self.output.status == Status::Nominal
    }
}

/// One agent (`Agent<f32, MT, NB>`: at most `MT` triangles and `NB`
/// neighbours) and the state of its control loop.
#[derive(Clone, Debug)]
pub struct ControlLoop<const MT: usize, const NB: usize> {
    agent: Agent<f32, MT, NB>,
    last_tick: Option<u64>,
    ticks: u32,
}

impl<const MT: usize, const NB: usize> ControlLoop<MT, NB> {
    /// A loop around `agent`; the first tick has `Δt = 0`.
    pub fn new(agent: Agent<f32, MT, NB>) -> Self {
        ControlLoop {
            agent,
            last_tick: None,
            ticks: 0,
        }
    }

    /// The agent.
    pub fn agent(&self) -> &Agent<f32, MT, NB> {
        &self.agent
    }

    /// Ticks run so far.
    pub fn ticks(&self) -> u32 {
        self.ticks
    }

    /// Runs one control tick on `board` (see the [module docs](self)).
    pub fn tick<B, V, R, A, C>(&mut self, board: &mut Board<B, V, R, A, C>) -> TickReport
    where
        B: BearingSensor,
        V: VelocitySource,
        R: Radio,
        A: Actuator,
        C: Clock,
    {
        let mut errors = HalErrors::default();

        // 1. Frames heard since the last tick.
        let (mut accepted, mut rejected) = (0u16, 0u16);
        let mut frame = [0u8; MAX_FRAME_LEN];
        for _ in 0..MAX_RX_FRAMES_PER_TICK {
            match board.radio.receive(&mut frame) {
                Ok(Some(len)) => match self.agent.receive(&frame[..len.min(MAX_FRAME_LEN)]) {
                    Ok(()) => accepted += 1,
                    Err(_) => rejected += 1,
                },
                Ok(None) => break,
                Err(_) => {
                    errors.radio_receive = true;
                    break;
                }
            }
        }

        // 2. Own measurements.
        let now = board.clock.now_ticks();
        let dt = match self.last_tick {
            Some(last) => board.clock.seconds_since(last),
            None => 0.0,
        };
        self.last_tick = Some(now);
        let time = board.clock.seconds();

        let mut raw = [Bearing::default(); NB];
        let seen = match board.bearings.read_bearings(&mut raw) {
            Ok(n) => n.min(NB),
            Err(_) => {
                errors.bearing_sensor = true;
                0
            }
        };
        let mut bearings = [BearingMeasurement {
            neighbour: 0,
            bearing: Vec2::zeros(),
            rate: None,
            range: None,
        }; NB];
        let mut used = 0;
        let mut ignored = 0u8;
        for b in &raw[..seen] {
            if !self.agent.neighbours().any(|id| id == b.neighbour) {
                ignored = ignored.saturating_add(1);
                continue;
            }
            bearings[used] = BearingMeasurement {
                neighbour: b.neighbour,
                bearing: vec2(b.direction),
                rate: b.rate.map(vec2),
                range: b.range,
            };
            used += 1;
        }
        let partner_offset = match board.bearings.partner_offset() {
            Ok(p) => p.map(vec2),
            Err(_) => {
                errors.bearing_sensor = true;
                None
            }
        };
        let velocity = match board.velocity.velocity() {
            Ok(v) => vec2(v),
            Err(_) => {
                errors.velocity = true;
                // Refused by the controller: safe output with zero force.
                Vec2::new(f32::NAN, f32::NAN)
            }
        };

        // 3. The control step.
        let output = self.agent.step(&Measurements {
            time,
            dt,
            velocity,
            bearings: &bearings[..used],
            partner_offset,
        });

        // 4. Actuate.
        if board
            .actuator
            .apply_force([output.force.x, output.force.y])
            .is_err()
        {
            errors.actuator = true;
        }

        // 5. Broadcast.
        let radio = &mut board.radio;
        let mut send_failed = false;
        let sent = self.agent.frames(|bytes| {
            if radio.send(bytes).is_err() {
                send_failed = true;
            }
        });
        errors.radio_send = send_failed;
        self.ticks = self.ticks.wrapping_add(1);

        TickReport {
            output,
            time,
            dt,
            frames_accepted: accepted,
            frames_rejected: rejected,
            frames_sent: u8::try_from(sent).unwrap_or(u8::MAX),
            bearings_ignored: ignored,
            errors,
        }
    }
}

fn vec2(a: [f32; 2]) -> Vec2<f32> {
    Vec2::new(a[0], a[1])
}

/// Runs `agent` at `rate_hz` control ticks per second on `board` until
/// `on_tick` returns [`ControlFlow::Break`]; returns the loop (agent and
/// counters) then.
///
/// Ticks are scheduled every `tick_hz / rate_hz` clock ticks (rounded down;
/// pick a clock rate that `rate_hz` divides). Between ticks it busy-waits on
/// [`Clock::now_ticks`] (a clock implementation may sleep there, e.g. `wfi`
/// until the next timer interrupt). A tick that starts late is not repeated:
/// after an overrun the schedule restarts from the current time.
pub fn run_agent<B, V, R, A, C, const MT: usize, const NB: usize>(
    agent: Agent<f32, MT, NB>,
    board: &mut Board<B, V, R, A, C>,
    rate_hz: u32,
    mut on_tick: impl FnMut(&TickReport) -> ControlFlow<()>,
) -> ControlLoop<MT, NB>
where
    B: BearingSensor,
    V: VelocitySource,
    R: Radio,
    A: Actuator,
    C: Clock,
{
    let period = u64::from((board.clock.tick_hz() / rate_hz.max(1)).max(1));
    let mut control = ControlLoop::new(agent);
    let mut next = board.clock.now_ticks();
    loop {
        while board.clock.now_ticks() < next {
            core::hint::spin_loop();
        }
        let report = control.tick(board);
        next += period;
        let now = board.clock.now_ticks();
        if now >= next + period {
            // Overrun by more than a period: do not try to catch up.
            next = now;
        }
        if on_tick(&report).is_break() {
            return control;
        }
    }
}
