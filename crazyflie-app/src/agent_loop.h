/*
 * One formation agent's per-tick logic, free of FreeRTOS and of the Crazyflie's
 * radio and commander: app.c calls it from the app task, and the tests run it on
 * the host and on the STM32F405 under QEMU (controller-ffi/tests/crazyflie_app.rs).
 *
 *   agent_loop_init()     configuration (blob by agent id, or the C struct), agent,
 *                         actuator, neighbour table;
 *   agent_loop_receive()  every P2P packet heard since the last tick;
 *   agent_loop_tick()     sensors -> ph_step -> ph_actuate (velocity setpoint), then
 *                         this tick's frames and own position through `send`.
 */
#pragma once

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "formation.h"
#include "ph_formation.h"

/* P2P port of the formation's frames (the core's frames: version, sender, CRC). */
#define AGENT_LOOP_FRAME_PORT 0u

/* Sends one P2P packet: `bytes[0..len]` on `port`. */
typedef void (*agent_loop_send_fn)(void *ctx, uint8_t port, const uint8_t *bytes, size_t len);

typedef struct {
    ph_agent *agent;      /* in the caller's PH_AGENT_SIZE bytes */
    ph_actuator actuator; /* virtual mass -> velocity setpoint */
    formation_state formation;
    uint8_t id;
    bool first;           /* no tick yet */
    ph_output out;        /* the last tick's controller output */
    ph_status status;     /* the last ph_step's status */
    float setpoint[2];    /* the last velocity setpoint (m/s, world frame) */
    uint32_t ticks;
    uint32_t safe_ticks;  /* ticks with the safe output, after the first */
} agent_loop;

/* Builds agent `id` in memory[0..size] (PH_AGENT_SIZE bytes, PH_AGENT_ALIGN-aligned):
 * from its blob (formation_blob()), or with -DFORMATION_USE_STRUCT from
 * formation_config() (the ph_config in `scratch`, which the caller keeps static:
 * it is 620 bytes; unused, and may be NULL, with blobs). */
ph_status agent_loop_init(agent_loop *loop, uint8_t *memory, size_t size, uint8_t id,
                          ph_config *scratch);

/* One P2P packet heard (`now`: s, the control clock). */
void agent_loop_receive(agent_loop *loop, uint8_t port, const uint8_t *bytes, size_t len,
                        float now);

/* One control tick at `now` (s), `dt` s after the previous one (ignored on the first):
 * reads the sensors, steps the controller, integrates the velocity setpoint into
 * loop->setpoint, then sends this tick's frames and the own position. Returns the
 * ph_step status. */
ph_status agent_loop_tick(agent_loop *loop, float now, float dt, agent_loop_send_fn send,
                          void *ctx);
