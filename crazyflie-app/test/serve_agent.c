/*
 * One simulated Crazyflie for `host-sim serve` (serve_agent.h): the firmware's
 * services the app calls, the vehicle, the P2P radio and the paced clock.
 *
 *   cfapp-agent --id N --crtp-port P --p2p-port P --relay-port P --x X --y Y
 *               --blob FILE [--speed F] [--relay-clock 0|1]
 *
 * prints "CFAGENT ready id=N crtp=P" on stdout once its sockets are bound, then runs
 * the app's appMain() (crazyflie-app/src/app.c) until killed (SIGTERM from host-sim
 * serve, or the parent's death: PR_SET_PDEATHSIG). Console lines go to stderr and to
 * the client's console (CRTP port 0).
 *
 * Modelled after crazyflie-firmware (commit 2a18fc29; test/firmware_model.c cites the
 * same lines for the app's host tests):
 *   commander (src/modules/src/commander.c:74-98): a setpoint is taken when its
 *     priority is at least the current one and timestamped; above HIGHLEVEL it stops
 *     the high-level planner; commanderRelaxPriority() lowers the priority to LOWEST.
 *   stabilizer (src/modules/src/stabilizer.c:335-338): each tick the high-level
 *     commander's setpoint, if any, goes in at HIGHLEVEL.
 *   high-level commander (src/modules/src/crtp_commander_high_level.c:345-367):
 *     disabled at boot (no setpoint); stopped: a null setpoint; planning: the plan.
 *     Plans here are straight lines at constant speed from the current state
 *     (the firmware's are smooth polynomials over the same duration).
 *   supervisor (src/modules/src/supervisor.c:58-59, 481-499): a setpoint older than
 *     500 ms levels out (here: zero velocity), older than 2000 ms cuts the motors
 *     and locks; an emergency stop locks.
 *   position control (src/modules/src/position_controller_pid.c; PID_POS_X_KP 2,
 *     PID_POS_VEL_X_MAX 1 m/s of src/platform/interface/platform_defaults_cf2.h): a
 *     position setpoint is flown as the velocity setpoint 2 (p* - p) + v*, clamped to
 *     1 m/s per axis.
 *
 * The world is planar (docs/crazyflie.md "Altitude, take-off, landing and ground
 * contact"): x, y fly the firmware's PID cascade in velocity mode (ph_vehicle_*, the
 * model host-sim's world = "crazyflie" flies); z is first order, dz/dt = the z
 * velocity command above. Motors run while the current setpoint is not null and
 * the supervisor has not cut them; with the motors off the drone is on the ground
 * (z = 0, at rest). A high-level landing to <= 5 cm that has ended and reached the
 * ground stops the motors (the drone has landed).
 */
#define _GNU_SOURCE
#include <arpa/inet.h>
#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "app.h"
#include "commander.h"
#include "configblock.h"
#include "crtp_commander_high_level.h"
#include "debug.h"
#include "FreeRTOS.h"
#include "pm.h"
#include "queue.h"
#include "radiolink.h"
#include "storage.h"
#include "supervisor.h"
#include "task.h"

#include "ph_formation.h"
#include "serve_agent.h"

#define TICK_MS 10u
#define WDT_STABILIZE_MS 500u /* supervisor.c:58 */
#define WDT_SHUTDOWN_MS 2000u /* supervisor.c:59 */
#define POS_KP 2.0f           /* platform_defaults_cf2.h PID_POS_X_KP */
#define POS_VEL_MAX 1.0f      /* platform_defaults_cf2.h PID_POS_VEL_X_MAX */
#define LANDED_HEIGHT 0.05f   /* a landing to at most this height ends on the ground */

static uint8_t agent_id;
static double speed = 1.0;
/* --clock relay: host-sim serve's relay grants time (SERVE_GRANT) and waits for each
 * agent's tick (SERVE_DONE), so that every drone runs on one clock however loaded the
 * machine; --clock self: paced by the wall clock alone (one agent on its own). */
static bool relay_clock;
static uint32_t granted_ms;
#define SERVE_GRANT 0xF0u /* relay -> agent: [0xF0, t u32 LE]: run up to t ms */
#define SERVE_DONE 0xF1u  /* agent -> relay: [0xF1, t u32 LE]: ticked at t ms */
static int crtp_fd = -1, p2p_fd = -1;
static struct sockaddr_in relay, client;
static bool have_client;
static uint32_t now_ms;
static struct timespec wall_start;
static P2PCallback p2p_cb;

/* This agent's blob (formation_blob overrides the compiled table). */
static uint8_t blob[PH_MAX_BLOB_LEN];
static size_t blob_len;

/* The vehicle. */
static ph_vehicle vehicle;
static float z;
static bool motors, locked;

/* The commander. */
static setpoint_t current;
static int priority = COMMANDER_PRIORITY_DISABLE;
static const setpoint_t null_setpoint;

/* The high-level commander: 0 disabled, 1 stopped, 2 planning. */
static int hl;
static bool hl_landing;
static float hl_from[3], hl_to[3];
static uint32_t hl_start_ms, hl_duration_ms;

/* The state estimator's and the battery's log variables (the firmware's TOC names). */
static float se_x, se_y, se_z, se_vx, se_vy;
static float var_px = 1e-4f, var_py = 1e-4f; /* positioning locked */
static float vbat = 4.0f;                    /* not modelled: a full battery */
static uint8_t sup_flying, sup_locked;

LOG_GROUP_START(stateEstimate)
LOG_ADD(LOG_FLOAT, x, &se_x)
LOG_ADD(LOG_FLOAT, y, &se_y)
LOG_ADD(LOG_FLOAT, z, &se_z)
LOG_ADD(LOG_FLOAT, vx, &se_vx)
LOG_ADD(LOG_FLOAT, vy, &se_vy)
LOG_GROUP_STOP(stateEstimate)

LOG_GROUP_START(kalman)
LOG_ADD(LOG_FLOAT, varPX, &var_px)
LOG_ADD(LOG_FLOAT, varPY, &var_py)
LOG_GROUP_STOP(kalman)

LOG_GROUP_START(pm)
LOG_ADD(LOG_FLOAT, vbat, &vbat)
LOG_GROUP_STOP(pm)

/* The controller's target (stabilizer.c:414-440, group ctrltarget): the current
 * setpoint's velocity (m/s; in position mode the plan's feed-forward). */
static float target_vx, target_vy;

LOG_GROUP_START(ctrltarget)
LOG_ADD(LOG_FLOAT, vx, &target_vx)
LOG_ADD(LOG_FLOAT, vy, &target_vy)
LOG_GROUP_STOP(ctrltarget)

/* Not the firmware's names: the stand-in's own state (docs/crazyflie.md). */
LOG_GROUP_START(serve)
LOG_ADD(LOG_UINT8, flying, &sup_flying)
LOG_ADD(LOG_UINT8, locked, &sup_locked)
LOG_GROUP_STOP(serve)

uint32_t serve_now_ms(void)
{
    return now_ms;
}

/* ---- firmware API the app calls ---- */

uint64_t configblockGetRadioAddress(void)
{
    return 0xE7E7E7E700ull | agent_id;
}

int consolePrintf(const char *format, ...)
{
    char text[200];
    va_list args;
    va_start(args, format);
    int n = vsnprintf(text, sizeof text, format, args);
    va_end(args);
    fprintf(stderr, "cf%u t=%u ms: %s", (unsigned)agent_id, (unsigned)now_ms, text);
    size_t len = strlen(text);
    for (size_t at = 0; at < len; at += CRTP_MAX_DATA) { /* console, port 0 */
        crtp_packet p = {0, 0, 0, {0}};
        p.size = (uint8_t)(len - at < CRTP_MAX_DATA ? len - at : CRTP_MAX_DATA);
        memcpy(p.data, text + at, p.size);
        crtp_send(&p);
    }
    return n;
}

ph_status formation_blob(uint8_t id, const uint8_t **b, size_t *len)
{
    if (id != agent_id || blob_len == 0)
        return PH_ERR_CONFIG_NOT_IN_TRIANGLE;
    *b = blob;
    *len = blob_len;
    return PH_OK;
}

logVarId_t logGetVarId(const char *group, const char *name)
{
    const char *g = "";
    uint16_t n = 0;
    for (const struct log_s *l = _log_start; l < _log_stop; l++) {
        if (l->name == NULL)
            continue; /* padding between two files' tables (serve_sections.ld) */
        if (l->type & LOG_GROUP) {
            g = (l->type & LOG_START) ? l->name : "";
            continue;
        }
        if (strcmp(g, group) == 0 && strcmp(l->name, name) == 0)
            return (logVarId_t)(l - _log_start);
        n++;
    }
    return 0xffffu;
}

float logGetFloat(logVarId_t id)
{
    const struct log_s *l = &_log_start[id];
    switch (l->type & 0x0f) {
    case LOG_FLOAT: return *(const float *)l->address;
    case LOG_UINT8: return *(const uint8_t *)l->address;
    case LOG_UINT32: return (float)*(const uint32_t *)l->address;
    default: return 0.0f;
    }
}

unsigned int logGetUint(logVarId_t id)
{
    return (unsigned int)logGetFloat(id);
}

float pmGetBatteryVoltage(void)
{
    return vbat;
}

static char stored_key[32];
static uint8_t stored[16];
static size_t stored_len;

bool storageStore(const char *key, const void *buffer, size_t length)
{
    if (length > sizeof stored || strlen(key) >= sizeof stored_key)
        return false;
    strcpy(stored_key, key);
    memcpy(stored, buffer, length);
    stored_len = length;
    return true;
}

size_t storageFetch(const char *key, void *buffer, size_t length)
{
    if (stored_len == 0 || strcmp(key, stored_key) != 0)
        return 0;
    size_t n = length < stored_len ? length : stored_len;
    memcpy(buffer, stored, n);
    return n;
}

/* commander.c:74-98 */
void commanderSetSetpoint(setpoint_t *sp, int p)
{
    if (p >= priority) {
        sp->timestamp = now_ms;
        current = *sp;
        priority = p;
        if (p > COMMANDER_PRIORITY_HIGHLEVEL && hl == 2)
            hl = 1; /* crtpCommanderHighLevelStop() */
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

static void plan(const float to[3], float duration_s, bool landing)
{
    hl_from[0] = vehicle.q[0];
    hl_from[1] = vehicle.q[1];
    hl_from[2] = z;
    memcpy(hl_to, to, sizeof hl_to);
    hl_start_ms = now_ms;
    hl_duration_ms = duration_s > 0.0f ? (uint32_t)(duration_s * 1000.0f) : 0u;
    hl_landing = landing;
    hl = 2;
}

bool crtpCommanderHighLevelIsStopped(void)
{
    return hl == 1;
}

int crtpCommanderHighLevelLand(const float height, const float duration_s)
{
    float to[3] = {vehicle.q[0], vehicle.q[1], height};
    plan(to, duration_s, true);
    return 0;
}

int crtpCommanderHighLevelGoTo(const float x, const float y, const float zz, const float yaw,
                               const float duration_s, const bool relative)
{
    (void)yaw;
    float to[3] = {x, y, zz};
    if (relative) {
        to[0] += vehicle.q[0];
        to[1] += vehicle.q[1];
        to[2] += z;
    }
    plan(to, duration_s, false);
    return 0;
}

void serve_hl_takeoff(float height, float duration_s)
{
    float to[3] = {vehicle.q[0], vehicle.q[1], height};
    if (!locked)
        plan(to, duration_s, false);
}

void serve_hl_land(float height, float duration_s)
{
    (void)crtpCommanderHighLevelLand(height, duration_s);
}

void serve_hl_go_to(float x, float y, float zz, float duration_s, bool relative)
{
    (void)crtpCommanderHighLevelGoTo(x, y, zz, 0.0f, duration_s, relative);
}

void serve_hl_stop(void)
{
    hl = 1;
}

void serve_emergency_stop(void)
{
    if (!locked)
        consolePrintf("supervisor: emergency stop, locked\n");
    locked = true;
}

void serve_client_setpoint(setpoint_t *sp)
{
    commanderSetSetpoint(sp, COMMANDER_PRIORITY_CRTP);
}

/* crtp_commander.c:91-97: the client's setpoints stop; the app or the high-level
 * commander may take over at once. */
void serve_client_notify_stop(void)
{
    if (priority == COMMANDER_PRIORITY_CRTP)
        commanderRelaxPriority();
}

bool supervisorCanFly(void)
{
    return !locked;
}

bool supervisorIsFlying(void)
{
    return motors;
}

bool supervisorIsLocked(void)
{
    return locked;
}

/* ---- the radio: P2P through host-sim serve's relay ---- */

bool radiolinkSendP2PPacketBroadcast(P2PPacket *p)
{
    uint8_t d[P2P_MAX_DATA_SIZE + 1];
    if (p->size > P2P_MAX_DATA_SIZE)
        return false;
    d[0] = p->port;
    memcpy(d + 1, p->data, p->size);
    return sendto(p2p_fd, d, (size_t)p->size + 1u, 0, (struct sockaddr *)&relay, sizeof relay) >= 0;
}

void p2pRegisterCB(P2PCallback cb)
{
    p2p_cb = cb;
}

void crtp_send(const crtp_packet *p)
{
    uint8_t d[CRTP_MAX_DATA + 1];
    if (!have_client)
        return;
    d[0] = (uint8_t)((p->port & 0x0f) << 4 | 3u << 2 | (p->channel & 0x03));
    memcpy(d + 1, p->data, p->size);
    (void)sendto(crtp_fd, d, (size_t)p->size + 1u, 0, (struct sockaddr *)&client, sizeof client);
}

/* ---- FreeRTOS: a queue and the paced tick ---- */

struct QueueDefinition {
    UBaseType_t length, item, head, count;
    uint8_t *buffer;
};

QueueHandle_t xQueueCreate(UBaseType_t length, UBaseType_t item)
{
    QueueHandle_t q = calloc(1, sizeof *q);
    if (q == NULL)
        return NULL;
    q->buffer = calloc(length, item);
    if (q->buffer == NULL) {
        free(q);
        return NULL;
    }
    q->length = length;
    q->item = item;
    return q;
}

BaseType_t xQueueSend(QueueHandle_t q, const void *item, TickType_t wait)
{
    (void)wait;
    if (q->count == q->length)
        return pdFALSE;
    memcpy(q->buffer + ((q->head + q->count) % q->length) * q->item, item, q->item);
    q->count++;
    return pdTRUE;
}

BaseType_t xQueueReceive(QueueHandle_t q, void *item, TickType_t wait)
{
    (void)wait;
    if (q->count == 0)
        return pdFALSE;
    memcpy(item, q->buffer + q->head * q->item, q->item);
    q->head = (q->head + 1) % q->length;
    q->count--;
    return pdTRUE;
}

TickType_t xTaskGetTickCount(void)
{
    return now_ms;
}

static bool is_null(const setpoint_t *sp)
{
    return sp->mode.x == modeDisable && sp->mode.y == modeDisable && sp->mode.z == modeDisable &&
           sp->thrust == 0.0f;
}

static float clamp(float v, float limit)
{
    return v > limit ? limit : (v < -limit ? -limit : v);
}

/* The velocity command of one axis (m/s) for the current setpoint. */
static float axis_command(stab_mode_t mode, float position, float velocity, float now)
{
    if (mode == modeVelocity)
        return velocity;
    if (mode == modeAbs)
        return clamp(POS_KP * (position - now) + velocity, POS_VEL_MAX);
    return 0.0f;
}

/* One 10 ms tick of the firmware: high-level commander, supervisor, motors, vehicle. */
static void firmware_tick(void)
{
    if (hl == 2) {
        uint32_t t = now_ms - hl_start_ms;
        float s = hl_duration_ms == 0 || t >= hl_duration_ms ? 1.0f : (float)t / (float)hl_duration_ms;
        setpoint_t sp = null_setpoint;
        sp.mode.x = sp.mode.y = sp.mode.z = modeAbs;
        float inv = hl_duration_ms > 0 && s < 1.0f ? 1000.0f / (float)hl_duration_ms : 0.0f;
        sp.position.x = hl_from[0] + s * (hl_to[0] - hl_from[0]);
        sp.position.y = hl_from[1] + s * (hl_to[1] - hl_from[1]);
        sp.position.z = hl_from[2] + s * (hl_to[2] - hl_from[2]);
        sp.velocity.x = inv * (hl_to[0] - hl_from[0]);
        sp.velocity.y = inv * (hl_to[1] - hl_from[1]);
        sp.velocity.z = inv * (hl_to[2] - hl_from[2]);
        if (hl_landing && s >= 1.0f && hl_to[2] <= LANDED_HEIGHT && z <= 0.01f) {
            hl = 1; /* landed: the planner stops, the motors with it */
        } else {
            commanderSetSetpoint(&sp, COMMANDER_PRIORITY_HIGHLEVEL);
        }
    }
    if (hl == 1) {
        setpoint_t sp = null_setpoint;
        commanderSetSetpoint(&sp, COMMANDER_PRIORITY_HIGHLEVEL);
    }
    uint32_t age = now_ms - current.timestamp;
    if (motors && age > WDT_SHUTDOWN_MS) {
        locked = true; /* supervisor.c:481-487: cut and lock */
        consolePrintf("supervisor: setpoint older than %u ms, motors cut\n", WDT_SHUTDOWN_MS);
    }
    motors = !locked && !is_null(&current) && priority != COMMANDER_PRIORITY_DISABLE;
    if (motors) {
        float cmd[2] = {0.0f, 0.0f}, vz = 0.0f;
        if (age <= WDT_STABILIZE_MS) {
            cmd[0] = axis_command(current.mode.x, current.position.x, current.velocity.x, vehicle.q[0]);
            cmd[1] = axis_command(current.mode.y, current.position.y, current.velocity.y, vehicle.q[1]);
            vz = axis_command(current.mode.z, current.position.z, current.velocity.z, z);
        }
        if (z <= 0.0f && vz <= 0.0f)
            cmd[0] = cmd[1] = 0.0f; /* on the ground: no sliding */
        target_vx = current.velocity.x;
        target_vy = current.velocity.y;
        (void)ph_vehicle_step(&vehicle, cmd, (float)TICK_MS / 1000.0f);
        z += vz * (float)TICK_MS / 1000.0f;
        if (z < 0.0f)
            z = 0.0f;
    }
    if (!motors)
        target_vx = target_vy = 0.0f;
    if (!motors || z <= 0.0f) { /* on the ground: at rest */
        float q[2] = {vehicle.q[0], vehicle.q[1]}, v[2] = {0.0f, 0.0f};
        z = 0.0f;
        (void)ph_vehicle_init(&vehicle, q, v);
    }
    se_x = vehicle.q[0];
    se_y = vehicle.q[1];
    se_z = z;
    se_vx = vehicle.v[0];
    se_vy = vehicle.v[1];
    sup_flying = motors;
    sup_locked = locked;
}

static double wall_ms(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)(t.tv_sec - wall_start.tv_sec) * 1e3 + (double)(t.tv_nsec - wall_start.tv_nsec) / 1e6;
}

static void receive_all(void)
{
    uint8_t d[64];
    for (;;) {
        struct sockaddr_in from;
        socklen_t fl = sizeof from;
        ssize_t n = recvfrom(crtp_fd, d, sizeof d, MSG_DONTWAIT, (struct sockaddr *)&from, &fl);
        if (n <= 0)
            break;
        client = from;
        have_client = true;
        crtp_packet p = {(uint8_t)(d[0] >> 4), (uint8_t)(d[0] & 3u), 0, {0}};
        p.size = (uint8_t)(n - 1 > CRTP_MAX_DATA ? CRTP_MAX_DATA : n - 1);
        memcpy(p.data, d + 1, p.size);
        crtp_handle(&p);
    }
    for (;;) {
        ssize_t n = recv(p2p_fd, d, sizeof d, MSG_DONTWAIT);
        if (n <= 0)
            break;
        if (n == 5 && d[0] == SERVE_GRANT) {
            granted_ms = (uint32_t)d[1] | (uint32_t)d[2] << 8 | (uint32_t)d[3] << 16 |
                         (uint32_t)d[4] << 24;
            break; /* what follows the grant is heard at the next tick */
        }
        if (n < 2 || n > P2P_MAX_DATA_SIZE + 1 || p2p_cb == NULL)
            continue;
        P2PPacket p;
        memset(&p, 0, sizeof p);
        p.port = d[0];
        p.size = (uint8_t)(n - 1);
        memcpy(p.data, d + 1, p.size);
        p2p_cb(&p);
    }
}

/* The app task's delay: serve the sockets until the wall clock reaches the wake
 * time (scaled by --speed), then run the firmware's ticks up to it. */
static bool time_left(uint32_t target)
{
    if (relay_clock)
        return (int32_t)(target - granted_ms) > 0;
    return (double)target / speed - wall_ms() > 0.0;
}

void vTaskDelayUntil(TickType_t *const wake, const TickType_t increment)
{
    uint32_t target = *wake + increment;
    if (relay_clock) { /* this tick's packets are sent: tell the relay */
        uint8_t d[5] = {SERVE_DONE, (uint8_t)now_ms, (uint8_t)(now_ms >> 8),
                        (uint8_t)(now_ms >> 16), (uint8_t)(now_ms >> 24)};
        (void)sendto(p2p_fd, d, sizeof d, 0, (struct sockaddr *)&relay, sizeof relay);
    }
    while (time_left(target)) {
        if (relay_clock) {
            struct pollfd fds[2] = {{crtp_fd, POLLIN, 0}, {p2p_fd, POLLIN, 0}};
            (void)poll(fds, 2, 100);
            receive_all();
            continue;
        }
        double left = (double)target / speed - wall_ms();
        if (left <= 0.0)
            break;
        struct pollfd fds[2] = {{crtp_fd, POLLIN, 0}, {p2p_fd, POLLIN, 0}};
        (void)poll(fds, 2, (int)(left + 0.999));
        receive_all();
    }
    if (!relay_clock)
        receive_all();
    while ((int32_t)(target - now_ms) > 0) {
        now_ms += TICK_MS;
        firmware_tick();
        crtp_tick(now_ms);
    }
    *wake = target;
}

void vTaskDelay(const TickType_t ticks)
{
    TickType_t wake = now_ms;
    vTaskDelayUntil(&wake, ticks);
}

static int bind_port(int port)
{
    int fd = socket(AF_INET, SOCK_DGRAM, 0);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (fd < 0 || bind(fd, (struct sockaddr *)&a, sizeof a) != 0) {
        fprintf(stderr, "cfapp-agent: cannot bind udp 127.0.0.1:%d: %s\n", port, strerror(errno));
        exit(1);
    }
    return fd;
}

static int usage(const char *why)
{
    fprintf(stderr,
            "cfapp-agent: %s\nusage: cfapp-agent --id N --crtp-port P --p2p-port P --relay-port P "
            "--x X --y Y --blob FILE [--speed F] [--relay-clock 0|1]\n",
            why);
    return 2;
}

int main(int argc, char **argv)
{
    int crtp_port = 0, p2p_port = 0, relay_port = 0;
    float q0[2] = {0.0f, 0.0f};
    const char *blob_path = NULL;
    for (int k = 1; k + 1 < argc; k += 2) {
        const char *key = argv[k], *value = argv[k + 1];
        char *end = NULL;
        double x = strtod(value, &end);
        if (strcmp(key, "--blob") == 0) {
            blob_path = value;
            continue;
        }
        if (end == value || *end != '\0')
            return usage("a flag's value is not a number");
        if (strcmp(key, "--id") == 0 && x >= 1 && x <= 255)
            agent_id = (uint8_t)x;
        else if (strcmp(key, "--crtp-port") == 0)
            crtp_port = (int)x;
        else if (strcmp(key, "--p2p-port") == 0)
            p2p_port = (int)x;
        else if (strcmp(key, "--relay-port") == 0)
            relay_port = (int)x;
        else if (strcmp(key, "--x") == 0)
            q0[0] = (float)x;
        else if (strcmp(key, "--y") == 0)
            q0[1] = (float)x;
        else if (strcmp(key, "--relay-clock") == 0)
            relay_clock = x != 0.0;
        else if (strcmp(key, "--speed") == 0 && x > 0.0)
            speed = x;
        else
            return usage(key);
    }
    if (agent_id == 0 || crtp_port <= 0 || p2p_port <= 0 || relay_port <= 0 || blob_path == NULL)
        return usage("missing flags");
    FILE *f = fopen(blob_path, "rb");
    if (f == NULL)
        return usage("cannot open the blob");
    blob_len = fread(blob, 1, sizeof blob, f);
    fclose(f);
    (void)prctl(PR_SET_PDEATHSIG, SIGTERM);
    float v0[2] = {0.0f, 0.0f};
    if (ph_vehicle_init(&vehicle, q0, v0) != PH_OK)
        return usage("bad initial position");
    se_x = q0[0];
    se_y = q0[1];
    crtp_fd = bind_port(crtp_port);
    p2p_fd = bind_port(p2p_port);
    memset(&relay, 0, sizeof relay);
    relay.sin_family = AF_INET;
    relay.sin_port = htons((uint16_t)relay_port);
    relay.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    clock_gettime(CLOCK_MONOTONIC, &wall_start);
    printf("CFAGENT ready id=%u crtp=%d\n", (unsigned)agent_id, crtp_port);
    fflush(stdout);
    appMain();
    consolePrintf("the app returned: no formation on this drone\n");
    for (;;)
        vTaskDelay(TICK_MS); /* the firmware lives on without the app */
}
