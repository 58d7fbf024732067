//! The lines `firmware-check` reads: the firmware's `FWCHECK …` lines (decoded defmt
//! logs, see `firmware-example/src/bin/measure.rs`) and the plugin's `qemu-insn …` lines.

use regex::Regex;
use std::collections::BTreeMap;
use std::sync::OnceLock;

fn re(cell: &'static OnceLock<Regex>, pattern: &str) -> &'static Regex {
    // The patterns are constants of this file, checked by the unit tests.
    cell.get_or_init(|| Regex::new(pattern).unwrap_or_else(|e| panic!("{pattern}: {e}")))
}

/// The last `FWCHECK stack peak_bytes=<n>` of a log.
pub fn stack_peak(log: &str) -> Option<u64> {
    static RE: OnceLock<Regex> = OnceLock::new();
    re(&RE, r"FWCHECK stack peak_bytes=([0-9]+)")
        .captures_iter(log)
        .last()
        .and_then(|c| c[1].parse().ok())
}

/// One measured region announced by `measure`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Region {
    /// Region id (the marker slot).
    pub id: u32,
    /// `tri2`, `tri2-rx`, `overhead`, …
    pub name: String,
    /// Triangles of the configuration.
    pub triangles: u32,
    /// How often the region runs.
    pub repeats: usize,
}

/// `FWCHECK region id=<id> name=<name> triangles=<n> repeats=<r>` lines, in order.
pub fn regions(log: &str) -> Vec<Region> {
    static RE: OnceLock<Regex> = OnceLock::new();
    re(
        &RE,
        r"FWCHECK region id=([0-9]+) name=([A-Za-z0-9_-]+) triangles=([0-9]+) repeats=([0-9]+)",
    )
    .captures_iter(log)
    .filter_map(|c| {
        Some(Region {
            id: c[1].parse().ok()?,
            name: c[2].to_owned(),
            triangles: c[3].parse().ok()?,
            repeats: c[4].parse().ok()?,
        })
    })
    .collect()
}

/// Field `field` of the first `FWCHECK bench name=<config> …` line, e.g. `rx_frames`.
pub fn bench_field(log: &str, config: &str, field: &str) -> Option<String> {
    let prefix = format!("FWCHECK bench name={config} ");
    let line = log.lines().find_map(|l| l.find(&prefix).map(|i| &l[i..]))?;
    let key = format!("{field}=");
    line.split_whitespace()
        .find_map(|w| w.strip_prefix(&key))
        .map(str::to_owned)
}

/// Every `FWCHECK error …` of a log (without the prefix).
pub fn errors(log: &str) -> Vec<String> {
    log.lines()
        .filter_map(|l| l.find("FWCHECK error").map(|i| l[i..].to_owned()))
        .collect()
}

/// The last line of `log` containing `tag`, from `tag` on.
pub fn last_with(log: &str, tag: &str) -> Option<String> {
    log.lines()
        .rev()
        .find_map(|l| l.find(tag).map(|i| l[i..].trim_end().to_owned()))
}

/// The plugin's counts: region id → instructions of each occurrence, in order.
pub fn insn_counts(plugin_out: &str) -> BTreeMap<u32, Vec<u64>> {
    static RE: OnceLock<Regex> = OnceLock::new();
    let re = re(
        &RE,
        r"(?m)^qemu-insn region=([0-9]+) seq=[0-9]+ insns=([0-9]+)$",
    );
    let mut out: BTreeMap<u32, Vec<u64>> = BTreeMap::new();
    for c in re.captures_iter(plugin_out) {
        if let (Ok(id), Ok(n)) = (c[1].parse(), c[2].parse()) {
            out.entry(id).or_default().push(n);
        }
    }
    out
}

/// The plugin's `qemu-insn error…` lines.
pub fn plugin_errors(plugin_out: &str) -> Vec<String> {
    plugin_out
        .lines()
        .filter(|l| l.starts_with("qemu-insn error"))
        .map(str::to_owned)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const MEASURE: &str = "\
FWCHECK region id=0 name=overhead triangles=0 repeats=3
FWCHECK region id=1 name=tri2 triangles=2 repeats=3
FWCHECK bench name=tri2 triangles=2 neighbours=3 rx_frames=3 rx_bytes=128 tx_frames=2 tx_bytes=105 force=1.5,-2
FWCHECK region id=2 name=tri2-step triangles=2 repeats=1
[INFO ] FWCHECK stack peak_bytes=100 size_bytes=9000
FWCHECK error tri8: not nominal
FWCHECK stack peak_bytes=11212 size_bytes=9000
FWCHECK done
";

    #[test]
    fn parses_the_measure_log() {
        assert_eq!(stack_peak(MEASURE), Some(11212));
        assert_eq!(stack_peak("nothing"), None);
        let r = regions(MEASURE);
        assert_eq!(r.len(), 3);
        assert_eq!(
            r[2],
            Region {
                id: 2,
                name: "tri2-step".into(),
                triangles: 2,
                repeats: 1
            }
        );
        assert_eq!(
            bench_field(MEASURE, "tri2", "rx_bytes").as_deref(),
            Some("128")
        );
        assert_eq!(
            bench_field(MEASURE, "tri2", "neighbours").as_deref(),
            Some("3")
        );
        assert_eq!(bench_field(MEASURE, "tri2", "nope"), None);
        assert_eq!(bench_field(MEASURE, "tri8", "rx_bytes"), None);
        assert_eq!(errors(MEASURE), ["FWCHECK error tri8: not nominal"]);
        assert_eq!(
            last_with(MEASURE, "FWCHECK done").as_deref(),
            Some("FWCHECK done")
        );
    }

    #[test]
    fn parses_the_plugin_output() {
        let out = "qemu-insn region=1 seq=0 insns=3527\nqemu-insn region=0 seq=0 insns=6\n\
                   qemu-insn region=1 seq=1 insns=3528\nqemu-insn error: region=4 never ended\n\
                   qemu-insn total=99 errors=1\n";
        let c = insn_counts(out);
        assert_eq!(c[&1], [3527, 3528]);
        assert_eq!(c[&0], [6]);
        assert!(!c.contains_key(&4));
        assert_eq!(
            plugin_errors(out),
            ["qemu-insn error: region=4 never ended"]
        );
    }
}
