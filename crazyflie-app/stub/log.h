/* Stub of crazyflie-firmware src/modules/interface/log.h (commit 2a18fc29): reading
 * log variables (lines 46-116) and declaring a log group with the firmware's own
 * macros (lines 119-189, the non-UNIT_TEST_MODE branch). Compile checks and host
 * tests only. */
#pragma once

#include <stdbool.h>
#include <stdint.h>

typedef uint16_t logVarId_t;

logVarId_t logGetVarId(const char *group, const char *name);
float logGetFloat(logVarId_t varid);
unsigned int logGetUint(logVarId_t varid);

static inline bool logVarIdIsValid(logVarId_t varId)
{
    return varId != 0xffffu;
}

/* Basic log structure (log.h:119). */
struct log_s {
    uint8_t type;
    char *name;
    void *address;
};

/* Possible variable types (log.h:126-133). */
#define LOG_UINT8 1
#define LOG_UINT16 2
#define LOG_UINT32 3
#define LOG_INT8 4
#define LOG_INT16 5
#define LOG_INT32 6
#define LOG_FLOAT 7
#define LOG_FP16 8

/* Internal defines (log.h:158-162). */
#define LOG_CORE 0x20
#define LOG_GROUP 0x80
#define LOG_BY_FUNCTION 0x40
#define LOG_START 1
#define LOG_STOP 0

/* Macros (log.h:168-189). */
#define LOG_ADD(TYPE, NAME, ADDRESS) \
    {.type = TYPE, .name = #NAME, .address = (void *)(ADDRESS), },

#define LOG_ADD_CORE(TYPE, NAME, ADDRESS) LOG_ADD(TYPE | LOG_CORE, NAME, ADDRESS)

#define LOG_ADD_GROUP(TYPE, NAME, ADDRESS) \
    {.type = TYPE, .name = #NAME, .address = (void *)(ADDRESS), },

#define LOG_GROUP_START(NAME)                                                              \
    static const struct log_s __logs_##NAME[] __attribute__((section(".log." #NAME), used)) = { \
        LOG_ADD_GROUP(LOG_GROUP | LOG_START, NAME, 0x0)

#define LOG_GROUP_STOP(NAME) \
    LOG_ADD_GROUP(LOG_GROUP | LOG_STOP, stop_##NAME, 0x0) };
