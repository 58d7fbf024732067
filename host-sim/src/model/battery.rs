//! The vehicles' battery (`[battery]`, docs/scenarios.md "Safety policies"): the voltage
//! the low-battery policy reads (the app reads the firmware's `pm.vbat`).

/// A battery discharging linearly in flight, the same for every agent: `full` volts
/// at the start of the run, `empty` after `flight_time` seconds, then on down (never
/// below 0). A reduced model (a LiPo's curve is flat in the middle and steep at both
/// ends): it places the low-battery landing at the time the voltages say, not the
/// voltage's path before it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BatteryModel {
    /// Voltage at the start (V, under flight load).
    pub full: f64,
    /// Voltage after `flight_time` (V, < `full`).
    pub empty: f64,
    /// Flight time from `full` to `empty` (s, > 0).
    pub flight_time: f64,
}

impl BatteryModel {
    /// The voltage after `t` seconds of flight (V).
    pub fn voltage(&self, t: f64) -> f64 {
        (self.full - (self.full - self.empty) * t / self.flight_time).max(0.0)
    }

    /// When the voltage reaches `v` (s; 0 when it starts below).
    pub fn time_at(&self, v: f64) -> f64 {
        ((self.full - v) / (self.full - self.empty) * self.flight_time).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn voltage_and_time_are_inverse() {
        let b = BatteryModel {
            full: 4.0,
            empty: 3.0,
            flight_time: 420.0,
        };
        assert_eq!(b.voltage(0.0), 4.0);
        assert!((b.voltage(420.0) - 3.0).abs() < 1e-12);
        assert!((b.time_at(3.2) - 336.0).abs() < 1e-9);
        assert!((b.voltage(b.time_at(3.5)) - 3.5).abs() < 1e-12);
        assert_eq!(b.voltage(1e6), 0.0);
        assert_eq!(b.time_at(4.5), 0.0);
    }
}
