/* Stub of FreeRTOS.h with the Crazyflie's FreeRTOSConfig.h tick helpers
 * (1 kHz tick: M2T/T2M are identities). Compile checks only. */
#pragma once

#include <stddef.h>
#include <stdint.h>

typedef uint32_t TickType_t;
typedef long BaseType_t;
typedef unsigned long UBaseType_t;

#define pdTRUE ((BaseType_t)1)
#define pdFALSE ((BaseType_t)0)
#define pdPASS pdTRUE

#define configTICK_RATE_HZ 1000
#define M2T(X) ((unsigned int)(X))
#define T2M(X) ((unsigned int)(X))
