//! Figures and claims of README.md and docs/*.md that the code produces, read back from
//! the docs and compared with a run, a constant or a closed form (issue 40 item 5):
//! * README.md: the paper run ("every angle error below 1e-3 rad from t ≈ X s, … |z − z*|
//!   ≈ A m and |v − v*| ≈ B m/s", the number of plots), the exit codes it lists, the
//!   agent's RAM (`PH_AGENT_SIZE` of the header's Cortex-M branch), the wire constants,
//!   the sensor sweeps' ranges (against docs/sensors.md's tables);
//! * docs/outputs.md: the exit code of every outcome, the paper run's replay size;
//! * docs/spec.md §9: the built-in `paper` and `paper-printed` scenario files;
//! * docs/sensors.md: the camera table (every row run, seed 1, 100 s), the "Result";
//! * docs/sweeps.md, sensors.md, world.md: every 95 % interval (Wilson, closed form);
//! * crazyflie-app/README.md: what the controller does with the bearings it is given
//!   (the exported blobs' bearing filter: the tracker).
//!
//! Elsewhere: docs/outputs.md's reference figures, the README's and scenarios.md's
//! `paper-printed` in `scenarios.rs`; sensors.md's noise-free tracker in `sensors.rs`;
//! radio.md's tables in `channel.rs`; attacks.md's in `attacks.rs`; crazyflie.md's
//! channel figures in `shared_positions.rs`; world.md's cascade in `world.rs` and its
//! step responses in `vehicle_step.rs`; design.md's N = 10 rows in `design_cli.rs`.

#[path = "support/docs.rs"]
mod docs;

use ph_formation_sim::{load, Outcome, Simulation};
use std::path::Path;

fn readme() -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md");
    std::fs::read_to_string(path).expect("README.md")
}

/// The number written after `before` (up to `after`), e.g. `t ≈ ` … ` s`.
fn figure(text: &str, before: &str, after: &str) -> f64 {
    let flat = text.split_whitespace().collect::<Vec<_>>().join(" ");
    let start = flat
        .find(before)
        .unwrap_or_else(|| panic!("README: no `{before}`"))
        + before.len();
    let rest = &flat[start..];
    rest[..rest.find(after).expect("end")]
        .trim()
        .parse()
        .expect("a number")
}

/// `x` rounds to `shown` at `shown`'s precision (one significant digit for `2e-5`).
fn rounds_to(x: f64, shown: f64, digits: i32) -> bool {
    let scale = 10f64.powi(shown.abs().log10().floor() as i32 - digits + 1);
    ((x / scale).round() * scale - shown).abs() < 1e-9 * shown.abs()
}

#[test]
fn the_readme_figures_of_the_paper_run_are_true() {
    let text = readme();
    let words = [
        "one", "two", "three", "four", "five", "six", "seven", "eight", "nine",
    ];
    let flat = text.split_whitespace().collect::<Vec<_>>().join(" ");
    let plots = words
        .iter()
        .position(|w| flat.contains(&format!("`summary.json`, {w} plots (PNG and SVG)")))
        .map(|k| k + 1)
        .expect("README: `summary.json`, N plots (PNG and SVG)");
    let settle = figure(&text, "every angle error below 1e-3 rad from t ≈", " s");
    let z = figure(&text, "|z − z*| ≈", " m");
    let v = figure(&text, "|v − v*| ≈", " m/s");

    let model = ph_formation_sim::load("paper", &[]).expect("paper");
    let dir = tempfile::tempdir().expect("tempdir");
    let run = ph_formation_sim::Simulation::new(&model)
        .keep_series(false)
        .write_to(dir.path(), ph_formation_sim::WriteOptions::default())
        .run()
        .expect("run");
    let r = &run.result;
    let pngs = run
        .files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "png"))
        .count();
    assert_eq!(pngs, plots, "README says {plots} plots");
    assert!(dir.path().join("replay.html").is_file());
    // docs/outputs.md: "`host-sim run paper`: 0.46 MB" (10⁶ bytes).
    let outputs = docs::read("docs/outputs.md");
    let mb = docs::between(&outputs, "`host-sim run paper`:", " MB;");
    let bytes = std::fs::metadata(dir.path().join("replay.html"))
        .expect("replay")
        .len();
    assert!(
        docs::shows(bytes as f64 / 1e6, &mb),
        "replay.html: {bytes} bytes, docs/outputs.md {mb} MB"
    );
    let got = r.settle_time.expect("settles");
    assert!(
        rounds_to(got, settle, 4),
        "settle time {got} s, README {settle} s"
    );
    let summary = run.summary_json(&model);
    let dz = summary["final_displacement_error"].as_f64().expect("dz");
    let dv = summary["final_velocity_error"].as_f64().expect("dv");
    assert!(rounds_to(dz, z, 1), "|z − z*| {dz}, README {z}");
    assert!(rounds_to(dv, v, 1), "|v − v*| {dv}, README {v}");
}

/// `docs::shows` prints a value at the doc's precision (its negative control: a value
/// that rounds otherwise is refused).
#[test]
fn a_figure_shows_at_the_docs_precision() {
    assert!(docs::shows(40.85, "40.85") && !docs::shows(40.86, "40.85"));
    assert!(docs::shows(5.462e-7, "5.5e-7") && !docs::shows(5.3e-7, "5.5e-7"));
    assert!(docs::shows(0.0, "0") && !docs::shows(0.3, "0"));
}

/// The outcome named by `words` (`"not converged"`, `` "`not_converged`" ``).
fn outcome_named(words: &str) -> Option<Outcome> {
    let name = words.trim().trim_matches('`').replace(' ', "_");
    Outcome::ALL.iter().copied().find(|o| o.as_str() == name)
}

#[test]
fn the_exit_codes_of_the_readme_and_outputs_md_are_the_outcomes() {
    // README.md: "the exit code names the outcome (0 converged, 10 not converged, …; 2x".
    let readme = docs::read("README.md");
    let list = docs::between(&readme, "the exit code names the outcome (", "; 2x");
    let mut named = Vec::new();
    for item in list.split(", ") {
        let (code, words) = item.split_once(' ').expect("CODE outcome");
        let o = outcome_named(words).unwrap_or_else(|| panic!("README: {words:?}"));
        assert_eq!(
            code.parse::<u8>().ok(),
            Some(o.exit_code()),
            "README: {item}"
        );
        named.push(o);
    }
    // docs/outputs.md's table: `| 10 | `not_converged` |`.
    let outputs = docs::read("docs/outputs.md");
    let rows = docs::table_after(&outputs, "## Exit codes");
    for o in Outcome::ALL {
        assert!(
            named.contains(o),
            "README names no exit code for {}",
            o.as_str()
        );
        let row = rows
            .iter()
            .find(|r| {
                r[1].split_whitespace()
                    .next()
                    .and_then(|w| outcome_named(w.trim_end_matches(':')))
                    == Some(*o)
            })
            .unwrap_or_else(|| panic!("docs/outputs.md: no exit code row for {}", o.as_str()));
        assert_eq!(row[0].parse::<u8>().ok(), Some(o.exit_code()), "{row:?}");
    }
}

#[test]
fn the_readme_states_the_headers_agent_size() {
    let readme = docs::read("README.md");
    let stated = docs::number(&readme, "`PH_AGENT_SIZE` =", "bytes on Cortex-M");
    let header = docs::read("controller-ffi/include/ph_formation.h");
    let branch = &header[header.find("#if defined(PH_PTR32)").expect("32-bit branch")..];
    let size = docs::number(branch, "#define PH_AGENT_SIZE", "#endif");
    assert_eq!(stated, size, "README.md against ph_formation.h");
}

/// crazyflie-app/README.md: the app leaves `rate` and `range` unset and "the controller's
/// bearing tracker (SPEC §11, σ_b = 2°: the exported blobs', …)" estimates the rates: every
/// exported blob carries the tracker with that σ_b.
#[test]
fn the_crazyflie_apps_blobs_track_bearings() {
    let readme = docs::read("crazyflie-app/README.md");
    let sigma = docs::number(
        &readme,
        "the controller's bearing tracker (SPEC §11, σ_b =",
        "°",
    );
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../crazyflie-app/src/blobs");
    let mut blobs = 0;
    for entry in std::fs::read_dir(&dir).expect("blobs") {
        let path = entry.expect("entry").path();
        if path.extension().is_some_and(|e| e == "blob") {
            let bytes = std::fs::read(&path).expect("blob");
            let config = ph_formation_ffi::blob::decode_blob(&bytes).expect("a valid blob");
            match config.bearing_filter {
                ph_formation_core::BearingFilter::Tracker(t) => {
                    let deg = f64::from(t.bearing_noise).to_degrees();
                    assert!((deg - sigma).abs() < 1e-5, "{}: σ_b {deg}°", path.display());
                }
                other => panic!("{}: {other:?}", path.display()),
            }
            blobs += 1;
        }
    }
    assert_eq!(blobs, 4);
}

/// docs/sensors.md's camera table: every row is one run of `formation-only` (seed 1,
/// 100 s) with the row's `KEY = VALUE` settings (a key without a dot is a
/// `sensors.camera` key); its outcome, settle time (where the row shows one) and safe
/// agent-ticks are the run's. The all-defaults camera gives the camera-less run's bits.
#[test]
fn the_camera_table_of_sensors_md_is_measured() {
    let doc = docs::read("docs/sensors.md");
    let total = docs::number(&doc, "in the safe output after the start, of", "(4 agents");
    let plain = Simulation::new(&load("formation-only", &[]).expect("formation-only"))
        .run()
        .expect("run")
        .result;
    // 4 agents, a tick every 10 ms over 100 s and one at t = 0.
    assert_eq!(total, 4.0 * (100.0 * 100.0 + 1.0));
    assert_eq!(plain.control.ticks as f64, total);
    let rows = docs::table_after(&doc, "| camera | outcome | settle (s) | safe |");
    assert!(rows.len() >= 10, "{rows:?}");
    for row in rows {
        let overrides: Vec<String> = row[0]
            .split('`')
            .skip(1)
            .step_by(2)
            .filter_map(|kv| kv.split_once(" = "))
            .map(|(k, v)| {
                let key = if k.contains('.') {
                    k.to_owned()
                } else {
                    format!("sensors.camera.{k}")
                };
                format!("{key}={v}")
            })
            .collect();
        assert!(!overrides.is_empty(), "{row:?}");
        let m = load("formation-only", &overrides).unwrap_or_else(|e| panic!("{row:?}: {e}"));
        let r = Simulation::new(&m).run().expect("run").result;
        let outcome = row[1].split_whitespace().next().unwrap_or_default();
        assert_eq!(outcome, r.outcome.as_str(), "{row:?}: {}", r.reason);
        if let Some(settle) = docs::parse(&row[2]) {
            let got = r.settle_time.unwrap_or(f64::NAN);
            assert!(docs::shows(got, &row[2]), "{row:?}: settle {got} s");
            assert!(settle > 0.0);
        }
        let safe = docs::parse(&row[3]).expect("safe agent-ticks");
        assert_eq!(r.control.safe_after_start as f64, safe, "{row:?}");
        if row[1].contains("bits of the camera-less run") {
            assert_eq!(r.final_positions, plain.final_positions, "{row:?}");
            assert_eq!(r.final_velocities, plain.final_velocities, "{row:?}");
        }
    }
}

/// One row of docs/sensors.md's tolerance tables: formation, noise (°), loss (%),
/// converged of 100, largest final angle error (°).
type ToleranceRow = (String, f64, f64, f64, f64);

/// The rows of every table of docs/sensors.md's "What the formations tolerate".
fn tolerance_rows(doc: &str) -> Vec<ToleranceRow> {
    let start = doc
        .find("## What the formations tolerate")
        .expect("section");
    let end = doc
        .find("### The honest verdict's camera check")
        .expect("end");
    let mut rows = Vec::new();
    let mut formation = String::new();
    for line in doc[start..end].lines() {
        if let Some(h) = line.strip_prefix("### ") {
            formation = h.to_owned();
        }
        let c = docs::cells(line);
        if line.starts_with("| ") && c.len() == 6 && c[0].ends_with('°') {
            let num = |s: &str| docs::parse(s.split(['°', '%', '/']).next().unwrap_or(s));
            let (Some(noise), Some(loss), Some(runs), Some(conv)) =
                (num(&c[0]), num(&c[1]), num(&c[2]), num(&c[3]))
            else {
                panic!("{line}")
            };
            assert_eq!(runs, 100.0, "{line}");
            let largest = docs::parse(c[5].split('/').nth(1).expect("median / max"));
            rows.push((formation.clone(), noise, loss, conv, largest.expect("max")));
        }
    }
    rows
}

/// README.md and docs/sensors.md's "Result" say what the sweep tables of
/// docs/sensors.md show (the tables are the sweeps' output, each under its command).
#[test]
fn the_tolerance_claims_are_the_sweep_tables() {
    let doc = docs::read("docs/sensors.md");
    let rows = tolerance_rows(&doc);
    assert!(rows.len() >= 50, "{} rows", rows.len());
    let noisy = |paper: bool| -> Vec<&ToleranceRow> {
        rows.iter()
            .filter(|r| r.1 >= 0.5 && (r.0 == "`paper`") == paper)
            .collect()
    };
    let range = |rs: &[&ToleranceRow]| {
        let lo = rs.iter().map(|r| r.3).fold(f64::INFINITY, f64::min);
        let hi = rs.iter().map(|r| r.3).fold(0.0, f64::max);
        format!("{lo}–{hi}")
    };
    let (others, paper) = (range(&noisy(false)), range(&noisy(true)));
    let readme = docs::read("README.md");
    let said = docs::between(&readme, "lattices converged in", " of 100 runs and `paper`");
    assert_eq!(said, others, "README.md");
    let said = docs::between(&readme, "of 100 runs and `paper` in", " (its long");
    assert_eq!(said, paper, "README.md");
    let result = docs::between(&doc, "**Result**", "issue 30's table");
    let said = docs::between(&result, "lattices converged in", " of 100 runs");
    assert_eq!(said, others, "docs/sensors.md Result");
    let at = |noise: f64| {
        rows.iter()
            .find(|r| r.0 == "`paper`" && r.1 == noise && r.2 == 10.0)
            .expect("paper row")
            .3
    };
    let two = docs::number(&result, "`paper` converged in", " of 100 at 2°");
    let five = docs::number(&result, "with 10 % loss and in", " at 5°");
    assert_eq!((two, five), (at(2.0), at(5.0)), "docs/sensors.md Result");
    let worst = rows.iter().map(|r| r.4).fold(0.0, f64::max);
    let worst_2 = rows
        .iter()
        .filter(|r| r.1 <= 2.0)
        .map(|r| r.4)
        .fold(0.0, f64::max);
    assert_eq!(
        docs::number(&result, "largest final angle error was", "°"),
        worst
    );
    assert_eq!(docs::number(&result, "at most", "° at 2°"), worst_2);
}

/// README.md: "one frame of at most 60 bytes per tick (wire version 4" are the core's
/// constants.
#[test]
fn the_readme_states_the_wire_constants() {
    let readme = docs::read("README.md");
    let len = docs::number(
        &readme,
        "one frame of at most",
        " bytes per tick (wire version",
    );
    let version = docs::number(&readme, "bytes per tick (wire version", ", postcard");
    assert_eq!(len, ph_formation_core::wire::MAX_FRAME_LEN as f64);
    assert_eq!(version, f64::from(ph_formation_core::wire::WIRE_VERSION));
}

/// `scenarios/NAME.toml` (the built-ins' text) as a TOML value.
fn scenario(name: &str) -> toml::Value {
    let text = docs::read(&format!("host-sim/scenarios/{name}.toml"));
    toml::from_str(&text).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// A number or an array of numbers of a TOML value at `path` (`"leader.displacement"`).
fn numbers(v: &toml::Value, path: &str) -> Vec<f64> {
    let mut at = v;
    for key in path.split('.') {
        at = at.get(key).unwrap_or_else(|| panic!("no {path}"));
    }
    let one = |x: &toml::Value| x.as_float().or(x.as_integer().map(|i| i as f64));
    match at.as_array() {
        Some(a) => a.iter().map(|x| one(x).expect("number")).collect(),
        None => vec![one(at).expect("number")],
    }
}

/// The numbers of a spec expression such as `(0.9, 2.2)`, `1.8 I` or `(10, −10)`.
fn spec_numbers(s: &str) -> Vec<f64> {
    s.replace('−', "-")
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .filter_map(|w| w.parse().ok())
        .collect()
}

/// SPEC §9 (the reference scenario) is the built-in `paper` and `paper-printed`:
/// initial positions, desired angles, leader, v*, the paper's and our constants, and
/// both sets of gains.
#[test]
fn spec_section_9_is_the_built_in_paper() {
    let spec = docs::read("docs/spec.md");
    let s9 = docs::between(&spec, "## 9. Reference scenario", "## 10. Errata");
    let paper = scenario("paper");
    let agents = paper["agents"].as_array().expect("agents");
    for (i, agent) in agents.iter().enumerate() {
        let stated = spec_numbers(&docs::between(&s9, &format!("q{} = (", i + 1), ")"));
        assert_eq!(stated, numbers(agent, "position"), "q{}", i + 1);
    }
    let says = |before: &str, after: &str| spec_numbers(&docs::between(&s9, before, after));
    assert_eq!(
        says("z* = q1 − q2 = (", ")"),
        numbers(&paper, "leader.displacement")
    );
    assert_eq!(says("`v* = (", ")`"), numbers(&paper, "velocity_reference"));
    assert_eq!(says("`m =", "`"), numbers(&paper, "agent_defaults.mass"));
    assert_eq!(says("`k_z =", "`"), numbers(&paper, "leader.stiffness"));
    assert_eq!(says("`D_z =", " I`"), numbers(&paper, "leader.damping"));
    assert_eq!(
        says("`D^v =", " I`"),
        numbers(&paper, "agent_defaults.velocity_damping")
    );
    assert_eq!(
        says("`D^r =", " I`"),
        numbers(&paper, "agent_defaults.friction")
    );
    assert_eq!(
        says("`r̂(0) =", "`"),
        numbers(&paper, "controller.initial_estimate")
    );
    assert_eq!(
        says("`r_min =", "`"),
        numbers(&paper, "controller.min_estimate")
    );
    // The angle table: apex and desired (π/2, π/4) per triangle, in the file's order.
    let mut table = Vec::new();
    for line in spec
        .lines()
        .filter(|l| l.starts_with("| θ") || l.starts_with("| φ"))
    {
        let c = docs::cells(line);
        let apex: f64 = c[2].trim_start_matches("agent ").parse().expect("apex");
        let desired = match c[3].as_str() {
            "π/2" => 90.0,
            "π/4" => 45.0,
            other => panic!("desired {other}"),
        };
        table.push((apex, desired));
    }
    let file: Vec<(f64, f64)> = paper["triangles"]
        .as_array()
        .expect("triangles")
        .iter()
        .flat_map(|t| t["angles"].as_array().expect("angles").clone())
        .map(|a| (numbers(&a, "apex")[0], numbers(&a, "desired_deg")[0]))
        .collect();
    assert_eq!(table, file);
    for (name, before) in [
        ("paper", "(the default): `c ="),
        ("paper-printed", "printed in the paper, `c ="),
    ] {
        let stated = spec_numbers(&docs::between(&s9, before, "`. It"));
        let v = scenario(name);
        let gains = [
            numbers(&v, "gains.stiffness")[0],
            numbers(&v, "gains.damping")[0],
            numbers(&v, "gains.estimator_gain")[0],
        ];
        assert_eq!(stated, gains, "{name}");
    }
}

/// The 95 % Wilson score interval of `k` successes in `n` runs, in percent.
fn wilson(k: f64, n: f64) -> (f64, f64) {
    let z = 1.959_963_985;
    let p = k / n;
    let d = 1.0 + z * z / n;
    let centre = (p + z * z / (2.0 * n)) / d;
    let half = z * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt() / d;
    (100.0 * (centre - half), 100.0 * (centre + half))
}

/// Every "P [L, H]" (docs/sweeps.md, world.md) and "P % (L–H %)" (docs/sensors.md) of a sweep
/// table is a share of the row's runs with its 95 % Wilson interval, computed here in
/// closed form (independently of `host-sim`'s statistics) and rounded to whole percent.
#[test]
fn the_sweep_tables_intervals_are_wilson_intervals() {
    let mut checked = 0;
    for path in ["docs/sweeps.md", "docs/sensors.md", "docs/world.md"] {
        let doc = docs::read(path);
        let mut runs_col = None;
        for line in doc.lines().filter(|l| l.starts_with('|')) {
            let c = docs::cells(line);
            if let Some(i) = c.iter().position(|h| h == "runs") {
                runs_col = Some(i);
                continue;
            }
            let Some(n) = runs_col.and_then(|i| c.get(i)).and_then(|s| docs::parse(s)) else {
                continue;
            };
            for cell in &c {
                let parts: Vec<f64> = cell
                    .split(|ch: char| !(ch.is_ascii_digit() || ch == '.'))
                    .filter_map(|w| w.parse().ok())
                    .collect();
                let shaped = (cell.contains(" [") && cell.ends_with(']'))
                    || (cell.contains(" % (") && cell.ends_with(" %)"));
                if !shaped || parts.len() != 3 {
                    continue;
                }
                // The share is rounded to whole percent: the count is the nearest one.
                let (lo, hi) = wilson((parts[0] / 100.0 * n).round(), n);
                assert_eq!(
                    (parts[1], parts[2]),
                    (lo.round(), hi.round()),
                    "{path}: {cell} of {n} runs in {line}"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 100, "{checked} intervals");
}

/// README.md's "equations cited as `S1`…`SN` and sections as `SPEC §1`…`§M`" are the
/// last equation and section of docs/spec.md.
#[test]
fn the_readme_cites_the_whole_spec() {
    let spec = docs::read("docs/spec.md");
    let last_section = spec
        .lines()
        .filter_map(|l| l.strip_prefix("## "))
        .filter_map(|h| h.split('.').next()?.parse::<u32>().ok())
        .max()
        .expect("numbered sections");
    let last_equation = spec
        .split(|c: char| !c.is_ascii_alphanumeric())
        .filter_map(|w| w.strip_prefix('S')?.parse::<u32>().ok())
        .max()
        .expect("equations");
    let readme = docs::read("README.md");
    let eq = docs::number(&readme, "equations cited as `S1`…`S", "` and sections");
    let sec = docs::number(&readme, "sections as `SPEC §1`…`§", "` throughout");
    assert_eq!(
        (eq, sec),
        (f64::from(last_equation), f64::from(last_section))
    );
}

/// README.md's `list` line and docs/scenarios.md's table name the built-in scenarios,
/// in order, and each built-in is the file `host-sim/scenarios/NAME.toml`.
#[test]
fn the_built_ins_are_the_ones_the_docs_name() {
    let names: Vec<&str> = ph_formation_sim::BUILTINS.iter().map(|b| b.name).collect();
    let readme = docs::read("README.md");
    let said = docs::between(&readme, "-- list #", " cargo");
    assert_eq!(said, names.join(", "), "README.md");
    let table = docs::read("docs/scenarios.md");
    for b in ph_formation_sim::BUILTINS {
        docs::row(&table, &format!("`{}`", b.name));
        assert_eq!(
            b.text,
            docs::read(&format!("host-sim/scenarios/{}.toml", b.name))
        );
    }
}
