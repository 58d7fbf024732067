/*
 * cfapp-flight: the app's flight states (src/flight.c) through every transition,
 * each with a negative control, and the commands (src/commands.c) against the model
 * of the firmware's commander and supervisor (firmware_model.c): no stale setpoint,
 * the supervisor always wins. Also the neighbours' positions across the 32-bit
 * millisecond clock's wrap (src/formation.c). Prints one line per check,
 *   FLIGHT ok <name>   or   FLIGHT FAIL <name>: <what>
 * then "FLIGHT checks=<n> failed=<m>"; exits 0 when none failed
 * (controller-ffi/tests/crazyflie_app.rs, flight_states_*).
 */
#include <stdio.h>

#include "commander.h"
#include "commands.h"
#include "crtp_commander_high_level.h"
#include "epoch.h"
#include "firmware_model.h"
#include "flight.h"
#include "formation.h"
#include "pm.h"
#include "supervisor.h"

static unsigned checks, failed;

static void check(int ok, const char *name, const char *what)
{
    checks++;
    if (ok)
        printf("FLIGHT ok %s\n", name);
    else {
        failed++;
        printf("FLIGHT FAIL %s: %s\n", name, what);
    }
}

/* Agent 1's policy; inputs of a healthy, flying drone at its initial position. */
static flight_policy pol;
static flight_inputs healthy(uint32_t now)
{
    flight_inputs in = {0};
    in.now_ms = now;
    in.flying = true;
    in.positioning = true;
    in.heard = in.neighbours = 2;
    in.position[0] = pol.start[0];
    in.position[1] = pol.start[1];
    in.vbat = 4.0f;
    return in;
}

/* The clock's starting points: boot, just before the 32-bit wrap, a year of uptime. */
static const uint32_t starts[] = {0u, 0xFFFFFF00u, (uint32_t)(31536000000ull % 4294967296ull)};

/* FORMATION at t0 (enable's rising edge after passing checks). */
static void to_formation(flight *f, uint32_t t0)
{
    flight_init(f);
    flight_inputs in = healthy(t0);
    (void)flight_update(f, &pol, &in);
    in.enable = 1;
    in.now_ms = t0 + 10u;
    (void)flight_update(f, &pol, &in);
}

static void idle_and_enable(void)
{
    flight f;
    flight_init(&f);
    flight_inputs in = healthy(0);
    int none = 1;
    for (uint32_t k = 0; k < 1000; k++) {
        in.now_ms = k * 10u;
        none &= flight_update(&f, &pol, &in) == FLIGHT_ACT_NONE && f.state == FLIGHT_IDLE;
    }
    check(none, "idle_sends_no_setpoint", "a setpoint without enable");
    in.enable = 1;
    flight_action a = flight_update(&f, &pol, &in);
    check(a == FLIGHT_ACT_SETPOINT && f.state == FLIGHT_FORMATION && f.fault == FLIGHT_FAULT_NONE,
          "enable_starts_the_formation", "no formation after enable with the checks passed");
    in.now_ms += 10u;
    a = flight_update(&f, &pol, &in);
    check(a == FLIGHT_ACT_SETPOINT && f.state == FLIGHT_FORMATION, "formation_sends_setpoints",
          "no setpoint in formation");
    /* Negative control: enable dropped hands control back (RELEASE), idle again. */
    in.enable = 0;
    in.now_ms += 10u;
    a = flight_update(&f, &pol, &in);
    check(a == FLIGHT_ACT_RELEASE && f.state == FLIGHT_IDLE && f.fault == FLIGHT_FAULT_NONE,
          "disable_releases_to_the_high_level_commander", "disable did not release");
    in.now_ms += 10u;
    check(flight_update(&f, &pol, &in) == FLIGHT_ACT_NONE, "idle_after_disable_sends_nothing",
          "a command after the release");
}

/* Each pre-flight check refuses on its own (with its reason), and the same inputs with
 * that check passing start the formation (the negative control). */
static void preflight(void)
{
    static const struct {
        const char *name;
        flight_fault fault;
    } cases[] = {
        {"preflight_refuses_on_the_ground", FLIGHT_REFUSED_NOT_FLYING},
        {"preflight_refuses_without_positioning", FLIGHT_REFUSED_POSITIONING},
        {"preflight_refuses_unheard_neighbour", FLIGHT_REFUSED_NEIGHBOURS},
        {"preflight_refuses_away_from_start", FLIGHT_REFUSED_AWAY},
    };
    for (unsigned c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        flight f;
        flight_init(&f);
        flight_inputs in = healthy(0);
        in.enable = 1;
        switch (cases[c].fault) {
        case FLIGHT_REFUSED_NOT_FLYING: in.flying = false; break;
        case FLIGHT_REFUSED_POSITIONING: in.positioning = false; break;
        case FLIGHT_REFUSED_NEIGHBOURS: in.heard = 1; break;
        default: in.position[0] += 0.31f; break;
        }
        flight_action a = flight_update(&f, &pol, &in);
        int refused = a == FLIGHT_ACT_NONE && f.state == FLIGHT_IDLE &&
                      f.fault == cases[c].fault && f.refusals == 1;
        /* Enable held at 1 while the cause is fixed: still idle (an edge is needed). */
        flight_inputs good = healthy(10);
        good.enable = 1;
        int held = flight_update(&f, &pol, &good) == FLIGHT_ACT_NONE && f.state == FLIGHT_IDLE;
        /* Negative control: 0 then 1 with the cause fixed starts the formation. */
        good.enable = 0;
        good.now_ms = 20;
        (void)flight_update(&f, &pol, &good);
        good.enable = 1;
        good.now_ms = 30;
        int starts_ok = flight_update(&f, &pol, &good) == FLIGHT_ACT_SETPOINT &&
                        f.state == FLIGHT_FORMATION;
        check(refused && held && starts_ok, cases[c].name,
              refused ? (held ? "no start once fixed" : "started without a new edge")
                      : "not refused with its reason");
    }
}

/* Lost neighbours or radio: HOLD at once (the position held), back to FORMATION when
 * heard again, LANDING after hold_timeout_ms, from every clock start. */
static void lost(void)
{
    for (unsigned s = 0; s < sizeof starts / sizeof starts[0]; s++) {
        uint32_t t0 = starts[s];
        flight f;
        to_formation(&f, t0);
        flight_inputs in = healthy(t0 + 20u);
        in.enable = 1;
        in.controller_safe = true;
        flight_action a = flight_update(&f, &pol, &in);
        int hold = a == FLIGHT_ACT_HOLD && f.state == FLIGHT_HOLD && f.fault == FLIGHT_FAULT_LOST &&
                   f.hold[0] == in.position[0] && f.hold[1] == in.position[1];
        check(hold, s == 0 ? "lost_holds" : s == 1 ? "lost_holds_across_the_wrap"
                                                    : "lost_holds_after_a_year",
              "no hold when lost");
        uint32_t lost_at = in.now_ms;
        /* Negative control: just before the timeout, still holding. */
        int holding = 1;
        for (in.now_ms = lost_at + 10u; in.now_ms != lost_at + pol.core.hold_timeout_ms;
             in.now_ms += 10u)
            holding &= flight_update(&f, &pol, &in) == FLIGHT_ACT_HOLD;
        a = flight_update(&f, &pol, &in);
        int land = a == FLIGHT_ACT_LAND && f.state == FLIGHT_LANDING &&
                   f.fault == FLIGHT_FAULT_LOST_TIMEOUT;
        check(holding && land,
              s == 0 ? "lost_lands_after_the_timeout"
                     : s == 1 ? "lost_lands_after_the_timeout_across_the_wrap"
                              : "lost_lands_after_the_timeout_after_a_year",
              holding ? "no landing at the timeout" : "landed before the timeout");
    }
    /* HOLD -> FORMATION when heard again. */
    flight f;
    to_formation(&f, 0);
    flight_inputs in = healthy(20);
    in.enable = 1;
    in.controller_safe = true;
    (void)flight_update(&f, &pol, &in);
    in.controller_safe = false;
    in.now_ms = 30;
    flight_action a = flight_update(&f, &pol, &in);
    check(a == FLIGHT_ACT_SETPOINT && f.state == FLIGHT_FORMATION && f.restart,
          "heard_again_resumes_the_formation", "no resume");
    /* HOLD -> IDLE on disable. */
    in.controller_safe = true;
    in.now_ms = 40;
    (void)flight_update(&f, &pol, &in);
    in.enable = 0;
    in.now_ms = 50;
    a = flight_update(&f, &pol, &in);
    check(a == FLIGHT_ACT_RELEASE && f.state == FLIGHT_IDLE, "disable_while_holding_releases",
          "no release from hold");
}

typedef void (*spoil_fn)(flight_inputs *in, int bad);
static void out_of_fence(flight_inputs *in, int bad)
{
    in->position[0] = bad ? FORMATION_FENCE_MAX_X + 0.01f : FORMATION_FENCE_MAX_X - 0.01f;
}
static void nan_position(flight_inputs *in, int bad)
{
    in->position[1] = bad ? __builtin_nanf("") : 1.0f;
}
static void positioning_lost(flight_inputs *in, int bad)
{
    in->positioning = !bad;
}

/* A policy that lands at once: the bad input lands from FORMATION and from HOLD; the
 * same input just inside the limit (negative control) keeps flying. */
static void lands(const char *name, spoil_fn spoil, flight_fault why)
{
    for (int from_hold = 0; from_hold < 2; from_hold++) {
        flight f;
        to_formation(&f, 0);
        flight_inputs in = healthy(20);
        in.enable = 1;
        in.controller_safe = from_hold;
        (void)flight_update(&f, &pol, &in);
        flight_state before = f.state;
        spoil(&in, 0);
        in.now_ms = 30;
        flight_action ok = flight_update(&f, &pol, &in);
        spoil(&in, 1);
        in.now_ms = 40;
        flight_action a = flight_update(&f, &pol, &in);
        int good = (ok == FLIGHT_ACT_SETPOINT || ok == FLIGHT_ACT_HOLD) && f.state == FLIGHT_LANDING;
        check(good && before == (from_hold ? FLIGHT_HOLD : FLIGHT_FORMATION) &&
                  a == FLIGHT_ACT_LAND && f.fault == why,
              name, from_hold ? "no landing from hold" : "no landing from formation");
    }
}

static void battery(void)
{
    for (unsigned s = 0; s < sizeof starts / sizeof starts[0]; s++) {
        flight f;
        to_formation(&f, starts[s]);
        flight_inputs in = healthy(starts[s] + 20u);
        in.enable = 1;
        /* Negative control: a dip shorter than vbat_ms. */
        in.vbat = pol.core.battery_land - 0.1f;
        int flying = 1;
        uint32_t t = in.now_ms;
        for (; t != in.now_ms + pol.core.battery_ms - 10u; t += 10u) {
            flight_inputs k = in;
            k.now_ms = t;
            flying &= flight_update(&f, &pol, &k) == FLIGHT_ACT_SETPOINT;
        }
        flight_inputs k = in;
        k.now_ms = t;
        k.vbat = 4.0f;
        flying &= flight_update(&f, &pol, &k) == FLIGHT_ACT_SETPOINT;
        /* Low for vbat_ms: land. */
        uint32_t t1 = t + 10u, u = t1;
        flight_action a = FLIGHT_ACT_SETPOINT;
        for (; a == FLIGHT_ACT_SETPOINT && u != t1 + pol.core.battery_ms + 100u; u += 10u) {
            k.now_ms = u;
            k.vbat = pol.core.battery_land - 0.1f;
            a = flight_update(&f, &pol, &k);
        }
        check(flying && a == FLIGHT_ACT_LAND && f.fault == FLIGHT_FAULT_BATTERY &&
                  u - 10u - t1 == pol.core.battery_ms,
              s == 0 ? "low_battery_lands" : s == 1 ? "low_battery_lands_across_the_wrap"
                                                     : "low_battery_lands_after_a_year",
              flying ? "no landing after vbat_ms" : "a short dip landed");
    }
}

/* The supervisor stops flying (emergency stop, crash, landed): IDLE at once with the
 * priority relaxed, from every state; a landing keeps its reason. */
static void supervisor(void)
{
    for (int st = 1; st <= 3; st++) {
        flight f;
        to_formation(&f, 0);
        flight_inputs in = healthy(20);
        in.enable = 1;
        in.controller_safe = st == 2;
        in.positioning = st != 3; /* LANDING (positioning lost) */
        (void)flight_update(&f, &pol, &in);
        flight_state was = f.state;
        flight_fault reason = f.fault;
        in.now_ms = 30;
        /* Negative control: still flying, no change. */
        flight_action still = flight_update(&f, &pol, &in);
        in.flying = false;
        in.now_ms = 40;
        flight_action a = flight_update(&f, &pol, &in);
        int ok = was == (flight_state)st && still != FLIGHT_ACT_RELAX && a == FLIGHT_ACT_RELAX &&
                 f.state == FLIGHT_IDLE &&
                 f.fault == (st == 3 ? reason : FLIGHT_FAULT_SUPERVISOR);
        in.now_ms = 50;
        ok &= flight_update(&f, &pol, &in) == FLIGHT_ACT_NONE;
        check(ok, st == 1 ? "supervisor_stops_the_formation"
                  : st == 2 ? "supervisor_stops_the_hold"
                            : "landing_ends_when_landed",
              "not idle with the priority relaxed");
    }
    /* A landing is not cancelled by enable = 0. */
    flight f;
    to_formation(&f, 0);
    flight_inputs in = healthy(20);
    in.enable = 1;
    in.positioning = false;
    (void)flight_update(&f, &pol, &in);
    in.enable = 0;
    in.now_ms = 30;
    flight_action a = flight_update(&f, &pol, &in);
    check(f.state == FLIGHT_LANDING && a == FLIGHT_ACT_NONE, "disable_does_not_cancel_a_landing",
          "landing cancelled");
}

/* ---- against the firmware model ---- */

/* One app tick: the flight states and their command, then the stabilizer. */
static flight fl;
static flight_action app_tick(uint8_t enable, bool lost_now)
{
    flight_inputs in = {0};
    in.now_ms = fw.now_ms;
    in.enable = enable;
    in.flying = supervisorIsFlying() && !supervisorIsLocked();
    in.positioning = fw.positioning;
    in.heard = in.neighbours = 2;
    in.controller_safe = lost_now;
    in.position[0] = pol.start[0];
    in.position[1] = pol.start[1];
    in.vbat = pmGetBatteryVoltage();
    flight_action a = flight_update(&fl, &pol, &in);
    static const float v[2] = {0.1f, 0.0f};
    commands_apply(a, &fl, v, in.position);
    fw_stabilizer_tick();
    return a;
}

typedef enum { END_DISABLE_THEN_LAND, END_BATTERY, END_LOST, END_STOP } ending;

/* Take-off (high-level), 2 s later enable, 5 s of formation, then the ending; 20 s in
 * all. */
static void operate(ending how, uint32_t t0, uint32_t *app_after_stop)
{
    fw_reset(t0);
    flight_init(&fl);
    fw_takeoff(0.5f, 2.0f);
    uint8_t enable = 0;
    *app_after_stop = 0;
    uint32_t stop_setpoints = 0;
    for (uint32_t k = 0; k < 2000; k++) {
        if (k == 200)
            enable = 1;
        bool lost_now = how == END_LOST && k >= 700;
        if (k == 700 && how == END_DISABLE_THEN_LAND)
            enable = 0;
        if (k == 900 && how == END_DISABLE_THEN_LAND)
            (void)crtpCommanderHighLevelLand(0.0f, 3.0f); /* the client lands */
        if (k == 700 && how == END_BATTERY)
            fw.vbat = 3.0f;
        if (k == 700 && how == END_STOP) {
            fw_emergency_stop();
            stop_setpoints = fw.app_setpoints;
        }
        (void)app_tick(enable, lost_now);
    }
    if (how == END_STOP)
        *app_after_stop = fw.app_setpoints - stop_setpoints;
}

static void against_the_firmware(void)
{
    static const char *const names[] = {
        "operate_disable_then_land", "operate_low_battery_lands",
        "operate_lost_holds_then_lands", "operate_emergency_stop_wins"};
    for (unsigned s = 0; s < sizeof starts / sizeof starts[0]; s++)
        for (int how = 0; how < 4; how++) {
            uint32_t after = 0;
            operate((ending)how, starts[s], &after);
            int landed = !fw.flying;
            int ok = fw.wdt_warnings == 0 && fw.wdt_cuts == 0 && fw.null_flying == 0 &&
                     fw.app_setpoints >= 500 && landed && fl.state == FLIGHT_IDLE;
            if (how == END_STOP)
                ok &= after == 0 && fw.locked && fl.fault == FLIGHT_FAULT_SUPERVISOR;
            else
                ok &= !fw.locked && fw.hl_setpoints > 0;
            if (how == END_BATTERY)
                ok &= fl.fault == FLIGHT_FAULT_BATTERY;
            if (how == END_LOST)
                ok &= fl.fault == FLIGHT_FAULT_LOST_TIMEOUT;
            char what[160];
            snprintf(what, sizeof what,
                     "warnings=%u cuts=%u null=%u app=%u hl=%u flying=%d locked=%d state=%s "
                     "fault=%s after_stop=%u",
                     (unsigned)fw.wdt_warnings, (unsigned)fw.wdt_cuts, (unsigned)fw.null_flying,
                     (unsigned)fw.app_setpoints, (unsigned)fw.hl_setpoints, (int)fw.flying,
                     (int)fw.locked, flight_state_str(fl.state), flight_fault_str(fl.fault),
                     (unsigned)after);
            if (s == 0)
                check(ok, names[how], what);
            else {
                char name[96];
                snprintf(name, sizeof name, "%s_%s", names[how],
                         s == 1 ? "across_the_wrap" : "after_a_year");
                check(ok, name, what);
            }
        }
}

/* Negative controls of the model: an app that stops sending in formation leaves a
 * stale setpoint (level-out after 500 ms, cut after 2 s); one that only relaxes the
 * priority hands the stabilizer the stopped planner's null setpoint. */
static void the_model_sees_the_bugs(void)
{
    fw_reset(0);
    flight_init(&fl);
    fw_takeoff(0.5f, 2.0f);
    for (uint32_t k = 0; k < 300; k++)
        (void)app_tick(k >= 200, false);
    for (uint32_t k = 0; k < 300; k++)
        fw_stabilizer_tick(); /* the app silent */
    check(fw.wdt_warnings > 0 && fw.wdt_cuts == 1 && fw.locked,
          "model_catches_a_stale_setpoint", "the model missed a silent app");
    fw_reset(0);
    flight_init(&fl);
    fw_takeoff(0.5f, 2.0f);
    for (uint32_t k = 0; k < 300; k++)
        (void)app_tick(k >= 200, false);
    commanderRelaxPriority(); /* without the high-level command */
    for (uint32_t k = 0; k < 10; k++)
        fw_stabilizer_tick();
    check(fw.null_flying > 0, "model_catches_a_bare_relax", "the model missed a bare relax");
}

/* Agent `id` of formation.c's struct (crc16, or auth with `auth`) in `memory`. */
static ph_agent *agent_of(uint8_t *memory, uint8_t id, int auth)
{
    static ph_config c;
    if (formation_config(id, &c) != PH_OK)
        return NULL;
    if (auth) {
        c.integrity = PH_INTEGRITY_AUTH;
        for (int k = 0; k < 16; k++)
            c.auth_key[k] = (uint8_t)(0xA5 ^ k);
    }
    ph_agent *a = (ph_agent *)memory;
    return ph_agent_init(a, PH_AGENT_SIZE, &c) == PH_OK ? a : NULL;
}

static uint8_t mem1[PH_AGENT_SIZE] __attribute__((aligned(PH_AGENT_ALIGN)));
static uint8_t mem2[PH_AGENT_SIZE] __attribute__((aligned(PH_AGENT_ALIGN)));

/* Under auth the app keeps a neighbour's position only from a packet with the swarm's
 * tag and a new counter: a spoofed one (changed x) and a replayed one are refused; the
 * genuine one (negative control) is kept. */
static void positions_under_auth(void)
{
    ph_agent *rx = agent_of(mem1, 1, 1), *tx = agent_of(mem2, 2, 1);
    formation_state st;
    if (rx == NULL || tx == NULL || formation_state_init(&st, rx) != PH_OK) {
        check(0, "positions_under_auth", "no agents");
        return;
    }
    uint8_t pkt[FORMATION_POSITION_LEN], spoof[FORMATION_POSITION_LEN];
    float q[2] = {1.0f, 2.0f};
    size_t n = formation_position_packet(tx, q, ((uint64_t)3 << 32) | 7u, pkt, sizeof pkt);
    __builtin_memcpy(spoof, pkt, n);
    spoof[3] ^= 0x40; /* another x, the same tag */
    bool spoofed = formation_position_received(&st, rx, spoof, n, 0u);
    bool genuine = formation_position_received(&st, rx, pkt, n, 0u);
    bool replayed = formation_position_received(&st, rx, pkt, n, 10u);
    check(n == 27 && !spoofed && genuine, "spoofed_position_refused_under_auth",
          "a spoofed position was kept, or the genuine one refused");
    check(!replayed, "replayed_position_refused_under_auth", "a replayed position was kept");
}

/* The neighbours' positions: fresh for FORMATION_POSITION_MAX_AGE_MS across the wrap;
 * expired every tick, a position heard once does not come back when the clock wraps
 * round to the same value (negative control: without formation_expire it would). */
static void positions_across_the_wrap(void)
{
    formation_state st;
    __builtin_memset(&st, 0, sizeof st);
    st.peer_count = 1;
    st.peers[0].id = 2;
    ph_agent *rx = agent_of(mem1, 1, 0), *tx = agent_of(mem2, 2, 0);
    uint8_t pkt[FORMATION_POSITION_LEN];
    float q[2] = {1.0f, 2.0f};
    size_t n = formation_position_packet(tx, q, 0, pkt, sizeof pkt);
    uint32_t t = 0xFFFFFFF0u;
    (void)formation_position_received(&st, rx, pkt, n, t);
    int fresh = formation_heard(&st, t + 50u) == 1 && formation_heard(&st, t + 100u) == 1 &&
                formation_heard(&st, t + 101u) == 0;
    check(fresh, "position_age_across_the_wrap", "wrong age across the wrap");
    /* Negative control: the float-seconds clock the app had before (app.c: T2M(now) /
     * 1000.0f) calls a 10 ms old position stale after 12 days of uptime (float's step
     * there is 0.125 s), and after a year (step 2 s). */
    volatile float day12 = 12.0f * 86400.0f, year = 365.0f * 86400.0f;
    check(!((day12 + 0.01f) - day12 <= 0.01f + 1e-4f && (day12 + 0.01f) - day12 > 0.0f) &&
              !((year + 0.01f) - year > 0.0f),
          "float_seconds_would_lose_positions", "float seconds resolve 10 ms at 12 days");
    formation_state copy = st;
    formation_expire(&st, t + 200u);
    /* 2^32 ms later the clock reads t + 50 again. */
    check(formation_heard(&st, t + 50u) == 0 && formation_heard(&copy, t + 50u) == 1,
          "expired_position_stays_stale_after_the_wrap", "an old position looked fresh");
}

/* The separation guard (the core's) on the app's setpoint: the approach to a close
 * neighbour is removed and counted; a far one (negative control) changes nothing. */
static void guard(void)
{
    formation_state st;
    __builtin_memset(&st, 0, sizeof st);
    st.peer_count = 1;
    st.peers[0].id = 2;
    uint8_t pkt[FORMATION_POSITION_LEN];
    float own[2] = {1.0f, 1.0f};
    ph_agent *rx = agent_of(mem1, 1, 0), *tx = agent_of(mem2, 2, 0);
    for (int close = 1; close >= 0; close--) {
        float q[2] = {own[0] + (close ? 0.2f : 0.5f), own[1]};
        size_t n = formation_position_packet(tx, q, 0, pkt, sizeof pkt);
        (void)formation_position_received(&st, rx, pkt, n, 1000u);
        ph_policy policy;
        (void)ph_policy_init(&policy);
        float v[2] = {0.4f, 0.3f};
        formation_guard(&st, 1010u, &policy, &pol.core, own, v);
        if (close)
            check(v[0] == 0.0f && v[1] == 0.3f && policy.guarded == 1,
                  "separation_guard_stops_the_approach", "the approach was kept");
        else
            check(v[0] == 0.4f && v[1] == 0.3f && policy.guarded == 0,
                  "separation_guard_leaves_far_neighbours", "a far neighbour changed the setpoint");
    }
}

/* Settings the core refuses land at once (negative control: the shipped ones fly). */
static void refused_settings(void)
{
    flight_policy bad = pol;
    bad.core.fence_min[0] = bad.core.fence_max[0] + 1.0f;
    for (int b = 0; b < 2; b++) {
        flight f;
        flight_init(&f);
        flight_inputs in = healthy(0);
        in.enable = 1;
        (void)flight_update(&f, b ? &bad : &pol, &in);
        in.now_ms = 10;
        flight_action a = flight_update(&f, b ? &bad : &pol, &in);
        if (b)
            check(a == FLIGHT_ACT_LAND && f.fault == FLIGHT_FAULT_SETTINGS,
                  "refused_policy_settings_land", "flew with refused settings");
        else
            check(a == FLIGHT_ACT_SETPOINT, "shipped_policy_settings_fly", "shipped settings land");
    }
}

/* The boot epoch: 1, 2, ... across reboots (the storage survives them); a storage
 * that fails gives none. */
static void boot_epochs(void)
{
    uint32_t e1 = 0, e2 = 0, e3 = 0;
    bool ok = formation_next_boot_epoch(&e1) && formation_next_boot_epoch(&e2);
    fw_storage_fails = true;
    bool refused = !formation_next_boot_epoch(&e3);
    fw_storage_fails = false;
    check(ok && e2 == e1 + 1 && refused, "boot_epoch_increments_and_persists",
          "the epoch does not increment, or a failed store gave one");
}

/* Agent 1 of formation.c's struct with auth; `memory` its PH_AGENT_SIZE bytes. */
static ph_agent *auth_agent(uint8_t *memory, uint8_t id)
{
    static ph_config c;
    if (formation_config(id, &c) != PH_OK)
        return NULL;
    c.integrity = PH_INTEGRITY_AUTH;
    for (int k = 0; k < 16; k++)
        c.auth_key[k] = (uint8_t)(0xA5 ^ k);
    ph_agent *a = (ph_agent *)memory;
    return ph_agent_init(a, PH_AGENT_SIZE, &c) == PH_OK ? a : NULL;
}

/* The first frame of a's broadcast, received by b: its status. */
static ph_status first_frame(ph_agent *a, ph_agent *b)
{
    uint8_t frames[PH_MAX_FRAMES_PER_TICK][PH_MAX_FRAME_LEN];
    uint8_t lens[PH_MAX_FRAMES_PER_TICK];
    size_t n = 0;
    if (ph_frames(a, frames, lens, PH_MAX_FRAMES_PER_TICK, &n) != PH_OK || n == 0)
        return PH_ERR_ARGUMENT;
    return ph_receive(b, frames[0], lens[0]);
}

/* Under auth a rebooted agent is heard again from its first frame with the next boot
 * epoch; rebooted with the same epoch (negative control: no persisted epoch), its
 * frames are replays to its neighbour. */
static void reboot_under_auth(void)
{
    static uint8_t ma[PH_AGENT_SIZE] __attribute__((aligned(PH_AGENT_ALIGN)));
    static uint8_t mb[PH_AGENT_SIZE] __attribute__((aligned(PH_AGENT_ALIGN)));
    ph_agent *b = auth_agent(mb, 3);
    uint32_t e = 0;
    ph_agent *a = auth_agent(ma, 1);
    bool setup = a != NULL && b != NULL && formation_next_boot_epoch(&e) &&
                 ph_agent_set_boot_epoch(a, e) == PH_OK;
    ph_status before = setup ? first_frame(a, b) : PH_ERR_ARGUMENT;
    /* Reboot with the persisted epoch + 1. */
    a = auth_agent(ma, 1);
    uint32_t e2 = 0;
    bool next = a != NULL && formation_next_boot_epoch(&e2) && ph_agent_set_boot_epoch(a, e2) == PH_OK;
    ph_status after = next ? first_frame(a, b) : PH_ERR_ARGUMENT;
    /* Reboot with the same epoch again. */
    a = auth_agent(ma, 1);
    ph_status same = a != NULL && ph_agent_set_boot_epoch(a, e2) == PH_OK ? first_frame(a, b)
                                                                           : PH_ERR_ARGUMENT;
    char what[128];
    snprintf(what, sizeof what, "before %s, after reboot %s, same epoch %s", ph_status_str(before),
             ph_status_str(after), ph_status_str(same));
    check(before == PH_OK && after == PH_OK, "rebooted_agent_heard_at_once_under_auth", what);
    check(same == PH_ERR_FRAME_REPLAYED, "reboot_without_a_new_epoch_is_a_replay", what);
}

/* The positioning check reads the Kalman filter's variances (the model's). */
static void positioning(void)
{
    fw_reset(0);
    int locked = formation_positioning_locked();
    fw.positioning = false;
    check(locked && !formation_positioning_locked(), "positioning_from_the_kalman_variances",
          "locked does not follow kalman.varPX, varPY");
}

int main(void)
{
    if (!formation_policy(1, &pol)) {
        printf("FLIGHT FAIL policy: no agent 1\n");
        return 1;
    }
    /* The policies come from the blob (formation.toml's [policy], host-sim export):
     * the same values as the FORMATION_USE_STRUCT build's defines. */
    check(pol.core.hold_timeout_ms == FORMATION_HOLD_TIMEOUT_MS && pol.core.fence == 1 &&
              pol.core.fence_min[0] == FORMATION_FENCE_MIN_X &&
              pol.core.fence_min[1] == FORMATION_FENCE_MIN_Y &&
              pol.core.fence_max[0] == FORMATION_FENCE_MAX_X &&
              pol.core.fence_max[1] == FORMATION_FENCE_MAX_Y &&
              pol.core.battery_land == FORMATION_VBAT_LAND &&
              pol.core.battery_ms == FORMATION_VBAT_MS &&
              pol.core.min_separation == FORMATION_MIN_SEPARATION &&
              pol.start_tolerance == FORMATION_START_TOLERANCE,
          "policy_from_the_blob", "the blob's [policy] differs from formation.h's defines");
    idle_and_enable();
    preflight();
    lost();
    lands("fence_lands", out_of_fence, FLIGHT_FAULT_FENCE);
    lands("non_finite_position_lands", nan_position, FLIGHT_FAULT_FENCE);
    lands("positioning_lost_lands", positioning_lost, FLIGHT_FAULT_POSITIONING);
    battery();
    supervisor();
    against_the_firmware();
    the_model_sees_the_bugs();
    positions_across_the_wrap();
    positioning();
    guard();
    refused_settings();
    boot_epochs();
    reboot_under_auth();
    positions_under_auth();
    /* The policies' initial positions (crazyflie_app.rs compares formation.toml). */
    for (uint8_t id = 1; id <= 4; id++) {
        flight_policy p;
        if (formation_policy(id, &p))
            printf("FLIGHT start id=%u x=%g y=%g\n", (unsigned)id, (double)p.start[0],
                   (double)p.start[1]);
    }
    printf("FLIGHT checks=%u failed=%u\n", checks, failed);
    return failed == 0 ? 0 : 1;
}
