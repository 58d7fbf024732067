//! The bands a run with random sensing or a random world is judged against
//! (`docs/outputs.md`, "Outcome"): what the controller achieves under the same sensing
//! when it starts at the target, measured by a **calibration run**, with a margin, never
//! below the noise-free tolerances and never above the caps of `[criteria]`.

use super::steady::Window;
use crate::model::Criteria;

/// The calibration's statistic times this is the band: a steady run's worst sub-window
/// varies from seed to seed, most in the slow modes (the leader edge's scale). With 1.5,
/// 10–29 % of `paper`'s runs at 0.5–2° missed a band by a few per cent (100 seeds per
/// point, docs/sensors.md); the caps keep a wider margin from excusing a bad shape.
pub const MARGIN: f64 = 2.0;

/// What the calibration run measured: the worst sub-window's 95th percentile of each
/// quantity over its steady window ([`super::steady::Series::worst_sub_window`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Calibration {
    /// Its seed (the run's, mixed: another draw of the same sensing).
    pub seed: u64,
    /// Its duration (s).
    pub duration: f64,
    /// The window it was read on (its last `W` seconds, `W` the run's own).
    pub window: Window,
    /// `max |α − α*|` (rad).
    pub angle: f64,
    /// `| |z| − |z*| |` (m).
    pub scale: f64,
    /// `max_n |v_n − v*|` (m/s).
    pub velocity: f64,
}

/// The bands of the steady window.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bands {
    /// Angle band (rad).
    pub angle: f64,
    /// Scale band of the leader edge (m).
    pub scale: f64,
    /// Velocity band (m/s).
    pub velocity: f64,
    /// Which bands the caps of `[criteria]` cut: angle, scale, velocity.
    pub capped: [bool; 3],
    /// The calibration they came from (`None`: it could not run; the bands are the caps).
    pub calibration: Option<Calibration>,
}

/// `MARGIN · x`, at least `lo`, at most `cap`; whether the cap cut it.
fn band(x: f64, lo: f64, cap: f64) -> (f64, bool) {
    if x.is_nan() {
        return (cap, true);
    }
    let b = (MARGIN * x).max(lo);
    if b > cap {
        (cap, true)
    } else {
        (b, false)
    }
}

/// The caps of a formation whose leader edge is `|z*|` long (0 without one) and that
/// moves at `|v*|`: `criteria`'s, or 1 % of `|z*|` for the scale and 2 % of `|v*|` for
/// the velocity when larger (a bearing error turns the whole edge and the whole velocity:
/// 1° is 1.7 % of either).
pub fn caps(cr: &Criteria, z_star: f64, v_star: f64) -> [f64; 3] {
    [
        cr.angle_band_cap,
        cr.scale_band_cap.max(SCALE_CAP_REL * z_star),
        cr.velocity_band_cap.max(VELOCITY_CAP_REL * v_star),
    ]
}

/// The scale cap's share of `|z*|`.
pub const SCALE_CAP_REL: f64 = 0.01;
/// The velocity cap's share of `|v*|`.
pub const VELOCITY_CAP_REL: f64 = 0.02;

impl Bands {
    /// The bands of a calibration under `cr` and the caps of [`caps`].
    pub fn calibrated(cr: &Criteria, c: Calibration, caps: [f64; 3]) -> Self {
        let (angle, ca) = band(c.angle, cr.angle_tolerance, caps[0]);
        let (scale, cs) = band(c.scale, cr.displacement_tolerance, caps[1]);
        let (velocity, cv) = band(c.velocity, cr.velocity_tolerance, caps[2]);
        Self {
            angle,
            scale,
            velocity,
            capped: [ca, cs, cv],
            calibration: Some(c),
        }
    }

    /// The caps themselves (a calibration that could not run).
    pub fn capped(caps: [f64; 3]) -> Self {
        Self {
            angle: caps[0],
            scale: caps[1],
            velocity: caps[2],
            capped: [true; 3],
            calibration: None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bands_are_the_margin_between_tolerance_and_cap() {
        let cr = Criteria::default();
        let w = Window {
            from: 75.0,
            to: 100.0,
            sub: 6.25,
        };
        let c = |angle| Calibration {
            seed: 1,
            duration: 31.25,
            window: w,
            angle,
            scale: 0.0,
            velocity: 0.02,
        };
        let cap = caps(&cr, 0.0, 0.0);
        let b = Bands::calibrated(&cr, c(0.004), cap);
        assert!((b.angle - 0.008).abs() < 1e-15);
        assert_eq!(b.scale, cr.displacement_tolerance);
        assert!((b.velocity - 0.04).abs() < 1e-15);
        assert_eq!(b.capped, [false; 3]);
        // Noise the cap cuts: the band is the cap, and says so.
        let b = Bands::calibrated(&cr, c(0.1), cap);
        assert_eq!(b.angle, cr.angle_band_cap);
        assert!(b.capped[0]);
        // A NaN statistic (no instant) is the cap, never a NaN band.
        assert_eq!(
            Bands::calibrated(&cr, c(f64::NAN), cap).angle,
            cr.angle_band_cap
        );
        // A long leader edge and a fast formation get caps relative to them.
        let [_, s, v] = caps(&cr, 14.14, 4.243);
        assert!((s - 0.1414).abs() < 1e-12 && (v - 0.08486).abs() < 1e-12);
    }
}
