//! Host-in-the-loop (`host-sim run … --hil ID`, `docs/hil.md`).
//!
//! Always run (no QEMU needed): the protocol, lock-step, error paths and exit codes
//! against the host-side stand-in of the firmware (`ph_formation_sim::engine::hil::fake`: an
//! `Agent<f32, 4, 8>` behind a TCP link speaking `ph_formation_core::link`), and the
//! start-up errors (missing ELF, missing QEMU, bad `--hil` arguments) through the binary.
//!
//! Ignored by default (`needs qemu-system-arm and the qemu-uart firmware ELF`): the same
//! with the real firmware under QEMU. Build the ELF first, then:
//!
//! ```text
//! cargo build -p firmware-example --target thumbv7em-none-eabihf --release --bin qemu-uart
//! cargo test -p ph-formation-sim --test hil -- --include-ignored --test-threads=1
//! ```
//!
//! The QEMU tests also serialize themselves (a lock), so that each one has the machine's
//! cores to itself.

use ph_formation_sim::engine::hil::fake::FakeBehaviour;
use ph_formation_sim::engine::hil::{self, HilError, HilOptions, Launcher, When};
use ph_formation_sim::engine::{self as sim, NullRecorder, RunResult};
use ph_formation_sim::model::Model;
use ph_formation_sim::{exit_code, load, RunError, Simulation};
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Largest difference of the final relative positions `q_i − q_1` between a run with
/// emulated agents (`f32` controllers) and the pure-host run (`f64`), in metres, on a
/// square of side 14.1 m. Measured (QEMU and stand-in alike, the firmware's outputs being
/// bit-identical to a host `Agent<f32, 4, 8>`): 1.8e-6 m with agent 3 emulated (100 s),
/// 3.2e-7 m with all four (60 s), 4.7e-7 m with all four (100 s). The tolerance, 1e-4 m
/// (7e-6 of the side), leaves a factor of 50.
const SHAPE_TOLERANCE: f64 = 1e-4;

fn paper(duration: Option<f64>) -> Model {
    let o: Vec<String> = duration
        .map(|d| vec![format!("duration={d:?}")])
        .unwrap_or_default();
    load("paper", &o).expect("paper")
}

fn fake(agents: &[u8], behaviour: FakeBehaviour, timeout_s: f64) -> HilOptions {
    HilOptions {
        agents: agents.iter().map(u8::to_string).collect(),
        launcher: Launcher::Fake(behaviour),
        timeout: Duration::from_secs_f64(timeout_s),
        pin: false,
    }
}

fn host_run(m: &Model) -> RunResult {
    sim::run(m, &mut NullRecorder, &mut |_| {}).expect("host run")
}

fn hil_run(m: &Model, o: &HilOptions) -> Result<RunResult, RunError> {
    hil::run(m, o, &mut NullRecorder, &mut |_| {})
}

/// Largest difference of `q_i − q_1` between two sets of final positions.
fn shape_difference(a: &[[f64; 2]], b: &[[f64; 2]]) -> f64 {
    let rel = |p: &[[f64; 2]], i: usize| [p[i][0] - p[0][0], p[i][1] - p[0][1]];
    (1..a.len())
        .map(|i| {
            let (x, y) = (rel(a, i), rel(b, i));
            (x[0] - y[0]).hypot(x[1] - y[1])
        })
        .fold(0.0, f64::max)
}

fn hil_error(r: Result<RunResult, RunError>) -> HilError {
    match r {
        Err(RunError::Hil(e)) => e,
        Err(e) => panic!("expected a host-in-the-loop error, got {e}"),
        Ok(r) => panic!(
            "expected a host-in-the-loop error, the run ended {}",
            r.outcome
        ),
    }
}

// ------------------------------------------------------------------ stand-in target

/// A target's controller knows the neighbour slots of the core it runs (the same
/// configuration as the host's core), so the simulator sends its bearings in that order.
#[test]
fn targets_get_their_bearings_in_their_cores_slot_order() {
    let m = paper(None);
    let mut cs = hil::controllers(&m, &fake(&[1, 2, 3, 4], FakeBehaviour::default(), 10.0))
        .expect("controllers");
    for (i, c) in cs.iter_mut().enumerate() {
        let local = sim::local_core(&m, i).expect("core");
        assert!(c.neighbour_order().is_some(), "agent {i}");
        assert_eq!(c.neighbour_order(), local.neighbour_order(), "agent {i}");
        c.finish().expect("finish");
    }
}

#[test]
fn stand_in_agents_converge_like_the_host() {
    let m = paper(None);
    let host = host_run(&m);
    for (agents, estimates) in [(&[3u8][..], false), (&[1, 2, 3, 4][..], true)] {
        let b = FakeBehaviour {
            send_estimates: estimates,
            ..FakeBehaviour::default()
        };
        let r = hil_run(&m, &fake(agents, b, 10.0)).expect("hil run");
        assert_eq!(r.outcome.as_str(), "converged", "{}", r.reason);
        let d = shape_difference(&r.final_positions, &host.final_positions);
        println!("stand-in {agents:?}: shape difference {d:.3e} m");
        assert!(d < SHAPE_TOLERANCE, "shape differs by {d} m");
        assert_eq!(r.hil.len(), agents.len());
        for h in &r.hil {
            assert_eq!(h.ticks, 10_001, "agent {}", h.agent);
            assert_eq!(h.estimates_from_target, estimates && h.agent != "4");
            let source = match (h.agent.as_str(), estimates) {
                ("4", _) => "none",
                (_, true) => "estimates_message",
                (_, false) => "radio_frames",
            };
            assert_eq!(h.estimates_source(), source);
            // Per tick: every Radio and the Step; back: Radio, [Estimates,] Output.
            assert_eq!(
                h.frames_to_target,
                h.radio_to_target + h.ticks + 2,
                "Configure + Finish"
            );
            let per_tick = if estimates && h.agent != "4" { 2 } else { 1 };
            assert_eq!(
                h.frames_from_target,
                h.radio_from_target + per_tick * h.ticks + 2,
                "Ready + Finished"
            );
            assert!(h.bytes_to_target > h.frames_to_target * 3);
            assert_eq!(h.target_rejected, Some(0));
            assert_eq!(h.target_accepted.map(u64::from), Some(h.radio_to_target));
            assert_eq!(h.exit_code, Some(0));
        }
        // The emulated agents' estimates reach the diagnostics (both sources).
        let owned = r
            .final_estimates
            .iter()
            .filter(|(rh, _)| *rh != 1.0)
            .count();
        assert_eq!(owned, r.final_estimates.len());
        let e = r
            .final_estimates
            .iter()
            .zip(&host.final_estimates)
            .map(|(a, b)| (a.0 - b.0).abs() / b.0)
            .fold(0.0, f64::max);
        assert!(e < 1e-3, "estimates differ by {e} (relative)");
    }
}

#[test]
fn stand_in_run_is_deterministic_and_lock_step() {
    let m = paper(Some(3.0));
    let dir = tempfile::tempdir().expect("tempdir");
    let mut csv = Vec::new();
    for k in 0..2 {
        let out = dir.path().join(format!("run{k}"));
        let options = fake(&[2, 3], FakeBehaviour::default(), 10.0);
        let run = Simulation::new(&m)
            .keep_series(false)
            .write_to(&out, ph_formation_sim::WriteOptions::without_plots())
            .hil(&options)
            .run()
            .expect("run");
        let r = &run.result;
        assert_eq!(r.hil.len(), 2);
        csv.push(std::fs::read(out.join("timeseries.csv")).expect("csv"));
        let s: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).expect("json"))
                .expect("json");
        let h = s["hil"].as_array().expect("hil figures");
        assert_eq!(h.len(), 2);
        for (a, id) in h.iter().zip([2, 3]) {
            assert_eq!(a["agent"], id);
            assert_eq!(a["ticks"], 301);
            for key in [
                "frames_to_target",
                "frames_from_target",
                "bytes_to_target",
                "bytes_from_target",
                "wall_s",
            ] {
                assert!(a[key].as_f64().is_some_and(|x| x > 0.0), "{key}");
            }
        }
        assert!(s["wall_s_per_sim_s"].as_f64().is_some_and(|x| x > 0.0));
    }
    assert!(csv[0] == csv[1], "same seed, different CSV");
    // A pure-host summary has no wall-clock figures (same seed, same summary).
    let out = dir.path().join("host");
    Simulation::new(&m)
        .write_to(&out, ph_formation_sim::WriteOptions::without_plots())
        .run()
        .expect("host run");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).expect("json"))
            .expect("json");
    assert!(s.get("hil").is_none() && s.get("wall_s_per_sim_s").is_none());
}

#[test]
fn corrupt_frame_is_an_error_naming_agent_tick_and_time() {
    let m = paper(Some(2.0));
    let b = FakeBehaviour {
        corrupt_at: Some(5),
        ..FakeBehaviour::default()
    };
    let e = hil_error(hil_run(&m, &fake(&[3], b, 10.0)));
    assert_eq!(e.exit_code(), exit_code::HIL_CORRUPT);
    match &e {
        HilError::Corrupt { agent, when, what } => {
            assert_eq!(agent, "3");
            assert_eq!(
                *when,
                When::Tick {
                    tick: 5,
                    time: 0.05
                }
            );
            assert!(what.contains("05 ff"), "{what}");
        }
        other => panic!("{other:?}"),
    }
    let text = e.to_string();
    assert!(
        text.contains("agent 3") && text.contains("tick 5") && text.contains("t = 0.050 s"),
        "{text}"
    );
    // A well-formed message out of protocol is reported the same way.
    let b = FakeBehaviour {
        unexpected_at: Some(2),
        ..FakeBehaviour::default()
    };
    let e = hil_error(hil_run(&m, &fake(&[1, 3], b, 10.0)));
    assert_eq!(e.exit_code(), exit_code::HIL_CORRUPT);
    assert!(e.to_string().contains("Ready"), "{e}");
}

#[test]
fn silent_target_is_a_timeout_not_a_hang() {
    let m = paper(Some(2.0));
    let b = FakeBehaviour {
        stop_after: Some(7),
        ..FakeBehaviour::default()
    };
    let started = Instant::now();
    let e = hil_error(hil_run(&m, &fake(&[3, 4], b, 0.5)));
    assert!(started.elapsed() < Duration::from_secs(10));
    assert_eq!(e.exit_code(), exit_code::HIL_TIMEOUT);
    match &e {
        HilError::Timeout {
            agent,
            when,
            timeout_s,
            ..
        } => {
            assert_eq!(agent, "3", "the first agent collected");
            assert_eq!(
                *when,
                When::Tick {
                    tick: 7,
                    time: 0.07
                }
            );
            assert_eq!(*timeout_s, 0.5);
        }
        other => panic!("{other:?}"),
    }
    let text = e.to_string();
    assert!(
        text.contains("did not answer within 0.5 s at tick 7 (t = 0.070 s)"),
        "{text}"
    );
}

#[test]
fn configuration_that_does_not_fit_the_firmware_is_refused() {
    // A fan around agent 0: 5 triangles, more than the firmware's 4.
    let toml = r#"
name = "fan5"
duration = 0.1
[[agents]]
id = 0
position = [0.0, 0.0]
[[agents]]
id = 1
position = [1.0, 0.0]
[[agents]]
id = 2
position = [0.8, 0.7]
[[agents]]
id = 3
position = [0.2, 1.0]
[[agents]]
id = 4
position = [-0.6, 0.8]
[[agents]]
id = 5
position = [-1.0, 0.1]
[[agents]]
id = 6
position = [-0.7, -0.7]
[gains]
stiffness = 10.0
damping = 1.0
estimator_gain = 10.0
[[triangles]]
vertices = [0, 1, 2]
angles = [{ apex = 0, desired_deg = 40.0 }, { apex = 1, desired_deg = 70.0 }]
[[triangles]]
vertices = [0, 2, 3]
angles = [{ apex = 0, desired_deg = 40.0 }, { apex = 2, desired_deg = 70.0 }]
[[triangles]]
vertices = [0, 3, 4]
angles = [{ apex = 0, desired_deg = 40.0 }, { apex = 3, desired_deg = 70.0 }]
[[triangles]]
vertices = [0, 4, 5]
angles = [{ apex = 0, desired_deg = 40.0 }, { apex = 4, desired_deg = 70.0 }]
[[triangles]]
vertices = [0, 5, 6]
angles = [{ apex = 0, desired_deg = 40.0 }, { apex = 5, desired_deg = 70.0 }]
"#;
    let dir = tempfile::tempdir().expect("tempdir");
    let f = dir.path().join("fan5.toml");
    std::fs::write(&f, toml).expect("write");
    let m = load(f.to_str().expect("path"), &[]).expect("fan5 is valid for the host");
    let e = hil_error(hil_run(&m, &fake(&[0], FakeBehaviour::default(), 5.0)));
    assert_eq!(e.exit_code(), exit_code::HIL_REFUSED);
    assert!(e.to_string().contains("at most 4"), "{e}");
    // Its neighbour in two triangles fits.
    let r = hil_run(&m, &fake(&[2], FakeBehaviour::default(), 5.0)).expect("agent 2 fits");
    assert_eq!(r.hil.len(), 1);
}

/// `--hil` takes the agent's id as the scenario writes it: the paper with agent 3 named
/// `carol` (so every wire id is assigned by the colouring) runs `carol` on the stand-in
/// target, the figures and messages name it, and the run matches the pure-host run.
#[test]
fn hil_agents_are_named_by_the_scenario_ids() {
    let text = ph_formation_sim::scenario::builtin("paper")
        .expect("paper")
        .text
        .replace("id = 3\n", "id = \"carol\"\n")
        .replace("vertices = [1, 2, 3]", "vertices = [1, 2, \"carol\"]")
        .replace("vertices = [2, 3, 4]", "vertices = [2, \"carol\", 4]")
        .replace("apex = 3,", "apex = \"carol\",")
        .replace("duration = 100.0", "duration = 3.0");
    let m = ph_formation_sim::load_toml(&text, "named", &[]).expect("named paper");
    assert_eq!(m.agents[2].name, "carol");
    let named = |ids: &[&str]| HilOptions {
        agents: ids.iter().map(|s| s.to_string()).collect(),
        ..fake(&[], FakeBehaviour::default(), 10.0)
    };
    let r = hil_run(&m, &named(&["carol"])).expect("carol runs on the target");
    assert_eq!(r.hil.len(), 1);
    assert_eq!(r.hil[0].agent, "carol");
    let host = host_run(&m);
    assert_eq!(r.outcome, host.outcome);
    assert!((r.final_max_angle_error - host.final_max_angle_error).abs() < 1e-3);
    let e = hil_error(hil_run(&m, &named(&["3"])));
    assert!(
        e.to_string()
            .contains("no agent 3 (its agents: 1, 2, carol, 4)"),
        "{e}"
    );
}

// ------------------------------------------------------------------ command line

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn run_bin(args: &[&str], env: &[(&str, &str)], remove: &[&str]) -> Output {
    let mut c = bin();
    c.args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    for k in remove {
        c.env_remove(k);
    }
    c.output().expect("spawn host-sim")
}

#[test]
fn missing_firmware_elf_is_reported_with_the_build_command() {
    let dir = tempfile::tempdir().expect("tempdir");
    let missing = dir.path().join("no-such-elf");
    let out = dir.path().join("out");
    let o = run_bin(
        &[
            "-q",
            "run",
            "paper",
            "--hil",
            "3",
            "--firmware",
            missing.to_str().expect("path"),
            "--out",
            out.to_str().expect("path"),
        ],
        &[],
        &[],
    );
    let err = text(&o.stderr);
    assert_eq!(
        o.status.code(),
        Some(i32::from(exit_code::HIL_NO_FIRMWARE)),
        "{err}"
    );
    assert!(err.contains(missing.to_str().expect("path")), "{err}");
    assert!(
        err.contains("cargo build -p firmware-example --target thumbv7em-none-eabihf --release --bin qemu-uart"),
        "{err}"
    );
    assert!(!out.exists(), "nothing is written before the checks");
}

#[test]
fn missing_qemu_is_reported_with_the_install_script() {
    let dir = tempfile::tempdir().expect("tempdir");
    let elf = dir.path().join("fake-elf");
    std::fs::write(&elf, b"\x7fELF").expect("write");
    let empty = dir.path().join("empty-path");
    std::fs::create_dir(&empty).expect("mkdir");
    let o = run_bin(
        &[
            "-q",
            "run",
            "paper",
            "--hil",
            "3",
            "--firmware",
            elf.to_str().expect("path"),
            "--out",
            dir.path().join("out").to_str().expect("path"),
        ],
        &[("PATH", empty.to_str().expect("path"))],
        &["QEMU_SYSTEM_ARM"],
    );
    let err = text(&o.stderr);
    assert_eq!(
        o.status.code(),
        Some(i32::from(exit_code::HIL_NO_QEMU)),
        "{err}"
    );
    assert!(err.contains("qemu-system-arm"), "{err}");
    assert!(err.contains("scripts/firmware-deps.sh"), "{err}");
}

#[test]
fn bad_hil_arguments_are_usage_errors() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out");
    let out = out.to_str().expect("path");
    for (args, needle) in [
        (vec!["--hil", "7"], "no agent 7 (its agents: 1, 2, 3, 4)"),
        (vec!["--hil", "300"], "300"),
        (vec!["--hil", "3", "--set", "mode=continuous"], "sampled"),
        (vec!["--hil", "3", "--hil-timeout", "0"], "--hil-timeout"),
        (vec!["--hil", "3", "--hil-timeout", "nan"], "--hil-timeout"),
    ] {
        let mut a = vec!["-q", "run", "paper", "--out", out];
        a.extend(&args);
        let o = run_bin(&a, &[], &[]);
        let err = text(&o.stderr);
        assert_eq!(
            o.status.code(),
            Some(i32::from(exit_code::USAGE)),
            "{args:?}: {err}"
        );
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
    }
}

// ------------------------------------------------------------------ QEMU

/// One QEMU test at a time: each has the cores to itself.
static QEMU_LOCK: Mutex<()> = Mutex::new(());

fn firmware() -> PathBuf {
    let elf = hil::default_firmware();
    assert!(
        elf.is_file(),
        "{} not found: build it with `{}`",
        elf.display(),
        hil::FIRMWARE_BUILD
    );
    elf
}

fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).expect("summary"))
        .expect("json")
}

fn positions(s: &serde_json::Value) -> Vec<[f64; 2]> {
    s["final_positions"]
        .as_array()
        .expect("positions")
        .iter()
        .map(|p| [p[0].as_f64().expect("x"), p[1].as_f64().expect("y")])
        .collect()
}

/// Runs `host-sim run paper` with `--hil` for `agents` into `out`; returns the output
/// and the wall-clock time.
fn qemu_run(agents: &[u8], out: &Path, extra: &[&str]) -> (Output, Duration) {
    qemu_run_scenario("paper", agents, out, extra)
}

/// [`qemu_run`] of another built-in scenario.
fn qemu_run_scenario(scenario: &str, agents: &[u8], out: &Path, x: &[&str]) -> (Output, Duration) {
    let mut c = bin();
    c.args(["-q", "run", scenario, "--no-plots", "--out"])
        .arg(out)
        .arg("--firmware")
        .arg(firmware())
        .args(x);
    for a in agents {
        c.args(["--hil", &a.to_string()]);
    }
    let started = Instant::now();
    let o = c.output().expect("spawn host-sim");
    (o, started.elapsed())
}

/// Checks a converged QEMU run against the pure-host run; returns the shape difference.
fn check_against_host(agents: &[u8], out: &Path, o: &Output, wall: Duration, m: &Model) -> f64 {
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "not converged: {err}");
    let s = summary(out);
    assert_eq!(s["outcome"], "converged");
    let host = host_run(m);
    let d = shape_difference(&positions(&s), &host.final_positions);
    let hil = s["hil"].as_array().expect("hil");
    assert_eq!(hil.len(), agents.len());
    let ticks = (m.duration / m.control_period()).round() as u64 + 1;
    for (h, id) in hil.iter().zip(agents) {
        assert_eq!(h["agent"], *id);
        assert_eq!(h["ticks"], ticks);
        assert_eq!(h["exit_code"], 0, "the firmware exits 0 after Finish");
        assert_eq!(h["target_frames_rejected"], 0);
        let owns = if *id == 4 {
            "none"
        } else {
            "estimates_message"
        };
        assert_eq!(h["estimates_from"], owns, "agent 4 owns no estimate");
        assert!(out.join(format!("qemu-agent-{id}.log")).is_file());
    }
    println!(
        "QEMU agents {agents:?}: {} s simulated in {:.1} s ({:.3} s wall per simulated s, {:.0} ticks/s); \
         shape difference to the pure-host run {d:.3e} m; per agent: {}",
        m.duration,
        wall.as_secs_f64(),
        s["wall_s_per_sim_s"].as_f64().unwrap_or(f64::NAN),
        ticks as f64 / s["wall_s"].as_f64().unwrap_or(f64::NAN),
        hil.iter()
            .map(|h| format!(
                "{}: {} / {} frames, {} / {} bytes to / from, {:.1} s in round trips",
                h["agent"],
                h["frames_to_target"],
                h["frames_from_target"],
                h["bytes_to_target"],
                h["bytes_from_target"],
                h["wall_s"].as_f64().unwrap_or(f64::NAN)
            ))
            .collect::<Vec<_>>()
            .join("; ")
    );
    assert!(
        d < SHAPE_TOLERANCE,
        "final shape differs from the host's by {d} m"
    );
    d
}

#[test]
#[ignore = "needs qemu-system-arm and the qemu-uart firmware ELF; run by scripts/test.sh"]
fn qemu_agent_3_converges_like_the_host() {
    let _serial = QEMU_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("paper-hil3");
    let (o, wall) = qemu_run(&[3], &out, &[]);
    check_against_host(&[3], &out, &o, wall, &paper(None));
}

#[test]
#[ignore = "needs qemu-system-arm and the qemu-uart firmware ELF; run by scripts/test.sh"]
fn qemu_agent_3_runs_the_bearing_tracker_with_noisy_bearings() {
    // Issue 30: with 2° of bearing noise the configuration sent to the target carries the
    // bearing tracker (SPEC §11), the f32 core on the STM32F405 runs it, and the run
    // converges like the pure-host one; on `formation-only`, as a 30 s `paper` has not
    // converged under the honest verdict (issue 39: its leader edge still 0.3 m off).
    let _serial = QEMU_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("formation-only-hil3-noisy");
    let (o, _) = qemu_run_scenario(
        "formation-only",
        &[3],
        &out,
        &[
            "--duration",
            "30",
            "--set",
            "sensors.bearing_noise_deg=2",
            "--set",
            "radio.loss=0.1",
        ],
    );
    assert_eq!(
        o.status.code(),
        Some(0),
        "not converged: {}",
        text(&o.stderr)
    );
    let s = summary(&out);
    assert_eq!(s["outcome"], "converged");
    assert_eq!(s["bearing_filter"]["kind"], "tracker");
    assert!(s["verdict"]["p95"]["angle_rad"].as_f64().is_some());
    assert!(s["final_max_angle_error_rad"].as_f64().expect("error") <= 0.035);
    let hil = s["hil"].as_array().expect("hil");
    assert_eq!(hil.len(), 1);
    assert_eq!(hil[0]["target_frames_rejected"], 0);
}

#[test]
#[ignore = "needs qemu-system-arm and the qemu-uart firmware ELF; run by scripts/test.sh"]
fn qemu_all_four_agents_converge_like_the_host() {
    // 60 s instead of 100 s: four QEMUs share two cores at about 1.25 s of wall clock per
    // simulated second (QEMU's UART costs ~20 µs of CPU per byte received; docs/hil.md),
    // so 100 s takes ~125 s, too close to the 3-minute budget on a busy machine. `paper`
    // settles at 40.6 s, and at 60 s every criterion holds with a margin of 3.7 or more
    // (pure host: |z − z*| = 2.7e-3 m < 1e-2, max |v − v*| = 4.7e-4 < 1e-2, max angle
    // error 8.4e-5 < 1e-3 rad), so convergence is still checked at the end.
    let _serial = QEMU_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("paper-hil1234");
    let (o, wall) = qemu_run(&[1, 2, 3, 4], &out, &["--duration", "60"]);
    check_against_host(&[1, 2, 3, 4], &out, &o, wall, &paper(Some(60.0)));
}

#[test]
#[ignore = "needs qemu-system-arm and the qemu-uart firmware ELF; run by scripts/test.sh"]
fn qemu_runs_are_deterministic() {
    let _serial = QEMU_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().expect("tempdir");
    let mut csv = Vec::new();
    for k in 0..2 {
        let out = dir.path().join(format!("run{k}"));
        let (o, _) = qemu_run(&[3], &out, &["--duration", "5"]);
        assert_eq!(
            o.status.code(),
            Some(10),
            "not converged at 5 s: {}",
            text(&o.stderr)
        );
        csv.push(std::fs::read(out.join("timeseries.csv")).expect("csv"));
    }
    assert!(csv[0].len() > 100_000);
    assert!(
        csv[0] == csv[1],
        "same seed, different CSV with agent 3 in QEMU"
    );
}

/// `(pid, state)` of the processes whose parent is `parent` and whose name is `name`.
fn children(parent: u32, name: &str) -> Vec<(u32, char)> {
    let mut v = Vec::new();
    for e in std::fs::read_dir("/proc").into_iter().flatten().flatten() {
        let Ok(stat) = std::fs::read_to_string(e.path().join("stat")) else {
            continue;
        };
        // "pid (comm) state ppid …"
        let (Some(open), Some(close)) = (stat.find('('), stat.rfind(')')) else {
            continue;
        };
        let comm = &stat[open + 1..close];
        let rest: Vec<&str> = stat[close + 1..].split_whitespace().collect();
        let (Some(state), Some(ppid)) = (rest.first(), rest.get(1)) else {
            continue;
        };
        if comm == name && ppid.parse::<u32>().ok() == Some(parent) {
            if let Ok(pid) = stat[..open].trim().parse() {
                v.push((pid, state.chars().next().unwrap_or('?')));
            }
        }
    }
    v
}

#[test]
#[ignore = "needs qemu-system-arm and the qemu-uart firmware ELF; run by scripts/test.sh"]
fn qemu_firmware_that_stops_answering_is_an_error_not_a_hang() {
    let _serial = QEMU_LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("stopped");
    let started = Instant::now();
    let mut child = bin()
        .args([
            "-q",
            "run",
            "paper",
            "--no-plots",
            "--hil",
            "3",
            "--hil-timeout",
            "2",
        ])
        .arg("--out")
        .arg(&out)
        .arg("--firmware")
        .arg(firmware())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn host-sim");
    // Wait until QEMU runs and the run is well under way (the CSV is flushed in 8 KiB
    // blocks: 64 KiB is about 150 logged rows, 1.5 s of simulated time), then freeze QEMU.
    let csv = out.join("timeseries.csv");
    let qemu = loop {
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "the run did not get under way"
        );
        if let Ok(Some(s)) = child.try_wait() {
            panic!("host-sim ended early: {s}");
        }
        let q = children(child.id(), "qemu-system-arm");
        if q.len() == 1 && std::fs::metadata(&csv).is_ok_and(|m| m.len() > 64 * 1024) {
            break q[0].0;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let stop = Command::new("kill")
        .args(["-STOP", &qemu.to_string()])
        .status()
        .expect("kill -STOP");
    assert!(stop.success());
    let stopped = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().expect("wait") {
            break s;
        }
        if stopped.elapsed() > Duration::from_secs(30) {
            let _ = child.kill();
            let _ = Command::new("kill")
                .args(["-KILL", &qemu.to_string()])
                .status();
            panic!("host-sim hangs on a stopped QEMU");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let waited = stopped.elapsed();
    let mut err = String::new();
    if let Some(mut e) = child.stderr.take() {
        use std::io::Read;
        let _ = e.read_to_string(&mut err);
    }
    assert_eq!(
        status.code(),
        Some(i32::from(exit_code::HIL_TIMEOUT)),
        "{err}"
    );
    assert!(
        err.contains("agent 3: the firmware did not answer within 2 s at tick "),
        "{err}"
    );
    assert!(
        err.contains("(t = ") && err.contains("qemu-agent-3.log"),
        "{err}"
    );
    assert!(
        waited < Duration::from_secs(10),
        "took {waited:?} to give up"
    );
    // host-sim killed and reaped the stopped QEMU.
    assert!(
        !Path::new(&format!("/proc/{qemu}")).exists(),
        "QEMU {qemu} left behind"
    );
    println!("stopped QEMU reported after {waited:?}: {}", err.trim());
}
