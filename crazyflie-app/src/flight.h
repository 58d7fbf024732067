/*
 * The app's flight states (docs/crazyflie.md "Operating the swarm"): what the app
 * does with the commander, tick by tick, free of the firmware so that the host tests
 * drive every transition (crazyflie-app/test/flight_test.c).
 *
 *   IDLE       no setpoints (the high-level commander or the client flies);
 *   FORMATION  the formation's velocity setpoints at COMMANDER_PRIORITY_EXTRX;
 *   HOLD       neighbours or radio lost: a position hold at EXTRX, for at most
 *              hold_timeout_ms;
 *   LANDING    by policy: control handed back (commanderRelaxPriority) and the
 *              high-level commander told to land.
 *
 * IDLE -> FORMATION on a rising edge of the parameter formation.enable, only after the
 * pre-flight checks pass (flying, positioning locked, every neighbour heard, own
 * position near its initial position); a refusal stays IDLE with the reason in
 * `fault`. FORMATION or HOLD -> IDLE when enable drops: control handed back and the
 * high-level commander told to hover where the drone is, so no setpoint is left to go
 * stale (the supervisor levels out after 500 ms and cuts the motors after 2 s without
 * a new setpoint: crazyflie-firmware src/modules/src/supervisor.c:58-59, 481-487).
 * Whatever the state: the supervisor not flying (emergency stop, crash, landed,
 * locked) -> IDLE at once, the priority relaxed, no setpoint ever again until the
 * next rising edge of enable.
 *
 * The policies (hold, then land when lost; fence; positioning; battery) are the
 * core's, through the C API (ph_policy_update, controller-core/src/policy.rs): the
 * simulator runs the same code (host-sim's [policy] keys, docs/scenarios.md).
 */
#pragma once

#include <stdbool.h>
#include <stdint.h>

#include "ph_formation.h"

typedef enum {
    FLIGHT_IDLE = 0,
    FLIGHT_FORMATION = 1,
    FLIGHT_HOLD = 2,
    FLIGHT_LANDING = 3,
} flight_state;

/* Why the state is what it is (the log variable formation.fault). */
typedef enum {
    FLIGHT_FAULT_NONE = 0,
    FLIGHT_REFUSED_NOT_FLYING = 1,  /* enable before take-off */
    FLIGHT_REFUSED_POSITIONING = 2, /* positioning not locked */
    FLIGHT_REFUSED_NEIGHBOURS = 3,  /* a neighbour's position not heard */
    FLIGHT_REFUSED_AWAY = 4,        /* own position not near its initial position */
    FLIGHT_FAULT_SUPERVISOR = 5,    /* the supervisor stopped flying (stop, crash, lock) */
    FLIGHT_FAULT_LOST = 6,          /* holding: neighbours or radio lost */
    FLIGHT_FAULT_LOST_TIMEOUT = 7,  /* landing: lost for hold_timeout_ms */
    FLIGHT_FAULT_FENCE = 8,         /* landing: outside the flight volume */
    FLIGHT_FAULT_BATTERY = 9,       /* landing: battery low */
    FLIGHT_FAULT_POSITIONING = 10,  /* landing: positioning lost in flight */
    FLIGHT_FAULT_SETTINGS = 11,     /* landing: ph_policy_update refused the settings */
} flight_fault;

/* What the app does with the commander this tick (app.c, flight_apply()). */
typedef enum {
    FLIGHT_ACT_NONE = 0,     /* nothing: no setpoint of ours */
    FLIGHT_ACT_SETPOINT = 1, /* the formation's velocity setpoint */
    FLIGHT_ACT_HOLD = 2,     /* hold the position `hold` */
    FLIGHT_ACT_RELEASE = 3,  /* relax the priority, high-level commander hovers here */
    FLIGHT_ACT_LAND = 4,     /* relax the priority, high-level commander lands */
    FLIGHT_ACT_RELAX = 5,    /* relax the priority only (the supervisor stopped flying) */
} flight_action;

/* The policies' settings: the core's (hold timeout, fence, battery, separation) and
 * the pre-flight check's reference. */
typedef struct {
    ph_policy_config core;
    float start_tolerance; /* m: pre-flight, own position from its initial one */
    float start[2];        /* own initial position (the scenario's) */
} flight_policy;

/* What the app knows at one tick. */
typedef struct {
    uint32_t now_ms;         /* the control clock (wraps after 49.7 days: harmless) */
    uint8_t enable;          /* the parameter formation.enable */
    bool flying;             /* supervisorIsFlying() && !supervisorIsLocked() */
    bool positioning;        /* the estimator's position is locked */
    uint8_t heard;           /* neighbours whose position is fresh */
    uint8_t neighbours;      /* neighbours in the formation */
    bool controller_safe;    /* this tick's ph_step gave the safe output */
    float position[2];       /* own estimate (m) */
    float vbat;              /* V */
} flight_inputs;

typedef struct {
    flight_state state;
    flight_fault fault;
    uint8_t last_enable;
    uint32_t last_ms;     /* the previous update (the policies' dt) */
    ph_policy policy;     /* the core's policies: timers and counts */
    bool restart;         /* FORMATION entered this tick: restart the actuator */
    float hold[2];        /* the position held in HOLD */
    uint32_t refusals;    /* enable refused by the pre-flight checks */
    uint32_t transitions; /* state changes */
} flight;

/* Starts IDLE. */
void flight_init(flight *f);

/* One tick: the new state in f->state, what to do returned. */
flight_action flight_update(flight *f, const flight_policy *p, const flight_inputs *in);

/* The name of a state or fault (console output). */
const char *flight_state_str(flight_state s);
const char *flight_fault_str(flight_fault f);
