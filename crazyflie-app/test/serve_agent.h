/*
 * One simulated Crazyflie for `host-sim serve` (docs/crazyflie.md "Simulated
 * Crazyflies over udp://"): the app's own code (crazyflie-app/src/app.c's appMain,
 * unchanged, with agent_loop.c, flight.c, commands.c, formation.c, epoch.c) against
 * host stand-ins of the firmware services it calls and of those a client (cflib)
 * talks to over CRTP, each written from crazyflie-firmware (commit 2a18fc29).
 *
 *   serve_agent.c   FreeRTOS (the 1 kHz tick as a paced clock, the queue), the
 *                   commander, high-level commander and supervisor, the battery,
 *                   storage, the state estimator (the vehicle), the P2P radio (UDP to
 *                   the relay of host-sim serve), the process's main();
 *   serve_crtp.c    the CRTP services on the agent's UDP port (one CRTP packet per
 *                   datagram, as cflib's udp:// driver sends): link, platform,
 *                   memory, parameters, logging, setpoints, high-level commander.
 *
 * Built by controller-ffi/c/build.sh cfapp-agent; linked with serve_sections.ld so
 * that the app's PARAM_GROUP/LOG_GROUP tables are found between _param_start and
 * _param_stop, _log_start and _log_stop, as the firmware's linker script does
 * (tools/make/F405/linker/sections_FLASH.ld:49-60).
 */
#pragma once

#include <stdbool.h>
#include <stdint.h>

#include "log.h"
#include "param.h"
#include "stabilizer_types.h"

/* The firmware's CRTP packet: 30 bytes of data (crtp.h CRTP_MAX_DATA_SIZE). */
#define CRTP_MAX_DATA 30

typedef struct {
    uint8_t port;
    uint8_t channel;
    uint8_t size;
    uint8_t data[CRTP_MAX_DATA];
} crtp_packet;

/* The simulated firmware's clock (ms since boot). */
uint32_t serve_now_ms(void);

/* Sends one packet to the connected client (if any). */
void crtp_send(const crtp_packet *p);

/* One packet from the client. */
void crtp_handle(const crtp_packet *p);

/* Once per 10 ms tick, after the stabilizer: log blocks due. */
void crtp_tick(uint32_t now_ms);

/* The parameter and log tables (the linker's sections). */
extern struct param_s _param_start[], _param_stop[];
extern const struct log_s _log_start[], _log_stop[];

/* Commander setpoints from the client (port 3 and 7, at COMMANDER_PRIORITY_CRTP). */
void serve_client_setpoint(setpoint_t *sp);
/* The client's notify-setpoint-stop (port 7, meta channel). */
void serve_client_notify_stop(void);
/* The high-level commander's client commands (port 8). */
void serve_hl_takeoff(float height, float duration_s);
void serve_hl_land(float height, float duration_s);
void serve_hl_go_to(float x, float y, float z, float duration_s, bool relative);
void serve_hl_stop(void);
/* The client's emergency stop (port 9, or the legacy port 6): the supervisor locks. */
void serve_emergency_stop(void);
