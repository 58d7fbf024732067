//! The `host-sim` binary: subcommands, outputs, exit codes, and the invalid-scenario
//! corpus in `tests/invalid/` (each file states its expected exit code, field and reason
//! in `# expect-…` comments).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_host-sim"))
}

fn run_in(dir: &Path, args: &[&str]) -> Output {
    bin()
        .current_dir(dir)
        .args(args)
        .output()
        .expect("spawn host-sim")
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

fn no_panic(o: &Output) {
    let err = text(&o.stderr);
    assert!(
        !err.contains("panicked") && !err.contains("RUST_BACKTRACE"),
        "{err}"
    );
}

fn corpus() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/invalid");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("corpus")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    files
}

fn expectation(text: &str, key: &str) -> String {
    text.lines()
        .find_map(|l| l.strip_prefix(&format!("# expect-{key}: ")))
        .unwrap_or_else(|| panic!("missing # expect-{key}"))
        .trim()
        .to_owned()
}

#[test]
fn every_invalid_scenario_gets_its_error_and_exit_code() {
    let files = corpus();
    assert!(files.len() >= 25, "corpus has {} files", files.len());
    let mut codes = std::collections::BTreeSet::new();
    for f in files {
        let src = std::fs::read_to_string(&f).expect("read");
        let code: i32 = expectation(&src, "code").parse().expect("code");
        let field = expectation(&src, "field");
        let reason = expectation(&src, "reason");
        for args in [
            vec!["validate"],
            vec!["run", "--no-plots", "--out", "/nonexistent/never"],
        ] {
            let mut a = args.clone();
            let path = f.to_string_lossy().into_owned();
            a.insert(1, &path);
            let o = bin().args(&a).output().expect("spawn");
            let err = text(&o.stderr);
            no_panic(&o);
            assert_eq!(o.status.code(), Some(code), "{}: {err}", f.display());
            let first = err.lines().next().unwrap_or("");
            assert!(
                first.contains(&path),
                "{}: file not named: {first}",
                f.display()
            );
            assert!(
                first.contains(&format!("`{field}`")),
                "{}: field `{field}` not named: {first}",
                f.display()
            );
            assert!(
                first.contains(&reason),
                "{}: reason `{reason}` missing: {first}",
                f.display()
            );
        }
        codes.insert(code);
    }
    // Syntax, Laman, angles, duplicate, unknown, collinear, gain, other value.
    assert_eq!(
        codes.into_iter().collect::<Vec<_>>(),
        [21, 22, 23, 24, 25, 26, 27, 28]
    );
}

#[test]
fn list_and_validate_builtins() {
    let o = bin().arg("list").output().expect("spawn");
    assert_eq!(o.status.code(), Some(0));
    let out = text(&o.stdout);
    for name in ["paper", "paper-printed", "formation-only"] {
        assert!(out.contains(name), "{out}");
        let o = bin().args(["validate", name]).output().expect("spawn");
        assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
        assert!(text(&o.stdout).starts_with("ok: "));
    }
    let scenarios = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    for f in std::fs::read_dir(scenarios).expect("scenarios") {
        let p = f.expect("entry").path();
        let o = bin().arg("validate").arg(&p).output().expect("spawn");
        assert_eq!(
            o.status.code(),
            Some(0),
            "{}: {}",
            p.display(),
            text(&o.stderr)
        );
    }
}

#[test]
fn bad_command_lines_exit_2_or_name_the_problem() {
    for args in [
        vec!["run", "paper", "--duration", "abc"],
        vec!["run", "paper", "--seed", "-3"],
        vec!["frobnicate"],
        vec!["validate"],
    ] {
        let o = bin().args(&args).output().expect("spawn");
        no_panic(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
    }
    let dir = tempfile::tempdir().expect("tempdir");
    let never = dir.path().join("never").to_string_lossy().into_owned();
    let cases: [(&[&str], i32, &str); 7] = [
        (
            &["validate", "paper", "--set", "integration.dt=1e-308"],
            28,
            "RK4 steps",
        ),
        (
            &[
                "run",
                "paper",
                "--duration",
                "0.5",
                "--no-plots",
                "--set",
                "radio.latency=1e308",
                "--out",
                &never,
            ],
            // No frame ever arrives: every agent stays in its safe output.
            15,
            "",
        ),
        (
            &["validate", "paper", "--set", "radio.los=0.1"],
            21,
            "unknown field `los`",
        ),
        (&["validate", "paper", "--set", "nokey"], 21, "key=value"),
        (
            &["validate", "paper", "--set", "radio.loss=2"],
            28,
            "`radio.loss`",
        ),
        (
            &["run", "paper", "--duration=-1", "--no-plots"],
            28,
            "`duration`",
        ),
        (&["run", "no-such-scenario"], 20, "not a built-in"),
    ];
    for (args, code, needle) in cases {
        let o = bin().args(args).output().expect("spawn");
        no_panic(&o);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
}

#[test]
fn run_writes_the_documented_outputs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("o");
    let o = bin()
        .args([
            "run",
            "paper",
            "--duration",
            "3",
            "--seed",
            "5",
            "--set",
            "radio.loss=0.1",
        ])
        .arg("--out")
        .arg(&out)
        .output()
        .expect("spawn");
    no_panic(&o);
    // 3 s is too short to converge.
    assert_eq!(o.status.code(), Some(10), "{}", text(&o.stderr));
    let table = text(&o.stdout);
    for row in [
        "outcome",
        "not_converged",
        "settle time",
        "frames sent / dropped / rejected",
    ] {
        assert!(table.contains(row), "{table}");
    }
    let csv = std::fs::read_to_string(out.join("timeseries.csv")).expect("csv");
    let header: Vec<&str> = csv.lines().next().expect("header").split(',').collect();
    let mut expected: Vec<String> = "t V V_kin V_ang V_lead V_est max_angle_err disp_err vel_err min_dist frames_sent frames_dropped frames_rejected"
        .split(' ')
        .map(str::to_owned)
        .collect();
    for i in 1..=4 {
        for c in ["x", "y", "vx", "vy"] {
            expected.push(format!("{c}_{i}"));
        }
    }
    for a in ["1_2_3", "3_1_2", "2_3_4", "3_2_4"] {
        expected.push(format!("angle_err_{a}"));
    }
    for e in [
        "1_1_2_3", "1_1_3_2", "2_2_3_4", "2_2_4_3", "3_3_1_2", "3_3_2_1", "3_3_2_4", "3_3_4_2",
    ] {
        expected.push(format!("rhat_{e}"));
        expected.push(format!("r_{e}"));
    }
    assert_eq!(header, expected);
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), 301, "10 ms log interval over 3 s");
    assert!(rows.iter().all(|r| r.split(',').count() == expected.len()));
    assert!(rows[300].starts_with("3.0,"));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).expect("json"))
            .expect("valid json");
    for key in [
        "scenario",
        "outcome",
        "settle_time_s",
        "final_max_angle_error_rad",
        "final_displacement_error",
        "final_velocity_error",
        "min_estimate",
        "min_distance",
        "v_max_increase_rel",
        "final_positions",
        "frames_sent",
        "frames_dropped",
        "agents",
        "edges",
        "leaders",
        "duration_s",
        "mode",
        "estimator",
        "seed",
        "outcome_reason",
        "exit_code",
    ] {
        assert!(s.get(key).is_some(), "summary lacks {key}");
    }
    assert_eq!(s["scenario"], "paper");
    assert_eq!(s["outcome"], "not_converged");
    assert_eq!(s["exit_code"], 10);
    assert_eq!(s["seed"], 5);
    assert_eq!(s["duration_s"], 3.0);
    assert_eq!(s["mode"], "sampled");
    assert_eq!(s["estimator"], "shared");
    assert_eq!(s["agents"], serde_json::json!([1, 2, 3, 4]));
    assert_eq!(
        s["edges"],
        serde_json::json!([[1, 2], [1, 3], [2, 3], [2, 4], [3, 4]])
    );
    assert_eq!(s["leaders"], serde_json::json!([1, 2]));
    assert!(s["settle_time_s"].is_null());
    assert_eq!(s["final_positions"].as_array().map(Vec::len), Some(4));
    assert!(s["frames_dropped"].as_u64() > Some(0));
}

#[test]
fn default_run_is_paper_into_out_paper_with_plots() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = run_in(dir.path(), &[]);
    no_panic(&o);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let out = dir.path().join("out/paper");
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).expect("json"))
            .expect("valid json");
    assert_eq!(s["outcome"], "converged");
    assert!(text(&o.stdout).contains("converged (exit code 0)"));
    let pngs = std::fs::read_dir(&out)
        .expect("out")
        .filter(|e| {
            e.as_ref()
                .is_ok_and(|e| e.path().extension().is_some_and(|x| x == "png"))
        })
        .count();
    let svgs = std::fs::read_dir(&out)
        .expect("out")
        .filter(|e| {
            e.as_ref()
                .is_ok_and(|e| e.path().extension().is_some_and(|x| x == "svg"))
        })
        .count();
    assert!(
        pngs >= 5 && svgs >= 5,
        "{pngs} PNG, {svgs} SVG: {}",
        text(&o.stderr)
    );
    assert!(
        !text(&o.stderr).contains("warning: plots"),
        "{}",
        text(&o.stderr)
    );
    // `plot` redraws them from the directory alone.
    let o = run_in(dir.path(), &["plot", "out/paper"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let o = run_in(dir.path(), &["plot", "out/nothing-here"]);
    no_panic(&o);
    assert_eq!(o.status.code(), Some(1));
}

#[test]
fn quiet_prints_nothing_and_failure_codes_are_distinct() {
    let dir = tempfile::tempdir().expect("tempdir");
    let o = run_in(
        dir.path(),
        &["-q", "run", "paper-printed", "--no-plots", "--out", "pp"],
    );
    no_panic(&o);
    assert_eq!(o.status.code(), Some(12), "estimate_collapse");
    assert!(o.stdout.is_empty());
    let s: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("pp/summary.json")).expect("json"),
    )
    .expect("valid json");
    assert_eq!(s["outcome"], "estimate_collapse");
    assert!(s["outcome_reason"]
        .as_str()
        .is_some_and(|r| r.contains("collided")));
    // A collision without a collapsed estimate: agents 2 and 4 start 1.27 m apart.
    let o = run_in(
        dir.path(),
        &[
            "-q",
            "run",
            "formation-only",
            "--no-plots",
            "--out",
            "c",
            "--set",
            "criteria.collision_distance=1.3",
        ],
    );
    assert_eq!(o.status.code(), Some(11), "collision");
    let o = run_in(
        dir.path(),
        // v* = (3, 3): the speed passes 2 m/s.
        &[
            "-q",
            "run",
            "paper",
            "--no-plots",
            "--out",
            "d",
            "--set",
            "criteria.divergence_speed=2.0",
        ],
    );
    assert_eq!(o.status.code(), Some(13), "diverged");
}

/// `-j N` changes only the speed: a run large enough for the parallel paths (agents' ticks,
/// plant, reading the estimates: ≥ 2,048 agents; the diagnostics' angle terms: ≥ 2,048
/// triangles) writes the same bytes on one and two threads; `--summary-only` writes
/// summary.json alone, with the same figures.
#[test]
fn jobs_do_not_change_the_outputs_and_summary_only_skips_the_series() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let scenario = d.join("big.toml");
    let o = run_in(
        d,
        &[
            "design",
            "--shape",
            "tri-lattice",
            "-n",
            "2200",
            "--duration",
            "0.2",
            "-o",
            scenario.to_str().expect("path"),
        ],
    );
    assert!(o.status.success(), "{}", text(&o.stderr));
    let mut summaries = Vec::new();
    for (name, extra) in [
        ("j1", vec!["-j", "1"]),
        ("j2", vec!["-j", "2"]),
        ("so", vec!["--summary-only"]),
    ] {
        let mut args = vec!["-q", "run", "big.toml", "--no-plots", "--out", name];
        args.extend(extra);
        let o = run_in(d, &args);
        no_panic(&o);
        let s = std::fs::read_to_string(d.join(name).join("summary.json")).expect("summary");
        let s: serde_json::Value = serde_json::from_str(&s).expect("json");
        summaries.push(s);
    }
    let csv = |n: &str| std::fs::read(d.join(n).join("timeseries.csv")).expect("csv");
    assert!(
        csv("j1") == csv("j2"),
        "timeseries.csv differs between -j 1 and -j 2"
    );
    assert_eq!(summaries[0], summaries[1]);
    assert_eq!(summaries[0]["outcome"], summaries[2]["outcome"]);
    assert_eq!(summaries[0]["V_final"], summaries[2]["V_final"]);
    assert!(!d.join("so").join("timeseries.csv").exists());
}

/// The lines of `host-sim ARGS`' standard error that contain `containing` (the command
/// must succeed without a panic).
fn validate_warnings(args: &[&str], containing: &str) -> Vec<String> {
    let o = bin().args(args).output().expect("spawn host-sim");
    no_panic(&o);
    assert!(o.status.success(), "{}", text(&o.stderr));
    text(&o.stderr)
        .lines()
        .filter(|l| l.contains(containing))
        .map(str::to_owned)
        .collect()
}

/// `validate` warns when a camera's field of view leaves an agent without one of its
/// triangles' neighbours, at the start and in the target shape (the 2×5 grid in the
/// camera world: its forward 87° camera cannot see a neighbour behind); an all-round
/// camera gets no such warning (negative control).
#[test]
fn validate_warns_when_a_camera_cannot_see_a_neighbour() {
    let grid = concat!(env!("CARGO_MANIFEST_DIR"), "/sweeps/world/grid2x5.toml");
    let warnings = |extra: &[&str]| {
        let args = [
            &["validate", grid, "--set", "world=crazyflie-camera"],
            extra,
        ]
        .concat();
        validate_warnings(&args, "out of view of its camera")
    };
    let seen = warnings(&[]);
    assert_eq!(seen.len(), 2, "{seen:?}");
    assert!(seen[0].starts_with("warning: at the initial positions, agent "));
    assert!(seen[1].starts_with("warning: in the target shape, agent "));
    assert!(warnings(&["--set", "sensors.camera.fov_deg=360"]).is_empty());
}

/// `validate` warns when the force limit lets a virtual mass accelerate faster than the
/// vehicle can (the ideal world's 1000 N under `world = "crazyflie"`, issue 42), naming
/// the key and what `design --vehicle crazyflie` chooses; the app's square (2 N per kg)
/// and the same scenario on the point mass are not warned (negative controls).
#[test]
fn validate_warns_when_the_force_limit_is_above_what_the_vehicle_flies() {
    let app = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../crazyflie-app/formation.toml"
    );
    let warned =
        |args: &[&str]| validate_warnings(&[&["validate"], args].concat(), "controller.max_force");
    let seen = warned(&["formation-only", "--set", "world=crazyflie"]);
    assert_eq!(seen.len(), 1, "{seen:?}");
    assert!(
        seen[0].contains("controller.max_force = 1000 N")
            && seen[0].contains("above the 3.57 m/s²")
            && seen[0].contains("--vehicle crazyflie"),
        "{}",
        seen[0]
    );
    assert!(warned(&["formation-only"]).is_empty());
    assert!(warned(&[app, "--set", "world=crazyflie"]).is_empty());
}
