/*
 * ph-formation on a Crazyflie 2.x: an out-of-tree app running ONE agent of the
 * angle-based port-Hamiltonian formation controller through its C API
 * (controller-ffi/include/ph_formation.h, docs/c-api.md).
 *
 * Every 10 ms (100 Hz):
 *   1. ph_receive() every P2P frame heard since the last tick (queued by the radio
 *      callback, which runs in the radio link's task);
 *   2. read the own measurements (formation.c: bearings, velocity, leader offset);
 *   3. ph_step() -> force U (N, world frame) and status;
 *   4. turn U into a velocity setpoint for the Crazyflie's own position/velocity
 *      controller (the formation's plant model, see actuate());
 *   5. ph_frames_cb() -> radiolinkSendP2PPacketBroadcast() for each frame.
 *
 * The agent's id is the last byte of the radio address (E7E7E7E701 is agent 1);
 * its configuration comes from formation.c.
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

#include "formation.h"
#include "ph_formation.h"

#define CONTROL_PERIOD_MS 10u /* 100 Hz */
/* P2P port of the formation's frames. The P2P API does not filter by port yet
 * and advises 0; every frame still carries the core's version and CRC, and
 * ph_receive() rejects anything else (counted in ph_stats()). */
#define PH_P2P_PORT 0u
/* Frames buffered between two ticks (the neighbours send one to two each). */
#define RX_QUEUE_LEN 16u
/* Our P2P payload must fit one P2P packet. */
_Static_assert(PH_MAX_FRAME_LEN <= P2P_MAX_DATA_SIZE, "a frame must fit a P2P packet");

typedef struct {
    uint8_t len;
    uint8_t bytes[PH_MAX_FRAME_LEN];
} rx_frame;

/* The agent lives here (PH_AGENT_SIZE bytes of .bss, about 3 KiB). */
static uint8_t agent_memory[PH_AGENT_SIZE] __attribute__((aligned(PH_AGENT_ALIGN)));
static ph_agent *const agent = (ph_agent *)agent_memory;
static ph_config config; /* static: about 0.6 KiB, only needed at init */
static QueueHandle_t rx_queue;
static volatile uint32_t rx_dropped; /* queue full */

static void copy(uint8_t *dst, const uint8_t *src, size_t n)
{
    for (size_t k = 0; k < n; k++)
        dst[k] = src[k];
}

/* Radio link task: queue the frame for the app task (the agent is not
 * thread-safe: only the app task touches it). */
static void p2p_received(P2PPacket *p)
{
    rx_frame f;
    if (p->port != PH_P2P_PORT || p->size == 0 || p->size > PH_MAX_FRAME_LEN)
        return;
    f.len = p->size;
    copy(f.bytes, p->data, p->size);
    if (xQueueSend(rx_queue, &f, 0) != pdTRUE)
        rx_dropped++;
}

/* ph_send_fn: one frame to the P2P broadcast. */
static void p2p_send(void *ctx, const uint8_t *bytes, size_t len)
{
    P2PPacket *packet = ctx;
    packet->port = PH_P2P_PORT;
    packet->size = (uint8_t)len;
    copy(packet->data, bytes, len);
    radiolinkSendP2PPacketBroadcast(packet);
}

/* The formation's plant is a double integrator with friction per axis,
 *   m dv/dt = -D^r v + U            (SPEC S1, formation.h: FORMATION_MASS, _FRICTION),
 * and the controller cancels D^r at the reference velocity. The Crazyflie's own
 * controller tracks velocity setpoints well, so the app integrates this model
 * and commands the result as the velocity setpoint (world frame), holding the
 * altitude. Start from the measured velocity so that the setpoint does not
 * jump when the app takes over. */
static void actuate(const float force[2], const float velocity[2], float dt, bool first)
{
    static float v_cmd[2];
    static setpoint_t sp;
    for (int k = 0; k < 2; k++) {
        if (first)
            v_cmd[k] = velocity[k];
        v_cmd[k] += dt / FORMATION_MASS * (force[k] - FORMATION_FRICTION * v_cmd[k]);
    }
    sp.mode.x = modeVelocity;
    sp.mode.y = modeVelocity;
    sp.mode.z = modeAbs;
    sp.mode.roll = modeDisable;
    sp.mode.pitch = modeDisable;
    sp.mode.yaw = modeVelocity;
    sp.velocity.x = v_cmd[0];
    sp.velocity.y = v_cmd[1];
    sp.position.z = FORMATION_ALTITUDE;
    sp.attitudeRate.yaw = 0.0f; /* keep the heading: bearings need the world frame */
    sp.velocity_body = false;
    commanderSetSetpoint(&sp, COMMANDER_PRIORITY_EXTRX);
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
    /* Needs about 7 KiB of stack once (CONFIG_APP_STACKSIZE in app-config). */
    ph_status s = formation_config(id, &config);
    if (s == PH_OK)
        s = ph_agent_init(agent, sizeof agent_memory, &config);
    if (s != PH_OK) {
        DEBUG_PRINT("no formation agent %u: %s\n", (unsigned)id, ph_status_str(s));
        return;
    }
    rx_queue = xQueueCreate(RX_QUEUE_LEN, sizeof(rx_frame));
    if (rx_queue == NULL) {
        DEBUG_PRINT("no memory for the P2P queue\n");
        return;
    }
    p2pRegisterCB(p2p_received);

    static P2PPacket tx_packet;
    ph_bearing bearings[PH_MAX_NEIGHBOURS];
    TickType_t wake = xTaskGetTickCount();
    TickType_t previous = wake;
    bool first = true;
    uint32_t ticks = 0, safe = 0;

    for (;;) {
        vTaskDelayUntil(&wake, M2T(CONTROL_PERIOD_MS));
        TickType_t now = xTaskGetTickCount();

        /* 1. Frames heard since the last tick (rejections are counted by the
         * agent: ph_stats()). */
        rx_frame f;
        while (xQueueReceive(rx_queue, &f, 0) == pdTRUE)
            (void)ph_receive(agent, f.bytes, f.len);

        /* 2. Own measurements. */
        ph_measurements m = {0};
        m.time = (float)T2M(now) / 1000.0f;
        m.dt = first ? 0.0f : (float)T2M(now - previous) / 1000.0f;
        formation_read_velocity(m.velocity);
        m.bearings = bearings;
        m.bearing_count = formation_read_bearings(agent, bearings, PH_MAX_NEIGHBOURS);
        m.has_partner_offset = formation_read_partner_offset(m.partner_offset) ? 1u : 0u;

        /* 3. Control step. A refused call (a bug here) leaves out as a zero,
         * safe force: still apply it. */
        ph_output out;
        s = ph_step(agent, &m, &out);
        if (out.status != PH_OUTPUT_NOMINAL && !first)
            safe++;

        /* 4. Actuate. */
        actuate(out.force, m.velocity, m.dt, first);

        /* 5. Broadcast this tick's frames. */
        (void)ph_frames_cb(agent, p2p_send, &tx_packet, NULL);

        if (s != PH_OK || (out.status != PH_OUTPUT_NOMINAL && ticks % 100u == 0u))
            DEBUG_PRINT("t=%u ms: %s, fault %u (neighbour %d)\n", (unsigned)T2M(now),
                        ph_status_str(s), (unsigned)out.fault, (int)out.fault_neighbour);
        if (ticks % 1000u == 0u) {
            ph_frame_stats st;
            if (ph_stats(agent, &st) == PH_OK)
                DEBUG_PRINT("10 s: %u frames accepted, %u from others, %u queue drops, %u safe ticks\n",
                            (unsigned)st.accepted, (unsigned)st.unknown_sender,
                            (unsigned)rx_dropped, (unsigned)safe);
        }
        previous = now;
        first = false;
        ticks++;
    }
}
