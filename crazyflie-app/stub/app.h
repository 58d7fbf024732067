/* Stub of crazyflie-firmware src/modules/interface/app.h (compile checks only). */
#pragma once

void appInit(void);
void appMain(void);
