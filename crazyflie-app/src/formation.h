/*
 * The formation as this Crazyflie sees it: its configuration and its sensors.
 * Edit formation.c for your formation and wire its read functions to your decks.
 */
#pragma once

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "ph_formation.h"

/* The plant model the controller assumes (SPEC S1, per axis): m dv/dt = -D^r v + U.
 * app.c integrates it into velocity setpoints; ph_config.friction must be D^r. */
#define FORMATION_MASS 1.0f     /* kg (virtual) */
#define FORMATION_FRICTION 0.5f /* D^r, N s/m (virtual) */
/* Flight altitude held while in formation (m). */
#define FORMATION_ALTITUDE 0.5f

/* The configuration of agent `id` (the last byte of the radio address). */
ph_status formation_config(uint8_t id, ph_config *config);

/* Own velocity (m/s, world frame). */
void formation_read_velocity(float velocity[2]);

/* Bearings to this agent's neighbours (ph_neighbours()), unit vectors in the
 * world frame; returns how many were written (at most `capacity`). */
size_t formation_read_bearings(const ph_agent *agent, ph_bearing *out, size_t capacity);

/* Leaders: the partner's position minus this agent's (m, world frame); returns
 * false when this agent is no leader or the measurement is missing. */
bool formation_read_partner_offset(float offset[2]);
