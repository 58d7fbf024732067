/*
 * flight_action -> the Crazyflie's commanders (commands.h).
 *
 * Priorities (crazyflie-firmware src/modules/interface/commander.h:35-41): the app's
 * setpoints use COMMANDER_PRIORITY_EXTRX (3), above the client's CRTP setpoints (2)
 * and the high-level commander (1). A setpoint above HIGHLEVEL stops the high-level
 * planner (src/modules/src/commander.c:86-89); a stopped planner hands the stabilizer
 * a null setpoint, motors off, once the priority is relaxed
 * (src/modules/src/crtp_commander_high_level.c:359-367). So handing control back is:
 * first the high-level command (go to / land, planned from the current state, which
 * the stopped planner keeps up to date: :360-362), then commanderRelaxPriority()
 * (commander.c:93-98), in the same tick. Otherwise the app's last setpoint would be
 * left to age: the supervisor levels out after 500 ms and cuts the motors after 2 s
 * (src/modules/src/supervisor.c:58-59, 481-487).
 */
#include "commands.h"

#include "commander.h"
#include "crtp_commander_high_level.h"

static void send(setpoint_t *sp)
{
    sp->mode.z = modeAbs;
    sp->mode.roll = modeDisable;
    sp->mode.pitch = modeDisable;
    sp->mode.yaw = modeVelocity; /* constant heading: bearings are in the world frame */
    sp->position.z = FORMATION_ALTITUDE;
    sp->attitudeRate.yaw = 0.0f;
    sp->velocity_body = false;
    commanderSetSetpoint(sp, COMMANDER_PRIORITY_EXTRX);
}

void commands_apply(flight_action action, const flight *f, const float velocity[2],
                    const float position[2])
{
    static setpoint_t sp;
    switch (action) {
    case FLIGHT_ACT_SETPOINT:
        __builtin_memset(&sp, 0, sizeof sp);
        sp.mode.x = modeVelocity;
        sp.mode.y = modeVelocity;
        sp.velocity.x = velocity[0];
        sp.velocity.y = velocity[1];
        send(&sp);
        break;
    case FLIGHT_ACT_HOLD:
        __builtin_memset(&sp, 0, sizeof sp);
        sp.mode.x = modeAbs;
        sp.mode.y = modeAbs;
        sp.position.x = f->hold[0];
        sp.position.y = f->hold[1];
        send(&sp);
        break;
    case FLIGHT_ACT_RELEASE:
        (void)crtpCommanderHighLevelGoTo(position[0], position[1], FORMATION_ALTITUDE, 0.0f,
                                         FORMATION_RELEASE_DURATION_S, false);
        commanderRelaxPriority();
        break;
    case FLIGHT_ACT_LAND:
        (void)crtpCommanderHighLevelLand(FORMATION_LAND_HEIGHT, FORMATION_LAND_DURATION_S);
        commanderRelaxPriority();
        break;
    case FLIGHT_ACT_RELAX:
        commanderRelaxPriority();
        break;
    case FLIGHT_ACT_NONE:
    default:
        break;
    }
}
