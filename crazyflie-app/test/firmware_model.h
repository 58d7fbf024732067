/*
 * A model of the Crazyflie firmware's commander, high-level commander and supervisor,
 * enough to test that the app never leaves a stale setpoint and that the supervisor
 * always wins (test/flight_test.c). Written from crazyflie-firmware (commit 2a18fc29):
 *
 *   commander (src/modules/src/commander.c:74-98): a setpoint is taken when its
 *     priority is at least the current one; it gets the current tick as timestamp; a
 *     priority above HIGHLEVEL stops the high-level planner; commanderRelaxPriority()
 *     lowers the current priority to LOWEST.
 *   stabilizer (src/modules/src/stabilizer.c:335-338, 354): every tick the
 *     high-level commander's setpoint, if it has one, goes in at HIGHLEVEL; then the
 *     current setpoint is read and the supervisor may override it.
 *   high-level commander (src/modules/src/crtp_commander_high_level.c:345-367):
 *     disabled (at boot): no setpoint; stopped: a null setpoint (motors off); after a
 *     go-to, take-off or land: the plan's setpoints.
 *   supervisor (src/modules/src/supervisor.c:58-59, 481-499;
 *     supervisor_state_machine.c:195-244): while flying, a setpoint older than
 *     500 ms levels out (warning), older than 2000 ms cuts the motors; an emergency
 *     stop cuts them (locked).
 */
#pragma once

#include <stdbool.h>
#include <stdint.h>

typedef struct {
    uint32_t now_ms;
    bool flying;          /* supervisorIsFlying() */
    bool locked;          /* supervisorIsLocked(): emergency stop or watchdog cut */
    uint32_t wdt_warnings; /* ticks flying with a setpoint older than 500 ms */
    uint32_t wdt_cuts;     /* motors cut for a setpoint older than 2000 ms */
    uint32_t null_flying;  /* ticks flying on a null setpoint (motors off in the air) */
    uint32_t app_setpoints; /* setpoints at EXTRX taken */
    uint32_t hl_setpoints;  /* setpoints of the high-level commander taken */
    int hl;                /* 0 disabled, 1 stopped, 2 planning */
    bool hl_landing;
    uint32_t hl_end_ms;    /* the plan's end */
    float vbat;
    bool positioning;
    float position[2];
} firmware_model;

extern firmware_model fw;

/* Boot: on the ground, nothing planned, battery full. */
void fw_reset(uint32_t now_ms);
/* The client's high-level take-off (cflib high_level_commander.takeoff). */
void fw_takeoff(float height, float duration_s);
/* The client's emergency stop (cfclient, cflib send_stop_setpoint / supervisor). */
void fw_emergency_stop(void);
/* One 10 ms stabilizer tick at fw.now_ms (then advance fw.now_ms). */
void fw_stabilizer_tick(void);
/* The storage refuses to store (storage.h's storageStore returns false). */
extern bool fw_storage_fails;
