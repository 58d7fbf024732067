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
    uint32_t previous_ms; /* the previous tick (ms, the control clock) */
    uint32_t origin_ms;   /* time 0 of the schedules v*, z* (agent_loop_restart) */
    ph_output out;        /* the last tick's controller output */
    ph_status status;     /* the last ph_step's status */
    float setpoint[2];    /* the last velocity setpoint (m/s, world frame) */
    uint32_t ticks;
    uint32_t safe_ticks;  /* ticks with the safe output, after the first */
    float safe_s;         /* how long the current safe output has lasted (s) */
    bool reseeded;        /* its actuator started again from the velocity (S21c) */
    uint64_t position_counter; /* auth: the next position packet's counter */
} agent_loop;

/* Builds agent `id` in memory[0..size] (PH_AGENT_SIZE bytes, PH_AGENT_ALIGN-aligned):
 * from its blob (formation_blob()), or with -DFORMATION_USE_STRUCT from
 * formation_config() (the ph_config in `scratch`, which the caller keeps static:
 * it is 620 bytes; unused, and may be NULL, with blobs). */
ph_status agent_loop_init(agent_loop *loop, uint8_t *memory, size_t size, uint8_t id,
                          ph_config *scratch);

/* Time: the control clock in integer milliseconds (xTaskGetTickCount() at the
 * Crazyflie's 1 kHz tick), which wraps every 49.7 days; only differences modulo 2^32
 * are used, so a year of uptime is no different from the first minute
 * (controller-ffi/tests/crazyflie_app.rs, the swarm started before a wrap). The C
 * API's float seconds are small numbers: dt (10 ms) and the time since the
 * formation started (the schedules' clock). */

/* One P2P packet heard at `now_ms`. */
void agent_loop_receive(agent_loop *loop, uint8_t port, const uint8_t *bytes, size_t len,
                        uint32_t now_ms);

/* One control tick at `now_ms` (dt: since the previous tick, 0 on the first): reads
 * the sensors, steps the controller, integrates the velocity setpoint into
 * loop->setpoint, then sends this tick's frames and the own position. Returns the
 * ph_step status. */
ph_status agent_loop_tick(agent_loop *loop, uint32_t now_ms, agent_loop_send_fn send,
                          void *ctx);

/* This boot's epoch (epoch.h): for the formation's frames (ph_agent_set_boot_epoch) and
 * the position packets' counters (epoch * 2^32 + n). */
ph_status agent_loop_set_boot_epoch(agent_loop *loop, uint32_t epoch);

/* The formation (re)starts at `now_ms`: the setpoint restarts from the measured
 * velocity at the next tick; with `new_origin`, the schedules' time restarts at 0. */
void agent_loop_restart(agent_loop *loop, uint32_t now_ms, bool new_origin);
