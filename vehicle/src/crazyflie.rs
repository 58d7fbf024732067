//! A Crazyflie 2.x flying the firmware's PID controller in velocity mode (docs/world.md,
//! "The Crazyflie's cascade"): two loops in series, at the firmware's own rates, per
//! horizontal axis of the yaw frame.
//!
//! - **Velocity PID**, every `1/POSITION_RATE` s (100 Hz): the tilt toward the axis
//!   `θ_d = clamp(clamp(K_p e + K_i ∫e, ±1.1 θ_max), ±θ_max)` (degrees, `e = v_sp − v`,
//!   the integral held to ±5000), `position_controller_pid.c` `velocityController`.
//! - **Attitude PID**, every `1/ATTITUDE_RATE` s (500 Hz): the body rate
//!   `ω = K_p^a (θ_d − θ) + K_i^a ∫(θ_d − θ)` (deg/s, the integral held to ±20),
//!   `attitude_pid_controller.c` `attitudeControllerCorrectAttitudePID`.
//! - **Reduced**: the rate loop (rate PID, motors, inertia) is taken as ideal (`θ̇ = ω`,
//!   held between attitude ticks), the altitude as held (`T cos θ cos φ = m g`), the
//!   estimator as exact, the yaw as 0 (body frame = world frame). Then the horizontal
//!   acceleration of Z-Y-X Euler angles pitch `θ` (toward x) and roll `φ` (toward y) is
//!   `a = g (tan θ, tan φ / cos θ) + a_w`. The firmware's signs (pitch and roll are the
//!   negated PID outputs, `position_controller_pid.c:251-252`) are folded into "tilt
//!   toward +x / +y".
//!
//! The clamps act per axis: a diagonal demand tilts both axes by `θ_max`, a total tilt of
//! `acos(cos² θ_max)` (28.0° for 20°). In velocity mode nothing limits the speed (the
//! position loop's `PID_POS_VEL_*_MAX` bounds only its own output); the setpoint limit
//! is the agent's (`max_speed`, the app's `FORMATION_MAX_SPEED`).

/// Standard gravity (m/s²).
pub const G: f64 = 9.806_65;

/// The firmware's figures (bitcraze/crazyflie-firmware at 2a18fc29; `docs/world.md`
/// cites each).
pub mod firmware {
    /// `PID_VEL_X_KP`, `PID_VEL_Y_KP` (deg per m/s): platform_defaults_cf2.h:132, :137.
    pub const VEL_KP: f64 = 25.0;
    /// `PID_VEL_X_KI`, `PID_VEL_Y_KI` (deg per m): platform_defaults_cf2.h:133, :138.
    pub const VEL_KI: f64 = 1.0;
    /// The velocity PIDs' integral limit: `DEFAULT_PID_INTEGRATION_LIMIT` (pid.h:33, set
    /// by `pidInit`, pid.c:48, and not changed by position_controller_pid.c).
    pub const VEL_I_LIMIT: f64 = 5000.0;
    /// `PID_VEL_ROLL_MAX`, `PID_VEL_PITCH_MAX` (deg): platform_defaults_cf2.h:152-153,
    /// the clamp of position_controller_pid.c:254-255.
    pub const TILT_MAX_DEG: f64 = 20.0;
    /// `rpLimitOverhead`: the PID's own output limit is 1.1 × the tilt limit
    /// (position_controller_pid.c:63, :239-240).
    pub const TILT_OVERHEAD: f64 = 1.10;
    /// `PID_ROLL_KP`, `PID_PITCH_KP` (1/s): platform_defaults_cf2.h:114, :120.
    pub const ATT_KP: f64 = 6.0;
    /// `PID_ROLL_KI`, `PID_PITCH_KI` (1/s²): platform_defaults_cf2.h:115, :121.
    pub const ATT_KI: f64 = 3.0;
    /// `PID_ROLL_INTEGRATION_LIMIT`, `PID_PITCH_INTEGRATION_LIMIT` (deg s):
    /// platform_defaults_cf2.h:118, :124 (attitude_pid_controller.c:129-130).
    pub const ATT_I_LIMIT: f64 = 20.0;
    /// `POSITION_RATE` (Hz): stabilizer_types.h:373 (controller_pid.c:115).
    pub const POSITION_RATE: u32 = 100;
    /// `ATTITUDE_RATE` (Hz): stabilizer_types.h:372 (controller_pid.c:85, :119).
    pub const ATTITUDE_RATE: u32 = 500;
}
use firmware as fw;

/// The lead (s, SPEC S21) that suits the cascade: the first moment of its velocity
/// response with the slow integral left out, `1 / (g K_p π/180)` = 0.2337 s. The attitude
/// loop adds nothing to it: its closed loop `(K_p^a s + K_i^a) / (s² + K_p^a s + K_i^a)`
/// has unit gain and zero slope at `s = 0` (`docs/world.md`).
pub fn derived_lead() -> f64 {
    1.0 / (G * fw::VEL_KP.to_radians())
}

/// The second-order lead (s², SPEC S21b) that suits the cascade: at the formation's
/// frequencies (well above the attitude integral's 0.5 rad/s) the attitude loop is a lag
/// of `1 / K_p^a`, so the velocity answers its setpoint like
/// `1 / (τ τ_a s² + τ s + 1)` with `τ` = [`derived_lead`] and `τ_a = 1 / K_p^a`:
/// `τ τ_a` = 0.0390 s² (`docs/world.md`).
pub fn derived_second_lead() -> f64 {
    derived_lead() / fw::ATT_KP
}

/// The horizontal acceleration (m/s²) at tilts `x` toward +x (pitch) and `y` toward +y
/// (roll), degrees, altitude held: `g (tan θ, tan φ / cos θ)`.
pub fn tilt_acceleration(x: f64, y: f64) -> [f64; 2] {
    let (p, r) = (x.to_radians(), y.to_radians());
    [G * libm::tan(p), G * libm::tan(r) / libm::cos(p)]
}

/// The total tilt from vertical (rad) of pitch `x` and roll `y` (degrees):
/// `acos(cos θ cos φ)`.
pub fn total_tilt(x: f64, y: f64) -> f64 {
    libm::acos((libm::cos(x.to_radians()) * libm::cos(y.to_radians())).clamp(-1.0, 1.0))
}

/// One axis of RK4 over `h` with the accelerations `k1` (start), `k2` = `k3` (middle;
/// the acceleration depends on time only) and `k4` (end).
#[inline]
fn rk4_axis(q: &mut f64, v: &mut f64, [k1, k2, k4]: [f64; 3], h: f64) {
    let v2 = *v + k1 * (0.5 * h);
    let v3 = *v + k2 * (0.5 * h);
    let v4 = *v + k2 * h;
    *q += (*v + v2 * 2.0 + v3 * 2.0 + v4) * (h / 6.0);
    *v += (k1 + k2 * 4.0 + k4) * (h / 6.0);
}

/// One axis's controller state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Axis {
    /// The velocity PID's integral (m).
    pub vel_integral: f64,
    /// The desired tilt `θ_d` (deg), held between velocity ticks.
    pub desired: f64,
    /// The attitude PID's integral (deg s).
    pub att_integral: f64,
    /// The tilt `θ` (deg).
    pub tilt: f64,
    /// The commanded body rate `ω` (deg/s), held between attitude ticks.
    pub rate: f64,
}

impl Axis {
    /// The velocity PID on error `e` (m/s): pid.c's update with `K_d = 0`, then the clamp.
    fn velocity_tick(&mut self, e: f64) {
        let dt = 1.0 / f64::from(fw::POSITION_RATE);
        self.vel_integral = (self.vel_integral + e * dt).clamp(-fw::VEL_I_LIMIT, fw::VEL_I_LIMIT);
        let limit = fw::TILT_MAX_DEG * fw::TILT_OVERHEAD;
        let out = (fw::VEL_KP * e + fw::VEL_KI * self.vel_integral).clamp(-limit, limit);
        self.desired = out.clamp(-fw::TILT_MAX_DEG, fw::TILT_MAX_DEG);
    }

    /// The attitude PID (`K_d = 0`): the body rate until the next attitude tick.
    fn attitude_tick(&mut self) {
        let dt = 1.0 / f64::from(fw::ATTITUDE_RATE);
        let e = self.desired - self.tilt;
        self.att_integral = (self.att_integral + e * dt).clamp(-fw::ATT_I_LIMIT, fw::ATT_I_LIMIT);
        self.rate = fw::ATT_KP * e + fw::ATT_KI * self.att_integral;
    }
}

/// One Crazyflie: its position and velocity (world frame) and its firmware's cascade.
/// The firmware's ticks run in phase with the time given to [`Crazyflie::step`], from
/// the first call on.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Crazyflie {
    /// Position (m).
    pub q: [f64; 2],
    /// Velocity (m/s).
    pub v: [f64; 2],
    /// The pitch (x) and roll (y) axes' controller states.
    pub axes: [Axis; 2],
    /// Time since the last attitude tick (s); 0: a tick is due.
    since: f64,
    /// Attitude ticks since the last velocity tick, modulo
    /// `ATTITUDE_RATE / POSITION_RATE` (0: the next tick also runs the velocity PID).
    phase: u32,
}

/// How many `f64` words [`Crazyflie::to_words`] gives (for the C API's plain-data copy).
pub const WORDS: usize = 16;

impl Crazyflie {
    /// A Crazyflie level at `q` moving with `v`, its controllers' integrals empty.
    pub fn new(q: [f64; 2], v: [f64; 2]) -> Self {
        Self {
            q,
            v,
            ..Self::default()
        }
    }

    /// The whole state as plain numbers: `q`, `v`, each axis's five states, the time
    /// since the attitude tick and the tick phase ([`Crazyflie::from_words`] reads it
    /// back exactly).
    pub fn to_words(&self) -> [f64; WORDS] {
        let [x, y] = self.axes;
        let axis = |a: Axis| [a.vel_integral, a.desired, a.att_integral, a.tilt, a.rate];
        let [x0, x1, x2, x3, x4] = axis(x);
        let [y0, y1, y2, y3, y4] = axis(y);
        [
            self.q[0],
            self.q[1],
            self.v[0],
            self.v[1],
            x0,
            x1,
            x2,
            x3,
            x4,
            y0,
            y1,
            y2,
            y3,
            y4,
            self.since,
            f64::from(self.phase),
        ]
    }

    /// The state [`Crazyflie::to_words`] wrote. Any words give a state that steps: a
    /// time since the tick outside `[0, 1/ATTITUDE_RATE)` (or NaN) is taken as 0 (a tick
    /// is due), a phase that is not one of `0..5` modulo 5 (NaN as 0).
    pub fn from_words(w: [f64; WORDS]) -> Self {
        let [q0, q1, v0, v1, x0, x1, x2, x3, x4, y0, y1, y2, y3, y4, since, phase] = w;
        let axis = |[vel_integral, desired, att_integral, tilt, rate]: [f64; 5]| Axis {
            vel_integral,
            desired,
            att_integral,
            tilt,
            rate,
        };
        let n = fw::ATTITUDE_RATE / fw::POSITION_RATE;
        Self {
            q: [q0, q1],
            v: [v0, v1],
            axes: [axis([x0, x1, x2, x3, x4]), axis([y0, y1, y2, y3, y4])],
            since: if (0.0..1.0 / f64::from(fw::ATTITUDE_RATE)).contains(&since) {
                since
            } else {
                0.0
            },
            // `as` saturates (NaN → 0); the phase only selects the velocity ticks.
            phase: (libm::fabs(phase) as u32) % n,
        }
    }

    /// The total tilt from vertical (rad).
    pub fn tilt(&self) -> f64 {
        let [x, y] = self.axes;
        total_tilt(x.tilt, y.tilt)
    }

    /// One firmware tick: the velocity PID on every fifth, then the attitude PID
    /// (controller_pid.c:115-131 runs them in that order).
    fn tick(&mut self, setpoint: [f64; 2]) {
        let velocity = self.phase == 0;
        let [x, y] = &mut self.axes;
        let ([sx, sy], [vx, vy]) = (setpoint, self.v);
        if velocity {
            x.velocity_tick(sx - vx);
            y.velocity_tick(sy - vy);
        }
        x.attitude_tick();
        y.attitude_tick();
        self.phase = (self.phase + 1) % (fw::ATTITUDE_RATE / fw::POSITION_RATE);
    }

    /// `h` seconds within one attitude period (the rates held): RK4 with the tilts exact
    /// (`θ(t) = θ₀ + ω t`), under the wind's acceleration `w`. (Written out per axis:
    /// the simulator's tests run an unoptimised build, where iterator chains cost.)
    fn flow(&mut self, h: f64, w: [f64; 2]) {
        let [x, y] = &mut self.axes;
        let a = |t: f64| {
            let [ax, ay] = tilt_acceleration(x.tilt + x.rate * t, y.tilt + y.rate * t);
            [ax + w[0], ay + w[1]]
        };
        let ([k1x, k1y], [k2x, k2y], [k4x, k4y]) = (a(0.0), a(0.5 * h), a(h));
        let [qx, qy] = &mut self.q;
        let [vx, vy] = &mut self.v;
        rk4_axis(qx, vx, [k1x, k2x, k4x], h);
        rk4_axis(qy, vy, [k1y, k2y, k4y], h);
        x.tilt += x.rate * h;
        y.tilt += y.rate * h;
    }

    /// `dt` seconds toward the velocity `setpoint` (m/s) under the wind's acceleration
    /// `wind` (m/s²), split at the firmware's attitude ticks.
    pub fn step(&mut self, setpoint: [f64; 2], wind: [f64; 2], dt: f64) {
        let period = 1.0 / f64::from(fw::ATTITUDE_RATE);
        let mut left = dt;
        while left > 1e-15 {
            if self.since == 0.0 {
                self.tick(setpoint);
            }
            let h = left.min(period - self.since);
            self.flow(h, wind);
            left -= h;
            self.since += h;
            if self.since >= period - 1e-12 {
                self.since = 0.0;
            }
        }
    }
}

#[cfg(test)]
mod tests;
