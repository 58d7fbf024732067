//! `[policy]` (docs/scenarios.md "Safety policies"): the core's safety policies run in
//! the simulator's controller adapter (`ph_formation_sim::engine::policy`), and the run result
//! says per agent what they did (`RunResult::policy`). Each check has its negative
//! control; bad values are refused with file, field and reason.

use ph_formation_core::policy::PolicyReason;
use ph_formation_sim::engine::{self as sim, NullRecorder, RunResult};
use ph_formation_sim::load_toml;

/// crazyflie-app/formation.toml without its own `[policy]` and `[battery]` (each test
/// sets its policies), named after the file for the errors.
fn room(overrides: &[&str]) -> Result<ph_formation_sim::model::Model, String> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../crazyflie-app/formation.toml"
    );
    let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    let bare = text.split("\n[policy]").next().unwrap_or(&text);
    let mut o: Vec<String> = vec!["duration=10".to_owned()];
    o.extend(overrides.iter().map(|s| (*s).to_owned()));
    load_toml(bare, "formation.toml", &o).map_err(|e| e.to_string())
}

fn run(overrides: &[&str]) -> RunResult {
    let m = room(overrides).unwrap_or_else(|e| panic!("{e}"));
    sim::run(&m, &mut NullRecorder, &mut |_| {}).expect("run")
}

#[test]
fn without_a_policy_table_nothing_runs() {
    let r = run(&[]);
    assert!(r.policy.is_empty());
}

#[test]
fn leaving_the_fence_lands_and_inside_does_not() {
    // The square drifts at 0.5 m/s in x: it leaves x <= 2.5 m within 10 s.
    let moving = "velocity_reference=[0.5, 0.0]";
    let r = run(&[
        moving,
        "policy.fence_min=[-1.0, -1.0]",
        "policy.fence_max=[2.5, 3.0]",
    ]);
    println!("fence: {:?}, final {:?}", r.policy, r.final_positions);
    assert_eq!(r.policy.len(), 4);
    assert!(
        r.policy
            .iter()
            .any(|c| c.landings == 1 && c.last_landing == PolicyReason::Fence),
        "{:?}",
        r.policy
    );
    // The landed agents stopped inside a braking distance of the fence.
    for q in &r.final_positions {
        assert!(q[0] < 3.5, "{q:?}");
    }
    // Negative control: a fence the run stays inside.
    let r = run(&[
        moving,
        "policy.fence_min=[-1.0, -1.0]",
        "policy.fence_max=[20.0, 20.0]",
    ]);
    assert!(r.policy.iter().all(|c| c.landings == 0), "{:?}", r.policy);
}

#[test]
fn lost_radio_holds_then_lands_after_the_timeout() {
    let r = run(&["radio.loss=1.0", "policy.hold_timeout_s=1.5"]);
    for c in &r.policy {
        assert_eq!(c.landings, 1, "{c:?}");
        assert_eq!(c.last_landing, PolicyReason::LostTimeout);
        // Lost from the first tick: 1.5 s of 10 ms ticks held, the next one lands.
        assert_eq!(c.hold_ticks, 150, "{c:?}");
    }
    // Negative control: the radio works; the first ticks (nobody heard yet) hold only.
    let r = run(&["policy.hold_timeout_s=1.5"]);
    for c in &r.policy {
        assert_eq!(c.landings, 0, "{c:?}");
        assert!(c.hold_ticks < 5, "{c:?}");
    }
}

/// A battery from 4.0 V to 3.0 V over 20 s reads 3.2 V at 16 s (`BatteryModel`'s
/// closed form); below it for 1 s, every agent lands at 17 s: not in a 16.8 s run,
/// in a 17.3 s one, each with the reason `Battery`. Without the policy (negative
/// control) the battery lands nobody.
#[test]
fn a_low_battery_lands_when_the_voltage_says() {
    let battery = [
        "battery.full_v=4.0",
        "battery.empty_v=3.0",
        "battery.flight_time_s=20",
        "policy.battery_land_v=3.2",
        "policy.battery_land_s=1.0",
    ];
    let with = |duration: &str| {
        let mut o = battery.to_vec();
        o.push(duration);
        run(&o)
    };
    let before = with("duration=16.8");
    assert!(
        before.policy.iter().all(|c| c.landings == 0),
        "{:?}",
        before.policy
    );
    let after = with("duration=17.3");
    assert_eq!(after.policy.len(), 4);
    assert!(
        after
            .policy
            .iter()
            .all(|c| c.landings == 1 && c.last_landing == PolicyReason::Battery),
        "{:?}",
        after.policy
    );
    // The outcome names the landings and their cause.
    assert!(
        after
            .reason
            .contains("the safety policies landed 4 of 4 agents (low battery: agents 1, 2, 3, 4)"),
        "{}",
        after.reason
    );
    assert!(!before.reason.contains("landed"), "{}", before.reason);
    let off = run(&[
        battery[0],
        battery[1],
        battery[2],
        "policy.hold_timeout_s=2",
        "duration=17.3",
    ]);
    assert!(
        off.policy.iter().all(|c| c.landings == 0),
        "{:?}",
        off.policy
    );
}

#[test]
fn separation_guard_acts_only_inside_the_minimum() {
    // 3 m: every neighbour is inside it, so every approach is cut.
    let r = run(&["policy.min_separation=3.0"]);
    println!("min_separation 3 m: {:?}", r.policy);
    assert!(r.policy.iter().any(|c| c.guarded > 0), "{:?}", r.policy);
    let r = run(&["policy.min_separation=0.05"]);
    assert!(r.policy.iter().all(|c| c.guarded == 0), "{:?}", r.policy);
}

#[test]
fn bad_policy_values_are_refused_with_the_field() {
    for (set, field) in [
        ("policy.hold_timeout_s=-1.0", "policy.hold_timeout_s"),
        ("policy.min_separation=-0.1", "policy.min_separation"),
        ("policy.fence_min=[0.0, 0.0]", "policy.fence_min"),
        ("policy.battery_land_v=3.2", "policy.battery_land_v"),
        ("policy.battery_land_s=-1", "policy.battery_land_s"),
        ("battery.full_v=3.0", "battery.full_v"),
        ("battery.flight_time_s=0", "battery.flight_time_s"),
    ] {
        let e = room(&[set]).expect_err(set);
        assert!(
            e.contains(field) && e.contains("formation.toml"),
            "{set}: {e}"
        );
    }
    let e = room(&["policy.fence_min=[2.0, 0.0]", "policy.fence_max=[1.0, 3.0]"])
        .expect_err("inverted fence");
    assert!(e.contains("policy.fence_max"), "{e}");
    // A battery's voltages must fall in flight.
    let e = room(&[
        "battery.full_v=3.0",
        "battery.empty_v=3.5",
        "battery.flight_time_s=60",
    ])
    .expect_err("inverted battery");
    assert!(e.contains("battery.full_v"), "{e}");
    let e = room(&["policy.hold_timeout=1"]).expect_err("unknown key");
    assert!(e.contains("hold_timeout"), "{e}");
}
