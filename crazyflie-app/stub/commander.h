/* Stub of crazyflie-firmware src/modules/interface/commander.h (commit 2a18fc29,
 * lines 35-53). Compile checks; test/firmware_model.c implements it for the host
 * tests after src/modules/src/commander.c. */
#pragma once

#include "stabilizer_types.h"

#define COMMANDER_PRIORITY_DISABLE 0
#define COMMANDER_PRIORITY_LOWEST 1
#define COMMANDER_PRIORITY_HIGHLEVEL 1
#define COMMANDER_PRIORITY_CRTP 2
#define COMMANDER_PRIORITY_EXTRX 3

/* Arg `setpoint` cannot be const; the commander will mutate its timestamp. */
void commanderSetSetpoint(setpoint_t *setpoint, int priority);
int commanderGetActivePriority(void);
/* Sets the priority of the current setpoint to the lowest non-disabled value, so any
 * new setpoint regardless of source will overwrite it. */
void commanderRelaxPriority(void);
