/*
 * ph-formation on a Crazyflie 2.x: an out-of-tree app running ONE agent of the
 * angle-based port-Hamiltonian formation controller through its C API
 * (controller-ffi/include/ph_formation.h, docs/c-api.md, docs/crazyflie.md).
 *
 * This file is the FreeRTOS and Crazyflie glue; the per-tick logic is
 * agent_loop.c (tested on the host and under QEMU). Every 10 ms (100 Hz):
 *   1. agent_loop_receive() every P2P packet heard since the last tick (queued by
 *      the radio callback, which runs in the radio link's task): the formation's
 *      frames (port 0) and the neighbours' positions (port 1);
 *   2. agent_loop_tick(): sensors (formation.c) -> ph_step() -> ph_actuate(), then
 *      this tick's frames and own position -> radiolinkSendP2PPacketBroadcast();
 *   3. the velocity setpoint -> commanderSetSetpoint().
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
#include "queue.h"
#include "radiolink.h"
#include "task.h"

#define DEBUG_MODULE "PHFORM"
#include "debug.h"

#include "agent_loop.h"
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

/* The agent lives here (PH_AGENT_SIZE bytes of .bss, 3,404 on the Crazyflie). */
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

/* The velocity setpoint (world frame) for the Crazyflie's own velocity controller,
 * holding the altitude and the heading (bearings need the world frame). */
static void command(const float velocity[2])
{
    static setpoint_t sp;
    sp.mode.x = modeVelocity;
    sp.mode.y = modeVelocity;
    sp.mode.z = modeAbs;
    sp.mode.roll = modeDisable;
    sp.mode.pitch = modeDisable;
    sp.mode.yaw = modeVelocity;
    sp.velocity.x = velocity[0];
    sp.velocity.y = velocity[1];
    sp.position.z = FORMATION_ALTITUDE;
    sp.attitudeRate.yaw = 0.0f;
    sp.velocity_body = false;
    commanderSetSetpoint(&sp, COMMANDER_PRIORITY_EXTRX);
}

static void report(const agent_loop *l, TickType_t now)
{
    if (l->status != PH_OK || (l->out.status != PH_OUTPUT_NOMINAL && l->ticks % 100u == 0u))
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
    p2pRegisterCB(p2p_received);

    TickType_t wake = xTaskGetTickCount();
    TickType_t previous = wake;
    for (;;) {
        vTaskDelayUntil(&wake, M2T(CONTROL_PERIOD_MS));
        TickType_t now = xTaskGetTickCount();
        float t = (float)T2M(now) / 1000.0f;
        rx_packet f;
        while (xQueueReceive(rx_queue, &f, 0) == pdTRUE)
            agent_loop_receive(&loop, f.port, f.bytes, f.len, t);
        (void)agent_loop_tick(&loop, t, (float)T2M(now - previous) / 1000.0f, p2p_send, NULL);
        command(loop.setpoint);
        report(&loop, now);
        previous = now;
    }
}
