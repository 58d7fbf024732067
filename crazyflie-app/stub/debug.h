/* Stub of crazyflie-firmware src/utils/interface/debug.h: DEBUG_PRINT to the
 * client's console (define DEBUG_MODULE before including). Compile checks only. */
#pragma once

int consolePrintf(const char *format, ...) __attribute__((format(printf, 1, 2)));

#ifndef DEBUG_MODULE
#define DEBUG_MODULE "APP"
#endif
#define DEBUG_PRINT(fmt, ...) consolePrintf(DEBUG_MODULE ": " fmt, ##__VA_ARGS__)
