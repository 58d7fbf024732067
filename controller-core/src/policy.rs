//! Safety policies of a flying agent, one implementation for the simulator and the
//! firmware (host-sim's controller adapter, the Crazyflie app through the C API's
//! `ph_policy_update`, `crazyflie-app/src/flight.c`).
//!
//! Every tick [`Policy::update`] takes what the vehicle knows (the controller's output
//! safe or not, its position, the positioning system's lock, the battery voltage) and
//! answers [`PolicyAction::Fly`], [`PolicyAction::Hold`] or [`PolicyAction::Land`]
//! with its [`PolicyReason`]:
//!
//! * **lost neighbours or radio** (the controller's safe output, SPEC §12's faults):
//!   hold at once, land when lost for [`PolicyConfig::hold_timeout_ms`];
//! * **flight volume**: a position outside the fence (or not finite) lands;
//! * **positioning lost**: lands;
//! * **low battery**: below [`PolicyConfig::battery_land`] for
//!   [`PolicyConfig::battery_ms`] lands (a short sag under load does not).
//!
//! A landing is final until [`Policy::reset`]. Durations are integer milliseconds
//! (saturating sums of each tick's `dt_ms`): no clock, no wrap, no float drift.
//!
//! [`separation_guard`] is the minimum-separation guard on a velocity setpoint (or a
//! force): the component towards any neighbour closer than the minimum is removed.

use crate::scalar::Real;
use crate::Vec2;

/// The policies' settings. A zero `hold_timeout_ms` lands at the first lost tick; a
/// `battery_land` of 0 and a fence with `fence: false` switch those policies off.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PolicyConfig<T> {
    /// Lost for this long (ms): land.
    pub hold_timeout_ms: u32,
    /// Whether the flight volume is checked.
    pub fence: bool,
    /// The flight volume's lower corner (m, world frame).
    pub fence_min: [T; 2],
    /// Its upper corner (m).
    pub fence_max: [T; 2],
    /// Battery voltage to land below (V; 0: off).
    pub battery_land: T,
    /// For this long (ms).
    pub battery_ms: u32,
    /// Minimum separation for [`separation_guard`] (m; 0: off).
    pub min_separation: T,
}

impl<T: Real> PolicyConfig<T> {
    /// Every policy off except the lost-neighbour hold, which lands after 2 s.
    pub fn off() -> Self {
        Self {
            hold_timeout_ms: 2000,
            fence: false,
            fence_min: [T::zero(); 2],
            fence_max: [T::zero(); 2],
            battery_land: T::zero(),
            battery_ms: 0,
            min_separation: T::zero(),
        }
    }

    /// Whether the settings are usable: finite numbers, a fence with `min ≤ max`,
    /// non-negative voltage and separation.
    pub fn is_valid(&self) -> bool {
        let fence = !self.fence
            || (0..2).all(|k| {
                let (lo, hi) = (pick(&self.fence_min, k), pick(&self.fence_max, k));
                lo.finite() && hi.finite() && lo <= hi
            });
        fence
            && self.battery_land.finite()
            && self.battery_land >= T::zero()
            && self.min_separation.finite()
            && self.min_separation >= T::zero()
    }
}

/// What the vehicle should do.
#[repr(u8)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PolicyAction {
    /// Fly the formation.
    #[default]
    Fly = 0,
    /// Hold the position (lost neighbours or radio).
    Hold = 1,
    /// Land.
    Land = 2,
}

/// Why.
#[repr(u8)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PolicyReason {
    /// Nothing wrong.
    #[default]
    None = 0,
    /// Neighbours or radio lost (holding).
    Lost = 1,
    /// Lost for `hold_timeout_ms` (landing).
    LostTimeout = 2,
    /// Outside the flight volume (landing).
    Fence = 3,
    /// Battery low (landing).
    Battery = 4,
    /// Positioning lost (landing).
    Positioning = 5,
}

/// What the policies did over a run (host-sim's outcome, the app's log group).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PolicyCounts {
    /// Ticks answered with [`PolicyAction::Hold`].
    pub hold_ticks: u32,
    /// Landings decided (0 or 1 between resets, more over several flights).
    pub landings: u32,
    /// The reason of the last landing ([`PolicyReason::None`] if none).
    pub last_landing: PolicyReason,
    /// Setpoints [`separation_guard`] changed (counted by the caller with
    /// [`Policy::count_guard`]).
    pub guarded: u32,
}

/// One tick's inputs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PolicyInputs<T> {
    /// Milliseconds since the previous update (0 on the first).
    pub dt_ms: u32,
    /// The controller gave its safe output this tick (neighbours or radio lost).
    pub lost: bool,
    /// Own position (m, world frame).
    pub position: [T; 2],
    /// The positioning system is locked.
    pub positioning: bool,
    /// Battery voltage (V; ignored when `battery_land` is 0).
    pub battery: T,
}

/// The policies' state for one vehicle: plain data (the C API keeps it in a C struct
/// between calls), changed only by [`Policy::update`] and [`Policy::reset`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Policy {
    /// How long the vehicle has been lost (ms, from its first lost tick).
    pub lost_ms: u32,
    /// How long the battery has been low (ms, from its first low tick).
    pub low_ms: u32,
    /// Lost at the last update.
    pub lost: bool,
    /// Low at the last update.
    pub low: bool,
    /// The landing decided, if any (final until [`Policy::reset`]).
    pub landing: Option<PolicyReason>,
    /// The counts so far.
    pub counts: PolicyCounts,
}

impl Policy {
    /// Flying, nothing counted.
    pub fn new() -> Self {
        Self::default()
    }

    /// A new flight (the formation enabled again): timers cleared and the landing
    /// forgotten; the counts are kept.
    pub fn reset(&mut self) {
        *self = Self {
            counts: self.counts,
            ..Self::default()
        };
    }

    /// The counts so far.
    pub fn counts(&self) -> PolicyCounts {
        self.counts
    }

    /// Counts a setpoint that [`separation_guard`] changed.
    pub fn count_guard(&mut self) {
        self.counts.guarded = self.counts.guarded.saturating_add(1);
    }

    fn land(&mut self, why: PolicyReason) -> (PolicyAction, PolicyReason) {
        self.landing = Some(why);
        self.counts.landings = self.counts.landings.saturating_add(1);
        self.counts.last_landing = why;
        (PolicyAction::Land, why)
    }

    /// One tick: what to do and why.
    pub fn update<T: Real>(
        &mut self,
        config: &PolicyConfig<T>,
        input: &PolicyInputs<T>,
    ) -> (PolicyAction, PolicyReason) {
        if let Some(why) = self.landing {
            return (PolicyAction::Land, why);
        }
        // Timers: the time a condition has held, in whole milliseconds.
        // Below the threshold, or a NaN voltage.
        let low = config.battery_land > T::zero()
            && matches!(
                input.battery.partial_cmp(&config.battery_land),
                Some(core::cmp::Ordering::Less) | None
            );
        self.low_ms = if low && self.low {
            self.low_ms.saturating_add(input.dt_ms)
        } else {
            0
        };
        self.low = low;
        self.lost_ms = if input.lost && self.lost {
            self.lost_ms.saturating_add(input.dt_ms)
        } else {
            0
        };
        self.lost = input.lost;

        if !input.positioning {
            return self.land(PolicyReason::Positioning);
        }
        if config.fence && !inside(config, &input.position) {
            return self.land(PolicyReason::Fence);
        }
        if low && self.low_ms >= config.battery_ms {
            return self.land(PolicyReason::Battery);
        }
        if input.lost {
            if self.lost_ms >= config.hold_timeout_ms {
                return self.land(PolicyReason::LostTimeout);
            }
            self.counts.hold_ticks = self.counts.hold_ticks.saturating_add(1);
            return (PolicyAction::Hold, PolicyReason::Lost);
        }
        (PolicyAction::Fly, PolicyReason::None)
    }
}

/// `min ≤ q ≤ max` on both axes (false for NaN).
fn inside<T: Real>(c: &PolicyConfig<T>, q: &[T; 2]) -> bool {
    (0..2).all(|k| {
        let x = pick(q, k);
        x >= pick(&c.fence_min, k) && x <= pick(&c.fence_max, k)
    })
}

/// `x[k]` for `k ∈ {0, 1}` (panic-free).
fn pick<T: Copy>(x: &[T; 2], k: usize) -> T {
    if k == 0 {
        x[0]
    } else {
        x[1]
    }
}

/// Distance below which two positions count as coincident (m): no direction between
/// them. The one rule for near-coincident neighbours: a guarded setpoint stops
/// ([`separation_guard`]), and a bearing from shared positions is not measured (the
/// Crazyflie app's `formation_read_bearings` through the C API's `PH_COINCIDENT_M`,
/// host-sim's `SharedPositions`).
pub const COINCIDENT: f64 = 1e-3;

/// The minimum-separation guard: `setpoint` (a velocity or a force, world frame) with
/// its component towards every neighbour closer than `min_separation` removed, in the
/// order given; a neighbour closer than [`COINCIDENT`] (or at a non-finite position)
/// stops it. Returns the guarded setpoint and whether it changed. `min_separation` of
/// 0 (or not positive) returns `setpoint` unchanged.
pub fn separation_guard<T: Real>(
    setpoint: Vec2<T>,
    own: Vec2<T>,
    neighbours: impl IntoIterator<Item = Vec2<T>>,
    min_separation: T,
) -> (Vec2<T>, bool) {
    if min_separation.partial_cmp(&T::zero()) != Some(core::cmp::Ordering::Greater) {
        return (setpoint, false);
    }
    let mut v = setpoint;
    let mut changed = false;
    for q in neighbours {
        let d = q - own;
        let r = d.norm_squared().sqrt_fast();
        if !r.finite() || r < T::lit(COINCIDENT) {
            return (Vec2::zeros(), true);
        }
        if r >= min_separation {
            continue;
        }
        let u = d / r;
        let towards = v.dot(&u);
        if towards > T::zero() {
            v -= u * towards;
            changed = true;
        }
    }
    (v, changed)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg() -> PolicyConfig<f64> {
        PolicyConfig {
            hold_timeout_ms: 2000,
            fence: true,
            fence_min: [-1.0, -1.0],
            fence_max: [3.0, 3.0],
            battery_land: 3.2,
            battery_ms: 1000,
            min_separation: 0.3,
        }
    }

    fn ok(dt_ms: u32) -> PolicyInputs<f64> {
        PolicyInputs {
            dt_ms,
            lost: false,
            position: [1.0, 1.0],
            positioning: true,
            battery: 4.0,
        }
    }

    #[test]
    fn healthy_flies() {
        let mut p = Policy::new();
        for _ in 0..10_000 {
            assert_eq!(
                p.update(&cfg(), &ok(10)),
                (PolicyAction::Fly, PolicyReason::None)
            );
        }
        assert_eq!(p.counts(), PolicyCounts::default());
    }

    #[test]
    fn lost_holds_then_lands_at_the_timeout() {
        let mut p = Policy::new();
        let lost = PolicyInputs {
            lost: true,
            ..ok(10)
        };
        // The first lost tick starts the timer at 0: 200 ticks of 10 ms hold.
        for k in 0..200 {
            assert_eq!(p.update(&cfg(), &lost).0, PolicyAction::Hold, "tick {k}");
        }
        assert_eq!(
            p.update(&cfg(), &lost),
            (PolicyAction::Land, PolicyReason::LostTimeout)
        );
        assert_eq!(p.counts().hold_ticks, 200);
        assert_eq!(p.counts().landings, 1);
        // Final until reset, even when heard again.
        assert_eq!(p.update(&cfg(), &ok(10)).0, PolicyAction::Land);
        p.reset();
        assert_eq!(p.update(&cfg(), &ok(10)).0, PolicyAction::Fly);
        assert_eq!(p.counts().landings, 1, "counts survive a reset");
    }

    #[test]
    fn heard_again_restarts_the_hold_timer() {
        let mut p = Policy::new();
        let lost = PolicyInputs {
            lost: true,
            ..ok(10)
        };
        for _ in 0..150 {
            p.update(&cfg(), &lost);
        }
        assert_eq!(p.update(&cfg(), &ok(10)).0, PolicyAction::Fly);
        // Negative control of the timer: another 150 lost ticks do not land.
        for _ in 0..150 {
            assert_eq!(p.update(&cfg(), &lost).0, PolicyAction::Hold);
        }
    }

    #[test]
    fn fence_lands_and_inside_flies() {
        for (q, action) in [
            ([3.0, 3.0], PolicyAction::Fly),
            ([-1.0, 0.0], PolicyAction::Fly),
            ([3.01, 1.0], PolicyAction::Land),
            ([1.0, -1.01], PolicyAction::Land),
            ([f64::NAN, 1.0], PolicyAction::Land),
        ] {
            let mut p = Policy::new();
            let (a, why) = p.update(
                &cfg(),
                &PolicyInputs {
                    position: q,
                    ..ok(10)
                },
            );
            assert_eq!(a, action, "{q:?}");
            if a == PolicyAction::Land {
                assert_eq!(why, PolicyReason::Fence);
            }
        }
        // The fence off: far away flies.
        let off = PolicyConfig {
            fence: false,
            ..cfg()
        };
        let mut p = Policy::new();
        let far = PolicyInputs {
            position: [100.0, 0.0],
            ..ok(10)
        };
        assert_eq!(p.update(&off, &far).0, PolicyAction::Fly);
    }

    #[test]
    fn low_battery_lands_after_its_time_and_a_sag_does_not() {
        let mut p = Policy::new();
        let low = PolicyInputs {
            battery: 3.1,
            ..ok(10)
        };
        for _ in 0..100 {
            assert_eq!(p.update(&cfg(), &low).0, PolicyAction::Fly);
        }
        assert_eq!(p.update(&cfg(), &ok(10)).0, PolicyAction::Fly);
        for _ in 0..100 {
            assert_eq!(p.update(&cfg(), &low).0, PolicyAction::Fly);
        }
        assert_eq!(
            p.update(&cfg(), &low),
            (PolicyAction::Land, PolicyReason::Battery)
        );
        // NaN voltage counts as low; battery_land = 0 is off.
        let off = PolicyConfig {
            battery_land: 0.0,
            ..cfg()
        };
        let mut q = Policy::new();
        for _ in 0..1000 {
            assert_eq!(q.update(&off, &low).0, PolicyAction::Fly);
        }
    }

    #[test]
    fn positioning_lost_lands() {
        let mut p = Policy::new();
        let none = PolicyInputs {
            positioning: false,
            ..ok(10)
        };
        assert_eq!(
            p.update(&cfg(), &none),
            (PolicyAction::Land, PolicyReason::Positioning)
        );
    }

    #[test]
    fn durations_saturate_instead_of_wrapping() {
        let mut p = Policy::new();
        let lost = PolicyInputs {
            lost: true,
            ..ok(u32::MAX)
        };
        let c = PolicyConfig {
            hold_timeout_ms: u32::MAX,
            ..cfg()
        };
        assert_eq!(p.update(&c, &lost).0, PolicyAction::Hold);
        assert_eq!(p.update(&c, &lost).0, PolicyAction::Land);
    }

    #[test]
    fn guard_removes_the_approach_only() {
        let own = Vec2::new(0.0, 0.0);
        let near = [Vec2::new(0.2, 0.0)];
        // Towards the close neighbour: the x component goes.
        let (v, changed) = separation_guard(Vec2::new(0.5, 0.3), own, near, 0.3);
        assert!(changed);
        assert!((v - Vec2::new(0.0, 0.3)).norm() < 1e-12, "{v:?}");
        // Away from it: unchanged (negative control).
        let (v, changed) = separation_guard(Vec2::new(-0.5, 0.3), own, near, 0.3);
        assert!(!changed);
        assert_eq!(v, Vec2::new(-0.5, 0.3));
        // Far neighbour, or the guard off: unchanged.
        let far = [Vec2::new(0.4, 0.0)];
        assert!(!separation_guard(Vec2::new(0.5, 0.0), own, far, 0.3).1);
        assert!(!separation_guard(Vec2::new(0.5, 0.0), own, near, 0.0).1);
        // Coincident: stop.
        let same = [Vec2::new(0.0005, 0.0)];
        assert_eq!(
            separation_guard(Vec2::new(0.5, 0.0), own, same, 0.3),
            (Vec2::zeros(), true)
        );
    }

    #[test]
    fn config_validity() {
        assert!(cfg().is_valid());
        assert!(PolicyConfig::<f32>::off().is_valid());
        assert!(!PolicyConfig {
            fence_min: [4.0, 0.0],
            ..cfg()
        }
        .is_valid());
        assert!(!PolicyConfig {
            battery_land: f64::NAN,
            ..cfg()
        }
        .is_valid());
        assert!(!PolicyConfig {
            min_separation: -1.0,
            ..cfg()
        }
        .is_valid());
    }
}
