//! Flights beside simulations (docs/crazyflie.md "Flights beside simulations"), on two
//! flight logs recorded once from `host-sim serve crazyflie-app/formation.toml --set
//! world=crazyflie --speed 2` and `crazyflie-app/tools/swarm.py` (`tests/flight/`):
//! `square_serve.csv`, the four drones of `swarm.py fly` from 0.5 s before the formation's
//! start to 4 s after it, and `step_serve.csv`, agent 1 through `swarm.py step --speed
//! 0.3` (both cut to those rows and rounded to 6 significant digits, nothing else).
//!
//! * `a_served_flight_is_held_against_its_run`: `host-sim compare` of the flight and a
//!   run of the same scenario: every agent within 15 cm RMS, the same largest angle error
//!   and convergence within a second, both in one replay page; the negative control, a
//!   run with the leader edge
//!   mirrored, is beyond (exit 1, every agent more than 0.5 m RMS).
//! * `a_flight_converts_like_a_run`: `host-sim flight` writes timeseries.csv, run.mcap and
//!   replay.html; the flight's angle errors at its first instant are the run's (the same
//!   positions, the simulator's one formula); the negative control swaps agents 1 and 4
//!   in the log, and they differ.
//! * `a_served_step_is_held_against_vehicle_step`: the step log against `host-sim
//!   vehicle step --speed 0.3` is within 3 cm/s; against the 0.6 m/s step it is not.
//! * `bad_flight_logs_are_named`: a missing agent, column or value, no formation start, an
//!   unknown reference and a step without `--speed` are refused naming file and reason.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/flight")
        .join(name)
}

/// Runs host-sim from the workspace root: (exit code, stdout, stderr).
fn host_sim(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .current_dir(root())
        .args(args)
        .output()
        .expect("run host-sim");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

const SQUARE: &str = "crazyflie-app/formation.toml";

/// `host-sim run` of the served scenario (with `extra` overrides) into `dir`.
fn run_square(dir: &Path, extra: &[&str]) {
    let mut args = vec!["-q", "run", SQUARE, "--set", "world=crazyflie"];
    args.extend_from_slice(extra);
    args.extend(["--duration", "5", "--no-plots", "--out", s(dir)]);
    let (code, _, err) = host_sim(&args);
    assert!(code == 0 || code == 10, "{err}");
}

fn compare_json(dir: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(dir.join("compare.json")).expect("compare.json");
    serde_json::from_str(&text).expect("compare.json is JSON")
}

fn compare_flight(run: &Path, flight: &Path, out: &Path, no_plots: bool) -> (i32, String) {
    let mut args = vec![
        "compare",
        s(run),
        s(flight),
        "--clock",
        "drone_ms",
        "--set",
        "world=crazyflie",
        "--settle-deg",
        "5",
        "--tolerance-m",
        "0.15",
        "--out",
        s(out),
    ];
    if no_plots {
        args.push("--no-plots");
    }
    let (code, said, err) = host_sim(&args);
    (code, format!("{said}{err}"))
}

fn rms_of(j: &serde_json::Value) -> Vec<f64> {
    j["agents"]
        .as_array()
        .expect("agents")
        .iter()
        .map(|a| a["rms_common_start_m"].as_f64().expect("rms"))
        .collect()
}

#[test]
fn a_served_flight_is_held_against_its_run() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let (run, out) = (tmp.path().join("run"), tmp.path().join("cmp"));
    run_square(&run, &[]);
    let (code, said) = compare_flight(&run, &fixture("square_serve.csv"), &out, false);
    println!("{said}");
    assert_eq!(code, 0, "{said}");
    assert!(said.contains("largest angle error: run"), "{said}");
    let j = compare_json(&out);
    let rms = rms_of(&j);
    assert_eq!(rms.len(), 4);
    assert!(rms.iter().all(|r| *r < 0.15), "{rms:?}");
    for a in j["agents"].as_array().expect("agents") {
        // Served drones start where the scenario puts them.
        assert!(a["start_offset_m"].as_f64().expect("offset") < 1e-3, "{a}");
    }
    let window = j["alignment"]["window_s"][1].as_f64().expect("window");
    assert!(window > 3.9, "{window}");
    let e = &j["angle_error_deg"];
    let (run_worst, flight_worst) = (e["run_worst"].as_f64(), e["flight_worst"].as_f64());
    assert!(
        (run_worst.expect("run") - flight_worst.expect("flight")).abs() < 0.1,
        "{e}"
    );
    let c = &j["convergence_s"];
    let (cr, cf) = (c["run"].as_f64(), c["flight"].as_f64());
    assert!(
        (cr.expect("run settles") - cf.expect("flight settles")).abs() < 1.0,
        "{c}"
    );
    assert_eq!(j["within_tolerance"], true);
    // docs/crazyflie.md quotes these figures.
    let doc = std::fs::read_to_string(root().join("docs/crazyflie.md")).expect("docs");
    let quoted = format!(
        "RMS {:.3}, {:.3}, {:.3}, {:.3} m for agents 1–4",
        rms[0], rms[1], rms[2], rms[3]
    );
    assert!(
        doc.contains(&quoted),
        "docs/crazyflie.md should say {quoted}"
    );
    for f in ["compare_positions.png", "compare_angles.png"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    // Both in one replay page: the run's agents and the flight's, the same instants.
    let page = std::fs::read_to_string(out.join("overlay/replay.html")).expect("overlay");
    assert!(
        page.contains(r#""ids":["1","2","3","4","flight-1","flight-2","flight-3","flight-4"]"#),
        "the overlay's ids"
    );
    let instants = j["alignment"]["instants"].as_u64().expect("instants");
    assert!(
        page.contains(&format!(r#""rows":{instants},"#)),
        "{instants} frames"
    );
    // The negative control: the run of the mirrored leader edge is another flight.
    let (bad, out_bad) = (tmp.path().join("bad"), tmp.path().join("cmp-bad"));
    run_square(&bad, &["--set", "leader.displacement=[-1.0,1.0]"]);
    let (code, said) = compare_flight(&bad, &fixture("square_serve.csv"), &out_bad, true);
    assert_eq!(code, 1, "{said}");
    assert!(said.contains("beyond 0.150 m"), "{said}");
    let rms = rms_of(&compare_json(&out_bad));
    assert!(rms.iter().all(|r| *r > 0.5), "{rms:?}");
}

/// The first data row of `dir/timeseries.csv`, by column name.
fn first_row(dir: &Path) -> Vec<(String, f64)> {
    let text = std::fs::read_to_string(dir.join("timeseries.csv")).expect("timeseries.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let row: Vec<f64> = lines
        .next()
        .expect("a row")
        .split(',')
        .map(|x| x.parse().expect("number"))
        .collect();
    header.iter().map(|h| (*h).to_owned()).zip(row).collect()
}

fn angle_errors(row: &[(String, f64)]) -> Vec<(String, f64)> {
    row.iter()
        .filter(|(h, _)| h.starts_with("angle_err_"))
        .cloned()
        .collect()
}

fn convert(flight: &Path, out: &Path) -> (i32, String) {
    let (code, said, err) = host_sim(&[
        "flight",
        s(flight),
        "--scenario",
        SQUARE,
        "--set",
        "world=crazyflie",
        "--clock",
        "drone_ms",
        "--mcap",
        "--out",
        s(out),
    ]);
    (code, format!("{said}{err}"))
}

#[test]
fn a_flight_converts_like_a_run() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let (run, out) = (tmp.path().join("run"), tmp.path().join("flight"));
    run_square(&run, &[]);
    let (code, said) = convert(&fixture("square_serve.csv"), &out);
    assert_eq!(code, 0, "{said}");
    for f in ["timeseries.csv", "summary.json", "replay.html", "run.mcap"] {
        assert!(out.join(f).is_file(), "{f}: {said}");
    }
    let mcap = std::fs::read(out.join("run.mcap")).expect("run.mcap");
    assert!(mcap.starts_with(b"\x89MCAP0\r\n"), "MCAP magic");
    let page = std::fs::read_to_string(out.join("replay.html")).expect("page");
    assert!(page.contains(r#""ids":["1","2","3","4"]"#));
    let (code, said, _) = host_sim(&["view", s(&out), "--no-open"]);
    assert_eq!((code, said.trim()), (0, s(&out.join("replay.html"))));
    // At its first instant (0.5 s before the formation's start, on the ground at the
    // scenario's positions) the flight's angle errors are the run's at t = 0.
    let (flight, simulated) = (
        angle_errors(&first_row(&out)),
        angle_errors(&first_row(&run)),
    );
    assert_eq!(flight.len(), 4);
    for ((h, f), (g, r)) in flight.iter().zip(&simulated) {
        assert_eq!(h, g);
        assert!((f - r).abs() < 1e-5, "{h}: flight {f}, run {r}");
    }
    // The negative control: agents 1 and 4 swapped in the log.
    let text = std::fs::read_to_string(fixture("square_serve.csv")).expect("fixture");
    let swapped: String = text
        .lines()
        .map(|l| {
            let mut f: Vec<&str> = l.split(',').collect();
            f[1] = match f[1] {
                "1" => "4",
                "4" => "1",
                other => other,
            };
            format!("{}\n", f.join(","))
        })
        .collect();
    let swapped_log = tmp.path().join("swapped.csv");
    std::fs::write(&swapped_log, swapped).expect("write");
    let out2 = tmp.path().join("swapped");
    let (code, said) = convert(&swapped_log, &out2);
    assert_eq!(code, 0, "{said}");
    let differs = angle_errors(&first_row(&out2))
        .iter()
        .zip(&simulated)
        .any(|((_, f), (_, r))| (f - r).abs() > 0.1);
    assert!(differs);
}

fn vehicle_step(out: &Path, speed: &str) {
    let (code, _, err) = host_sim(&[
        "-q",
        "vehicle",
        "step",
        "--set",
        "world=crazyflie",
        "--speed",
        speed,
        "--out",
        s(out),
    ]);
    assert_eq!(code, 0, "{err}");
}

#[test]
fn a_served_step_is_held_against_vehicle_step() {
    let tmp = tempfile::tempdir().expect("tempdir");
    for (speed, within) in [("0.3", true), ("0.6", false)] {
        let model = tmp.path().join(format!("vehicle-{speed}"));
        vehicle_step(&model, speed);
        let out = tmp.path().join(format!("cmp-{speed}"));
        let log = fixture("step_serve.csv");
        let (code, said, err) = host_sim(&[
            "compare",
            s(&model),
            s(&log),
            "--speed",
            "0.3",
            "--out",
            s(&out),
        ]);
        assert_eq!(code, if within { 0 } else { 1 }, "{said}{err}");
        let j = compare_json(&out);
        let rms = j["rms_m_s"].as_f64().expect("rms");
        assert_eq!(j["within_tolerance"], within);
        if within {
            assert!(rms < 0.03, "{rms}");
            assert!(out.join("compare_step.png").is_file());
        } else {
            assert!(rms > 0.1, "{rms}");
        }
    }
}

#[test]
fn bad_flight_logs_are_named() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let run = tmp.path().join("run");
    run_square(&run, &[]);
    let text = std::fs::read_to_string(fixture("square_serve.csv")).expect("fixture");
    let write = |name: &str, body: String| {
        let p = tmp.path().join(name);
        std::fs::write(&p, body).expect("write");
        p
    };
    let cases = [
        (
            write(
                "no4.csv",
                text.lines()
                    .filter(|l| l.split(',').nth(1) != Some("4"))
                    .map(|l| format!("{l}\n"))
                    .collect(),
            ),
            "agent 4 of the scenario crazyflie-square has fewer than 2 rows",
        ),
        (
            write("novx.csv", text.replacen(",vx,", ",speed_x,", 1)),
            "no column `vx`",
        ),
        (
            write("badx.csv", text.replacen("0.45,", "east,", 1)),
            "line 2, column `x`: \"east\": not a finite number",
        ),
        (
            write(
                "idle.csv",
                text.lines()
                    .map(|l| {
                        let mut f: Vec<&str> = l.split(',').collect();
                        if f[10] == "1" {
                            f[10] = "0";
                        }
                        format!("{}\n", f.join(","))
                    })
                    .collect(),
            ),
            "no row in state 1 (formation): give --start",
        ),
    ];
    for (log, reason) in &cases {
        let (code, said) = compare_flight(&run, log, &tmp.path().join("x"), true);
        assert_eq!(code, 2, "{said}");
        assert!(said.contains(reason), "{reason}: {said}");
        assert!(said.contains(s(log)), "names the file: {said}");
    }
    let (code, said) = compare_flight(
        &run,
        &tmp.path().join("none.csv"),
        &tmp.path().join("x"),
        true,
    );
    assert_eq!(code, 2, "{said}");
    assert!(said.contains("none.csv: cannot read"), "{said}");
    // The control: the intact log passes the same reading.
    let intact = write("intact.csv", text.clone());
    let (code, said) = compare_flight(&run, &intact, &tmp.path().join("x"), true);
    assert_eq!(code, 0, "{said}");
    // A reference that is neither a run nor a vehicle step; a step without --speed.
    let (code, _, err) = host_sim(&["compare", s(tmp.path()), s(&intact)]);
    assert_eq!(code, 2);
    assert!(
        err.contains("neither host-sim run's output directory"),
        "{err}"
    );
    let model = tmp.path().join("vehicle");
    vehicle_step(&model, "0.3");
    let step_log = fixture("step_serve.csv");
    let (code, _, err) = host_sim(&["compare", s(&model), s(&step_log)]);
    assert_eq!(code, 2);
    assert!(err.contains("--speed"), "{err}");
    let (code, _, err) = host_sim(&["compare", s(&model), s(&step_log), "--speed", "0.5"]);
    assert_eq!(code, 2);
    assert!(err.contains("no setpoint_vx of 0.5 m/s"), "{err}");
}
