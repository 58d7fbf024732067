//! The per-point results as a Markdown table (printed by `host-sim sweep`, pasted into
//! `docs/sweeps.md`): axis values, runs, each outcome that happened as a percentage with
//! its 95 % interval, and the settle-time quantiles.

use super::aggregate::PointStats;
use super::output::Manifest;
use std::fmt::Write as _;

fn pct(x: f64) -> String {
    if x.is_finite() {
        format!("{:.0}", 100.0 * x)
    } else {
        "–".to_owned()
    }
}

fn secs(x: Option<f64>) -> String {
    x.map_or("–".to_owned(), |t| format!("{t:.1}"))
}

/// The table (one row per point).
pub fn markdown(m: &Manifest, stats: &[PointStats]) -> String {
    let seen: Vec<usize> = (0..m.outcomes.len())
        .filter(|&o| stats.iter().any(|s| s.fractions[o].count > 0))
        .collect();
    let mut head: Vec<String> = m.axes.iter().map(|a| format!("`{a}`")).collect();
    head.push("runs".to_owned());
    head.extend(
        seen.iter()
            .map(|&o| format!("{} % [95 % CI]", m.outcomes[o])),
    );
    head.push("settle p10 / p50 / p90 (s)".to_owned());
    let mut out = String::new();
    let _ = writeln!(out, "| {} |", head.join(" | "));
    let _ = writeln!(out, "|{}", "---|".repeat(head.len()));
    for s in stats {
        let mut row: Vec<String> = m.points[s.point].clone();
        row.push(if s.errors > 0 {
            format!("{} (+{} errors)", s.n, s.errors)
        } else {
            s.n.to_string()
        });
        for &o in &seen {
            let f = &s.fractions[o];
            row.push(format!(
                "{} [{}, {}]",
                pct(f.fraction),
                pct(f.lo),
                pct(f.hi)
            ));
        }
        row.push(format!(
            "{} / {} / {}",
            secs(s.settle[0]),
            secs(s.settle[1]),
            secs(s.settle[2])
        ));
        let _ = writeln!(out, "| {} |", row.join(" | "));
    }
    out
}
