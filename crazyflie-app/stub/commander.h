/* Stub of crazyflie-firmware src/modules/interface/commander.h. Compile checks only. */
#pragma once

#include "stabilizer_types.h"

#define COMMANDER_PRIORITY_DISABLE 0
#define COMMANDER_PRIORITY_LOWEST 1
#define COMMANDER_PRIORITY_HIGHLEVEL 1
#define COMMANDER_PRIORITY_CRTP 2
#define COMMANDER_PRIORITY_EXTRX 3

void commanderSetSetpoint(setpoint_t *setpoint, int priority);
void commanderRelaxPriority(void);
