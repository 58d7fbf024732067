//! The command line: parsing, a run end to end with figures, `sweep plot`, a refusal.

use super::*;

#[test]
fn command_line_runs_a_sweep_and_refuses_a_bad_one() {
    use clap::Parser;
    use ph_formation_sim::cli::{Cli, Command};
    let cli = Cli::try_parse_from(["host-sim", "sweep", "merge", "--out", "m", "a", "b"]).unwrap();
    assert!(matches!(cli.command, Some(Command::Sweep(_))));
    let cli = Cli::try_parse_from(["host-sim", "sweep", "basin", "--shard", "2/3"]).unwrap();
    let Some(Command::Sweep(args)) = cli.command else {
        panic!("not a sweep")
    };
    assert_eq!(
        (args.sweep.as_deref(), args.shard),
        (Some("basin"), Some(ShardArg::Fixed(Shard { k: 2, n: 3 })))
    );
    for bad in ["4/3", "0/3", "2", "a/b"] {
        assert!(
            Cli::try_parse_from(["host-sim", "sweep", "basin", "--shard", bad]).is_err(),
            "{bad}"
        );
    }

    let tmp = tempfile::tempdir().unwrap();
    let file = tmp.path().join("tiny.toml");
    std::fs::write(&file, TINY.replace("runs = 3", "runs = 1")).unwrap();
    let out = tmp.path().join("out");
    let bin = env!("CARGO_BIN_EXE_host-sim");
    let run = std::process::Command::new(bin)
        .args(["-q", "sweep"])
        .arg(&file)
        .arg("--out")
        .arg(&out)
        .args(["--jobs", "2"])
        .output()
        .unwrap();
    assert_eq!(
        run.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert_eq!(
        read(&out, "runs.csv").lines().count(),
        5,
        "header + 4 points × 1 run"
    );
    assert!(out.join("outcomes_vs_radio_loss.png").is_file());
    assert!(out.join("settle_vs_perturbation.svg").is_file());
    // `sweep plot` redraws the figures from sweep.json and runs.csv.
    std::fs::remove_file(out.join("outcomes_vs_radio_loss.png")).unwrap();
    let plot = std::process::Command::new(bin)
        .args(["-q", "sweep", "plot"])
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(
        plot.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&plot.stderr)
    );
    assert!(out.join("outcomes_vs_radio_loss.png").is_file());

    std::fs::write(
        &file,
        "[base]\nscenario = \"paper\"\n[[axes]]\nkey = \"radio.loss\"\nvalues = [2.0]\n",
    )
    .unwrap();
    let bad = std::process::Command::new(bin)
        .args(["-q", "sweep"])
        .arg(&file)
        .output()
        .unwrap();
    assert_eq!(bad.status.code(), Some(28));
    let msg = String::from_utf8_lossy(&bad.stderr);
    assert!(
        msg.contains("tiny.toml: field `axes[0].values`") && msg.contains("probability"),
        "{msg}"
    );
}
