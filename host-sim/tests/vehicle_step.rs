//! `host-sim vehicle step`: the files it writes, its figures against closed forms, and
//! its refusals of bad flags.

use std::process::Command;

fn step(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .arg("-q")
        .arg("vehicle")
        .arg("step")
        .args(args)
        .output()
        .expect("host-sim runs");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn scratch(name: &str) -> String {
    let d = std::env::temp_dir().join(format!("vehicle-step-{name}-{}", std::process::id()));
    d.to_string_lossy().into_owned()
}

/// The first-order vehicle's step is its closed form: the 63 % rise time is `τ`, no
/// overshoot, the peak acceleration `v/τ` (at t = 0; the CSV's central difference
/// gives it within 0.5 %), and step.csv has one row per ms with the five columns.
#[test]
fn a_first_order_step_is_its_closed_form() {
    let dir = scratch("first-order");
    let (code, out, err) = step(&[
        "--set",
        "plant.model=velocity_tracking",
        "--set",
        "plant.time_constant_s=0.25",
        "--speed",
        "0.5",
        "--duration",
        "2",
        "--out",
        &dir,
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("63 % rise time 0.250 s"), "{out}");
    assert!(out.contains("overshoot 0.0 %"), "{out}");
    let csv = std::fs::read_to_string(format!("{dir}/step.csv")).expect("step.csv");
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("t,v_along,v_across,a,tilt_deg"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().expect("number")).collect())
        .collect();
    assert_eq!(rows.len(), 2001);
    let peak = rows.iter().map(|r| r[3]).fold(0.0, f64::max);
    assert!((peak / 2.0 - 1.0).abs() < 0.005, "peak a {peak}");
    assert!(std::path::Path::new(&format!("{dir}/step.svg")).exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// The Crazyflie's cascade: a diagonal 2 m/s step tilts beyond 20° (the per-axis
/// clamp), along an axis it stays near 20°; and it overshoots (which no first-order
/// vehicle does).
#[test]
fn the_cascade_tilts_more_on_a_diagonal() {
    let peak_tilt = |dir: &str| {
        let d = scratch(&format!("cf-{dir}"));
        let (code, out, err) = step(&[
            "--set",
            "world=crazyflie",
            "--speed",
            "2",
            "--direction-deg",
            dir,
            "--out",
            &d,
        ]);
        assert_eq!(code, 0, "{err}");
        let _ = std::fs::remove_dir_all(&d);
        let tilt: f64 = out
            .split("peak tilt ")
            .nth(1)
            .and_then(|s| s.trim().trim_end_matches('°').parse().ok())
            .expect("peak tilt");
        let overshoot: f64 = out
            .split("overshoot ")
            .nth(1)
            .and_then(|s| s.split(' ').next()?.parse().ok())
            .expect("overshoot");
        (tilt, overshoot)
    };
    let (axis, overshoot) = peak_tilt("0");
    let (diagonal, _) = peak_tilt("45");
    assert!(axis < 21.0 && diagonal > 25.0, "{axis} {diagonal}");
    assert!(overshoot > 5.0, "{overshoot}");
}

/// Bad flags and a vehicle without a velocity loop are refused, naming the flag.
#[test]
fn bad_flags_are_refused() {
    let dir = scratch("bad");
    for (args, says) in [
        (vec!["--speed", "0"], "--speed"),
        (vec!["--speed", "nan"], "--speed"),
        (vec!["--speed", "1", "--duration=-1"], "--duration"),
        (
            vec!["--speed", "1", "--direction-deg", "inf"],
            "--direction-deg",
        ),
        (
            vec!["--speed", "1", "--set", "plant.max_tilt_deg=10"],
            "plant.max_tilt_deg",
        ),
    ] {
        let mut a = vec!["--set", "world=crazyflie"];
        a.extend(args.iter().copied());
        a.extend(["--out", dir.as_str()]);
        let (code, _, err) = step(&a);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(says), "{args:?}: {err}");
    }
    let (code, _, err) = step(&["--speed", "1", "--out", &dir]);
    assert_eq!(code, 2);
    assert!(err.contains("point mass"), "{err}");
    // Negative control: good flags pass.
    let (code, _, err) = step(&["--set", "world=crazyflie", "--speed", "1", "--out", &dir]);
    assert_eq!(code, 0, "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// docs/world.md's step-response table: every row re-run with the command above it
/// (`--set world=crazyflie --speed V --direction-deg D`), its printed figures the
/// table's, at the precision shown (the step is deterministic).
#[test]
fn the_step_table_of_world_md_is_measured() {
    let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/world.md"))
        .expect("docs/world.md");
    let table = &doc[doc
        .find("| speed | direction | 63 % rise |")
        .expect("table")..];
    let rows: Vec<Vec<String>> = table
        .lines()
        .skip(2)
        .take_while(|l| l.starts_with('|'))
        .map(|l| {
            l.trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_owned())
                .collect()
        })
        .collect();
    assert_eq!(rows.len(), 6);
    for c in rows {
        let speed = c[0].trim_end_matches(" m/s");
        let direction = c[1].split('°').next().expect("direction");
        let dir = scratch(&format!("table-{speed}-{direction}"));
        let (code, out, err) = step(&[
            "--set",
            "world=crazyflie",
            "--speed",
            speed,
            "--direction-deg",
            direction,
            "--out",
            &dir,
        ]);
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(code, 0, "{err}");
        let printed = format!("{out}{err}");
        let want = format!(
            "63 % rise time {}, overshoot {}, peak acceleration {}, peak tilt {}",
            c[2], c[3], c[4], c[5]
        );
        assert!(printed.contains(&want), "docs/world.md {c:?}:\n{printed}");
    }
}
