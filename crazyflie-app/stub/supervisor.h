/* Stub of crazyflie-firmware src/modules/interface/supervisor.h (commit 2a18fc29,
 * lines 70, 78, 120). Compile checks; test/firmware_model.c models it for the host
 * tests after src/modules/src/supervisor.c. */
#pragma once

#include <stdbool.h>

bool supervisorCanFly(void);
bool supervisorIsFlying(void);
/* Locked after an emergency stop or a watchdog timeout (reboot required). */
bool supervisorIsLocked(void);
