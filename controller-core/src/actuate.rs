//! Actuation through a virtual mass: the controller's force `U` turned into velocity
//! setpoints for a vehicle whose own controller tracks velocity (a Crazyflie's
//! position/velocity controller, a ground robot's wheel controller).
//!
//! The controller assumes the plant of SPEC S1 per agent,
//! `m v̇ = −D^r v + U`. A vehicle that tracks velocity setpoints well behaves like
//! that plant when it is commanded the velocity of a *virtual* mass `m` with
//! friction `D^r` driven by `U`: this module integrates S1 over each control period
//! and returns the new velocity, the setpoint. `D^r` must be the `friction` of the
//! agent's configuration (the controller cancels it at the reference velocity, S10).
//!
//! The step is implicit in the friction and explicit in the force (semi-implicit
//! Euler, first order):
//!
//! `v_{k+1} = (v_k + Δt/m · U_k) / (1 + Δt/m · D^r)` (per axis, S1)
//!
//! which is stable for every `Δt ≥ 0` (a late tick never makes the setpoint
//! oscillate), and tends to the exact solution of S1 as `Δt → 0` (the test below
//! compares it with the closed form `v(t) = U/D + (v₀ − U/D) e^{−D t/m}`).
//!
//! One implementation for every user: the C API's `ph_actuate` (controller-ffi, called
//! by `crazyflie-app/src/agent_loop.c`) and any simulated velocity-tracking vehicle.

use crate::Real;

/// Why a [`VirtualMass`] was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ActuateError {
    /// The mass is not finite and positive.
    Mass,
    /// A friction coefficient is not finite and non-negative.
    Friction,
    /// The speed limit is NaN or not positive (use infinity for none).
    MaxSpeed,
    /// The lead is not finite and non-negative.
    Lead,
    /// The second-order lead is not finite and non-negative.
    SecondLead,
    /// The jerk filter's time constant is not finite and non-negative.
    JerkFilter,
    /// The gap bound is NaN or not positive (use infinity for none).
    MaxGap,
    /// The stall limit is NaN or not positive (use infinity for none).
    MaxInterval,
}

/// The virtual plant of SPEC S1 for one agent: mass, friction `D^r` per axis, the
/// vehicle's largest velocity setpoint, and the lead that compensates the vehicle's own
/// velocity loop (S21).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VirtualMass<T> {
    mass: T,
    friction: [T; 2],
    max_speed: T,
    lead: T,
    second_lead: T,
    jerk_filter: T,
    max_gap: T,
    max_interval: T,
}

impl<T: Real> VirtualMass<T> {
    /// A virtual mass `mass` (kg, finite, > 0) with friction `friction` (`D^r`, N s/m
    /// per axis, finite, ≥ 0); setpoints are limited to `max_speed` (m/s, > 0;
    /// infinity for no limit), scaling the vector so that its direction is kept.
    pub fn new(mass: T, friction: [T; 2], max_speed: T) -> Result<Self, ActuateError> {
        if !(mass.finite() && is_positive(mass)) {
            return Err(ActuateError::Mass);
        }
        if !friction.iter().all(|d| d.finite() && *d >= T::zero()) {
            return Err(ActuateError::Friction);
        }
        if !is_positive(max_speed) {
            return Err(ActuateError::MaxSpeed);
        }
        Ok(Self {
            mass,
            friction,
            max_speed,
            lead: T::zero(),
            second_lead: T::zero(),
            jerk_filter: T::zero(),
            max_gap: T::lit(f64::INFINITY),
            max_interval: T::lit(f64::INFINITY),
        })
    }

    /// The same plant with the gap bound `max_gap` (m/s, > 0; infinity, the default, for
    /// none; SPEC S21c): [`VelocityCommand::step`] starts from a virtual velocity at most
    /// `max_gap` from the measured one. A vehicle that follows its setpoints lags the
    /// virtual velocity by about its loop's time constant times the virtual acceleration;
    /// a larger gap means it is not following (blocked, saturated), and the virtual
    /// velocity would wind up like an integrator without anti-windup.
    pub fn with_max_gap(self, max_gap: T) -> Result<Self, ActuateError> {
        if !is_positive(max_gap) {
            return Err(ActuateError::MaxGap);
        }
        Ok(Self { max_gap, ..self })
    }

    /// The same plant with the stall limit `max_interval` (s, > 0; infinity, the
    /// default, for none; SPEC S21c): a [`VelocityCommand::step`] over a longer period
    /// (a stalled task, a jumped clock) starts again from the measured velocity.
    pub fn with_max_interval(self, max_interval: T) -> Result<Self, ActuateError> {
        if !is_positive(max_interval) {
            return Err(ActuateError::MaxInterval);
        }
        Ok(Self {
            max_interval,
            ..self
        })
    }

    /// The gap bound (m/s; S21c).
    pub fn max_gap(&self) -> T {
        self.max_gap
    }

    /// The stall limit (s; S21c).
    pub fn max_interval(&self) -> T {
        self.max_interval
    }

    /// The same plant with lead `lead` (s, finite, ≥ 0): the time constant of the
    /// vehicle's velocity loop, which the setpoint then anticipates (S21). 0 (the
    /// default) gives the virtual velocity itself.
    pub fn with_lead(self, lead: T) -> Result<Self, ActuateError> {
        if !(lead.finite() && lead >= T::zero()) {
            return Err(ActuateError::Lead);
        }
        Ok(Self { lead, ..self })
    }

    /// The same plant with second-order lead `second_lead` (s², finite, ≥ 0; S21b): for
    /// a vehicle whose velocity answers its setpoint like `1 / (τ_a τ s² + τ s + 1)` (a
    /// velocity loop of time constant `τ` through an attitude loop of time constant
    /// `τ_a`), `second_lead = τ τ_a` adds that many times the virtual jerk to the
    /// setpoint ([`VelocityCommand::step`]). 0 (the default): first order only.
    pub fn with_second_lead(self, second_lead: T) -> Result<Self, ActuateError> {
        if !(second_lead.finite() && second_lead >= T::zero()) {
            return Err(ActuateError::SecondLead);
        }
        Ok(Self {
            second_lead,
            ..self
        })
    }

    /// The same plant with the second-order lead's jerk taken through a first-order
    /// filter of time constant `jerk_filter` (s, finite, ≥ 0; S21d): the jerk is the
    /// virtual acceleration's distance from its filtered value over `jerk_filter + Δt`,
    /// so that velocity noise differenced twice does not reach the vehicle's velocity
    /// loop tick by tick. 0 (the default): S21b's plain difference.
    pub fn with_jerk_filter(self, jerk_filter: T) -> Result<Self, ActuateError> {
        if !(jerk_filter.finite() && jerk_filter >= T::zero()) {
            return Err(ActuateError::JerkFilter);
        }
        Ok(Self {
            jerk_filter,
            ..self
        })
    }

    /// The jerk filter's time constant (s, S21d).
    pub fn jerk_filter(&self) -> T {
        self.jerk_filter
    }

    /// The second-order lead (s²).
    pub fn second_lead(&self) -> T {
        self.second_lead
    }

    /// The lead (s).
    pub fn lead(&self) -> T {
        self.lead
    }

    /// S21: the setpoint for a vehicle whose velocity follows its setpoint with time
    /// constant `τ` (the lead): the virtual velocity `next` plus `τ` times the virtual
    /// acceleration over the period `dt` from `from`,
    /// `v_sp = v_{k+1} + τ (v_{k+1} − v_k) / Δt`, limited to the speed limit. Then
    /// `v̇ = (v_sp − v) / τ` makes the vehicle's velocity error to the virtual one decay
    /// as `e^{−t/τ}` instead of lagging behind it. Without lead, or for `dt ≤ 0`,
    /// `next` itself.
    pub fn setpoint(&self, from: [T; 2], next: [T; 2], dt: T) -> [T; 2] {
        if !(self.lead > T::zero() && dt > T::zero() && dt.finite()) {
            return next;
        }
        let k = self.lead / dt;
        let [x, y] = next;
        let [x0, y0] = from;
        self.limit([x + k * (x - x0), y + k * (y - y0)])
    }

    /// The mass.
    pub fn mass(&self) -> T {
        self.mass
    }

    /// The friction `D^r` per axis.
    pub fn friction(&self) -> [T; 2] {
        self.friction
    }

    /// The speed limit of the setpoints.
    pub fn max_speed(&self) -> T {
        self.max_speed
    }

    /// One period `dt` (s) of S1 from velocity `velocity` under force `force` (N, world
    /// frame): the next velocity, limited to the speed limit. A negative or non-finite
    /// `dt`, or a non-finite force, leaves the velocity as it is (still limited).
    pub fn step(&self, velocity: [T; 2], force: [T; 2], dt: T) -> [T; 2] {
        let usable = dt.finite() && dt >= T::zero() && force.iter().all(|u| u.finite());
        let h = if usable { dt / self.mass } else { T::zero() };
        let force = if usable { force } else { [T::zero(); 2] };
        // S1, semi-implicit: v' = (v + h U) / (1 + h D^r).
        let next = [0, 1].map(|k| {
            let (v, u, d) = match (velocity.get(k), force.get(k), self.friction.get(k)) {
                (Some(v), Some(u), Some(d)) => (*v, *u, *d),
                _ => (T::zero(), T::zero(), T::zero()),
            };
            (v + h * u) / (T::one() + h * d)
        });
        self.limit(next)
    }

    /// `v` scaled down to the speed limit if faster (a non-finite `v` becomes zero).
    fn limit(&self, v: [T; 2]) -> [T; 2] {
        let [x, y] = v;
        let speed = (x * x + y * y).sqrt_fast();
        if !speed.finite() {
            [T::zero(); 2]
        } else if speed > self.max_speed {
            let s = self.max_speed / speed;
            [x * s, y * s]
        } else {
            v
        }
    }
}

/// S21c: `c` moved towards `m` until at most `gap` from it (`c` itself when it is
/// within, or when the distance is NaN).
fn within<T: Real>(c: [T; 2], m: [T; 2], gap: T) -> [T; 2] {
    let [x, y] = [c[0] - m[0], c[1] - m[1]];
    let d = (x * x + y * y).sqrt_fast();
    if d > gap {
        let k = gap / d;
        [m[0] + x * k, m[1] + y * k]
    } else {
        c
    }
}

/// `x > 0` (false for NaN).
fn is_positive<T: Real>(x: T) -> bool {
    x.partial_cmp(&T::zero()) == Some(core::cmp::Ordering::Greater)
}

/// The velocity setpoint of one agent over time: a [`VirtualMass`] and its state.
/// The first step after [`VelocityCommand::new`] or [`VelocityCommand::restart`]
/// starts from the measured velocity, so that the setpoint does not jump when the
/// formation takes over the vehicle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VelocityCommand<T> {
    plant: VirtualMass<T>,
    command: Option<[T; 2]>,
    /// The virtual acceleration of the last step (for the second-order lead).
    accel: Option<[T; 2]>,
}

impl<T: Real> VelocityCommand<T> {
    /// Starts a command with no state yet.
    pub fn new(plant: VirtualMass<T>) -> Self {
        Self {
            plant,
            command: None,
            accel: None,
        }
    }

    /// Resumes a command at setpoint `command` (`None`: no state yet), e.g. state kept
    /// by a C caller between calls.
    pub fn resume(plant: VirtualMass<T>, command: Option<[T; 2]>) -> Self {
        Self {
            plant,
            command,
            accel: None,
        }
    }

    /// Resumes a command at setpoint `command` and last virtual acceleration `accel`
    /// (for the second-order lead, S21b), e.g. state kept by a C caller between calls.
    pub fn resume_with_accel(
        plant: VirtualMass<T>,
        command: Option<[T; 2]>,
        accel: Option<[T; 2]>,
    ) -> Self {
        Self {
            plant,
            command,
            accel,
        }
    }

    /// The virtual acceleration of the last step (`None` before a step with a
    /// second-order lead).
    pub fn accel(&self) -> Option<[T; 2]> {
        self.accel
    }

    /// The next step starts again from the measured velocity, as the first one (no jerk
    /// term, S21b): after a reboot or a stall.
    pub fn restart(&mut self) {
        self.command = None;
        self.accel = None;
    }

    /// The next step starts from the measured velocity, keeping the virtual acceleration
    /// the second-order lead differences (S21b/S21d). Call it once the agent's safe
    /// output has lasted the stall limit (SPEC S21c; once per episode): the safe force
    /// damps the vehicle's own velocity, not a virtual one that may have run ahead of it,
    /// and the setpoint's lead goes on without a jump (the C API's `has_command = 0`).
    pub fn reseed(&mut self) {
        self.command = None;
    }

    /// The current virtual velocity (`None` before the first step): the setpoint
    /// without lead.
    pub fn command(&self) -> Option<[T; 2]> {
        self.command
    }

    /// The plant.
    pub fn plant(&self) -> &VirtualMass<T> {
        &self.plant
    }

    /// One control period: integrates S1 from the previous virtual velocity (or, on the
    /// first step, from `measured`, the vehicle's velocity) under `force` for `dt`
    /// seconds (S20) and returns the new setpoint (S21: the new virtual velocity, led by
    /// the plant's lead). S21c: the previous virtual velocity is first brought within
    /// the plant's gap bound of `measured` (a finite `measured` only), and a `dt` above
    /// its stall limit starts again from `measured`.
    pub fn step(&mut self, force: [T; 2], measured: [T; 2], dt: T) -> [T; 2] {
        if dt > self.plant.max_interval {
            self.restart();
        }
        let from = match self.command {
            Some(c) => within(c, measured, self.plant.max_gap),
            None => measured,
        };
        let next = self.plant.step(from, force, dt);
        self.command = Some(next);
        let p = &self.plant;
        if !(p.second_lead > T::zero() && dt > T::zero() && dt.finite()) {
            return p.setpoint(from, next, dt);
        }
        // S21b: S21 plus `τ₂` times the virtual jerk (none on the first step after a
        // (re)start). S21d: the jerk is the acceleration's distance from its filtered
        // value `ā` over `τ_f + Δt`, and `ā` moves by `Δt` times it; with `τ_f = 0`,
        // `ā` is the last acceleration and the jerk S21b's difference (the same bits).
        let ([x, y], [x0, y0]) = (next, from);
        let (ax, ay) = ((x - x0) / dt, (y - y0) / dt);
        let [px, py] = self.accel.unwrap_or([ax, ay]);
        if p.jerk_filter > T::zero() {
            let span = p.jerk_filter + dt;
            let (jx, jy) = ((ax - px) / span, (ay - py) / span);
            self.accel = Some([px + dt * jx, py + dt * jy]);
            return p.limit([
                x + p.lead * ax + p.second_lead * jx,
                y + p.lead * ay + p.second_lead * jy,
            ]);
        }
        self.accel = Some([ax, ay]);
        let k = p.second_lead / dt;
        p.limit([
            x + p.lead * ax + k * (ax - px),
            y + p.lead * ay + k * (ay - py),
        ])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn exact(v0: f64, u: f64, d: f64, m: f64, t: f64) -> f64 {
        u / d + (v0 - u / d) * libm::exp(-d * t / m)
    }

    #[test]
    fn converges_to_the_closed_form_of_s1() {
        let (m, d, u, v0, t_end) = (1.5_f64, 0.5, 2.0, -0.3, 4.0);
        let plant = VirtualMass::new(m, [d, 2.0 * d], f64::INFINITY).unwrap();
        let mut errors = [0.0; 2];
        for (e, steps) in errors.iter_mut().zip([400_u32, 800]) {
            let dt = t_end / f64::from(steps);
            let mut v = [v0, v0];
            for _ in 0..steps {
                v = plant.step(v, [u, u], dt);
            }
            let want = [exact(v0, u, d, m, t_end), exact(v0, u, 2.0 * d, m, t_end)];
            *e = (v[0] - want[0]).abs().max((v[1] - want[1]).abs());
        }
        // First order: halving the step halves the error (2.5e-3 m/s at Δt = 10 ms).
        assert!(errors[0] < 4e-3, "{errors:?}");
        let ratio = errors[0] / errors[1];
        assert!((1.8..2.2).contains(&ratio), "order: {errors:?}");
    }

    #[test]
    fn without_friction_the_force_is_integrated_exactly() {
        let plant = VirtualMass::new(2.0_f64, [0.0, 0.0], f64::INFINITY).unwrap();
        let v = plant.step([1.0, -1.0], [4.0, 2.0], 0.5);
        assert_eq!(v, [2.0, -0.5]);
    }

    #[test]
    fn stable_for_any_step_and_limited() {
        let plant = VirtualMass::new(1.0_f32, [5.0, 5.0], 1.0).unwrap();
        // A 10 s hiccup with strong friction: relaxes toward U/D, no overshoot.
        let v = plant.step([0.0, 0.0], [2.0, 0.0], 10.0);
        assert!(v[0] > 0.0 && v[0] < 0.4 && v[1] == 0.0, "{v:?}");
        // A setpoint faster than the limit keeps its direction at the limit.
        let v = plant.step([3.0, 4.0], [0.0, 0.0], 0.0);
        assert!(
            (v[0] - 0.6).abs() < 1e-3 && (v[1] - 0.8).abs() < 1e-3,
            "{v:?}"
        );
        // Bad inputs hold the velocity.
        assert_eq!(plant.step([0.5, 0.0], [f32::NAN, 0.0], 0.01), [0.5, 0.0]);
        assert_eq!(plant.step([0.5, 0.0], [1.0, 0.0], -1.0), [0.5, 0.0]);
    }

    #[test]
    fn bad_parameters_are_refused() {
        let inf = f32::INFINITY;
        assert_eq!(
            VirtualMass::new(0.0, [0.0; 2], inf),
            Err(ActuateError::Mass)
        );
        assert_eq!(
            VirtualMass::new(inf, [0.0; 2], inf),
            Err(ActuateError::Mass)
        );
        assert_eq!(
            VirtualMass::new(1.0, [-1.0, 0.0], inf),
            Err(ActuateError::Friction)
        );
        assert_eq!(
            VirtualMass::new(1.0, [0.0; 2], f32::NAN),
            Err(ActuateError::MaxSpeed)
        );
        assert_eq!(
            VirtualMass::new(1.0, [0.0; 2], 0.0),
            Err(ActuateError::MaxSpeed)
        );
    }

    /// S21: with lead τ, a first-order vehicle `v̇ = (v_sp − v)/τ` follows the virtual
    /// velocity with an error that decays; without lead it lags by about `τ a`.
    #[test]
    fn the_lead_cancels_a_first_order_velocity_loop() {
        let tau = 0.2_f64;
        let lag = |lead: f64| {
            let plant = VirtualMass::new(1.0, [0.5; 2], f64::INFINITY)
                .and_then(|p| p.with_lead(lead))
                .unwrap();
            let mut c = VelocityCommand::new(plant);
            let (dt, sub) = (0.01, 100);
            let mut v = 0.0;
            let mut worst: f64 = 0.0;
            for k in 0..300 {
                // A force that keeps changing: the virtual velocity ramps and turns.
                let u = if k < 150 { 1.0 } else { -1.0 };
                let sp = c.step([u, 0.0], [v, 0.0], dt)[0];
                for _ in 0..sub {
                    v += (sp - v) / tau * (dt / f64::from(sub));
                }
                if k > 20 {
                    worst = worst.max((v - c.command().unwrap()[0]).abs());
                }
            }
            worst
        };
        let (without, with) = (lag(0.0), lag(tau));
        assert!(without > 0.15, "{without}");
        assert!(with < 0.03 * without, "{with} vs {without}");
        assert_eq!(
            VirtualMass::new(1.0_f64, [0.0; 2], 1.0).and_then(|p| p.with_lead(-1.0)),
            Err(ActuateError::Lead)
        );
    }

    /// S21b: a second-order vehicle `τ τ_a v̈ + τ v̇ + v = v_sp` follows a smoothly
    /// turning virtual velocity far closer with the second-order lead `τ τ_a` than with
    /// S21 alone.
    #[test]
    fn the_second_lead_cancels_a_second_order_velocity_loop() {
        let (tau, tau_a) = (0.2337_f64, 1.0 / 6.0);
        let lag = |second: f64, filter: f64| {
            let plant = VirtualMass::new(1.0, [0.0; 2], f64::INFINITY)
                .and_then(|p| p.with_lead(tau))
                .and_then(|p| p.with_second_lead(second))
                .and_then(|p| p.with_jerk_filter(filter))
                .unwrap();
            let mut c = VelocityCommand::new(plant);
            let (dt, sub) = (0.01, 100);
            let (mut v, mut a) = (0.0, 0.0);
            let mut worst: f64 = 0.0;
            for k in 0..400 {
                // A force turning smoothly (period 2 s): the virtual velocity oscillates.
                let u = libm::sin(core::f64::consts::PI * f64::from(k) * dt);
                let sp = c.step([u, 0.0], [v, 0.0], dt)[0];
                let h = dt / f64::from(sub);
                for _ in 0..sub {
                    let jerk = (sp - v - tau * a) / (tau * tau_a);
                    a += jerk * h;
                    v += a * h;
                }
                if k > 100 {
                    worst = worst.max((v - c.command().unwrap()[0]).abs());
                }
            }
            worst
        };
        let (first, second) = (lag(0.0, 0.0), lag(tau * tau_a, 0.0));
        assert!(first > 0.02, "{first}");
        assert!(second < 0.1 * first, "{second} vs {first}");
        // S21d's filter (30 ms) keeps most of the cancellation.
        let filtered = lag(tau * tau_a, 0.03);
        assert!(filtered < 0.25 * first, "{filtered} vs {first}");
        assert_eq!(
            VirtualMass::new(1.0_f64, [0.0; 2], 1.0).and_then(|p| p.with_second_lead(f64::NAN)),
            Err(ActuateError::SecondLead)
        );
    }

    /// S21d: under a constant virtual jerk `J` the filtered jerk converges to `J`
    /// exactly (the filter's steady state, `ā = a − τ_f J`), so the setpoint gains `τ₂ J`
    /// as S21b's does; under white force noise the setpoint's change from tick to tick
    /// is several times smaller than S21b's; the lead still cancels the second-order
    /// loop; a bad time constant is refused.
    #[test]
    fn the_jerk_filter_keeps_the_lead_and_drops_tick_noise() {
        let (tau, tau2, tf, dt) = (0.2337_f64, 0.039, 0.03, 0.01);
        let plant = |filter: f64| {
            VirtualMass::new(1.0, [0.0; 2], f64::INFINITY)
                .and_then(|p| p.with_lead(tau))
                .and_then(|p| p.with_second_lead(tau2))
                .and_then(|p| p.with_jerk_filter(filter))
                .unwrap()
        };
        // A force ramp U = J t on a unit mass: acceleration J t, jerk J.
        let jerk = 2.0;
        let mut c = VelocityCommand::new(plant(tf));
        let mut sp = [0.0; 2];
        for k in 0..200 {
            sp = c.step([jerk * f64::from(k) * dt, 0.0], [0.0; 2], dt);
        }
        let v = c.command().unwrap()[0];
        let a = jerk * 199.0 * dt;
        let expected = v + tau * a + tau2 * jerk;
        assert!((sp[0] - expected).abs() < 1e-9, "{} vs {expected}", sp[0]);
        // White force noise: the setpoint's tick-to-tick change.
        let spread = |filter: f64| {
            let mut c = VelocityCommand::new(plant(filter));
            let mut rng = 0x2545_f491_u32;
            let (mut last, mut sum) = (0.0, 0.0);
            for k in 0..2000 {
                rng ^= rng << 13;
                rng ^= rng >> 17;
                rng ^= rng << 5;
                let u = f64::from(rng) / f64::from(u32::MAX) - 0.5;
                let sp = c.step([u, 0.0], [0.0; 2], dt)[0];
                if k > 0 {
                    sum += (sp - last) * (sp - last);
                }
                last = sp;
            }
            libm::sqrt(sum / 1999.0)
        };
        let (plain, filtered) = (spread(0.0), spread(tf));
        assert!(filtered < plain / 3.0, "{filtered} vs {plain}");
        assert_eq!(
            VirtualMass::new(1.0_f64, [0.0; 2], 1.0).and_then(|p| p.with_jerk_filter(-1.0)),
            Err(ActuateError::JerkFilter)
        );
    }

    #[test]
    fn the_command_starts_from_the_measured_velocity() {
        let plant = VirtualMass::new(1.0_f64, [0.5, 0.5], f64::INFINITY).unwrap();
        let mut c = VelocityCommand::new(plant);
        assert_eq!(c.command(), None);
        let first = c.step([0.0, 0.0], [0.2, -0.1], 0.01);
        assert!((first[0] - 0.2 / 1.005).abs() < 1e-12, "{first:?}");
        // Later steps ignore the measurement.
        let second = c.step([0.0, 0.0], [9.0, 9.0], 0.01);
        assert!((second[0] - first[0] / 1.005).abs() < 1e-12);
        c.restart();
        assert_eq!(c.step([0.0, 0.0], [1.0, 0.0], 0.0), [1.0, 0.0]);
    }
}
