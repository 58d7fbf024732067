/*
 * The formation as this Crazyflie sees it: its configuration and its sensors.
 *
 * Configuration: by default this agent's blob, exported with every other agent's by
 * `host-sim export --all` into blobs/ph_blobs.c and found by agent id (the last byte
 * of the radio address); the alternative is the C struct of formation_config()
 * (build with -DFORMATION_USE_STRUCT).
 *
 * Sensors as shipped, for a first flight under a positioning system (Lighthouse,
 * Loco, motion capture): own position and velocity from the state estimator, the
 * neighbours' positions from their position packets (P2P port
 * FORMATION_POSITION_PORT, docs/core.md "Position packets"), and from those the
 * bearings (q_j - q_i)/|q_j - q_i| and the leaders' partner offset q_partner - q_i.
 *
 * Nothing here keeps global state per agent: formation_state is the caller's, so
 * that tests can run several agents in one program.
 */
#pragma once

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "flight.h"
#include "ph_formation.h"

/* The plant model the controller assumes (SPEC S1, per axis): m dv/dt = -D^r v + U,
 * integrated into velocity setpoints by ph_actuate(); D^r is the agent's friction. */
#define FORMATION_MASS 1.0f /* kg (virtual) */
/* Largest velocity setpoint (m/s): the app's own limit. The firmware sets none in
 * velocity mode (PID_POS_VEL_X_MAX / _Y_MAX of platform_defaults_cf2.h bound only the
 * position loop's output, which the app does not use; docs/world.md). */
#ifndef FORMATION_MAX_SPEED
#define FORMATION_MAX_SPEED 1.0f
#endif
/* Lead of the setpoints (s, SPEC S21): the time constant of the Crazyflie's velocity
 * loop, derived from PID_VEL_X_KP = PID_VEL_Y_KP = 25 deg per m/s
 * (platform_defaults_cf2.h): 1 / (g K_p pi/180) = 0.2337 s (docs/world.md,
 * ph-formation-vehicle's derived_lead). */
#ifndef FORMATION_LEAD
#define FORMATION_LEAD 0.2337f
#endif
/* Second-order lead (s^2, SPEC S21b): the attitude loop behind the velocity loop,
 * FORMATION_LEAD / PID_ROLL_KP (6 1/s) = 0.03895 s^2 (docs/world.md,
 * derived_second_lead). 0 turns it off. */
#ifndef FORMATION_SECOND_LEAD
#define FORMATION_SECOND_LEAD 0.03895f
#endif
/* The filter on the second-order lead's jerk (s, SPEC S21d): keeps the velocity noise,
 * differenced twice, out of the setpoints the 100 Hz velocity loop samples on its own
 * clock (docs/world.md measures 0 to 0.1 s). 0 turns it off. */
#ifndef FORMATION_JERK_FILTER
#define FORMATION_JERK_FILTER 0.03f
#endif
/* Gap bound (m/s, SPEC S21c): the virtual velocity stays within this of the measured
 * one, so that a blocked or saturated Crazyflie does not wind it up. Half the speed
 * limit: a following Crazyflie lags by FORMATION_LEAD times the virtual acceleration
 * (0.5 m/s would take 2.1 m/s^2 sustained); a larger gap means it is not following.
 * 0 turns it off. */
#ifndef FORMATION_MAX_GAP
#define FORMATION_MAX_GAP 0.5f
#endif
/* P2P port of the position packets (the formation's frames use port 0). */
#define FORMATION_POSITION_PORT 1u
/* Room for a position packet: the core's (controller-core/src/wire/position.rs, C API
 * ph_position_encode / ph_position_decode) with the agent's integrity mode: 13 bytes
 * with crc16, 11 with link, 27 with auth (a tag and a counter: spoofed or replayed
 * positions are refused). */
#define FORMATION_POSITION_LEN PH_MAX_POSITION_LEN
/* A neighbour's position older than this (ms) gives no bearing: the agent's own
 * neighbour timeout then makes the output safe. */
#define FORMATION_POSITION_MAX_AGE_MS 100u

/* The last position heard from one neighbour. */
typedef struct {
    uint8_t id;
    uint8_t heard;    /* 1 while the last position is at most MAX_AGE old */
    uint32_t time_ms; /* the receiver's clock at arrival (ms, wraps: only differences) */
    ph_position_peer link; /* auth: the last accepted counter (replays refused) */
    float position[2];
} formation_peer;

/* What this agent knows of its neighbours' positions. */
typedef struct {
    formation_peer peers[PH_MAX_NEIGHBOURS];
    size_t peer_count; /* ph_neighbours() of the agent, in that order */
    uint8_t partner;   /* the leader partner, if has_partner */
    uint8_t has_partner;
} formation_state;

/* This agent's configuration blob (blobs/ph_blobs.c, indexed by agent id):
 * PH_OK with *blob and *len, or PH_ERR_CONFIG_NOT_IN_TRIANGLE when the exported
 * scenario has no agent `id`. */
ph_status formation_blob(uint8_t id, const uint8_t **blob, size_t *len);

/* The alternative: the configuration of agent `id` as a C struct. */
ph_status formation_config(uint8_t id, ph_config *config);

/* Neighbour table of an initialised agent (no positions heard yet). */
ph_status formation_state_init(formation_state *state, const ph_agent *agent);

/* Own velocity and position (m/s, m; world frame) from the state estimator. */
void formation_read_velocity(float velocity[2]);
void formation_read_position(float position[2]);

/* This agent's position packet into out[0..capacity] (`counter`: with auth, this
 * boot's epoch * 2^32 + a new n per packet); returns its length (0 if refused). */
size_t formation_position_packet(const ph_agent *agent, const float position[2],
                                 uint64_t counter, uint8_t *out, size_t capacity);

/* A received position packet at `now_ms`, checked with `agent`'s integrity mode;
 * returns true if it was a neighbour's and was kept. */
bool formation_position_received(formation_state *state, const ph_agent *agent,
                                 const uint8_t *bytes, size_t len, uint32_t now_ms);

/* Forgets the positions older than FORMATION_POSITION_MAX_AGE_MS at `now_ms`. Called
 * every tick, it keeps a position heard once from looking fresh again when the 32-bit
 * millisecond clock wraps (every 49.7 days): ages are differences modulo 2^32. */
void formation_expire(formation_state *state, uint32_t now_ms);

/* Neighbours whose position is fresh at `now_ms`. */
uint8_t formation_heard(const formation_state *state, uint32_t now_ms);

/* Bearings to the neighbours whose position is fresh, unit vectors in the world
 * frame, in ph_neighbours() order; returns how many were written (at most
 * `capacity`). */
size_t formation_read_bearings(const formation_state *state, const float own[2],
                               uint32_t now_ms, ph_bearing *out, size_t capacity);

/* Leaders: the partner's position minus this agent's (m, world frame); false when
 * this agent is no leader or the partner's position is stale. */
bool formation_read_partner_offset(const formation_state *state, const float own[2],
                                   uint32_t now_ms, float offset[2]);

/* Positioning locked: the Kalman estimator's position variances kalman.varPX and
 * varPY (crazyflie-firmware src/modules/src/estimator/estimator_kalman.c:474-478)
 * below FORMATION_POSITION_VAR (m^2, a 5 cm standard deviation); false without the
 * Kalman estimator. */
#define FORMATION_POSITION_VAR 0.0025f
bool formation_positioning_locked(void);

/* The safety policies of agent `id` (flight.h): its initial position in
 * crazyflie-app/formation.toml (the pre-flight check's reference, within
 * FORMATION_START_TOLERANCE), the flight volume, the low-battery landing (pm.vbat
 * below FORMATION_VBAT_LAND for FORMATION_VBAT_MS: the Crazyflie 2.x's
 * DEFAULT_BAT_LOW_VOLTAGE, platform_defaults_cf2.h:37), the hold before a landing
 * when neighbours or radio are lost and the minimum separation of the setpoint guard
 * (the core's policies, ph_policy_config). false: no agent `id`. */
#define FORMATION_START_TOLERANCE 0.3f
#define FORMATION_FENCE_MIN_X -0.5f
#define FORMATION_FENCE_MIN_Y -0.5f
#define FORMATION_FENCE_MAX_X 3.0f
#define FORMATION_FENCE_MAX_Y 3.0f
#define FORMATION_VBAT_LAND 3.2f
#define FORMATION_VBAT_MS 2000u
#define FORMATION_HOLD_TIMEOUT_MS 2000u
#define FORMATION_MIN_SEPARATION 0.3f
bool formation_policy(uint8_t id, flight_policy *policy);

/* The minimum-separation guard (the core's, ph_separation_guard) on the velocity
 * `setpoint` against every neighbour whose position is fresh at `now_ms`; a change is
 * counted in policy->guarded. */
void formation_guard(const formation_state *state, uint32_t now_ms, ph_policy *policy,
                     const ph_policy_config *config, const float own[2], float setpoint[2]);
