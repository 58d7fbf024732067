//! `cargo xtask cluster-test`: a sweep as a Slurm job array on a real one-node cluster.
//!
//! Installs Slurm and MUNGE if missing (`scripts/slurm-deps.sh`), starts `munged`,
//! `slurmctld` and `slurmd` as children (foreground, in a temporary directory, no systemd,
//! no cgroups: `proctrack/linuxproc`, `task/none`), then:
//!
//! 1. submits a built-in-size sweep as `sbatch --array=1-3` of `docs/sweeps.md`'s batch
//!    script (`--shard auto`: the shard from the array's variables), waits for it,
//!    merges the shards and compares the files with an unsharded run, byte for byte;
//! 2. submits a longer sweep the same way, cancels task 2 while it runs (`scancel`: SIGTERM,
//!    as at a time limit), checks that `sweep merge` refuses and names shard 2/3, resubmits
//!    only that task (`--array=2`; it resumes its folder) and checks the merge again.
//!
//! Every daemon it started is stopped at the end, on failure too (`Cluster`'s `Drop`).
//! Prints the Slurm version and the time of each step.

mod daemons;

use crate::tools;
use daemons::Cluster;
use qemu_harness::firmware::{target_dir, workspace_root};
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// The batch script submitted (also in `docs/sweeps.md`): one shard per array task.
/// `HOST_SIM`, `SWEEP` and `SHARDS` come from the submitting environment.
pub const BATCH_SCRIPT: &str = r#"#!/bin/bash
#SBATCH --job-name=ph-sweep
#SBATCH --cpus-per-task=1
#SBATCH --output=slurm-%A_%a.out
# One shard of the sweep per array task, into $SHARDS/<task id>. --resume: a task that
# was stopped (scancel, time limit, preemption) and is run again goes on where it was.
# SHARDS_N set (the number of shards): the task can be resubmitted alone (--array=2).
exec "$HOST_SIM" -q sweep "$SWEEP" --jobs "${SLURM_CPUS_PER_TASK:-1}" --no-plots \
    --shard auto ${SHARDS_N:+--shards "$SHARDS_N"} --resume "$SHARDS/$SLURM_ARRAY_TASK_ID"
"#;

/// The sweep of step 1: 2 × 2 points, 3 runs each, 2 s of formation-only with noise, loss
/// and random initial shapes (the sweep tests' file).
const SWEEP: &str = include_str!("../../host-sim/sweeps/tiny.toml");

/// Shards of the array.
const K: u32 = 3;
/// Longest wait for the cluster or a job array.
const TIMEOUT: Duration = Duration::from_secs(300);
/// The outputs compared byte for byte.
const FILES: [&str; 4] = ["sweep.json", "runs.csv", "points.csv", "points.json"];

/// Runs the cluster test.
pub fn run() -> Result<(), String> {
    let mut times: Vec<(&str, Duration)> = Vec::new();
    let t = Instant::now();
    tools::run(Command::new("bash").arg(workspace_root().join("scripts/slurm-deps.sh")))?;
    times.push(("install slurm-wlm, munge (if missing)", t.elapsed()));
    let t = Instant::now();
    // The binary `cargo test` builds, so that after the test phase of `cargo xtask test`
    // nothing is rebuilt.
    let ph_formation_sim = tools::host_sim_dev()?;
    times.push(("build host-sim (as cargo test does)", t.elapsed()));
    let work = target_dir().join("cluster-test");
    let _ = std::fs::remove_dir_all(&work);
    mkdir(&work)?;

    let t = Instant::now();
    let cluster = Cluster::start()?;
    let version = cluster.output(Command::new("sinfo").arg("-V"))?;
    println!("cluster-test: {} up (one node, localhost)", version.trim());
    times.push(("start munged, slurmctld, slurmd", t.elapsed()));

    let script = work.join("sweep.sbatch");
    write(&script, BATCH_SCRIPT)?;
    let tiny = work.join("tiny.toml");
    write(&tiny, SWEEP)?;
    let longer = work.join("longer.toml");
    write(
        &longer,
        &SWEEP
            .replace("runs = 3", "runs = 30")
            .replace("duration=2", "duration=30"),
    )?;

    // 1. The array, merged, against one unsharded run.
    let t = Instant::now();
    let whole = work.join("tiny-whole");
    sweep_alone(&ph_formation_sim, &tiny, &whole)?;
    let shards = work.join("tiny-shards");
    let job = cluster.submit(&script, &ph_formation_sim, &tiny, &shards, "1-3", None)?;
    let states = cluster.wait(&job)?;
    if states.iter().any(|(_, s)| s != "COMPLETED") || states.len() != K as usize {
        return Err(format!(
            "job array {job}: {states:?} (logs in {})",
            work.display()
        ));
    }
    println!("cluster-test: job array {job} ran: {states:?}");
    let merged = work.join("tiny-merged");
    let m = merge(&ph_formation_sim, &merged, &shards)?;
    if !m.status.success() {
        return Err(format!(
            "merge failed: {}",
            String::from_utf8_lossy(&m.stderr)
        ));
    }
    same(&whole, &merged)?;
    println!("cluster-test: {K} shards merged = the unsharded run, byte for byte");
    times.push(("sweep as a 3-task job array + merge", t.elapsed()));

    // 2. One task cancelled while it runs, merge names it, resubmitted alone.
    let t = Instant::now();
    let whole = work.join("longer-whole");
    sweep_alone(&ph_formation_sim, &longer, &whole)?;
    let shards = work.join("longer-shards");
    let job = cluster.submit(&script, &ph_formation_sim, &longer, &shards, "1-3", None)?;
    let started = shards.join("2/sweep.json");
    let deadline = Instant::now() + TIMEOUT;
    while !started.is_file() {
        if Instant::now() > deadline {
            return Err(format!("task 2 of {job} did not start"));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    cluster.output(Command::new("scancel").arg(format!("{job}_2")))?;
    let states = cluster.wait(&job)?;
    println!("cluster-test: task 2 cancelled while running: {states:?}");
    let merged = work.join("longer-merged");
    let m = merge(&ph_formation_sim, &merged, &shards)?;
    let said = String::from_utf8_lossy(&m.stderr).into_owned();
    if m.status.success() || !said.contains("2/3") {
        return Err(format!(
            "merge after the cancel: exit {:?}, expected a refusal naming shard 2/3:\n{said}",
            m.status.code()
        ));
    }
    println!(
        "cluster-test: merge names it: {}",
        said.trim().replace('\n', " | ")
    );
    let again = cluster.submit(&script, &ph_formation_sim, &longer, &shards, "2", Some(K))?;
    let states = cluster.wait(&again)?;
    if states.iter().any(|(_, s)| s != "COMPLETED") {
        return Err(format!("resubmitted task: {states:?}"));
    }
    let m = merge(&ph_formation_sim, &merged, &shards)?;
    if !m.status.success() {
        return Err(format!(
            "merge after resubmitting: {}",
            String::from_utf8_lossy(&m.stderr)
        ));
    }
    same(&whole, &merged)?;
    println!("cluster-test: task 2 resubmitted alone ({again}) resumed; merge = unsharded run");
    times.push(("cancel a task, merge refuses, resubmit, merge", t.elapsed()));

    let t = Instant::now();
    drop(cluster);
    times.push(("stop the daemons", t.elapsed()));
    println!("\n== cluster-test timings ({})", version.trim());
    for (name, d) in &times {
        println!("   {name:<46} {:>6.1} s", d.as_secs_f64());
    }
    println!("cluster-test: a Slurm job array ran the sweep; all checks passed");
    Ok(())
}

fn mkdir(d: &Path) -> Result<(), String> {
    std::fs::create_dir_all(d).map_err(|e| format!("{}: {e}", d.display()))
}

fn write(p: &Path, text: &str) -> Result<(), String> {
    std::fs::write(p, text).map_err(|e| format!("{}: {e}", p.display()))
}

fn sweep_alone(ph_formation_sim: &Path, sweep: &Path, out: &Path) -> Result<(), String> {
    tools::run(
        Command::new(ph_formation_sim)
            .args(["-q", "sweep"])
            .arg(sweep)
            .args(["--no-plots", "--jobs", "2", "--out"])
            .arg(out),
    )
}

fn merge(
    ph_formation_sim: &Path,
    out: &Path,
    shards: &Path,
) -> Result<std::process::Output, String> {
    let mut c = Command::new(ph_formation_sim);
    c.args(["-q", "sweep", "merge", "--no-plots", "--out"])
        .arg(out);
    for k in 1..=K {
        c.arg(shards.join(k.to_string()));
    }
    c.output().map_err(|e| format!("{}: {e}", tools::show(&c)))
}

fn same(a: &Path, b: &Path) -> Result<(), String> {
    for f in FILES {
        let read = |d: &Path| std::fs::read(d.join(f)).map_err(|e| format!("{}: {e}", d.display()));
        if read(a)? != read(b)? {
            return Err(format!("{f} differs: {} vs {}", a.display(), b.display()));
        }
    }
    Ok(())
}
