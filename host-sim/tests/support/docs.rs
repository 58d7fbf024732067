//! Reading figures back from README.md and docs/*.md, so that a test compares what the
//! docs say with a run or a constant (issue 40 item 5). Used through
//! `#[path = "support/docs.rs"] mod docs;`.
//!
//! A figure matches when the value, printed at the precision the doc shows it with, is
//! the doc's text: the runs are deterministic (same scenario and seed, same bits, in
//! debug and release), so the doc's rounding is the only tolerance.
#![allow(dead_code)] // each test file uses a part

use std::path::Path;

/// A file of the repository, by its path from the root (`"docs/outputs.md"`).
pub fn read(path: &str) -> String {
    let full = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(path);
    std::fs::read_to_string(&full).unwrap_or_else(|e| panic!("read {path}: {e}"))
}

/// `text` with every run of whitespace (line breaks too) made one space.
pub fn flat(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

/// The text of `doc` (flattened) between the first `before` and the next `until`.
pub fn between(doc: &str, before: &str, until: &str) -> String {
    let flat = flat(doc);
    let start = flat
        .find(before)
        .unwrap_or_else(|| panic!("no {before:?} in the doc"))
        + before.len();
    let rest = &flat[start..];
    let end = rest
        .find(until)
        .unwrap_or_else(|| panic!("no {until:?} after {before:?}"));
    rest[..end].trim().to_owned()
}

/// The number of `doc` between `before` and `until` (thousands separators `,` and
/// spaces allowed).
pub fn number(doc: &str, before: &str, until: &str) -> f64 {
    let s = between(doc, before, until);
    parse(&s).unwrap_or_else(|| panic!("{before:?} … {until:?}: {s:?} is no number"))
}

/// `"40,004"`, `"3 716"`, `"5.5e-7"` → the number.
pub fn parse(s: &str) -> Option<f64> {
    s.trim().replace([',', ' '], "").parse().ok()
}

/// The cells of the first table row of `text` whose first cell starts with `first`
/// (trimmed; the row's outer pipes dropped).
pub fn row(text: &str, first: &str) -> Vec<String> {
    let line = text
        .lines()
        .filter(|l| l.starts_with('|'))
        .find(|l| l[1..].trim_start().starts_with(first))
        .unwrap_or_else(|| panic!("no table row starting with {first:?}"));
    cells(line)
}

/// The cells of one table row.
pub fn cells(line: &str) -> Vec<String> {
    let inner = line.trim().trim_start_matches('|').trim_end_matches('|');
    // `\|` is a pipe inside a cell.
    inner
        .replace("\\|", "\u{1}")
        .split('|')
        .map(|c| c.trim().replace('\u{1}', "|"))
        .collect()
}

/// The body rows (after the `|---|` line) of the first table after `heading` in `doc`.
pub fn table_after(doc: &str, heading: &str) -> Vec<Vec<String>> {
    let start = doc
        .find(heading)
        .unwrap_or_else(|| panic!("no {heading:?}"));
    doc[start..]
        .lines()
        .skip_while(|l| !l.starts_with("|---"))
        .skip(1)
        .take_while(|l| l.starts_with('|'))
        .map(cells)
        .collect()
}

/// Whether `value`, printed like `shown` (the same number of decimals, in the same
/// notation), is `shown`: `shows(40.8499, "40.85")`, `shows(5.46e-7, "5.5e-7")`. A bare
/// `"0"` means exactly zero.
pub fn shows(value: f64, shown: &str) -> bool {
    let shown = shown.trim();
    if shown == "0" {
        return value == 0.0;
    }
    let decimals = |m: &str| m.split_once('.').map_or(0, |(_, d)| d.len());
    let printed = match shown.split_once('e') {
        Some((mantissa, _)) => format!("{:.*e}", decimals(mantissa), value),
        None => format!("{:.*}", decimals(shown), value),
    };
    printed == shown
}

/// Every `<number> s` in `text`, in order (times stated in seconds).
pub fn seconds(text: &str) -> Vec<f64> {
    let words: Vec<&str> = text.split_whitespace().collect();
    words
        .windows(2)
        .filter(|w| w[1].trim_end_matches([')', ',', ';', '.']) == "s")
        .filter_map(|w| parse(w[0]))
        .collect()
}
