//! `ph_policy_*` and `ph_separation_guard`: the core's policies through the C API
//! (`src/policy.rs`), state kept in the caller's `ph_policy` between calls.

use ph_formation_ffi::ph_status;
use ph_formation_ffi::policy::{
    ph_policy, ph_policy_action, ph_policy_config, ph_policy_init, ph_policy_input,
    ph_policy_reason, ph_policy_reset, ph_policy_update, ph_separation_guard,
};

fn config() -> ph_policy_config {
    ph_policy_config {
        hold_timeout_ms: 100,
        fence: 1,
        fence_min: [0.0, 0.0],
        fence_max: [2.0, 2.0],
        battery_land: 3.2,
        battery_ms: 50,
        min_separation: 0.3,
    }
}

fn step(
    p: &mut ph_policy,
    c: &ph_policy_config,
    i: &ph_policy_input,
) -> (ph_status, ph_policy_action, ph_policy_reason) {
    let mut a = ph_policy_action::PH_POLICY_FLY;
    let mut w = ph_policy_reason::PH_POLICY_NONE;
    // SAFETY: valid pointers to live values.
    let s = unsafe { ph_policy_update(p, c, i, &mut a, &mut w) };
    (s, a, w)
}

fn healthy() -> ph_policy_input {
    ph_policy_input {
        dt_ms: 10,
        lost: 0,
        positioning: 1,
        position: [1.0, 1.0],
        battery: 4.0,
    }
}

#[test]
fn lost_holds_then_lands_and_reset_flies_again() {
    let mut p = ph_policy::default();
    // SAFETY: a valid pointer.
    assert_eq!(unsafe { ph_policy_init(&mut p) }, ph_status::PH_OK);
    let c = config();
    let lost = ph_policy_input {
        lost: 1,
        ..healthy()
    };
    // The first lost tick starts the timer at 0: 10 ticks of 10 ms hold, the 11th lands.
    for _ in 0..10 {
        let (s, a, w) = step(&mut p, &c, &lost);
        assert_eq!(s, ph_status::PH_OK);
        assert_eq!(a, ph_policy_action::PH_POLICY_HOLD);
        assert_eq!(w, ph_policy_reason::PH_POLICY_LOST);
    }
    let (_, a, w) = step(&mut p, &c, &lost);
    assert_eq!(
        (a, w),
        (
            ph_policy_action::PH_POLICY_LAND,
            ph_policy_reason::PH_POLICY_LOST_TIMEOUT
        )
    );
    assert_eq!((p.hold_ticks, p.landings), (10, 1));
    // The landing is kept in the C struct: still landing when heard again.
    assert_eq!(
        step(&mut p, &c, &healthy()).1,
        ph_policy_action::PH_POLICY_LAND
    );
    // SAFETY: a valid pointer.
    assert_eq!(unsafe { ph_policy_reset(&mut p) }, ph_status::PH_OK);
    assert_eq!(
        step(&mut p, &c, &healthy()).1,
        ph_policy_action::PH_POLICY_FLY
    );
    assert_eq!(p.landings, 1);
}

#[test]
fn bad_settings_state_and_pointers_are_refused() {
    let mut p = ph_policy::default();
    let bad = ph_policy_config {
        fence_min: [3.0, 0.0],
        ..config()
    };
    assert_eq!(step(&mut p, &bad, &healthy()).0, ph_status::PH_ERR_ARGUMENT);
    let mut corrupt = ph_policy {
        landing: 99,
        ..ph_policy::default()
    };
    assert_eq!(
        step(&mut corrupt, &config(), &healthy()).0,
        ph_status::PH_ERR_ARGUMENT
    );
    let mut a = ph_policy_action::PH_POLICY_FLY;
    let mut w = ph_policy_reason::PH_POLICY_NONE;
    // SAFETY: NULL is allowed and refused.
    let s = unsafe { ph_policy_update(&mut p, &config(), std::ptr::null(), &mut a, &mut w) };
    assert_eq!(s, ph_status::PH_ERR_NULL);
    // Negative control: the good settings are taken.
    assert_eq!(step(&mut p, &config(), &healthy()).0, ph_status::PH_OK);
}

#[test]
fn separation_guard_counts_what_it_changes() {
    let mut p = ph_policy::default();
    let own = [1.0f32, 1.0];
    let near = [[1.2f32, 1.0], [5.0, 5.0]];
    let mut v = [0.5f32, 0.25];
    // SAFETY: valid pointers; 2 pairs.
    let s = unsafe {
        ph_separation_guard(
            &mut p,
            &config(),
            own.as_ptr(),
            near.as_ptr().cast(),
            2,
            v.as_mut_ptr(),
        )
    };
    assert_eq!(s, ph_status::PH_OK);
    assert_eq!(v, [0.0, 0.25]);
    assert_eq!(p.guarded, 1);
    // Away from the neighbour: unchanged, not counted.
    let mut away = [-0.5f32, 0.0];
    // SAFETY: as above.
    let s = unsafe {
        ph_separation_guard(
            &mut p,
            &config(),
            own.as_ptr(),
            near.as_ptr().cast(),
            2,
            away.as_mut_ptr(),
        )
    };
    assert_eq!(s, ph_status::PH_OK);
    assert_eq!((away, p.guarded), ([-0.5, 0.0], 1));
    // More neighbours than an agent has: refused.
    // SAFETY: the count is checked before the pointer is read.
    let s = unsafe {
        ph_separation_guard(
            &mut p,
            &config(),
            own.as_ptr(),
            near.as_ptr().cast(),
            13,
            away.as_mut_ptr(),
        )
    };
    assert_eq!(s, ph_status::PH_ERR_ARGUMENT);
}
