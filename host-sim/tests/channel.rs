//! Issue 9 §2 and §3: broadcasting every k-th control tick, and the shared radio channel
//! (`docs/radio.md`). The figures asserted here are read from there, or derived in
//! closed form (broadcast counts, air time = bytes · 8 / bit rate).

#[path = "support/docs.rs"]
mod docs;

use ph_formation_sim::engine::{self as sim, NullRecorder, RunResult};
use ph_formation_sim::model::{Access, Model};
use ph_formation_sim::{load, Outcome, Simulation};

fn model(name: &str, overrides: &[&str]) -> Model {
    let o: Vec<String> = overrides.iter().map(|s| (*s).to_owned()).collect();
    load(name, &o).unwrap_or_else(|e| panic!("{name}: {e}"))
}

fn run(m: &Model) -> RunResult {
    sim::run(m, &mut NullRecorder, &mut |_| {}).expect("run")
}

fn strip20() -> String {
    format!("{}/scenarios/strip20.toml", env!("CARGO_MANIFEST_DIR"))
}

/// The error message of a scenario that must be refused.
fn refused(name: &str, overrides: &[&str]) -> String {
    let o: Vec<String> = overrides.iter().map(|s| (*s).to_owned()).collect();
    match load(name, &o) {
        Ok(_) => panic!("{overrides:?} accepted"),
        Err(e) => e.to_string(),
    }
}

/// docs/radio.md's table "The paper formation, 100 Hz control, ideal links", every row
/// run with the command listed under it: the outcome (and the failure's time), the
/// settle time and final angle error at the precision shown (deterministic runs), and
/// the broadcasts, which must also be the closed form of one broadcast per agent every
/// k ticks (agent i on the ticks ≡ i mod k). The prose's claims on the table are checked
/// on its figures: settling grows with the broadcast period, by the percentages stated.
#[test]
fn the_broadcast_rate_table_of_radio_md_is_measured() {
    let doc = docs::read("docs/radio.md");
    let section = &doc[doc
        .find("### The paper formation, 100 Hz control, ideal links")
        .expect("section")..];
    let rows = docs::table_after(section, "| comm rate (Hz) |");
    let commands: Vec<&str> = section
        .lines()
        .skip_while(|l| !l.starts_with("```sh"))
        .skip(1)
        .take_while(|l| !l.starts_with("```"))
        .collect();
    assert_eq!(rows.len(), commands.len(), "one command per row");
    let mut settles = Vec::new();
    for (row, command) in rows.iter().zip(&commands) {
        let sets: Vec<&str> = command.split("--set").skip(1).map(str::trim).collect();
        let hz = &row[0];
        assert!(sets.contains(&format!("controller.comm_rate_hz={hz}").as_str()));
        let m = model("paper", &sets);
        let r = run(&m);
        let k = m.comm_every as u64;
        assert_eq!(m.comm_period(), k as f64 * 0.01, "{hz} Hz");
        let outcome = row[1].split(':').next().unwrap_or_default();
        assert_eq!(outcome, r.outcome.as_str(), "{hz} Hz: {}", r.reason);
        if let Some(t) = row[1].split("t = ").nth(1) {
            let stated = t.trim_end_matches(" s");
            assert!(docs::shows(r.events[0].t, stated), "{hz} Hz: {}", r.reason);
        }
        if row[2] != "—" {
            let settle = r.settle_time.expect("settled");
            let shown = row[2].trim_end_matches(" s");
            assert!(docs::shows(settle, shown), "{hz} Hz: settle {settle} s");
            settles.push((k, docs::parse(shown).expect("settle")));
            // Only at start-up: an agent whose neighbours' first broadcast is due at a
            // later phase waits for it (docs/radio.md); never afterwards.
            if let Some((t, _, f)) = r.control.last_fault {
                assert!(t <= m.comm_period() + 1e-9, "{hz} Hz: {f:?} at {t} s");
            }
        }
        assert!(
            docs::shows(r.final_max_angle_error, &row[3]),
            "{hz} Hz: {}",
            r.final_max_angle_error
        );
        let ticks = r.control.ticks / 4;
        let expected: u64 = (0..4u64).map(|i| (ticks - i % k).div_ceil(k)).sum();
        assert_eq!(r.frames.broadcasts, expected, "{hz} Hz");
        assert_eq!(docs::parse(&row[4]), Some(expected as f64), "{hz} Hz");
    }
    // "Settle time grows smoothly": with the period, and by the stated percentages.
    assert!(
        settles
            .windows(2)
            .all(|w| w[0].0 < w[1].0 && w[0].1 < w[1].1),
        "{settles:?}"
    );
    let base = settles[0].1;
    let flat = docs::flat(section);
    for (k, settle) in &settles[1..] {
        let hz = 100 / k;
        if let Some(at) = flat.find(&format!("at {hz} Hz")) {
            let before = &flat[..at];
            let pct = before[before.rfind('+').expect("+N %") + 1..]
                .trim_end_matches([' ', ','])
                .trim_end_matches('%')
                .trim();
            let growth = format!(
                "{:.*}",
                pct.split('.').nth(1).map_or(0, str::len),
                100.0 * (settle / base - 1.0)
            );
            assert_eq!(growth, pct, "+{pct} % at {hz} Hz");
        }
    }
}

#[test]
fn paper_tolerates_5_hz_but_not_4_hz() {
    // Either side of the boundary with the same (generous) neighbour timeout: the
    // outcome, not a settle time, is what this pins.
    let ok = run(&model(
        "paper",
        &[
            "controller.comm_rate_hz=5",
            "controller.neighbour_timeout=0.75",
        ],
    ));
    assert_eq!(ok.outcome, Outcome::Converged, "{}", ok.reason);
    let bad = run(&model(
        "paper",
        &[
            "controller.comm_rate_hz=4",
            "controller.neighbour_timeout=0.75",
        ],
    ));
    assert_eq!(bad.outcome, Outcome::Collision, "{}", bad.reason);
}

#[test]
fn comm_rate_and_channel_mistakes_name_the_field() {
    let e = refused("paper", &["controller.comm_rate_hz=30"]);
    assert!(
        e.contains("builtin:paper") && e.contains("`controller.comm_rate_hz`"),
        "{e}"
    );
    assert!(e.contains("whole multiple"), "{e}");
    let e = refused("paper", &["controller.comm_rate_hz=200"]);
    assert!(
        e.contains("`controller.comm_rate_hz`") && e.contains("exceeds"),
        "{e}"
    );
    let e = refused("paper", &["controller.comm_rate_hz=0"]);
    assert!(e.contains("`controller.comm_rate_hz`"), "{e}");
    let e = refused("paper", &["controller.comm_rate_hz=10"]);
    assert!(e.contains("`controller.neighbour_timeout`"), "{e}");
    let e = refused("paper", &["controller.integrity=sha"]);
    assert!(e.contains("integrity"), "{e}");
    let e = refused("paper", &["radio.channel.preset=wifi"]);
    assert!(
        e.contains("`radio.channel.preset`") && e.contains("crazyflie"),
        "{e}"
    );
    let e = refused("paper", &["radio.channel.access=tdma"]);
    assert!(e.contains("`radio.channel.bit_rate_bps`"), "{e}");
    let e = refused(
        "paper",
        &[
            "radio.channel.preset=crazyflie",
            "radio.channel.access=csma",
        ],
    );
    assert!(e.contains("access"), "{e}");
    let e = refused(
        "paper",
        &[
            "radio.channel.preset=crazyflie",
            "radio.channel.access=tdma",
            "radio.channel.slot=1e-4",
        ],
    );
    assert!(e.contains("`radio.channel.slot`"), "{e}");
    let e = refused(
        "paper",
        &["radio.channel.preset=crazyflie", "radio.bandwidth_bps=8000"],
    );
    assert!(e.contains("`radio.bandwidth_bps`"), "{e}");
    let e = refused(
        "paper",
        &["radio.channel.preset=crazyflie", "radio.channel.range=-1"],
    );
    assert!(e.contains("`radio.channel.range`"), "{e}");
}

#[test]
fn the_old_bandwidth_keys_are_refused_naming_the_new_ones() {
    // `--set` (and sweep axes, which are `--set` keys).
    let e = refused("paper", &["radio.bandwidth=20000"]);
    assert!(
        e.contains("`radio.bandwidth`")
            && e.contains("renamed `bandwidth_bps`")
            && e.contains("bits per second")
            && e.contains("multiply the old value by 8"),
        "{e}"
    );
    let e = refused("paper", &["radio.channel.bit_rate=1e6"]);
    assert!(
        e.contains("`radio.channel.bit_rate`") && e.contains("renamed `bit_rate_bps`"),
        "{e}"
    );
    // In a file: the file, the line and the field.
    let text = include_str!("../scenarios/paper-lossy.toml")
        .replace("bandwidth_bps = 160000.0", "bandwidth = 20000.0");
    let e = ph_formation_sim::load_toml(&text, "old.toml", &[])
        .expect_err("old key accepted")
        .to_string();
    assert!(
        e.contains("old.toml")
            && e.contains("field `radio.bandwidth`")
            && e.contains("(line 84")
            && e.contains("renamed `bandwidth_bps`")
            && e.contains("multiply the old value by 8"),
        "{e}"
    );
}

#[test]
fn the_crazyflie_preset_and_the_summary() {
    let m = model(
        "paper",
        &[
            "radio.channel.preset=crazyflie",
            "radio.channel.access=tdma",
            "controller.integrity=link",
            "duration=2.0",
        ],
    );
    let c = m.radio.channel.as_ref().expect("channel");
    assert_eq!(
        (c.bit_rate, c.overhead_bytes, c.turnaround),
        (2e6, 11.125, 130e-6)
    );
    assert_eq!(c.access, Access::Tdma);
    // A 60-byte frame plus overhead: 71.125 bytes = 284.5 µs at 2 Mbit/s.
    assert!((c.slot - (130e-6 + 284.5e-6)).abs() < 1e-12);
    let run = Simulation::new(&m).run().expect("run");
    let s = run.summary_json(&m);
    let ch = &s["channel"];
    assert_eq!(ch["access"], "tdma");
    assert_eq!(ch["preset"], "crazyflie");
    assert_eq!(ch["bit_rate_bps"], 2e6);
    assert_eq!(ch["collided_copies"], 0);
    assert!(ch["air_time_s"].as_f64().expect("air") > 0.0);
    assert!(ch["utilisation"].as_f64().expect("util") > 0.0);
    let age = ch["max_neighbour_age_s"].as_f64().expect("age");
    assert!((age - 0.01).abs() < 1e-9, "{age}");
    assert_eq!(s["integrity"], "link");
    // Without a channel or a reduced rate, none of these keys exist (byte-identical
    // summaries of the existing scenarios).
    let m = model("paper", &["duration=1.0"]);
    let s = Simulation::new(&m).run().expect("run").summary_json(&m);
    for key in ["channel", "integrity", "comm_period_s", "comm_every_ticks"] {
        assert!(s.get(key).is_none(), "{key}");
    }
}

#[test]
fn twenty_agents_on_one_crazyflie_channel() {
    let path = strip20();
    let base = [
        "radio.channel.preset=crazyflie",
        "controller.integrity=link",
    ];
    // TDMA: 20 slots of 414.5 µs fit in the 10 ms tick; nothing collides and the
    // neighbour data is exactly one tick old.
    let mut o = base.to_vec();
    o.push("radio.channel.access=tdma");
    let m = model(&path, &o);
    assert_eq!(m.n(), 20);
    let r = run(&m);
    assert_eq!(r.outcome, Outcome::Converged, "tdma: {}", r.reason);
    let c = r.channel.expect("channel");
    assert_eq!(c.collided, 0);
    assert_eq!(r.frames.dropped, 0);
    assert!((c.max_age - 0.01).abs() < 1e-9, "{}", c.max_age);
    // ALOHA at the same load (a third of the air time busy) loses many copies to
    // collisions, yet converges.
    let mut o = base.to_vec();
    o.push("radio.channel.access=aloha");
    let r = run(&model(&path, &o));
    assert_eq!(r.outcome, Outcome::Converged, "aloha: {}", r.reason);
    let c = r.channel.expect("channel");
    let lost = c.collided_transmissions as f64 / c.transmissions as f64;
    assert!(lost > 0.3, "only {lost} of the transmissions collided");
    assert!(c.utilisation(r.final_time) > 0.3);
    assert_eq!(r.frames.dropped, c.collided);
}

#[test]
fn every_agent_gets_the_swarm_integrity_and_its_broadcast_phase() {
    let m = model(
        &strip20(),
        &["controller.comm_rate_hz=25", "controller.integrity=link"],
    );
    for i in 0..m.n() {
        let c = m.agent_config(i).expect("config");
        assert_eq!(c.integrity, ph_formation_core::Integrity::Link);
        assert_eq!((c.comm_every, c.comm_phase), (4, (i % 4) as u16));
        // The emulated firmware's configuration carries the same (host-in-the-loop).
        let t = ph_formation_sim::engine::hil::target_config(&m, i).expect("target");
        assert_eq!(
            (t.integrity, t.comm_every, t.comm_phase),
            (c.integrity, 4, c.comm_phase)
        );
    }
    let m = model("paper", &[]);
    let c = m.agent_config(0).expect("config");
    assert_eq!(
        (c.integrity, c.comm_every, c.comm_phase),
        (ph_formation_core::Integrity::Crc16, 1, 0)
    );
}

#[test]
fn the_summary_table_shows_the_channel_only_when_used() {
    let out = std::path::Path::new("out");
    let m = model(
        "paper",
        &[
            "radio.channel.preset=crazyflie",
            "radio.channel.access=aloha",
            "controller.comm_rate_hz=50",
            "duration=3.0",
        ],
    );
    let r = run(&m);
    let c = r.channel.expect("channel");
    let text = ph_formation_sim::report::summary_table(&m, &r, out, 0);
    for row in [
        "broadcast",
        "every 2 tick(s) (0.0200 s), integrity crc16",
        "aloha (crazyflie), 2000000 bit/s, 11.125 bytes overhead, 130 µs turnaround",
        "air time / utilisation",
        "lost to collisions",
        &format!(
            "{} copies ({} of {} transmissions)",
            c.collided, c.collided_transmissions, c.transmissions
        ),
        "neighbour data age",
    ] {
        assert!(text.contains(row), "no `{row}` in\n{text}");
    }
    let m = model("paper", &["duration=1.0"]);
    let text = ph_formation_sim::report::summary_table(&m, &run(&m), out, 0);
    for row in ["broadcast", "channel", "collisions", "neighbour data age"] {
        assert!(!text.contains(row), "`{row}` in\n{text}");
    }
}

#[test]
fn a_channel_run_is_reproducible_bit_for_bit() {
    let o = [
        "radio.channel.preset=crazyflie",
        "radio.channel.access=aloha",
        "radio.channel.range=3",
        "radio.loss=0.05",
        "radio.jitter=0.002",
        "duration=3.0",
    ];
    let dir = tempfile::tempdir().expect("tempdir");
    let mut files = Vec::new();
    for (k, seed) in ["seed=4", "seed=4", "seed=5"].iter().enumerate() {
        let mut o = o.to_vec();
        o.push(seed);
        let m = model(&strip20(), &o);
        let out = dir.path().join(format!("run{k}"));
        let r = Simulation::new(&m)
            .keep_series(false)
            .write_to(&out, ph_formation_sim::WriteOptions::without_plots())
            .run()
            .expect("run");
        assert!(r.result.channel.expect("channel").collided > 0);
        files.push((
            std::fs::read(out.join("summary.json")).expect("json"),
            std::fs::read(out.join("timeseries.csv")).expect("csv"),
        ));
    }
    assert!(files[0] == files[1], "same seed, different output");
    assert!(files[0].0 != files[2].0, "the seed changes nothing");
}

/// One row of docs/radio.md's shared-channel tables against its run: `scenario` with the
/// row's access and broadcast rate (and, below 25 Hz, the neighbour timeout of 2.5
/// broadcast periods the commands use). Outcome exact, figures at the precision shown
/// (deterministic runs); the payload in closed form from the air time (`air =
/// transmissions · (payload + overhead) · 8 / bit rate`).
fn check_channel_row(scenario: &str, row: &[String]) {
    let c: Vec<String> = row.iter().map(|c| c.replace("**", "")).collect();
    let hz: f64 = c[1].parse().expect("comm rate");
    let mut sets = vec![
        "radio.channel.preset=crazyflie".to_owned(),
        format!("radio.channel.access={}", c[0]),
        "controller.integrity=link".to_owned(),
        format!("controller.comm_rate_hz={hz}"),
    ];
    if hz <= 20.0 {
        sets.push(format!("controller.neighbour_timeout={}", 2.5 / hz));
    }
    let sets: Vec<&str> = sets.iter().map(String::as_str).collect();
    let m = model(scenario, &sets);
    let r = run(&m);
    let what = format!("docs/radio.md {scenario} {} {hz} Hz", c[0]);
    let outcome = c[2].trim_end_matches(" in 60 s").replace(' ', "_");
    assert_eq!(outcome, r.outcome.as_str(), "{what}: {}", r.reason);
    let unit = |s: &str, u: &str| s.trim_end_matches(u).trim().to_owned();
    if c[3] != "—" {
        let settle = r.settle_time.expect("settled");
        assert!(
            docs::shows(settle, &unit(&c[3], " s")),
            "{what}: settle {settle}"
        );
    }
    assert!(
        docs::shows(r.final_max_angle_error, &c[4]),
        "{what}: {}",
        r.final_max_angle_error
    );
    let ch = r.channel.as_ref().expect("channel");
    let cm = m.radio.channel.as_ref().expect("channel");
    let payload = ch.air_time * cm.bit_rate / 8.0 / ch.transmissions as f64 - cm.overhead_bytes;
    assert!(
        docs::shows(payload, &unit(&c[5], " B")),
        "{what}: payload {payload}"
    );
    let util = 100.0 * ch.air_time / r.final_time;
    assert!(
        docs::shows(util, &unit(&c[6], " %")),
        "{what}: utilisation {util}"
    );
    let lost = c[7].split(" (").next().expect("count");
    assert_eq!(docs::parse(lost), Some(ch.collided as f64), "{what}");
    if let Some(pct) = c[7].split(" (").nth(1) {
        let pct = pct.split(" %").next().expect("%");
        let share = 100.0 * ch.collided_transmissions as f64 / ch.transmissions as f64;
        assert!(docs::shows(share, pct), "{what}: {share} % of tx");
    }
    let (mean, worst) = unit(&c[8], " ms")
        .split_once(" / ")
        .map(|(a, b)| (a.to_owned(), b.to_owned()))
        .expect("mean / worst");
    assert!(
        docs::shows(ch.mean_age * 1e3, &mean),
        "{what}: mean age {}",
        ch.mean_age
    );
    assert!(
        docs::shows(ch.max_age * 1e3, &worst),
        "{what}: worst age {}",
        ch.max_age
    );
}

/// docs/radio.md's shared-channel tables: every row of the paper's (12 runs of 100 s)
/// and of the 20-agent strip's (14 runs of 60 s), on every core.
#[test]
fn the_shared_channel_tables_of_radio_md_are_measured() {
    use rayon::prelude::*;
    let doc = docs::read("docs/radio.md");
    let header = "| access | comm (Hz) | outcome |";
    let paper = &doc[doc
        .find("### The paper formation (4 agents)")
        .expect("paper")..];
    let rows = docs::table_after(paper, header);
    assert_eq!(rows.len(), 12);
    let strip = &doc[doc.find("### 20 agents").expect("strip")..];
    let strip_rows = docs::table_after(strip, header);
    assert_eq!(strip_rows.len(), 14);
    let strip20 = strip20();
    let jobs: Vec<(&str, &Vec<String>)> = rows
        .iter()
        .map(|r| ("paper", r))
        .chain(strip_rows.iter().map(|r| (strip20.as_str(), r)))
        .collect();
    jobs.par_iter().for_each(|(s, r)| check_channel_row(s, r));
}

/// An ALOHA channel carrying more than a tenth of its air time is named in the run's
/// warnings with the communication rate (and timeouts) that bring the load under it:
/// the 20-agent strip in the Crazyflie world offers about half of the air time; at the
/// suggested rate the warning is gone and the load is under 10 % (the frames and the
/// position packets both go at the communication rate). The app's 4-drone square in the
/// same world (9.5 %) gets no warning (negative control).
#[test]
fn an_overloaded_aloha_channel_names_the_rate_that_fits() {
    let strip = concat!(env!("CARGO_MANIFEST_DIR"), "/scenarios/strip20.toml");
    let crazy = |file: &str, extra: &[&str]| {
        // The file's own rate (every tick), not the preset's "auto".
        let mut o = vec![
            "world=crazyflie".to_owned(),
            "duration=10".to_owned(),
            "controller.comm_rate_hz=100".to_owned(),
        ];
        o.extend(extra.iter().map(|s| (*s).to_owned()));
        let m = load(file, &o).expect("load");
        let r = sim::run(&m, &mut NullRecorder, &mut |_| {}).expect("run");
        (m, r)
    };
    let (m, r) = crazy(strip, &[]);
    // `host-sim validate` says it before the run, with the same rate.
    let before = ph_formation_sim::engine::load::overload_warning(&m).expect("validate warns");
    let note = r
        .warnings
        .iter()
        .find(|w| w.contains("overloaded for ALOHA"))
        .unwrap_or_else(|| panic!("no channel warning: {:?}", r.warnings));
    let ch = r.channel.as_ref().expect("channel");
    let load_now = ch.utilisation(r.final_time);
    assert!(load_now > 0.4, "{load_now}");
    // Every agent loses more than 37 % of its copies: all twenty are named.
    let lossy = r
        .warnings
        .iter()
        .find(|w| w.starts_with("agents whose link copies were lost more than 37 %"))
        .unwrap_or_else(|| panic!("no lossy agents named: {:?}", r.warnings));
    assert_eq!(lossy.matches(" %)").count(), 20, "{lossy}");
    // The suggested rate: the control rate over ⌈G / 0.1⌉.
    let rate: f64 = note
        .split("controller.comm_rate_hz = ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .and_then(|s| s.parse().ok())
        .expect("a rate in the note");
    let control = 1.0 / (m.dt * m.steps_per_tick as f64);
    assert_eq!(rate, control / (load_now / 0.1).ceil(), "{note}");
    let timeout = format!("{:.3}", 3.5 / rate);
    assert!(note.contains(&timeout), "{note}");
    assert!(
        before.contains(&format!("controller.comm_rate_hz = {rate} ")),
        "{before}"
    );
    let set = [
        format!("controller.comm_rate_hz={rate}"),
        format!("controller.neighbour_timeout={timeout}"),
        format!("sensors.positions.max_age_s={timeout}"),
        format!("controller.bearing_hold_s={timeout}"),
    ];
    let set: Vec<&str> = set.iter().map(String::as_str).collect();
    let (_, slow) = crazy(strip, &set);
    let ch = slow.channel.as_ref().expect("channel");
    assert!(ch.utilisation(slow.final_time) <= 0.1, "{:?}", ch);
    assert!(
        slow.warnings
            .iter()
            .all(|w| !w.contains("ALOHA") && !w.contains("link copies were lost")),
        "{:?}",
        slow.warnings
    );
    let square = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../crazyflie-app/formation.toml"
    );
    let (square_model, quiet) = crazy(square, &[]);
    assert_eq!(
        ph_formation_sim::engine::load::overload_warning(&square_model),
        None
    );
    assert!(
        quiet.warnings.iter().all(|w| !w.contains("ALOHA")),
        "{:?}",
        quiet.warnings
    );
}

/// `controller.comm_rate_hz = "auto"` (the Crazyflie preset's): the strip's 20 agents,
/// which offer 54 % of the air time at every tick, broadcast at the highest rate
/// `100 / k` Hz that keeps the measured load at or under ALOHA's 10 % (k = 6, 16.7 Hz:
/// k = 5 measures above it), with the timeouts raised to 3.5 broadcast periods; the run
/// then stays under 10 %, without the overload warning, and in control. The app's
/// square (9.5 %) keeps every tick and its timeouts. Negative control: the strip at the
/// file's rate is overloaded. A word other than "auto" is refused naming the field.
/// `"auto"` under TDMA counts the frames the access drops (an agent's packets of one
/// broadcast wait for its own slot, a superframe each): the 20-strip in the Crazyflie
/// world on a TDMA channel offers 39 % of the air time at every tick, which the air time
/// alone would take, but drops frames there; auto broadcasts at 50 Hz, where none is
/// dropped (negative control: at every tick the run drops more than 1 %). With a queue
/// limit no rate fits, and the note says so.
#[test]
fn comm_rate_auto_under_tdma_counts_the_dropped_frames() {
    let set = ["world=crazyflie", "duration=2", "radio.channel.access=tdma"];
    let m = model(&strip20(), &set);
    let auto = m.comm_auto.as_ref().expect("the preset asks for auto");
    assert_eq!(m.comm_every, 2, "{auto:?}");
    assert!(auto.dropped.unwrap() <= 0.01, "{auto:?}");
    let dropped = |m: &Model| {
        let r = run(m);
        let c = r.channel.expect("channel");
        c.access_dropped as f64 / (c.access_dropped + c.transmissions) as f64
    };
    assert!(dropped(&m) <= 0.01);
    let every = model(
        &strip20(),
        &[&set[..], &["controller.comm_rate_hz=100"]].concat(),
    );
    assert!(dropped(&every) > 0.01, "every tick drops nothing");
    let tight = model(
        &strip20(),
        &[&set[..], &["radio.queue_limit=0.012"]].concat(),
    );
    let note = ph_formation_sim::engine::load::auto_note(tight.comm_auto.as_ref().unwrap());
    assert!(note.contains("even so the access drops"), "{note}");
    assert!(
        !ph_formation_sim::engine::load::auto_note(auto).contains("even so"),
        "{auto:?}"
    );
}

#[test]
fn comm_rate_auto_picks_the_highest_rate_the_channel_carries() {
    let set = ["world=crazyflie", "duration=10"];
    let m = model(&strip20(), &set);
    let auto = m.comm_auto.as_ref().expect("the preset asks for auto");
    assert_eq!(m.comm_every, 6, "{auto:?}");
    assert!((auto.rate_hz - 100.0 / 6.0).abs() < 1e-9, "{auto:?}");
    let (g1, g) = (auto.load_every_tick.unwrap(), auto.load.unwrap());
    assert!(g1 > 0.5 && g <= 0.1, "{auto:?}");
    // k = 5 would not fit: the highest rate is the one chosen.
    let five = model(
        &strip20(),
        &[
            &set[..],
            &[
                "controller.comm_rate_hz=20",
                "controller.neighbour_timeout=0.2",
                "sensors.positions.max_age_s=0.2",
                "controller.bearing_hold_s=0.2",
            ],
        ]
        .concat(),
    );
    let g5 = ph_formation_sim::engine::load::offered_load(&five).unwrap();
    assert!(g5 > 0.1, "{g5}");
    let need = 3.5 * 6.0 / 100.0;
    assert!((m.limits.neighbour_timeout - need).abs() < 1e-12);
    assert!((m.limits.bearing_hold - need).abs() < 1e-12);
    assert!((m.sensors.positions.as_ref().unwrap().max_age - need).abs() < 1e-12);
    assert_eq!(auto.raised.len(), 3, "{auto:?}");
    let r = run(&m);
    let ch = r.channel.as_ref().expect("channel");
    assert!(ch.utilisation(r.final_time) <= 0.1, "{ch:?}");
    assert!(
        r.warnings.iter().all(|w| !w.contains("overloaded")),
        "{:?}",
        r.warnings
    );
    assert!(
        r.warnings
            .iter()
            .any(|w| w.contains("\"auto\" chose 16.6667 Hz")),
        "{:?}",
        r.warnings
    );
    assert_ne!(r.outcome, Outcome::NotInControl, "{}", r.reason);
    // Negative control: the file's rate.
    let every = model(
        &strip20(),
        &[&set[..], &["controller.comm_rate_hz=100"]].concat(),
    );
    assert!(every.comm_auto.is_none());
    assert!(ph_formation_sim::engine::load::overload_warning(&every).is_some());
    // The square fits at every tick and keeps its timeouts.
    let square = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../crazyflie-app/formation.toml"
    );
    let sq = model(square, &set);
    assert_eq!(sq.comm_every, 1);
    let auto = sq.comm_auto.as_ref().unwrap();
    assert!(
        auto.raised.is_empty() && auto.load.unwrap() <= 0.1,
        "{auto:?}"
    );
    assert_eq!(sq.limits.neighbour_timeout, 0.1);
    let e = refused("paper", &["controller.comm_rate_hz=fast"]);
    assert!(
        e.contains("`controller.comm_rate_hz`") && e.contains("auto"),
        "{e}"
    );
}

/// `"auto"` sizes the timeouts for the link's loss (docs/radio.md "comm_rate_hz =
/// auto"): the 2×5 grid designed for the Crazyflie broadcasts at 33.3 Hz; with 10 %
/// random loss on top of ALOHA's collisions its timeouts span 4.5 periods (0.135 s), with
/// 20 % 5.5 (0.165 s), and with 20 % the grid stays in control over 100 s. Negative
/// control: the same loss with the timeouts of a loss-free channel (3.5 periods, 0.105
/// s) is not in control.
#[test]
fn comm_rate_auto_spans_more_broadcasts_under_random_loss() {
    let grid = concat!(env!("CARGO_MANIFEST_DIR"), "/sweeps/world/grid2x5.toml");
    let lossless = model(grid, &["duration=100"]);
    assert!((lossless.limits.neighbour_timeout - 3.5 / (100.0 / 3.0)).abs() < 1e-9);
    let ten = model(grid, &["duration=100", "radio.loss=0.1"]);
    assert!((ten.limits.neighbour_timeout - 4.5 / (100.0 / 3.0)).abs() < 1e-9);
    let lossy = model(grid, &["duration=100", "radio.loss=0.2"]);
    assert!((lossy.limits.neighbour_timeout - 5.5 / (100.0 / 3.0)).abs() < 1e-9);
    assert!((lossy.limits.bearing_hold - 0.165).abs() < 1e-9);
    let r = run(&lossy);
    assert_ne!(r.outcome, Outcome::NotInControl, "{}", r.reason);
    let short = model(
        grid,
        &[
            "duration=100",
            "radio.loss=0.2",
            "controller.comm_rate_hz=33.333333333333336",
            "controller.neighbour_timeout=0.105",
            "sensors.positions.max_age_s=0.105",
            "controller.bearing_hold_s=0.105",
        ],
    );
    assert_eq!(run(&short).outcome, Outcome::NotInControl);
}
