/*
 * ph-formation on a Crazyflie 2.x: an out-of-tree app running ONE agent of the
 * angle-based port-Hamiltonian formation controller through its C API
 * (controller-ffi/include/ph_formation.h, docs/c-api.md, docs/crazyflie.md).
 *
 * This file is the FreeRTOS and Crazyflie glue; the per-tick logic is
 * agent_loop.c, the flight states flight.c and their commands commands.c (tested on
 * the host and under QEMU). Every 10 ms (100 Hz):
 *   1. agent_loop_receive() every P2P packet heard since the last tick (queued by
 *      the radio callback, which runs in the radio link's task): the formation's
 *      frames (port 0) and the neighbours' positions (port 1);
 *   2. agent_loop_tick(): sensors (formation.c) -> ph_step() -> ph_actuate(), then
 *      this tick's frames and own position -> radiolinkSendP2PPacketBroadcast();
 *   3. flight_update(): the parameter formation.enable, the supervisor, the
 *      positioning, the neighbours heard and the battery -> the flight state and
 *      what to do with the commander (commands_apply()).
 *
 * From boot the app sends no setpoint (IDLE): take off with the high-level
 * commander, then set formation.enable = 1 (cfclient's parameter tab or cflib);
 * formation.enable = 0 hands control back to the high-level commander, hovering,
 * for its land. The log group formation shows the state.
 *
 * The agent's id is the last byte of the radio address (E7E7E7E701 is agent 1);
 * its configuration is its blob in blobs/ph_blobs.c (host-sim export --all).
 */
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "app.h"
#include "commander.h"
#include "configblock.h"
#include "FreeRTOS.h"
#include "log.h"
#include "param.h"
#include "pm.h"
#include "queue.h"
#include "radiolink.h"
#include "supervisor.h"
#include "task.h"

#define DEBUG_MODULE "PHFORM"
#include "debug.h"

#include "agent_loop.h"
#include "commands.h"
#include "epoch.h"
#include "flight.h"
#include "ph_formation.h"

#define CONTROL_PERIOD_MS 10u /* 100 Hz */
/* Packets buffered between two ticks: each neighbour sends one or two frames and one
 * position packet per tick. */
#define RX_QUEUE_LEN 24u
/* A frame must fit one P2P packet (crazyflie-firmware src/hal/interface/radiolink.h:
 * P2P_MAX_DATA_SIZE 60). */
_Static_assert(PH_MAX_FRAME_LEN <= P2P_MAX_DATA_SIZE, "a frame must fit a P2P packet");
_Static_assert(FORMATION_POSITION_LEN <= P2P_MAX_DATA_SIZE, "a position must fit a P2P packet");

typedef struct {
    uint8_t port;
    uint8_t len;
    uint8_t bytes[PH_MAX_FRAME_LEN];
} rx_packet;

/* The agent lives here (PH_AGENT_SIZE bytes of .bss, 3,860 on the Crazyflie). */
static uint8_t agent_memory[PH_AGENT_SIZE] __attribute__((aligned(PH_AGENT_ALIGN)));
static agent_loop loop;
#ifdef FORMATION_USE_STRUCT
static ph_config scratch_config; /* 620 bytes, only read at init */
#define SCRATCH (&scratch_config)
#else
#define SCRATCH NULL /* the configuration is this agent's blob */
#endif
static P2PPacket tx_packet;
static QueueHandle_t rx_queue;
static volatile uint32_t rx_dropped; /* queue full */
static flight fl;
static flight_policy policy;

/* The parameter group formation (crazyflie-firmware src/modules/interface/param.h:
 * PARAM_GROUP_START, PARAM_ADD, PARAM_GROUP_STOP). Written by the parameter task
 * (a byte: no lock needed), read by the app task once per tick. */
static uint8_t enable; /* formation.enable: 1 starts the formation (rising edge) */

PARAM_GROUP_START(formation)
PARAM_ADD(PARAM_UINT8, enable, &enable)
PARAM_GROUP_STOP(formation)

/* The log group formation (log.h: LOG_GROUP_START, LOG_ADD, LOG_GROUP_STOP), updated
 * once per tick by the app task. */
static uint8_t log_state;       /* flight_state */
static uint8_t log_fault;       /* flight_fault: the last refusal or policy */
static uint8_t log_heard;       /* neighbours whose position is fresh */
static uint8_t log_neighbours;  /* neighbours in the formation */
static uint32_t log_safe_ticks; /* ticks with the controller's safe output */
static uint32_t log_refusals;   /* enable refused by the pre-flight checks */
static uint8_t log_ph_fault;    /* the controller's ph_fault this tick */
static uint32_t log_hold_ticks; /* policy: ticks holding (lost neighbours or radio) */
static uint32_t log_guarded;    /* policy: setpoints the separation guard changed */
static uint32_t log_landings;   /* policy: landings decided */
static uint32_t log_resets;     /* bearing-track restarts, all neighbours (SPEC S15c-d) */

LOG_GROUP_START(formation)
LOG_ADD(LOG_UINT8, state, &log_state)
LOG_ADD(LOG_UINT8, fault, &log_fault)
LOG_ADD(LOG_UINT32, safeTicks, &log_safe_ticks)
LOG_ADD(LOG_UINT8, heard, &log_heard)
LOG_ADD(LOG_UINT8, neighbours, &log_neighbours)
LOG_ADD(LOG_UINT32, refusals, &log_refusals)
LOG_ADD(LOG_UINT8, phFault, &log_ph_fault)
LOG_ADD(LOG_UINT32, holdTicks, &log_hold_ticks)
LOG_ADD(LOG_UINT32, guarded, &log_guarded)
LOG_ADD(LOG_UINT32, landings, &log_landings)
LOG_ADD(LOG_UINT32, resets, &log_resets)
LOG_GROUP_STOP(formation)

/* Radio link task: queue the packet for the app task (the agent is not thread-safe:
 * only the app task touches it). The P2P API does not filter ports
 * (crazyflie-firmware docs/functional-areas/p2p_api.md): agent_loop_receive does. */
static void p2p_received(P2PPacket *p)
{
    rx_packet f;
    if (p->size == 0 || p->size > PH_MAX_FRAME_LEN)
        return;
    f.port = p->port;
    f.len = p->size;
    __builtin_memcpy(f.bytes, p->data, p->size);
    if (xQueueSend(rx_queue, &f, 0) != pdTRUE)
        rx_dropped++;
}

/* agent_loop_send_fn: one packet to the P2P broadcast. */
static void p2p_send(void *ctx, uint8_t port, const uint8_t *bytes, size_t len)
{
    (void)ctx;
    tx_packet.port = port;
    tx_packet.size = (uint8_t)len;
    __builtin_memcpy(tx_packet.data, bytes, len);
    radiolinkSendP2PPacketBroadcast(&tx_packet);
}

/* The bearing trackers' reset counters (ph_frame_stats.track_resets), summed. */
static uint32_t track_resets(const agent_loop *l)
{
    ph_frame_stats st;
    uint32_t sum = 0;
    if (ph_stats(l->agent, &st) == PH_OK)
        for (size_t i = 0; i < PH_MAX_NEIGHBOURS; i++)
            sum += st.track_resets[i];
    return sum;
}

static void report(const agent_loop *l, TickType_t now, flight_state before)
{
    if (fl.state != before || (fl.fault != FLIGHT_FAULT_NONE && fl.fault != log_fault))
        DEBUG_PRINT("t=%u ms: %s -> %s (%s)\n", (unsigned)T2M(now), flight_state_str(before),
                    flight_state_str(fl.state), flight_fault_str(fl.fault));
    if (l->status != PH_OK ||
        (fl.state == FLIGHT_FORMATION && l->out.status != PH_OUTPUT_NOMINAL && l->ticks % 100u == 0u))
        DEBUG_PRINT("t=%u ms: %s, fault %u (neighbour %d)\n", (unsigned)T2M(now),
                    ph_status_str(l->status), (unsigned)l->out.fault,
                    (int)l->out.fault_neighbour);
    if (l->ticks % 1000u == 0u) {
        ph_frame_stats st;
        if (ph_stats(l->agent, &st) == PH_OK)
            DEBUG_PRINT("10 s: %u frames accepted, %u from others, %u queue drops, %u safe ticks\n",
                        (unsigned)st.accepted, (unsigned)st.unknown_sender,
                        (unsigned)rx_dropped, (unsigned)l->safe_ticks);
    }
}

void appMain(void)
{
    uint8_t id = (uint8_t)(configblockGetRadioAddress() & 0xFFu);
    DEBUG_PRINT("agent %u, C API v%u, %u bytes of agent memory\n", (unsigned)id,
                (unsigned)ph_abi_version(), (unsigned)PH_AGENT_SIZE);
    if (ph_abi_version() != PH_ABI_VERSION || ph_agent_size() != PH_AGENT_SIZE) {
        DEBUG_PRINT("ph_formation.h does not match the linked library\n");
        return;
    }
    /* The app's stack peak (CONFIG_APP_STACKSIZE in app-config; docs/c-api.md). */
    ph_status s = agent_loop_init(&loop, agent_memory, sizeof agent_memory, id, SCRATCH);
    if (s != PH_OK) {
        DEBUG_PRINT("no formation agent %u: %s\n", (unsigned)id, ph_status_str(s));
        return;
    }
    rx_queue = xQueueCreate(RX_QUEUE_LEN, sizeof(rx_packet));
    if (rx_queue == NULL) {
        DEBUG_PRINT("no memory for the P2P queue\n");
        return;
    }
    /* Authenticated frames: this boot's epoch, one more than the last boot's (kept in
     * the storage), so that neighbours accept our frames at once (epoch.h). Without
     * auth the call changes nothing. */
    uint32_t epoch = 0;
    if (!formation_next_boot_epoch(&epoch)) {
        DEBUG_PRINT("no boot epoch (storage): no formation\n");
        return;
    }
    s = agent_loop_set_boot_epoch(&loop, epoch);
    if (s != PH_OK) {
        DEBUG_PRINT("boot epoch: %s\n", ph_status_str(s));
        return;
    }
    if (!formation_policy(id, &policy)) {
        DEBUG_PRINT("no policy for agent %u\n", (unsigned)id);
        return;
    }
    flight_init(&fl);
    p2pRegisterCB(p2p_received);

    TickType_t wake = xTaskGetTickCount();
    for (;;) {
        vTaskDelayUntil(&wake, M2T(CONTROL_PERIOD_MS));
        /* The control clock: integer ms (1 kHz tick, FreeRTOSConfig.h M2T/T2M), used
         * only as differences modulo 2^32 (agent_loop.h). */
        uint32_t now = (uint32_t)T2M(xTaskGetTickCount());
        rx_packet f;
        while (xQueueReceive(rx_queue, &f, 0) == pdTRUE)
            agent_loop_receive(&loop, f.port, f.bytes, f.len, now);
        (void)agent_loop_tick(&loop, now, p2p_send, NULL);

        float position[2];
        formation_read_position(position);
        flight_inputs in = {
            .now_ms = now,
            .enable = enable,
            .flying = supervisorIsFlying() && !supervisorIsLocked(),
            .positioning = formation_positioning_locked(),
            .heard = formation_heard(&loop.formation, now),
            .neighbours = (uint8_t)loop.formation.peer_count,
            .controller_safe = loop.status != PH_OK || loop.out.status != PH_OUTPUT_NOMINAL,
            .position = {position[0], position[1]},
            .vbat = pmGetBatteryVoltage(),
        };
        flight_state before = fl.state;
        flight_action action = flight_update(&fl, &policy, &in);
        /* Outside FORMATION the setpoint restarts from the measured velocity at every
         * tick, so entering FORMATION starts from the vehicle's own motion; the
         * schedules' clock restarts unless holding. */
        if (fl.state != FLIGHT_FORMATION)
            agent_loop_restart(&loop, now, fl.state != FLIGHT_HOLD);
        if (action == FLIGHT_ACT_SETPOINT)
            formation_guard(&loop.formation, now, &fl.policy, &policy.core, position,
                            loop.setpoint);
        commands_apply(action, &fl, loop.setpoint, position);

        report(&loop, now, before);
        log_state = (uint8_t)fl.state;
        log_fault = (uint8_t)fl.fault;
        log_heard = in.heard;
        log_neighbours = in.neighbours;
        log_safe_ticks = loop.safe_ticks;
        log_refusals = fl.refusals;
        log_ph_fault = (uint8_t)loop.out.fault;
        log_hold_ticks = fl.policy.hold_ticks;
        log_guarded = fl.policy.guarded;
        log_landings = fl.policy.landings;
        log_resets = track_resets(&loop);
    }
}
