/* Stub of crazyflie-firmware src/modules/interface/crtp_commander_high_level.h
 * (commit 2a18fc29, lines 73, 115, 198): the calls the app makes. Compile checks;
 * test/firmware_model.c models them for the host tests. */
#pragma once

#include <stdbool.h>

bool crtpCommanderHighLevelIsStopped(void);
int crtpCommanderHighLevelLand(const float absoluteHeight_m, const float duration_s);
int crtpCommanderHighLevelGoTo(const float x, const float y, const float z, const float yaw,
                               const float duration_s, const bool relative);
