//! Issue 10 §3: adversaries on the radio (`[[attacks]]`, docs/attacks.md), on the paper
//! formation.
//!
//! * With `crc16` integrity a forger of agent 3 (the apex of φ1 and φ2) takes over its
//!   frames (its own next frames then look like replays) and pulls the formation out of
//!   its square.
//! * Replayed frames are refused by the sequence numbers: the run is the clean one.
//! * A flood on a shared channel costs the agents frames to collisions, and the summary
//!   shows it.
//! * Bad `[[attacks]]` entries get errors naming the file, the field and the reason.

#[path = "support/docs.rs"]
mod docs;

use ph_formation_sim::{load_toml, Model, Outcome, RunResult, Simulation};

const PAPER: &str = include_str!("../scenarios/paper.toml");

fn model(extra: &str) -> Model {
    load_toml(&format!("{PAPER}\n{extra}"), "paper-attacked", &[]).expect("valid scenario")
}

fn run(m: &Model) -> RunResult {
    Simulation::new(m).run().expect("run").result
}

/// Largest difference of the relative positions `q_i − q_1` of two runs (m): the shape,
/// whatever the translation along `v*`.
fn shape_difference(a: &RunResult, b: &RunResult) -> f64 {
    let (p, q) = (&a.final_positions, &b.final_positions);
    let mut worst = 0.0f64;
    for i in 1..p.len() {
        for k in 0..2 {
            worst = worst.max(((p[i][k] - p[0][k]) - (q[i][k] - q[0][k])).abs());
        }
    }
    worst
}

const FORGE: &str = r#"
[[attacks]]
kind = "forge"
victim = 3
gamma = 5.0
start = 10.0
"#;

/// The row of docs/attacks.md's forgery table starting with `first` states `r`: the
/// outcome (and its exit code), the settle time ("never": none), the final angle error
/// at the precision shown (deterministic runs), the frames injected and rejected.
fn assert_forge_row(first: &str, r: &RunResult) {
    let doc = docs::read("docs/attacks.md");
    let c = docs::row(&doc, first);
    let what = format!("docs/attacks.md, {first}");
    let outcome = c[1].replace("**", "");
    let name = outcome
        .split(" (")
        .next()
        .expect("outcome")
        .replace(' ', "_");
    assert_eq!(name, r.outcome.as_str(), "{what}: {}", r.reason);
    if let Some(code) = outcome.split("(exit ").nth(1) {
        let code = code.trim_end_matches(')');
        assert_eq!(code.parse().ok(), Some(r.outcome.exit_code()), "{what}");
    }
    match c[2].as_str() {
        "never" => assert_eq!(r.settle_time, None, "{what}"),
        s => {
            let settle = r.settle_time.expect("settled");
            assert!(
                docs::shows(settle, s.trim_end_matches(" s")),
                "{what}: {settle}"
            );
        }
    }
    let angle = c[3].trim_end_matches(" rad");
    assert!(
        docs::shows(r.final_max_angle_error, angle),
        "{what}: {}",
        r.final_max_angle_error
    );
    let injected = r.attacks.first().map_or(0, |a| a.injected);
    assert_eq!(docs::parse(&c[4]).unwrap_or(0.0), injected as f64, "{what}");
    let rejected = c[5].split(" *").next().expect("rejected");
    assert_eq!(
        docs::parse(rejected),
        Some(r.frames.rejected as f64),
        "{what}"
    );
}

#[test]
fn forged_frames_with_crc16_pull_the_formation_out_of_shape() {
    let clean = run(&model(""));
    assert_eq!(clean.outcome, Outcome::Converged, "{}", clean.reason);
    assert_forge_row("none (clean run", &clean);
    let m = model(FORGE);
    let r = run(&m);
    let d = shape_difference(&r, &clean);
    println!(
        "forge (crc16): outcome {}, shape {d:.3} m from the clean run, {:?}",
        r.outcome.as_str(),
        r.frames.by_reason
    );
    // The forged efforts hold the formation in another shape: it moves and settles, but
    // not into the target (not a collision, not a collapse).
    assert_eq!(r.outcome, Outcome::NotConverged, "{}", r.reason);
    assert_forge_row("`crc16`", &r);
    assert!(d > 1.0, "the forged run ends {d} m from the clean shape");
    // One forgery per broadcast of agent 3 from t = 10 s (100 Hz): 9,000.
    assert_eq!(r.attacks.len(), 1);
    assert_eq!(r.attacks[0].injected, 9000);
    // The forgeries carry a valid CRC: the agents accept them and refuse agent 3's own
    // frames as stale (3 neighbours each).
    assert_eq!(r.frames.by_reason.bad_crc, 0);
    assert!(
        r.frames.by_reason.stale >= 3 * 8990,
        "{:?}",
        r.frames.by_reason
    );
    let summary = Simulation::new(&m).run().expect("run").summary_json(&m);
    assert_eq!(summary["attacks"][0]["kind"], "forge");
    assert_eq!(summary["attacks"][0]["victim"], 3);
    assert!(summary["frames_rejected_by_reason"]["stale_sequence"].as_u64() > Some(0));
}

#[test]
fn replayed_frames_are_refused_and_change_nothing() {
    let clean = run(&model(""));
    let r = run(&model(
        "[[attacks]]\nkind = \"replay\"\ndelay = 0.5\nstart = 5.0\nend = 80.0\n",
    ));
    assert_eq!(r.outcome, Outcome::Converged, "{}", r.reason);
    // Rejected frames change no state: the very same run.
    assert_eq!(r.final_positions, clean.final_positions);
    assert_eq!(r.settle_time, clean.settle_time);
    let injected = r.attacks[0].injected;
    assert!(injected > 20_000, "{injected}");
    // Every replayed copy (3 receivers per frame in the paper graph) is refused as stale.
    assert_eq!(r.frames.rejected, r.frames.by_reason.stale);
    assert!(r.frames.by_reason.stale >= 2 * injected);
}

#[test]
fn a_flood_on_the_shared_channel_costs_frames_to_collisions() {
    let channel = "[radio.channel]\npreset = \"crazyflie\"\naccess = \"tdma\"\n";
    let clean = run(&model(channel));
    let flood =
        "[[attacks]]\nkind = \"flood\"\nrate_hz = 4000\nbytes = 60\nstart = 10.0\nend = 20.0\n";
    let m = model(&format!("{channel}\n{flood}"));
    let r = run(&m);
    let (c0, c1) = (clean.channel.expect("channel"), r.channel.expect("channel"));
    println!(
        "tdma: collided copies {} clean, {} flooded; outcome {}",
        c0.collided,
        c1.collided,
        r.outcome.as_str()
    );
    assert_eq!(c0.collided, 0, "tdma alone never collides");
    assert!(c1.collided > 1000, "{}", c1.collided);
    assert_eq!(r.attacks[0].injected, 40_000);
    // Flood frames are never delivered: nothing was rejected, only lost.
    assert_eq!(r.frames.rejected, 0);
    let summary = Simulation::new(&m).run().expect("run").summary_json(&m);
    assert_eq!(summary["attacks"][0]["kind"], "flood");
    assert_eq!(summary["attacks"][0]["frames_injected"], 40_000);
    assert_eq!(
        summary["channel"]["collided_copies"].as_u64(),
        Some(c1.collided)
    );
    // The flood's 40,000 frames of 60 bytes are on the air too, counted apart from the
    // swarm's: 10 s at 4 kHz of (60 + overhead) bytes at 2 Mbit/s.
    assert_eq!(c0.external_transmissions, 0);
    assert_eq!(c1.external_transmissions, 40_000);
    let air = m.radio.channel.as_ref().expect("channel").air_time(60);
    assert!((c1.external_air_time - 40_000.0 * air).abs() < 1e-9 * c1.external_air_time);
    assert!((c1.air_time - c0.air_time).abs() < 0.05 * c0.air_time);
    let total = summary["channel"]["total_utilisation"]
        .as_f64()
        .expect("total");
    let own = summary["channel"]["utilisation"].as_f64().expect("own");
    assert!((total - own - c1.external_air_time / r.final_time).abs() < 1e-12);
    assert_eq!(summary["channel"]["external_transmissions"], 40_000);
    // docs/attacks.md's flood table, row by row: the swarm's transmissions lost to
    // collisions ("A of B"), the outcome and the settle time at the precision shown.
    let doc = docs::read("docs/attacks.md");
    let rows = docs::table_after(&doc, "| access | flood rate |");
    assert_eq!(rows.len(), 4);
    for row in rows {
        let access = row[0].split('`').nth(1).expect("`access`");
        let channel = format!("[radio.channel]\npreset = \"crazyflie\"\naccess = \"{access}\"\n");
        let r = match docs::parse(row[1].trim_end_matches(" /s")) {
            None => run(&model(&channel)),
            Some(rate) => run(&model(&format!(
                "{channel}\n[[attacks]]\nkind = \"flood\"\nrate_hz = {rate}\nbytes = 60\nstart = 10.0\nend = 20.0\n"
            ))),
        };
        let c = r.channel.as_ref().expect("channel");
        let lost = match row[2].split_once(" of ") {
            Some((a, b)) => (docs::parse(a), docs::parse(b)),
            None => (docs::parse(&row[2]), Some(c.transmissions as f64)),
        };
        let got = (
            Some(c.collided_transmissions as f64),
            Some(c.transmissions as f64),
        );
        assert_eq!(lost, got, "docs/attacks.md {row:?}");
        assert_eq!(row[3], r.outcome.as_str(), "{row:?}: {}", r.reason);
        let settle = r.settle_time.expect("settled");
        assert!(
            docs::shows(settle, row[4].trim_end_matches(" s")),
            "{row:?}: {settle}"
        );
    }
}

#[test]
fn bad_attack_entries_name_file_field_and_reason() {
    let cases = [
        (
            "[[attacks]]\nkind = \"jam\"\n",
            "attacks[0].kind",
            "unknown attack",
        ),
        (
            "[[attacks]]\nkind = \"forge\"\n",
            "attacks[0].victim",
            "needs the id",
        ),
        (
            "[[attacks]]\nkind = \"forge\"\nvictim = 9\n",
            "attacks[0].victim",
            "no agent has id 9",
        ),
        (
            "[[attacks]]\nkind = \"replay\"\ngamma = 1.0\n",
            "attacks[0].gamma",
            "only a `forge` attack",
        ),
        (
            "[[attacks]]\nkind = \"flood\"\nbytes = 61\n",
            "attacks[0].bytes",
            "1 to 60",
        ),
        (
            "[[attacks]]\nkind = \"flood\"\nstart = 50.0\nend = 40.0\n",
            "attacks[0].end",
            "after start",
        ),
    ];
    for (extra, field, reason) in cases {
        let e = load_toml(&format!("{PAPER}\n{extra}"), "bad.toml", &[])
            .expect_err(extra)
            .to_string();
        assert!(e.contains("bad.toml"), "{e}");
        assert!(e.contains(field), "{extra}: {e}");
        assert!(e.contains(reason), "{extra}: {e}");
    }
}

/// The paper scenario with `auth` integrity: its own `[controller]` table gets the two
/// keys (a second `[controller]` header would be a TOML error).
fn paper_auth(extra: &str) -> Model {
    let text = PAPER.replacen(
        "[controller]\n",
        "[controller]\nintegrity = \"auth\"\nauth_key = \"000102030405060708090a0b0c0d0e0f\"\n",
        1,
    );
    assert!(
        text.contains("auth_key"),
        "paper.toml has a [controller] table"
    );
    load_toml(&format!("{text}\n{extra}"), "paper-auth", &[]).expect("valid scenario")
}

#[test]
fn with_auth_the_same_forgery_changes_nothing_but_the_counters() {
    let clean = run(&paper_auth(""));
    assert_eq!(clean.outcome, Outcome::Converged, "{}", clean.reason);
    let r = run(&paper_auth(FORGE));
    let d = shape_difference(&r, &clean);
    println!(
        "forge (auth): outcome {}, shape {d:.2e} m from the clean auth run, {:?}",
        r.outcome.as_str(),
        r.frames.by_reason
    );
    assert_eq!(r.outcome, Outcome::Converged, "{}", r.reason);
    assert!(d <= 1e-3, "shape {d} m from the clean run");
    // Every forged copy fails its tag; agent 3's own frames are all accepted.
    assert_eq!(r.attacks[0].injected, 9000);
    assert_eq!(r.frames.by_reason.bad_tag, 3 * 9000);
    assert_eq!(r.frames.by_reason.stale, 0);
    assert_eq!(r.frames.rejected, 3 * 9000);
    assert_forge_row("`auth`", &r);
    // Replays too are refused (by the counter), and change nothing.
    let rp = run(&paper_auth(
        "[[attacks]]\nkind = \"replay\"\ndelay = 0.5\nstart = 5.0\n",
    ));
    assert_eq!(rp.final_positions, clean.final_positions);
    assert_eq!(rp.frames.by_reason.replayed, rp.frames.rejected);
}

#[test]
fn the_auth_key_is_checked_and_never_written() {
    let bad = [
        ("integrity = \"auth\"\n", "needs the swarm key"),
        (
            "integrity = \"auth\"\nauth_key = \"0011\"\n",
            "exactly 32 hexadecimal digits",
        ),
        (
            "auth_key = \"000102030405060708090a0b0c0d0e0f\"\n",
            "only integrity = \"auth\"",
        ),
    ];
    for (keys, reason) in bad {
        let text = PAPER.replacen("[controller]\n", &format!("[controller]\n{keys}"), 1);
        let e = load_toml(&text, "k.toml", &[]).expect_err(keys).to_string();
        assert!(
            e.contains("controller.auth_key") && e.contains(reason),
            "{e}"
        );
    }
    let m = paper_auth("");
    let summary = Simulation::new(&m)
        .run()
        .expect("run")
        .summary_json(&m)
        .to_string();
    assert!(
        summary.contains("\"auth\""),
        "the summary names the integrity"
    );
    assert!(!summary.contains("000102030405060708090a0b0c0d0e0f"));
    assert!(
        !format!("{m:?}").contains("0a0b0c0d0e0f"),
        "Debug of the model"
    );
}
