/* Stub of crazyflie-firmware src/hal/interface/pm.h (commit 2a18fc29, line 76): the
 * battery voltage (the log variable pm.vbat, src/hal/src/pm_stm32f4.c:515). */
#pragma once

float pmGetBatteryVoltage(void);
