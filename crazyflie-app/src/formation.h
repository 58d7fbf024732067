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

#include "ph_formation.h"

/* The plant model the controller assumes (SPEC S1, per axis): m dv/dt = -D^r v + U,
 * integrated into velocity setpoints by ph_actuate(); D^r is the agent's friction. */
#define FORMATION_MASS 1.0f /* kg (virtual) */
/* Largest velocity setpoint (m/s): the Crazyflie's position-mode limit
 * (crazyflie-firmware src/platform/interface/platform_defaults_cf2.h,
 * PID_POS_VEL_X_MAX / _Y_MAX = 1.0; docs/crazyflie.md). */
#ifndef FORMATION_MAX_SPEED
#define FORMATION_MAX_SPEED 1.0f
#endif
/* Lead of the setpoints (s, SPEC S21): the time constant of the Crazyflie's velocity
 * loop, derived from PID_VEL_X_KP = PID_VEL_Y_KP = 25 deg per m/s
 * (platform_defaults_cf2.h): 1 / (g tan(25 deg)/(m/s)) ~ 0.23 s (docs/world.md). */
#ifndef FORMATION_LEAD
#define FORMATION_LEAD 0.23f
#endif
/* Flight altitude held while in formation (m). */
#define FORMATION_ALTITUDE 0.5f

/* P2P port of the position packets (the formation's frames use port 0). */
#define FORMATION_POSITION_PORT 1u
/* Bytes of a position packet: version, sender id, x and y (float32, little-endian). */
#define FORMATION_POSITION_LEN 10u
/* Version byte of the position packet layout. */
#define FORMATION_POSITION_VERSION 1u
/* A neighbour's position older than this (s) gives no bearing: the agent's own
 * neighbour timeout then makes the output safe. */
#define FORMATION_POSITION_MAX_AGE 0.1f

/* The last position heard from one neighbour. */
typedef struct {
    uint8_t id;
    uint8_t heard; /* 1 once a position arrived */
    float time;    /* s, the receiver's clock at arrival */
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

/* This agent's position packet into out[0..capacity]; returns its length (0 if it
 * does not fit). */
size_t formation_position_packet(uint8_t id, const float position[2], uint8_t *out,
                                 size_t capacity);

/* A received position packet; returns true if it was a neighbour's and was kept. */
bool formation_position_received(formation_state *state, const uint8_t *bytes, size_t len,
                                 float now);

/* Bearings to the neighbours whose position is fresh, unit vectors in the world
 * frame, in ph_neighbours() order; returns how many were written (at most
 * `capacity`). */
size_t formation_read_bearings(const formation_state *state, const float own[2], float now,
                               ph_bearing *out, size_t capacity);

/* Leaders: the partner's position minus this agent's (m, world frame); false when
 * this agent is no leader or the partner's position is stale. */
bool formation_read_partner_offset(const formation_state *state, const float own[2],
                                   float now, float offset[2]);
