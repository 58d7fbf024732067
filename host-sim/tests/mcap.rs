//! `host-sim run --mcap` writes `run.mcap` and changes no other output; the PyPI `mcap`
//! reader (Foxglove's) finds in it every agent's pose for every row of `timeseries.csv`
//! and every other value (`tests/mcap_check.py`), and refuses a truncated file or a run
//! whose values differ (negative controls).

use std::path::{Path, PathBuf};
use std::process::Command;

/// MCAP's magic, at both ends of a complete file.
const MAGIC: &[u8] = b"\x89MCAP0\r\n";

fn run(scenario: &str, out: &Path, extra: &[&str]) {
    let status = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args(["run", scenario, "--quiet", "--no-plots", "--out"])
        .arg(out)
        .args(extra)
        .status()
        .expect("host-sim runs");
    // paper converges (0); paper-printed ends in a failure outcome (non-zero): both write.
    assert!(status.code().is_some(), "host-sim was killed");
}

fn read(p: PathBuf) -> Vec<u8> {
    std::fs::read(&p).unwrap_or_else(|e| panic!("cannot read {}: {e}", p.display()))
}

#[test]
fn mcap_flag_writes_run_mcap_and_changes_no_other_output() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (plain, with) = (dir.path().join("plain"), dir.path().join("mcap"));
    for scenario in ["paper", "paper-printed"] {
        run(scenario, &plain, &["--duration", "3"]);
        run(scenario, &with, &["--duration", "3", "--mcap"]);
        for f in ["timeseries.csv", "summary.json"] {
            assert_eq!(read(plain.join(f)), read(with.join(f)), "{scenario}: {f}");
        }
        assert!(!plain.join("run.mcap").exists(), "run.mcap without --mcap");
        let mcap = read(with.join("run.mcap"));
        assert!(
            mcap.starts_with(MAGIC) && mcap.ends_with(MAGIC),
            "{scenario}"
        );
    }
}

/// The venv of `scripts/python-deps.sh`.
fn python() -> PathBuf {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/py-venv/bin/python");
    assert!(
        p.is_file(),
        "{} is missing: run `bash scripts/python-deps.sh` first",
        p.display()
    );
    p
}

/// Runs `tests/mcap_check.py` on `dir`: whether it passed, and what it printed.
fn check(dir: &Path) -> (bool, String) {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/mcap_check.py");
    let out = Command::new(python())
        .arg(script)
        .arg(dir)
        .output()
        .expect("python runs");
    let text =
        String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    (out.status.success(), text)
}

#[test]
#[ignore = "needs the venv of scripts/python-deps.sh: run by cargo xtask test"]
fn pypi_mcap_reader_finds_every_agent_pose_of_every_row() {
    let dir = tempfile::tempdir().expect("temp dir");
    // The whole paper run (10,001 rows) and a run with events (estimate collapse and
    // collision: paper-printed).
    for (scenario, events) in [("paper", false), ("paper-printed", true)] {
        let out = dir.path().join(scenario);
        run(scenario, &out, &["--mcap"]);
        let (ok, text) = check(&out);
        assert!(ok, "{scenario}: {text}");
        assert!(text.contains("mcap_check: ok"), "{text}");
        assert_eq!(!text.contains(" 0 events"), events, "{scenario}: {text}");
        println!("{scenario}: {}", text.trim());
    }

    // Negative control 1: a truncated file is refused by the reader.
    let out = dir.path().join("paper");
    let bad = dir.path().join("truncated");
    std::fs::create_dir(&bad).expect("dir");
    for f in ["timeseries.csv", "summary.json"] {
        std::fs::copy(out.join(f), bad.join(f)).expect("copy");
    }
    let mcap = read(out.join("run.mcap"));
    std::fs::write(bad.join("run.mcap"), &mcap[..mcap.len() / 2]).expect("write");
    let (ok, text) = check(&bad);
    assert!(!ok && text.contains("refused"), "truncated: {text}");

    // Negative control 2: one position changed in the CSV (row 5,000, agent 2's x) is
    // found and named.
    let csv = String::from_utf8(read(out.join("timeseries.csv"))).expect("utf-8");
    let mut lines: Vec<String> = csv.lines().map(str::to_owned).collect();
    let k = lines[0].split(',').position(|c| c == "x_2").expect("x_2");
    let mut cells: Vec<String> = lines[5000].split(',').map(str::to_owned).collect();
    let x: f64 = cells[k].parse().expect("number");
    cells[k] = format!("{:?}", x + 1e-9);
    lines[5000] = cells.join(",");
    std::fs::write(bad.join("timeseries.csv"), lines.join("\n") + "\n").expect("write");
    std::fs::copy(out.join("run.mcap"), bad.join("run.mcap")).expect("copy");
    let (ok, text) = check(&bad);
    assert!(
        !ok && text.contains("agent 2's x differs"),
        "changed value: {text}"
    );
}

/// A run over the size budget (docs/outputs.md, "Size budget"): `run.mcap` holds the
/// rows of its thinned `timeseries.csv` (every 10th of a 100-agent lattice's 5,801), in
/// zstd chunks, and the PyPI reader finds every pose of every row in it.
#[test]
#[ignore = "needs the venv of scripts/python-deps.sh: run by cargo xtask test"]
fn pypi_mcap_reader_reads_a_thinned_run() {
    let dir = tempfile::tempdir().expect("temp dir");
    let scenario = dir.path().join("lat100.toml");
    let status = Command::new(env!("CARGO_BIN_EXE_host-sim"))
        .args([
            "design",
            "--shape",
            "tri-lattice",
            "-n",
            "100",
            "--duration",
            "58",
            "-q",
            "-o",
        ])
        .arg(&scenario)
        .status()
        .expect("host-sim design");
    assert!(status.success());
    let out = dir.path().join("run");
    run(scenario.to_str().expect("utf-8"), &out, &["--mcap"]);
    let summary = String::from_utf8(read(out.join("summary.json"))).expect("utf-8");
    assert!(summary.contains("\"stride\": 10"), "{summary}");
    let (ok, text) = check(&out);
    assert!(ok && text.contains("mcap_check: ok: 581 rows"), "{text}");
}
