//! Interrupted sweeps: a run limit, SIGTERM and a killed process, each resumed to the
//! bytes of an uninterrupted run; the interleaved order; the refusal of a huge sweep.

use super::*;
use std::process::{Command, Output};

const BIN: &str = env!("CARGO_BIN_EXE_host-sim");

fn sweep(args: &[&str], dir: Option<&Path>) -> Output {
    let mut c = Command::new(BIN);
    c.args(["-q", "sweep"])
        .args(args)
        .args(["--no-plots", "--jobs", "2"]);
    if let Some(d) = dir {
        c.arg("--out").arg(d);
    }
    c.output().unwrap()
}

fn resume(dir: &Path, more: &[&str]) -> Output {
    Command::new(BIN)
        .args(["-q", "sweep", "--resume"])
        .arg(dir)
        .args(more)
        .args(["--no-plots", "--jobs", "2"])
        .output()
        .unwrap()
}

fn code(o: &Output) -> Option<i32> {
    assert!(
        o.status.code().is_some(),
        "killed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    o.status.code()
}

/// The rows of `runs.csv` (without the header).
fn rows(dir: &Path) -> Vec<String> {
    read(dir, "runs.csv")
        .lines()
        .skip(1)
        .map(str::to_owned)
        .collect()
}

fn same_files(a: &Path, b: &Path) {
    for f in FILES {
        assert_eq!(
            read(a, f),
            read(b, f),
            "{f} differs from the uninterrupted run"
        );
    }
}

/// The whole sweep of `file` in memory (`run_all` + `write_all`, the code before
/// streaming).
fn reference(file: &Path, dir: &Path) {
    let p = Plan::load(file.to_str().unwrap(), None).unwrap();
    let done = run_in_pool(&p, 2, Shard::ALL);
    write_all(
        dir,
        &Manifest::new(&p, Shard::ALL, &done),
        &done.rows,
        false,
    )
    .unwrap();
}

#[test]
fn a_run_limit_then_resume_gives_the_uninterrupted_bytes() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("tiny.toml");
    std::fs::write(&file, TINY).unwrap();
    let file = file.to_str().unwrap();
    let (whole, part, mem) = (
        tmp.path().join("whole"),
        tmp.path().join("part"),
        tmp.path().join("mem"),
    );
    assert_eq!(code(&sweep(&[file], Some(&whole))), Some(0));
    reference(Path::new(file), &mem);
    same_files(&whole, &mem);

    let first = sweep(&[file, "--max-runs", "5"], Some(&part));
    assert_eq!(code(&first), Some(130));
    let stderr = String::from_utf8_lossy(&first.stderr);
    assert!(stderr.contains("--resume"), "{stderr}");
    // Interleaved: 5 runs reach all 4 points (in job order in the file).
    let keys: Vec<String> = rows(&part)
        .iter()
        .map(|l| l.split(',').take(2).collect::<Vec<_>>().join(","))
        .collect();
    assert_eq!(keys, ["0,0", "0,1", "1,0", "2,0", "3,0"]);
    let json: serde_json::Value = serde_json::from_str(&read(&part, "sweep.json")).unwrap();
    assert_eq!(
        (json["finished"].as_u64(), json["interrupted"].as_bool()),
        (Some(5), Some(true))
    );
    // Each row is a row of the whole run.
    let all = rows(&whole);
    assert!(rows(&part).iter().all(|r| all.contains(r)));

    // The sweep named again, then without its name: from sweep.json.
    let again = Command::new(BIN)
        .args(["-q", "sweep", file, "--resume"])
        .arg(&part)
        .args(["--max-runs", "4", "--no-plots"])
        .output()
        .unwrap();
    assert_eq!(code(&again), Some(130));
    assert_eq!(rows(&part).len(), 9);
    let last = resume(&part, &[]);
    assert_eq!(
        code(&last),
        Some(0),
        "{}",
        String::from_utf8_lossy(&last.stderr)
    );
    same_files(&whole, &part);
    // Resuming a finished sweep runs nothing and changes nothing.
    assert_eq!(code(&resume(&part, &[])), Some(0));
    same_files(&whole, &part);
    // --runs and --set are kept in sweep.json: the sweep named again without them resumes.
    let small = tmp.path().join("small");
    let args = [
        file,
        "--runs",
        "2",
        "--set",
        "duration=1",
        "--max-runs",
        "3",
    ];
    assert_eq!(code(&sweep(&args, Some(&small))), Some(130));
    let json: serde_json::Value = serde_json::from_str(&read(&small, "sweep.json")).unwrap();
    assert_eq!(json["set"], serde_json::json!(["duration=1"]));
    let rest = Command::new(BIN)
        .args(["-q", "sweep", file, "--no-plots", "--resume"])
        .arg(&small)
        .output()
        .unwrap();
    assert_eq!(
        code(&rest),
        Some(0),
        "{}",
        String::from_utf8_lossy(&rest.stderr)
    );
    assert_eq!(rows(&small).len(), 8);
    // Another sweep's folder is refused.
    let other = tmp.path().join("other.toml");
    std::fs::write(&other, TINY.replace("seed = 7", "seed = 8")).unwrap();
    let o = Command::new(BIN)
        .args(["-q", "sweep", other.to_str().unwrap(), "--resume"])
        .arg(&part)
        .output()
        .unwrap();
    assert_eq!(code(&o), Some(1));
    assert!(String::from_utf8_lossy(&o.stderr).contains("another sweep"));
}

#[test]
fn sigterm_stops_cleanly_and_resume_completes() {
    let text = TINY.replace("runs = 3", "runs = 300");
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("longer.toml");
    std::fs::write(&file, &text).unwrap();
    let (part, mem) = (tmp.path().join("part"), tmp.path().join("mem"));
    let mut child = Command::new(BIN)
        .args([
            "-q",
            "sweep",
            file.to_str().unwrap(),
            "--no-plots",
            "--jobs",
            "2",
            "--out",
        ])
        .arg(&part)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // Wait (polling) for the first chunk of rows, then send SIGTERM as Slurm does.
    while !part.join("runs.csv").is_file() || rows(&part).is_empty() {
        assert!(child.try_wait().unwrap().is_none(), "ended before SIGTERM");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    let kill = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        code(&out),
        Some(130),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let n = rows(&part).len();
    assert!(n > 0 && n < 1200, "{n} of 1200 rows");
    let json: serde_json::Value = serde_json::from_str(&read(&part, "sweep.json")).unwrap();
    assert_eq!(json["interrupted"], true);
    assert_eq!(json["finished"].as_u64(), Some(n as u64));
    // Every point has runs, within one block (⌈300/256⌉ = 2) of each other, give or take
    // the run that was still going on the other thread.
    let mut per_point = [0; 4];
    for r in rows(&part) {
        per_point[r[..1].parse::<usize>().unwrap()] += 1;
    }
    let spread = per_point.iter().max().unwrap() - per_point.iter().min().unwrap();
    assert!(spread <= 3, "{per_point:?}");
    assert_eq!(code(&resume(&part, &[])), Some(0));
    reference(&file, &mem);
    same_files(&mem, &part);
}

#[test]
fn a_killed_sweep_is_resumed_from_its_unsorted_torn_runs_csv() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("tiny.toml");
    std::fs::write(&file, TINY).unwrap();
    let (whole, part) = (tmp.path().join("whole"), tmp.path().join("part"));
    assert_eq!(
        code(&sweep(&[file.to_str().unwrap()], Some(&whole))),
        Some(0)
    );
    // What a SIGKILL leaves: sweep.json of the start, some rows out of job order (two
    // rounds), and half a row.
    std::fs::create_dir_all(&part).unwrap();
    let all = rows(&whole);
    let header = read(&whole, "runs.csv").lines().next().unwrap().to_owned();
    let torn = &all[5][..20];
    let text = format!(
        "{header}\n{}\n{}\n{}\n{}\n{torn}",
        all[0], all[3], all[1], all[4]
    );
    std::fs::write(part.join("runs.csv"), text).unwrap();
    let json = read(&whole, "sweep.json")
        .replace("\"finished\": 12", "\"finished\": 0")
        .replace("\"interrupted\": false", "\"interrupted\": true");
    std::fs::write(part.join("sweep.json"), json).unwrap();
    let r = resume(&part, &[]);
    assert_eq!(code(&r), Some(0), "{}", String::from_utf8_lossy(&r.stderr));
    same_files(&whole, &part);
    // A row twice is refused, naming it.
    let dup = format!("{header}\n{}\n{}\n{}\n", all[0], all[1], all[1]);
    std::fs::write(part.join("runs.csv"), dup).unwrap();
    let r = resume(&part, &[]);
    assert_eq!(code(&r), Some(1));
    assert!(String::from_utf8_lossy(&r.stderr).contains("point 0 run 1 appears twice"));
}

#[test]
fn merge_names_a_partial_or_killed_shard_and_accepts_it_resumed() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("tiny.toml");
    std::fs::write(&file, TINY).unwrap();
    let file = file.to_str().unwrap();
    let whole = tmp.path().join("whole");
    assert_eq!(code(&sweep(&[file], Some(&whole))), Some(0));
    let (s1, s2, merged) = (
        tmp.path().join("s1"),
        tmp.path().join("s2"),
        tmp.path().join("merged"),
    );
    assert_eq!(code(&sweep(&[file, "--shard", "1/2"], Some(&s1))), Some(0));
    let cut = sweep(&[file, "--shard", "2/2", "--max-runs", "2"], Some(&s2));
    assert_eq!(code(&cut), Some(130));
    let merge = || {
        Command::new(BIN)
            .args(["-q", "sweep", "merge", "--no-plots", "--out"])
            .arg(&merged)
            .args([&s1, &s2])
            .output()
            .unwrap()
    };
    let m = merge();
    let said = String::from_utf8_lossy(&m.stderr);
    assert_eq!(code(&m), Some(130), "{said}");
    assert!(
        said.contains("partial: shard 2/2") && said.contains("2 of 6 runs"),
        "{said}"
    );
    // Killed before its end: sweep.json as written at the start (0 finished).
    let json = read(&s2, "sweep.json").replace("\"finished\": 2", "\"finished\": 0");
    std::fs::write(s2.join("sweep.json"), json).unwrap();
    let m = merge();
    let said = String::from_utf8_lossy(&m.stderr);
    assert_eq!(code(&m), Some(1), "{said}");
    assert!(said.contains("has 2 runs, sweep.json says 0") && said.contains("--resume"));
    assert_eq!(code(&resume(&s2, &[])), Some(0));
    assert_eq!(code(&merge()), Some(0));
    same_files(&whole, &merged);
}

#[test]
fn more_stretches_than_open_files_are_merged_in_passes() {
    // One point, 300 runs: a runs.csv in descending run order has 300 stretches, more
    // than journal::FAN_IN, so sorting it takes two passes.
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("many.toml");
    std::fs::write(
        &file,
        "name = \"many\"\nruns = 300\n[base]\nscenario = \"formation-only\"\nset = [\"duration=1\"]\n",
    )
    .unwrap();
    let dir = tmp.path().join("many");
    let first = sweep(&[file.to_str().unwrap(), "--max-runs", "1"], Some(&dir));
    assert_eq!(code(&first), Some(130));
    let row = rows(&dir)[0].clone();
    let tail = row.strip_prefix("0,0,").unwrap();
    let header = read(&dir, "runs.csv").lines().next().unwrap().to_owned();
    let line = |r: u64| format!("0,{r},{tail}\n");
    let down: String = (0..300).rev().map(line).collect();
    std::fs::write(dir.join("runs.csv"), format!("{header}\n{down}")).unwrap();
    const { assert!(300 > ph_formation_sim::sweep::journal::FAN_IN) };
    let r = resume(&dir, &[]);
    assert_eq!(code(&r), Some(0), "{}", String::from_utf8_lossy(&r.stderr));
    let up: String = (0..300).map(line).collect();
    assert_eq!(read(&dir, "runs.csv"), format!("{header}\n{up}"));
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.contains(".pass") || n.contains("sorting"))
        .collect();
    assert!(left.is_empty(), "{left:?}");
}

#[test]
fn a_huge_sweep_is_refused_before_it_allocates() {
    let o = Command::new(BIN)
        .args(["-q", "sweep", "basin", "--runs", "100000000"])
        .output()
        .unwrap();
    assert_eq!(code(&o), Some(28));
    let msg = String::from_utf8_lossy(&o.stderr);
    assert!(
        msg.contains("600000000 runs") && msg.contains("GB") && msg.contains("--allow-large"),
        "{msg}"
    );
    // One run more than the limit allows in time, one less passes (the estimate is
    // linear in the runs).
    let p = Plan::load("basin", Some(100_000_000)).unwrap();
    let e = ph_formation_sim::sweep::estimate(&p, Shard::ALL, 2);
    assert_eq!(e.runs, 600_000_000);
    assert!(e.check("basin").is_err());
    let small = Plan::load("basin", Some(100)).unwrap();
    assert!(ph_formation_sim::sweep::estimate(&small, Shard::ALL, 2)
        .check("basin")
        .is_ok());
}
