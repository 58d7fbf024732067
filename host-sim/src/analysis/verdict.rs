//! The verdict of a run (`docs/outputs.md`, "Outcome"): terminal failures first, then
//! whether the agents were in control over the steady window, then whether the formation
//! held its shape, either against the noise-free criteria at the last instant (a run whose
//! sensing and world are deterministic: today's criteria, unchanged) or against the
//! calibrated bands over the steady window ([`super::steady`], [`super::bands`]); the
//! pose (orientation, scale, translation) is reported apart.

use super::bands::Bands;
use super::control::{fault_kind, WindowCounts, FAULT_KINDS, FAULT_SAMPLES};
use super::monitor::Monitor;
use super::outcome::Outcome;
use super::shape_check::{folded_names, shape_check};
use super::snapshot::Snapshot;
use super::steady::{Quantity, Window};
use crate::model::Model;
use ph_formation_core::{Fault, Vec2};

/// What the verdict found.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    /// How the run ended.
    pub outcome: Outcome,
    /// Why, in words.
    pub reason: String,
    /// When the formation settled: the noise-free settle time, or with bands the steady
    /// window's (the latest of the judged quantities'; `None` when one never settled).
    pub settle_time: Option<f64>,
    /// The steady window's figures (judged with bands; `None` for a noise-free run).
    pub steady: Option<SteadyReport>,
    /// The pose over the steady window.
    pub pose: PoseReport,
    /// Share of the controllers' outputs in the steady window that were the safe output.
    pub safe_share: Option<f64>,
}

/// What the steady window of a run judged with bands showed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SteadyReport {
    /// The window.
    pub window: Window,
    /// The bands.
    pub bands: Bands,
    /// The 95th percentile over the window of the angle, scale and velocity errors.
    pub p95: [Option<f64>; 3],
    /// Each quantity's settle time (angle, scale, velocity).
    pub settle: [Option<f64>; 3],
}

/// The pose of the formation over the steady window, reported apart from its shape:
/// each as `(final, 95th percentile over the window)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseReport {
    /// The window.
    pub window: Window,
    /// `|∠(z*, z)|` (rad), with a leader edge.
    pub orientation: Option<(f64, f64)>,
    /// `| |z| − |z*| | / |z*|`, with a leader edge.
    pub scale_rel: Option<(f64, f64)>,
    /// Distance of the centroid from `c(0) + ∫ v*` (m).
    pub translation: Option<(f64, f64)>,
}

/// The judged quantities with their names.
const JUDGED: [(Quantity, &str, &str); 3] = [
    (Quantity::Angle, "max angle error", "rad"),
    (
        Quantity::Scale,
        "leader-edge scale error | |z| − |z*| |",
        "m",
    ),
    (Quantity::Velocity, "max |v − v*|", "m/s"),
];

impl Monitor {
    /// The outcome and its reason, given the last snapshot, the final positions `q`, the
    /// controllers' outputs in the steady window and, for a run with random sensing or a
    /// random world, the calibrated bands.
    ///
    /// In this order: a terminal failure (a collapse before it is reported as the cause);
    /// `not_in_control` when more than `criteria.safe_share` of the outputs in the steady
    /// window were the safe output; `converged` when the shape held (noise-free: every
    /// angle below `angle_tolerance` from the settle time, `|z − z*|` and `|v − v*|` within
    /// tolerance at the end; with bands: angle, scale and velocity settled by the start of
    /// the steady window), and the final positions are the target shape, else
    /// `wrong_shape`; an estimate collapse; `not_converged`.
    pub fn verdict(
        &self,
        model: &Model,
        last: &Snapshot,
        q: &[Vec2<f64>],
        control: &WindowCounts,
        bands: Option<&Bands>,
    ) -> Verdict {
        let window = Window::of(model);
        let pose = self.pose(model, &window);
        let steady = bands.map(|b| self.steady_report(model, &window, b));
        let safe_share =
            (control.ticks > 0).then(|| control.safe.total() as f64 / control.ticks as f64);
        let settle_time = match &steady {
            Some(r) => r.settle_time(model),
            None => self.settle_candidate,
        };
        let (outcome, reason) = self.decide(model, last, q, control, steady.as_ref(), &window);
        Verdict {
            outcome,
            reason,
            settle_time,
            steady,
            pose,
            safe_share,
        }
    }

    fn chain(&self) -> String {
        self.events
            .iter()
            .map(|e| format!("t = {:.3} s: {}", e.t, e.message))
            .collect::<Vec<_>>()
            .join("; then ")
    }

    fn decide(
        &self,
        model: &Model,
        last: &Snapshot,
        q: &[Vec2<f64>],
        control: &WindowCounts,
        steady: Option<&SteadyReport>,
        window: &Window,
    ) -> (Outcome, String) {
        let collapse = self
            .events
            .iter()
            .find(|e| e.kind == Outcome::EstimateCollapse);
        if self.terminal {
            let kind = match (collapse, self.events.last()) {
                (Some(c), Some(last)) if c.t <= last.t => Outcome::EstimateCollapse,
                (_, Some(last)) => last.kind,
                _ => Outcome::Diverged,
            };
            return (kind, self.chain());
        }
        if let Some(why) = not_in_control(model, control, window) {
            return (Outcome::NotInControl, why);
        }
        let held = match steady {
            None => self.noise_free(model, last),
            Some(r) => r.held(model),
        };
        match held {
            Ok(mut why) => {
                if let Some(wrong) = self.wrong_shape(model, q, &why) {
                    return (Outcome::WrongShape, wrong);
                }
                if !self.events.is_empty() {
                    why.push_str(&format!(" (despite: {})", self.chain()));
                }
                (Outcome::Converged, why)
            }
            Err(end) => match collapse {
                Some(_) => (
                    Outcome::EstimateCollapse,
                    format!("{}; {end}", self.chain()),
                ),
                None => (Outcome::NotConverged, end),
            },
        }
    }

    /// The noise-free criteria at the last instant: `Ok(why)` when they hold, else
    /// `Err(what is missing)`.
    fn noise_free(&self, model: &Model, last: &Snapshot) -> Result<String, String> {
        let cr = &model.criteria;
        let settled = self.settle_candidate.is_some();
        let disp_ok = last.disp_err <= cr.displacement_tolerance;
        let vel_ok = last.vel_err <= cr.velocity_tolerance;
        if settled && disp_ok && vel_ok {
            return Ok(format!(
                "every angle error below {} rad from t = {:.3} s; final |z − z*| = {:.2e} m, max |v − v*| = {:.2e} m/s",
                cr.angle_tolerance,
                self.settle_candidate.unwrap_or(0.0),
                last.disp_err,
                last.vel_err
            ));
        }
        let mut missing = Vec::new();
        if !settled {
            missing.push(format!(
                "max angle error {:.3e} rad ≥ {} rad",
                last.max_angle_err, cr.angle_tolerance
            ));
        }
        if !disp_ok {
            missing.push(format!(
                "|z − z*| = {:.3e} m > {} m",
                last.disp_err, cr.displacement_tolerance
            ));
        }
        if !vel_ok {
            missing.push(format!(
                "max |v − v*| = {:.3e} m/s > {} m/s",
                last.vel_err, cr.velocity_tolerance
            ));
        }
        Err(format!(
            "not converged at t = {:.3} s: {}",
            last.t,
            missing.join(", ")
        ))
    }

    /// `Some(reason)` when the final positions are not the target shape.
    fn wrong_shape(&self, model: &Model, q: &[Vec2<f64>], held: &str) -> Option<String> {
        let cr = &model.criteria;
        let pos: Vec<[f64; 2]> = q.iter().map(|p| [p.x, p.y]).collect();
        let c = shape_check(model, &pos)?;
        if c.folded.is_empty() && c.fit.max_rel <= cr.shape_tolerance {
            return None;
        }
        let folded = if c.folded.is_empty() {
            String::new()
        } else {
            format!(
                "{} folded across an edge ({}); ",
                if c.folded.len() == 1 {
                    "triangle"
                } else {
                    "triangles"
                },
                folded_names(model, &c.folded).join(", ")
            )
        };
        // The held part up to its first `;` (the angles), then why the shape is wrong.
        let angles = held.split(';').next().unwrap_or(held);
        Some(format!(
            "{angles}, but the formation is not the target shape: {folded}an agent is {:.3e} of the target's size from its target point (tolerance {})",
            c.fit.max_rel, cr.shape_tolerance
        ))
    }

    /// The steady window's figures against `bands`.
    fn steady_report(&self, model: &Model, w: &Window, bands: &Bands) -> SteadyReport {
        let band = [bands.angle, bands.scale, bands.velocity];
        let mut p95 = [None; 3];
        let mut settle = [None; 3];
        for (k, (q, _, _)) in JUDGED.iter().enumerate() {
            p95[k] = self.series.percentile(*q, w.from, w.to);
            settle[k] = self.series.settle_time(*q, band[k], w.sub);
        }
        if model.leader.is_none() {
            p95[1] = None;
            settle[1] = None;
        }
        SteadyReport {
            window: *w,
            bands: *bands,
            p95,
            settle,
        }
    }

    /// The pose over the window.
    fn pose(&self, model: &Model, w: &Window) -> PoseReport {
        let last = self.series.last();
        let both = |q: Quantity, scale: f64| {
            let fin = last.map(|i| q.of(i) / scale)?;
            let p = self.series.percentile(q, w.from, w.to)? / scale;
            Some((fin, p))
        };
        let z_star = model
            .z_star(model.duration)
            .map_or(0.0, |z| z[0].hypot(z[1]));
        let leader = model.leader.is_some() && z_star > 0.0;
        PoseReport {
            window: *w,
            orientation: if leader {
                both(Quantity::Orientation, 1.0)
            } else {
                None
            },
            scale_rel: if leader {
                both(Quantity::Scale, z_star)
            } else {
                None
            },
            translation: both(Quantity::Translation, 1.0),
        }
    }
}

impl SteadyReport {
    /// The run's settle time: the latest of the judged quantities' (`None` if one never
    /// settled).
    pub fn settle_time(&self, model: &Model) -> Option<f64> {
        let mut t: f64 = 0.0;
        for (k, s) in self.settle.iter().enumerate() {
            if k == 1 && model.leader.is_none() {
                continue;
            }
            t = t.max((*s)?);
        }
        Some(t)
    }

    /// Whether every judged quantity settled by the start of the window: `Ok(why)` or
    /// `Err(what did not)`.
    fn held(&self, model: &Model) -> Result<String, String> {
        let w = &self.window;
        let b = &self.bands;
        let band = [b.angle, b.scale, b.velocity];
        let cal = b.calibration.as_ref();
        let cal_x = [
            cal.map(|c| c.angle),
            cal.map(|c| c.scale),
            cal.map(|c| c.velocity),
        ];
        let caps = [b.angle, b.scale, b.velocity];
        let mut ok = Vec::new();
        let mut missing = Vec::new();
        for (k, (_, name, unit)) in JUDGED.iter().enumerate() {
            if k == 1 && model.leader.is_none() {
                continue;
            }
            let how = match (b.capped[k], cal_x[k]) {
                (true, _) => format!("the cap {:.4} {unit}", caps[k]),
                (false, Some(x)) => format!(
                    "calibrated: {x:.3e} {unit} at the target under the same sensing × {}",
                    super::bands::MARGIN
                ),
                (false, None) => "the noise-free tolerance".to_owned(),
            };
            let p = self.p95[k].map_or("—".to_owned(), |p| format!("{p:.3e}"));
            match self.settle[k] {
                Some(s) if s <= w.from => ok.push(format!(
                    "{name} p95 {p} ≤ band {:.3e} {unit} ({how}) from t = {s:.2} s",
                    band[k]
                )),
                s => missing.push(format!(
                    "{name} p95 {p} {unit} against a band of {:.3e} {unit} ({how}){}",
                    band[k],
                    s.map_or_else(
                        || ", still outside it at the end".to_owned(),
                        |s| format!(", inside it only from t = {s:.2} s")
                    )
                )),
            }
        }
        let span = format!(
            "the steady window [{:.2}, {:.2}] s (95 % of every {:.2} s sub-window)",
            w.from, w.to, w.sub
        );
        if missing.is_empty() {
            Ok(format!("held over {span}: {}", ok.join("; ")))
        } else {
            Err(format!("not held over {span}: {}", missing.join("; ")))
        }
    }
}

/// `Some(reason)` when more than `criteria.safe_share` of the outputs in the steady window
/// were the safe output: the share, the causes by count, and the first agents with theirs.
fn not_in_control(model: &Model, control: &WindowCounts, w: &Window) -> Option<String> {
    let safe = control.safe.total();
    if control.ticks == 0 {
        return None;
    }
    let share = safe as f64 / control.ticks as f64;
    if share <= model.criteria.safe_share {
        return None;
    }
    let mut kinds: Vec<(u64, &str)> = (0..FAULT_KINDS)
        .filter(|&k| control.safe.counts[k] > 0)
        .map(|k| (control.safe.counts[k], kind_words(model, k)))
        .collect();
    kinds.sort_by_key(|k| std::cmp::Reverse(k.0));
    let causes: Vec<String> = kinds
        .iter()
        .map(|(c, w)| format!("{w} ({c} outputs)"))
        .collect();
    let agents: Vec<String> = control
        .safe
        .examples
        .iter()
        .flatten()
        .map(|&(i, f)| format!("agent {} ({})", name(model, i), fault_words(model, f)))
        .collect();
    let more = if agents.len() == super::control::FAULT_EXAMPLES {
        ", …"
    } else {
        ""
    };
    Some(format!(
        "the agents were not in control: {:.1} % of the controllers' outputs in the steady window [{:.2}, {:.2}] s were the safe output ({safe} of {}; at most {} % allowed): {}; first: {}{more}",
        100.0 * share,
        w.from,
        w.to,
        control.ticks,
        100.0 * model.criteria.safe_share,
        causes.join(", "),
        agents.join(", ")
    ))
}

fn name(model: &Model, i: usize) -> &str {
    model.agents.get(i).map_or("?", |a| a.name.as_str())
}

/// The user's id of the agent with wire id `id`.
fn by_wire_id(model: &Model, id: u8) -> String {
    model
        .agents
        .iter()
        .find(|a| a.id == id)
        .map_or_else(|| format!("wire id {id}"), |a| a.name.clone())
}

/// A fault kind in words, naming the sensor that caused it.
fn kind_words(model: &Model, k: usize) -> &'static str {
    let se = &model.sensors;
    match k {
        1 if se.camera.is_some() => {
            "bearings missing: neighbours not seen by the camera (field of view, range, occlusion or detection)"
        }
        1 if se.positions.is_some() => "bearings missing: neighbours' positions stale or never heard",
        1 => "bearings missing",
        2 => "a neighbour silent: no frame within the timeout (loss, or an overloaded channel)",
        _ => FAULT_SAMPLES
            .get(k)
            .map_or("unknown", |f| fault_kind(f).1),
    }
}

/// One agent's fault in words, with the user's ids.
fn fault_words(model: &Model, f: Fault) -> String {
    match f {
        Fault::MissingBearing(id) => format!("no bearing to agent {}", by_wire_id(model, id)),
        Fault::Stale(id) => format!("agent {} not heard", by_wire_id(model, id)),
        Fault::MissingData(id) => format!("agent {}'s frames lack data", by_wire_id(model, id)),
        Fault::MissingRange(id) => format!("no range to agent {}", by_wire_id(model, id)),
        other => other.to_string(),
    }
}
