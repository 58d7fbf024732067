/* Stub of crazyflie-firmware src/utils/interface/configblock.h. Compile checks only. */
#pragma once

#include <stdint.h>

uint64_t configblockGetRadioAddress(void);
