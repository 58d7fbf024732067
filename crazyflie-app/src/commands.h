/*
 * A flight_action (flight.h) done with the Crazyflie's commander and high-level
 * commander (crazyflie-firmware src/modules/interface/commander.h,
 * crtp_commander_high_level.h). Free of FreeRTOS: the host tests run it against
 * test/firmware_model.c, a model of the commander, the high-level commander and the
 * supervisor written from the firmware's source.
 */
#pragma once

#include "flight.h"

/* Flight altitude held while in formation (m). */
#define FORMATION_ALTITUDE 0.5f
/* The high-level commander's landing: to this height (m) in this time (s). */
#define FORMATION_LAND_HEIGHT 0.0f
#define FORMATION_LAND_DURATION_S 3.0f
/* The high-level commander's hover when the formation is switched off (s to reach
 * the current position: it starts from the current state). */
#define FORMATION_RELEASE_DURATION_S 1.0f

/* Does `action`: `velocity` is the formation's setpoint (FLIGHT_ACT_SETPOINT),
 * f->hold the held position (FLIGHT_ACT_HOLD), `position` the own estimate (the
 * hover of FLIGHT_ACT_RELEASE). */
void commands_apply(flight_action action, const flight *f, const float velocity[2],
                    const float position[2]);
