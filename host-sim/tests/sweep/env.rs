//! `--shard auto`: the shard from a Slurm job array's or a Kubernetes Indexed Job's
//! variables; a missing or inconsistent variable is an error, never shard 1.

use super::*;
use ph_formation_sim::sweep::ShardError;

fn auto(shards: Option<u64>, vars: &[(&str, &str)]) -> Result<Shard, ShardError> {
    Shard::from_env(shards, |name| {
        vars.iter()
            .find(|(k, _)| *k == name)
            .map(|(_, v)| (*v).to_owned())
    })
}

fn slurm(id: &str, min: &str, max: &str, count: &str) -> Vec<(&'static str, String)> {
    vec![
        ("SLURM_ARRAY_TASK_ID", id.to_owned()),
        ("SLURM_ARRAY_TASK_MIN", min.to_owned()),
        ("SLURM_ARRAY_TASK_MAX", max.to_owned()),
        ("SLURM_ARRAY_TASK_COUNT", count.to_owned()),
    ]
}

fn with<'a>(vars: &'a [(&'static str, String)]) -> Vec<(&'static str, &'a str)> {
    vars.iter().map(|(k, v)| (*k, v.as_str())).collect()
}

#[test]
fn shard_auto_reads_slurm_and_kubernetes() {
    let s = |k, n| Ok(Shard { k, n });
    // Slurm, arrays from 1 and from 0: the array is the sweep.
    assert_eq!(auto(None, &with(&slurm("2", "1", "3", "3"))), s(2, 3));
    assert_eq!(auto(None, &with(&slurm("0", "0", "7", "8"))), s(1, 8));
    assert_eq!(auto(None, &with(&slurm("7", "0", "7", "8"))), s(8, 8));
    // With --shards: ids 1..=N, one task resubmitted alone (its COUNT is 1).
    assert_eq!(auto(Some(3), &with(&slurm("2", "2", "2", "1"))), s(2, 3));
    // Kubernetes: 0-based index with --shards.
    assert_eq!(auto(Some(4), &[("JOB_COMPLETION_INDEX", "0")]), s(1, 4));
    assert_eq!(auto(Some(4), &[("JOB_COMPLETION_INDEX", "3")]), s(4, 4));
    assert_eq!(
        "auto".parse::<ShardArg>(),
        Ok(ShardArg::Auto),
        "`--shard auto` parses"
    );
}

#[test]
fn shard_auto_refuses_missing_or_inconsistent_variables() {
    let msg = |r: Result<Shard, ShardError>| match r {
        Ok(s) => panic!("accepted as {s}"),
        Err(e) => e.to_string(),
    };
    assert_eq!(auto(None, &[]), Err(ShardError::NoBatchSystem));
    let m = msg(auto(None, &[("SLURM_ARRAY_TASK_ID", "2")]));
    assert!(
        m.contains("SLURM_ARRAY_TASK_COUNT") && m.contains("--shards"),
        "{m}"
    );
    // A stepped array (--array=1-9:4: ids 1, 5, 9) is not one contiguous range.
    let m = msg(auto(None, &with(&slurm("5", "1", "9", "3"))));
    assert!(m.contains("contiguous") && m.contains("COUNT = 3"), "{m}");
    let m = msg(auto(Some(3), &with(&slurm("0", "0", "2", "3"))));
    assert!(m.contains("must be 1 to 3"), "{m}");
    let m = msg(auto(Some(3), &with(&slurm("4", "1", "4", "4"))));
    assert!(m.contains("SLURM_ARRAY_TASK_ID = 4"), "{m}");
    let m = msg(auto(None, &[("SLURM_ARRAY_TASK_ID", "two")]));
    assert!(m.contains("SLURM_ARRAY_TASK_ID is `two`"), "{m}");
    let m = msg(auto(None, &[("JOB_COMPLETION_INDEX", "1")]));
    assert!(m.contains("--shards N"), "{m}");
    let m = msg(auto(Some(2), &[("JOB_COMPLETION_INDEX", "2")]));
    assert!(m.contains("not below --shards 2"), "{m}");
    assert!(matches!(
        "3/2".parse::<ShardArg>(),
        Err(ShardError::Syntax(s)) if s == "3/2"
    ));
}

#[test]
fn the_command_takes_the_shard_from_the_environment() {
    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("tiny.toml");
    std::fs::write(&file, TINY).unwrap();
    let vars = [
        "SLURM_ARRAY_TASK_ID",
        "SLURM_ARRAY_TASK_MIN",
        "SLURM_ARRAY_TASK_MAX",
        "SLURM_ARRAY_TASK_COUNT",
        "JOB_COMPLETION_INDEX",
    ];
    let cmd = || {
        let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_host-sim"));
        c.args(["-q", "sweep"])
            .arg(&file)
            .args(["--shard", "auto", "--no-plots", "--jobs", "1"]);
        for v in vars {
            c.env_remove(v);
        }
        c
    };
    let none = cmd().output().unwrap();
    assert_eq!(none.status.code(), Some(2));
    let msg = String::from_utf8_lossy(&none.stderr);
    assert!(msg.contains("neither SLURM_ARRAY_TASK_ID"), "{msg}");
    let out = tmp.path().join("s");
    let task = cmd()
        .args(["--max-runs", "2", "--out"])
        .arg(&out)
        .envs([
            ("SLURM_ARRAY_TASK_ID", "0"),
            ("SLURM_ARRAY_TASK_MIN", "0"),
            ("SLURM_ARRAY_TASK_MAX", "2"),
            ("SLURM_ARRAY_TASK_COUNT", "3"),
        ])
        .output()
        .unwrap();
    assert_eq!(task.status.code(), Some(130), "2 of 4 runs");
    let json: serde_json::Value = serde_json::from_str(&read(&out, "sweep.json")).unwrap();
    assert_eq!(json["shard"], "1/3");
    assert_eq!(read(&out, "runs.csv").lines().count(), 3, "jobs 0 and 3");
}
