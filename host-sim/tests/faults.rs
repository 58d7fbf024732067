//! `[[faults]]` (issue 45, docs/faults.md): a lost agent, a rebooted agent and a radio
//! blackout on the 20-agent strip, what the swarm did about each, and the file's
//! mistakes named.

use ph_formation_sim::engine::{self as sim, NullRecorder, RunResult};
use ph_formation_sim::{load_toml, Outcome};

fn strip20() -> String {
    std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/scenarios/strip20.toml"
    ))
    .expect("strip20.toml")
}

/// strip20 with `faults` (TOML of `[[faults]]` tables) appended, run for `duration`.
fn run(faults: &str, duration: f64) -> RunResult {
    let text = format!("{}\n{faults}", strip20());
    let m = load_toml(&text, "strip20-faults", &[format!("duration={duration}")])
        .unwrap_or_else(|e| panic!("{e}"));
    sim::run(&m, &mut NullRecorder, &mut |_| {}).expect("run")
}

/// Agent 10 (index 10) is lost at 30 s: the report names the fault and its four triangle
/// neighbours (8, 9, 11, 12) going to their safe output within the neighbour timeout;
/// none comes back (it never returns); nobody collides, and the others stay put (the
/// safe output damps them: each within 5 cm of where it was when the fault struck).
/// Negative control: without the fault nobody goes safe after 30 s, and the report is
/// empty.
#[test]
fn a_lost_agent_is_reported_and_nobody_collides() {
    let lost = run(
        "[[faults]]\nkind = \"agent_loss\"\nagent = 10\nt = 30.0\n",
        60.0,
    );
    assert_ne!(lost.outcome, Outcome::Collision, "{}", lost.reason);
    assert!(lost.min_distance.0 > 0.5, "{:?}", lost.min_distance);
    let [f] = lost.faults.as_slice() else {
        panic!("{:?}", lost.faults)
    };
    let mut safe: Vec<usize> = f.went_safe.iter().map(|x| x.0).collect();
    safe.sort_unstable();
    assert_eq!(safe, vec![8, 9, 11, 12], "{:?}", f.went_safe);
    assert!(f
        .went_safe
        .iter()
        .all(|x| x.1 > 30.0 && x.1 <= 30.0 + 0.1 + 0.011));
    assert!(f.recovered.is_empty());
    assert!(
        lost.reason
            .contains("fault: agent_loss of agent 10 at 30 s"),
        "{}",
        lost.reason
    );
    // The others hold still: compare with a run stopped when the fault struck.
    let before = run("", 30.0);
    for (i, (a, b)) in lost
        .final_positions
        .iter()
        .zip(&before.final_positions)
        .enumerate()
    {
        let d = ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
        assert!(d < 0.05, "agent {i} moved {d} m after the loss");
    }
    let clean = run("", 60.0);
    assert!(clean.faults.is_empty());
    assert_eq!(clean.outcome, Outcome::Converged, "{}", clean.reason);
}

/// Agent 10 reboots at 30 s and is down for 2 s: its neighbours go safe, then it and
/// they run their law again from 32 s, and the strip converges again. Negative control:
/// the same agent lost instead (never back) leaves its neighbours in their safe output,
/// and the run is not in control.
#[test]
fn a_rebooted_agent_rejoins_and_the_formation_converges_again() {
    let r = run(
        "[[faults]]\nkind = \"reboot\"\nagent = 10\nt = 30.0\nduration = 2.0\n",
        90.0,
    );
    assert_eq!(r.outcome, Outcome::Converged, "{}", r.reason);
    let f = &r.faults[0];
    let mut back: Vec<usize> = f.recovered.iter().map(|x| x.0).collect();
    back.sort_unstable();
    assert_eq!(back, vec![8, 9, 10, 11, 12], "{:?}", f.recovered);
    assert!(f.recovered.iter().all(|x| x.1 >= 32.0 - 1e-9 && x.1 < 33.0));
    let lost = run(
        "[[faults]]\nkind = \"agent_loss\"\nagent = 10\nt = 30.0\n",
        90.0,
    );
    assert_eq!(lost.outcome, Outcome::NotInControl, "{}", lost.reason);
}

/// Every radio off for 1 s at 20 s: every agent with a neighbour goes safe and every one
/// comes back after the blackout; the strip converges again.
#[test]
fn a_blackout_of_every_radio_is_ridden_out() {
    let r = run(
        "[[faults]]\nkind = \"radio_blackout\"\nt = 20.0\nduration = 1.0\n",
        80.0,
    );
    assert_eq!(r.outcome, Outcome::Converged, "{}", r.reason);
    let f = &r.faults[0];
    assert_eq!(f.went_safe.len(), 20, "{:?}", f.went_safe);
    assert_eq!(f.recovered.len(), 20, "{:?}", f.recovered);
    assert!(f.recovered.iter().all(|x| x.1 >= 21.0 - 1e-9));
}

/// Agent 10's clock jumps half a second ahead, or back, at 30 s: it takes its safe
/// output for the one tick whose interval the jump spoils (the neighbours' data looks
/// 0.5 s old, or the interval is negative) and runs its law at the next; the strip stays
/// converged.
#[test]
fn a_clock_jump_costs_one_tick() {
    for jump in ["0.5", "-0.5"] {
        let r = run(
            &format!("[[faults]]\nkind = \"clock_jump\"\nagent = 10\nt = 30.0\njump_s = {jump}\n"),
            60.0,
        );
        assert_eq!(r.outcome, Outcome::Converged, "{jump}: {}", r.reason);
        let f = &r.faults[0];
        assert_eq!(f.went_safe, vec![(10, 30.0)], "{jump}: {:?}", f.went_safe);
        assert_eq!(f.recovered.len(), 1, "{jump}: {:?}", f.recovered);
        assert!((f.recovered[0].1 - 30.01).abs() < 1e-9, "{:?}", f.recovered);
    }
}

/// A burst of random bearings at agent 10 for 1 s: the bearing tracker's gate and its
/// recovery rules (SPEC §11a) ride it out and the strip stays converged. Negative
/// control: the finite-difference path (the ideal world's default, no gate) turns the
/// same burst into an estimate collapse (docs/faults.md).
#[test]
fn an_outlier_burst_is_ridden_out_by_the_tracker_not_by_finite_differences() {
    let burst = "[[faults]]\nkind = \"outlier_burst\"\nagent = 10\nt = 30.0\nduration = 1.0\n";
    let text = format!("{}\n{burst}", strip20());
    let go = |filter: &str| {
        let set = [
            "duration=90".to_owned(),
            format!("sensors.bearing_filter={filter}"),
        ];
        let m = load_toml(&text, "strip20-burst", &set).unwrap_or_else(|e| panic!("{e}"));
        sim::run(&m, &mut NullRecorder, &mut |_| {}).expect("run")
    };
    let tracked = go("tracker");
    assert_eq!(tracked.outcome, Outcome::Converged, "{}", tracked.reason);
    let raw = go("none");
    assert_eq!(raw.outcome, Outcome::EstimateCollapse, "{}", raw.reason);
}

/// Agent 10's sensors freeze for 5 s at 2 s, while the strip is still forming: it acts on
/// stale bearings and velocity (its settle time grows from 10.6 s to about 27 s: the
/// freeze took effect) and the strip converges once its sensors are back.
#[test]
fn a_frozen_sensor_delays_the_formation_and_it_recovers() {
    let clean = run("", 60.0);
    let frozen = run(
        "[[faults]]\nkind = \"sensor_freeze\"\nagent = 10\nt = 2.0\nduration = 5.0\n",
        60.0,
    );
    assert_eq!(frozen.outcome, Outcome::Converged, "{}", frozen.reason);
    let (a, b) = (clean.settle_time.unwrap(), frozen.settle_time.unwrap());
    assert!(b > a + 10.0, "settled at {b} s, {a} s without the freeze");
}

/// Mistakes are refused naming the entry and the field.
#[test]
fn fault_mistakes_name_the_field() {
    let refused = |faults: &str, set: &[&str]| {
        let text = format!("{}\n{faults}", strip20());
        let set: Vec<String> = set.iter().map(|s| (*s).to_owned()).collect();
        match load_toml(&text, "strip20-faults", &set) {
            Ok(_) => panic!("accepted: {faults}"),
            Err(e) => e.to_string(),
        }
    };
    let e = refused("[[faults]]\nkind = \"meteor\"\nagent = 1\nt = 1.0\n", &[]);
    assert!(
        e.contains("faults[0].kind") && e.contains("agent_loss"),
        "{e}"
    );
    let e = refused(
        "[[faults]]\nkind = \"sensor_freeze\"\nagent = 1\nt = 1.0\n",
        &[],
    );
    assert!(e.contains("faults[0].duration"), "{e}");
    let e = refused(
        "[[faults]]\nkind = \"clock_jump\"\nagent = 1\nt = 1.0\n",
        &[],
    );
    assert!(e.contains("faults[0].jump_s"), "{e}");
    let e = refused(
        "[[faults]]\nkind = \"reboot\"\nagent = 1\nt = 1.0\nduration = 1.0\njump_s = 1.0\n",
        &[],
    );
    assert!(
        e.contains("faults[0].jump_s") && e.contains("clock_jump"),
        "{e}"
    );
    let e = refused("[[faults]]\nkind = \"reboot\"\nagent = 1\nt = 1.0\n", &[]);
    assert!(e.contains("faults[0].duration"), "{e}");
    let e = refused(
        "[[faults]]\nkind = \"agent_loss\"\nagent = 1\nt = 1.0\nduration = 2.0\n",
        &[],
    );
    assert!(
        e.contains("faults[0].duration") && e.contains("reboot"),
        "{e}"
    );
    let e = refused(
        "[[faults]]\nkind = \"agent_loss\"\nagent = 99\nt = 1.0\n",
        &[],
    );
    assert!(e.contains("faults[0].agent") && e.contains("99"), "{e}");
    let e = refused(
        "[[faults]]\nkind = \"reboot\"\nt = 1.0\nduration = 1.0\n",
        &[],
    );
    assert!(e.contains("faults[0].agent"), "{e}");
    let e = refused(
        "[[faults]]\nkind = \"agent_loss\"\nagent = 1\nt = -1.0\n",
        &[],
    );
    assert!(e.contains("faults[0].t"), "{e}");
    let e = refused(
        "[[faults]]\nkind = \"agent_loss\"\nagent = 1\nt = 1.0\n",
        &["mode=continuous"],
    );
    assert!(e.contains("faults") && e.contains("sampled"), "{e}");
}
