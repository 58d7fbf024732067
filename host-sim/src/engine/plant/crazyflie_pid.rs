//! A Crazyflie 2.x flying the firmware's PID controller in velocity mode
//! (`[plant] model = "crazyflie_pid"`, `docs/world.md` "The Crazyflie's cascade"): two
//! loops in series, at the firmware's own rates, per horizontal axis of the yaw frame.
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

use super::{Held, Plant};
use crate::engine::error::SetupError;
use crate::model::{CrazyfliePid, Model};
use ph_formation_core::actuate::{VelocityCommand, VirtualMass};
use ph_formation_core::Vec2;

/// Standard gravity (m/s²).
const G: f64 = 9.806_65;

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

/// One axis's controller state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Axis {
    /// The velocity PID's integral (m).
    vel_integral: f64,
    /// The desired tilt `θ_d` (deg), held between velocity ticks.
    desired: f64,
    /// The attitude PID's integral (deg s).
    att_integral: f64,
    /// The tilt `θ` (deg).
    tilt: f64,
    /// The commanded body rate `ω` (deg/s), held between attitude ticks.
    rate: f64,
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

/// The horizontal acceleration (m/s²) at tilts `x` toward +x (pitch) and `y` toward +y
/// (roll), degrees, altitude held: `g (tan θ, tan φ / cos θ)`.
pub fn tilt_acceleration(x: f64, y: f64) -> Vec2<f64> {
    let (p, r) = (x.to_radians(), y.to_radians());
    Vec2::new(G * p.tan(), G * r.tan() / p.cos())
}

/// The total tilt from vertical (rad) of pitch `x` and roll `y` (degrees):
/// `acos(cos θ cos φ)`.
pub fn total_tilt(x: f64, y: f64) -> f64 {
    (x.to_radians().cos() * y.to_radians().cos())
        .clamp(-1.0, 1.0)
        .acos()
}

/// Every agent's Crazyflie.
#[derive(Clone, Debug)]
pub struct CrazyfliePidPlant {
    q: Vec<Vec2<f64>>,
    v: Vec<Vec2<f64>>,
    setpoint: Vec<Vec2<f64>>,
    axes: Vec<[Axis; 2]>,
    command: Vec<VelocityCommand<f64>>,
    /// Time since the last attitude tick (s); 0: a tick is due.
    since: f64,
    /// Attitude ticks so far (every fifth also runs the velocity PID).
    ticks: u64,
}

impl CrazyfliePidPlant {
    /// The model's agents hovering at their initial positions and velocities, each
    /// holding its initial velocity as its setpoint until its first tick.
    pub fn new(model: &Model, vehicle: &CrazyfliePid) -> Result<Self, SetupError> {
        let a = &model.agents;
        let command = a
            .iter()
            .enumerate()
            .map(|(i, x)| {
                VirtualMass::new(x.mass, x.friction, vehicle.max_speed)
                    .and_then(|m| m.with_lead(vehicle.lead.unwrap_or_else(derived_lead)))
                    .and_then(|m| {
                        m.with_second_lead(vehicle.second_lead.unwrap_or_else(derived_second_lead))
                    })
                    .map(VelocityCommand::new)
                    .map_err(|error| SetupError::Vehicle { agent: i, error })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let v: Vec<Vec2<f64>> = a
            .iter()
            .map(|x| Vec2::new(x.velocity[0], x.velocity[1]))
            .collect();
        Ok(Self {
            q: a.iter()
                .map(|x| Vec2::new(x.position[0], x.position[1]))
                .collect(),
            setpoint: v.clone(),
            axes: vec![[Axis::default(); 2]; v.len()],
            v,
            command,
            since: 0.0,
            ticks: 0,
        })
    }

    /// One firmware tick of every agent: the velocity PID on every fifth, then the
    /// attitude PID (controller_pid.c:115-131 runs them in that order).
    fn tick(&mut self) {
        let velocity = self
            .ticks
            .is_multiple_of(u64::from(fw::ATTITUDE_RATE / fw::POSITION_RATE));
        for ((axes, v), sp) in self.axes.iter_mut().zip(&self.v).zip(&self.setpoint) {
            for (k, axis) in axes.iter_mut().enumerate() {
                if velocity {
                    axis.velocity_tick(sp[k] - v[k]);
                }
                axis.attitude_tick();
            }
        }
        self.ticks += 1;
    }

    /// Every agent over `h` seconds within one attitude period (the rates held): RK4
    /// with the tilts exact (`θ(t) = θ₀ + ω t`).
    fn flow(&mut self, h: f64, wind: &[Vec2<f64>]) {
        for (i, ((q, v), axes)) in self
            .q
            .iter_mut()
            .zip(self.v.iter_mut())
            .zip(self.axes.iter_mut())
            .enumerate()
        {
            let w = wind.get(i).copied().unwrap_or_else(Vec2::zeros);
            let [x, y] = *axes;
            let a = |t: f64| tilt_acceleration(x.tilt + x.rate * t, y.tilt + y.rate * t) + w;
            let (k1, k2, k4) = (a(0.0), a(0.5 * h), a(h));
            let v2 = *v + k1 * (0.5 * h);
            let v3 = *v + k2 * (0.5 * h);
            let v4 = *v + k2 * h;
            *q += (*v + v2 * 2.0 + v3 * 2.0 + v4) * (h / 6.0);
            *v += (k1 + k2 * 4.0 + k4) * (h / 6.0);
            for axis in axes.iter_mut() {
                axis.tilt += axis.rate * h;
            }
        }
    }
}

impl Plant for CrazyfliePidPlant {
    fn q(&self) -> &[Vec2<f64>] {
        &self.q
    }

    fn v(&self) -> &[Vec2<f64>] {
        &self.v
    }

    fn takes_commands(&self) -> bool {
        true
    }

    /// The virtual mass integrates S1 over `period` under `force` (S20, with the lead of
    /// S21): the new velocity setpoint.
    fn command(&mut self, i: usize, force: Vec2<f64>, period: f64) {
        super::command_setpoint(
            &mut self.command,
            &self.v,
            &mut self.setpoint,
            i,
            force,
            period,
        );
    }

    fn set_velocity_setpoint(&mut self, i: usize, setpoint: Vec2<f64>) -> bool {
        self.setpoint.get_mut(i).map(|sp| *sp = setpoint).is_some()
    }

    fn tilt(&self, i: usize) -> Option<f64> {
        self.axes.get(i).map(|[x, y]| total_tilt(x.tilt, y.tilt))
    }

    /// `steps × dt` seconds, split at the firmware's attitude ticks (every agent's
    /// firmware in phase with the simulation's clock).
    fn step(&mut self, held: &Held<'_>, dt: f64, steps: usize, _chunk: Option<usize>) {
        let period = 1.0 / f64::from(fw::ATTITUDE_RATE);
        for _ in 0..steps {
            let mut left = dt;
            while left > 1e-15 {
                if self.since == 0.0 {
                    self.tick();
                }
                let h = left.min(period - self.since);
                self.flow(h, held.wind);
                left -= h;
                self.since += h;
                if self.since >= period - 1e-12 {
                    self.since = 0.0;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One Crazyflie hovering at the origin (no virtual mass in the way).
    fn hover() -> CrazyfliePidPlant {
        CrazyfliePidPlant {
            q: vec![Vec2::zeros()],
            v: vec![Vec2::zeros()],
            setpoint: vec![Vec2::zeros()],
            axes: vec![[Axis::default(); 2]],
            command: vec![VelocityCommand::new(
                VirtualMass::new(1.0, [0.0; 2], f64::INFINITY).unwrap(),
            )],
            since: 0.0,
            ticks: 0,
        }
    }

    /// `v(t)` every millisecond for `seconds` after a setpoint step `sp` from hover.
    fn response(sp: Vec2<f64>, seconds: f64) -> (CrazyfliePidPlant, Vec<Vec2<f64>>, f64) {
        let mut p = hover();
        p.set_velocity_setpoint(0, sp);
        let held = Held {
            forces: &[Vec2::zeros()],
            wind: &[],
        };
        let mut out = vec![p.v[0]];
        let mut tilt: f64 = 0.0;
        for _ in 0..(seconds * 1000.0).round() as usize {
            p.step(&held, 1e-3, 1, None);
            out.push(p.v[0]);
            tilt = tilt.max(p.tilt(0).unwrap_or(0.0));
        }
        (p, out, tilt.to_degrees())
    }

    /// The continuous-time linearisation (no clamps, no sampling) by fine RK4:
    /// `θ_d = K_p e + K_i ∫e`, `θ̇ = K_p^a (θ_d − θ) + K_i^a ∫(θ_d − θ)`, `v̇ = g θ`.
    fn linear(sp: f64, seconds: f64, kp_att: f64) -> Vec<f64> {
        let f = |x: [f64; 4]| {
            let [v, iv, th, ith] = x;
            let e = sp - v;
            let d = fw::VEL_KP * e + fw::VEL_KI * iv;
            [
                G * th.to_radians(),
                e,
                kp_att * (d - th) + fw::ATT_KI * ith,
                d - th,
            ]
        };
        let h = 1e-5;
        let mut x = [0.0; 4];
        let mut out = vec![0.0];
        for k in 1..=(seconds / h).round() as usize {
            let add = |a: [f64; 4], b: [f64; 4], s: f64| [0, 1, 2, 3].map(|i| a[i] + b[i] * s);
            let k1 = f(x);
            let k2 = f(add(x, k1, h / 2.0));
            let k3 = f(add(x, k2, h / 2.0));
            let k4 = f(add(x, k3, h));
            x = [0, 1, 2, 3].map(|i| x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
            if k % 100 == 0 {
                out.push(x[0]);
            }
        }
        out
    }

    /// A small step (0.01 m/s: tilts under 0.3°, far from the clamps) follows the
    /// cascade's transfer function; the firmware's sampling (velocity held 10 ms, rate
    /// held 2 ms) delays it by a few ms, within 3 % of the step everywhere.
    #[test]
    fn small_step_follows_the_linear_cascade() {
        let sp = 0.01;
        let (_, v, _) = response(Vec2::new(sp, 0.0), 3.0);
        let lin = linear(sp, 3.0, fw::ATT_KP);
        let worst = v
            .iter()
            .zip(&lin)
            .map(|(a, b)| (a.x - b).abs())
            .fold(0.0, f64::max);
        assert!(worst < 0.03 * sp, "worst {worst}");
        // Negative control: a ten times faster attitude loop (nearly the first-order
        // model) is not within that band.
        let fast = linear(sp, 3.0, 10.0 * fw::ATT_KP);
        let off = fast
            .iter()
            .zip(&lin)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(off > 0.05 * sp, "off {off}");
    }

    /// The integral leaves no steady error: after 20 s the velocity is the setpoint's
    /// (within 0.5 %), and the drone is level again.
    #[test]
    fn steady_state_is_the_setpoint() {
        let (p, v, _) = response(Vec2::new(0.3, -0.4), 20.0);
        let last = v.last().copied().unwrap_or_default();
        assert!((last - Vec2::new(0.3, -0.4)).norm() < 0.0025, "{last:?}");
        assert!(p.tilt(0).unwrap_or(1.0).to_degrees() < 0.2);
    }

    /// Along an axis the tilt stays near the 20° clamp; on the diagonal each axis is
    /// clamped to 20°, so the drone tilts by `acos(cos² 20°)` = 28.0° in total.
    #[test]
    fn per_axis_clamp_tilts_more_on_a_diagonal() {
        // 4 m/s: the clamps hold for long enough for the attitude loop to reach them.
        let (_, _, axis) = response(Vec2::new(4.0, 0.0), 2.0);
        let d = 4.0 / 2f64.sqrt();
        let (p, _, diagonal) = response(Vec2::new(d, d), 2.0);
        let both = total_tilt(20.0, 20.0).to_degrees();
        assert!((both - 27.99).abs() < 0.01, "{both}");
        // The attitude PI overshoots its 20° demand by about a degree.
        assert!(axis > 20.0 && axis < 22.0, "axis {axis}");
        assert!(
            diagonal > both - 0.5 && diagonal < both + 2.0,
            "diagonal {diagonal}"
        );
        assert!(diagonal > axis + 5.0);
        let [x, y] = p.axes[0];
        assert!(x.desired <= fw::TILT_MAX_DEG && y.desired <= fw::TILT_MAX_DEG);
    }

    /// Velocity mode has no speed limit: a 3 m/s setpoint is flown (within the slowly
    /// decaying overshoot the integral wound up while the tilt was clamped).
    #[test]
    fn no_speed_limit_in_velocity_mode() {
        let (_, v, _) = response(Vec2::new(3.0, 0.0), 8.0);
        let last = v.last().copied().unwrap_or_default();
        assert!((last.x - 3.0).abs() < 0.1, "{last:?}");
    }

    /// Every firmware figure the model uses is in docs/world.md's table with its value
    /// and its source line (the constants above cite the same lines).
    #[test]
    fn the_docs_cite_every_figure() {
        let doc = include_str!("../../../../docs/world.md");
        let rows = [
            (fw::VEL_KP, "25 °/(m/s)", "platform_defaults_cf2.h:132"),
            (fw::VEL_KI, "1 °/m", "platform_defaults_cf2.h:133"),
            (fw::VEL_I_LIMIT, "±5000", "pid.h:33"),
            (
                fw::TILT_MAX_DEG * fw::TILT_OVERHEAD,
                "1.1 × 20° = 22°",
                "position_controller_pid.c:63",
            ),
            (fw::ATT_KP, "6 1/s", "platform_defaults_cf2.h:114"),
            (fw::ATT_KI, "3 1/s²", "platform_defaults_cf2.h:115"),
            (fw::ATT_I_LIMIT, "±20 ° s", "platform_defaults_cf2.h:118"),
            (
                f64::from(fw::POSITION_RATE),
                "100 Hz",
                "stabilizer_types.h:373",
            ),
            (
                f64::from(fw::ATTITUDE_RATE),
                "500 Hz",
                "stabilizer_types.h:372",
            ),
        ];
        for (value, text, source) in rows {
            let row = doc
                .lines()
                .find(|l| l.contains(text) && l.contains(source))
                .unwrap_or_else(|| panic!("docs/world.md: no row with {text} and {source}"));
            let number = text
                .trim_start_matches('±')
                .split([' ', '°'])
                .next()
                .and_then(|n| n.parse::<f64>().ok());
            if let Some(n) = number.filter(|_| !text.contains('×')) {
                assert_eq!(n, value, "{row}");
            }
        }
    }

    /// At 20° the acceleration is `g tan 20°` along an axis; the lead is `1 / (g K_p)`.
    #[test]
    fn closed_forms() {
        let a = tilt_acceleration(20.0, 0.0);
        assert!((a.x - 3.569_3).abs() < 1e-3 && a.y == 0.0, "{a:?}");
        assert!((derived_lead() - 0.2337).abs() < 1e-4, "{}", derived_lead());
        assert!((derived_second_lead() - 0.03895).abs() < 1e-5);
    }
}
