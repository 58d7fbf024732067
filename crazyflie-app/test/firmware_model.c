/*
 * The firmware model (firmware_model.h) and the firmware functions the app calls.
 */
#include "firmware_model.h"

#include "log.h"

#include "commander.h"
#include "crtp_commander_high_level.h"
#include "pm.h"
#include "storage.h"
#include "supervisor.h"

firmware_model fw;
static setpoint_t current;
static int priority;
static const setpoint_t null_setpoint;

#define WDT_STABILIZE_MS 500u /* supervisor.c:58 */
#define WDT_SHUTDOWN_MS 2000u /* supervisor.c:59 */

void fw_reset(uint32_t now_ms)
{
    __builtin_memset(&fw, 0, sizeof fw);
    fw.now_ms = now_ms;
    fw.vbat = 4.1f;
    fw.positioning = true;
    current = null_setpoint;
    current.timestamp = now_ms;
    priority = COMMANDER_PRIORITY_DISABLE;
}

void commanderSetSetpoint(setpoint_t *setpoint, int p)
{
    if (p >= priority) {
        setpoint->timestamp = fw.now_ms;
        current = *setpoint;
        priority = p;
        if (p > COMMANDER_PRIORITY_HIGHLEVEL)
            fw.hl = 1; /* crtpCommanderHighLevelStop() */
        if (p == COMMANDER_PRIORITY_EXTRX)
            fw.app_setpoints++;
    }
}

int commanderGetActivePriority(void)
{
    return priority;
}

void commanderRelaxPriority(void)
{
    priority = COMMANDER_PRIORITY_LOWEST;
}

static void plan(float duration_s, bool landing)
{
    fw.hl = 2;
    fw.hl_landing = landing;
    fw.hl_end_ms = fw.now_ms + (uint32_t)(duration_s * 1000.0f);
}

void fw_takeoff(float height, float duration_s)
{
    (void)height;
    plan(duration_s, false);
    fw.flying = true;
}

bool crtpCommanderHighLevelIsStopped(void)
{
    return fw.hl == 1;
}

int crtpCommanderHighLevelLand(const float absoluteHeight_m, const float duration_s)
{
    (void)absoluteHeight_m;
    plan(duration_s, true);
    return 0;
}

int crtpCommanderHighLevelGoTo(const float x, const float y, const float z, const float yaw,
                               const float duration_s, const bool relative)
{
    (void)x, (void)y, (void)z, (void)yaw, (void)relative;
    plan(duration_s, false);
    return 0;
}

void fw_emergency_stop(void)
{
    fw.locked = true;
    fw.flying = false;
}

static bool is_null(const setpoint_t *sp)
{
    return sp->mode.x == modeDisable && sp->mode.y == modeDisable && sp->mode.z == modeDisable &&
           sp->thrust == 0.0f;
}

void fw_stabilizer_tick(void)
{
    /* stabilizer.c:335-336: the high-level commander's setpoint, if any. */
    if (fw.flying && fw.hl != 0) {
        setpoint_t hl = null_setpoint;
        if (fw.hl == 2) {
            hl.mode.x = hl.mode.y = hl.mode.z = modeAbs;
            if (fw.hl_landing && (int32_t)(fw.now_ms - fw.hl_end_ms) >= 0)
                fw.flying = false; /* landed: the supervisor's Landed state */
        }
        int before = priority;
        commanderSetSetpoint(&hl, COMMANDER_PRIORITY_HIGHLEVEL);
        if (priority == COMMANDER_PRIORITY_HIGHLEVEL && before <= COMMANDER_PRIORITY_HIGHLEVEL &&
            fw.hl == 2)
            fw.hl_setpoints++;
    }
    /* supervisor.c:481-487: the setpoint's age. */
    if (fw.flying) {
        uint32_t age = fw.now_ms - current.timestamp;
        if (age > WDT_STABILIZE_MS)
            fw.wdt_warnings++;
        if (age > WDT_SHUTDOWN_MS) {
            fw.wdt_cuts++;
            fw.flying = false;
            fw.locked = true;
        } else if (is_null(&current))
            fw.null_flying++;
    }
    fw.now_ms += 10u;
}

bool supervisorCanFly(void)
{
    return !fw.locked;
}

bool supervisorIsFlying(void)
{
    return fw.flying;
}

bool supervisorIsLocked(void)
{
    return fw.locked;
}

float pmGetBatteryVoltage(void)
{
    return fw.vbat;
}

/* The persistent storage (storage.h): one entry, survives fw_reset (a reboot). */
static char stored_key[32];
static uint8_t stored[16];
static size_t stored_len;
bool fw_storage_fails;

bool storageStore(const char *key, const void *buffer, size_t length)
{
    if (fw_storage_fails || length > sizeof stored || __builtin_strlen(key) >= sizeof stored_key)
        return false;
    __builtin_strcpy(stored_key, key);
    __builtin_memcpy(stored, buffer, length);
    stored_len = length;
    return true;
}

size_t storageFetch(const char *key, void *buffer, size_t length)
{
    if (stored_len == 0 || __builtin_strcmp(key, stored_key) != 0)
        return 0;
    size_t n = length < stored_len ? length : stored_len;
    __builtin_memcpy(buffer, stored, n);
    return n;
}

/* The log variables the app reads (log.h): kalman.varPX, varPY (small with
 * positioning, large without) and stateEstimate.x, y. */
logVarId_t logGetVarId(const char *group, const char *name)
{
    static const char *const names[][2] = {
        {"kalman", "varPX"}, {"kalman", "varPY"}, {"stateEstimate", "x"}, {"stateEstimate", "y"}};
    for (uint16_t k = 0; k < 4; k++)
        if (__builtin_strcmp(group, names[k][0]) == 0 && __builtin_strcmp(name, names[k][1]) == 0)
            return k;
    return 0xffffu;
}

float logGetFloat(logVarId_t id)
{
    if (id < 2)
        return fw.positioning ? 1e-4f : 0.1f;
    return id < 4 ? fw.position[id - 2] : 0.0f;
}

unsigned int logGetUint(logVarId_t id)
{
    (void)id;
    return 0;
}
