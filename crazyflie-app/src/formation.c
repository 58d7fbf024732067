/*
 * The formation of this app and its sensors (formation.h).
 *
 * Configuration: by default the blob of this agent from blobs/ph_blobs.c, written by
 *   host-sim export --all crazyflie-app/formation.toml --vehicle crazyflie \
 *       -o crazyflie-app/src/blobs
 * (the paper's four agents, SPEC §9, scaled for a room: docs/crazyflie.md). The C
 * struct of formation_config() is the alternative (-DFORMATION_USE_STRUCT); it holds
 * the same numbers as crazyflie-app/formation.toml.
 *
 * Sensors: the state estimator's position and velocity (Kalman filter with
 * Lighthouse, Loco or motion capture), and the neighbours' positions heard on the
 * P2P port FORMATION_POSITION_PORT. For bearings from a camera (AI deck) or a UWB
 * angle-of-arrival deck instead, replace formation_read_bearings(): body-frame
 * direction rotated by the estimated yaw into the world frame (S2), and set
 * PH_BEARING_HAS_RATE only if the sensor measures the bearing rate.
 */
#include "formation.h"

#include "log.h"
#include "ph_blobs.h"

#define COS_45 0.70710678f

/* Weak: `host-sim serve`'s agent (crazyflie-app/test/serve_agent.c) gives the blob it
 * was handed at start instead of the table compiled in. */
__attribute__((weak)) ph_status formation_blob(uint8_t id, const uint8_t **blob, size_t *len)
{
    if (id >= ph_blob_count || ph_blobs[id] == NULL)
        return PH_ERR_CONFIG_NOT_IN_TRIANGLE;
    *blob = ph_blobs[id];
    *len = ph_blob_lens[id];
    return PH_OK;
}

static void constant(ph_schedule *s, float x, float y)
{
    s->count = 1;
    s->steps[0].from = 0.0f;
    s->steps[0].value[0] = x;
    s->steps[0].value[1] = y;
}

static void angle(ph_angle *a, uint8_t apex, float cos_desired)
{
    a->apex = apex;
    a->cos_desired = cos_desired; /* the core takes cosines: no trigonometry on board */
    a->stiffness = 30.0f;         /* c (S7) */
    a->damping = 10.0f;           /* d (S7) */
    a->estimator_gain = 100.0f;   /* c_e (S9) */
}

ph_status formation_config(uint8_t id, ph_config *c)
{
    if (id < 1 || id > 4)
        return PH_ERR_CONFIG_NOT_IN_TRIANGLE;
    ph_status s = ph_config_default(c, id);
    if (s != PH_OK)
        return s;
    c->friction[0] = c->friction[1] = 0.5f; /* D^r */
    c->velocity_damping[0] = c->velocity_damping[1] = 1.8f;
    constant(&c->velocity_reference, 0.0f, 0.0f);
    c->limits.max_force = 2.0f;
    c->limits.neighbour_timeout = 0.1f; /* 10 ticks without a frame: safe output */
    c->limits.bearing_hold = 0.05f;     /* a missing bearing predicted for 5 ticks (SPEC §12) */
    if (id <= 3) { /* triangle {1, 2, 3}: theta1 = 90 deg at 1, phi1 = 45 deg at 3 */
        ph_triangle *t = &c->triangles[c->triangle_count++];
        t->vertices[0] = 1;
        t->vertices[1] = 2;
        t->vertices[2] = 3;
        angle(&t->angles[0], 1, 0.0f);
        angle(&t->angles[1], 3, COS_45);
    }
    if (id >= 2) { /* triangle {2, 3, 4}: theta2 = 45 deg at 2, phi2 = 45 deg at 3 */
        ph_triangle *t = &c->triangles[c->triangle_count++];
        t->vertices[0] = 2;
        t->vertices[1] = 3;
        t->vertices[2] = 4;
        angle(&t->angles[0], 2, COS_45);
        angle(&t->angles[1], 3, COS_45);
    }
    if (id == 1 || id == 2) { /* the leader edge: z* = q1 - q2 */
        c->has_leader = 1;
        c->leader.role = id == 1 ? PH_LEADER_A : PH_LEADER_B;
        c->leader.partner = id == 1 ? 2 : 1;
        c->leader.stiffness = 4.0f;
        c->leader.damping[0] = c->leader.damping[1] = 2.0f;
        constant(&c->leader.displacement, 1.0f, -1.0f);
    }
    return PH_OK;
}

ph_status formation_state_init(formation_state *state, const ph_agent *agent)
{
    uint8_t ids[PH_MAX_NEIGHBOURS];
    size_t n = 0;
    __builtin_memset(state, 0, sizeof *state);
    ph_status s = ph_neighbours(agent, ids, PH_MAX_NEIGHBOURS, &n);
    if (s != PH_OK)
        return s;
    for (size_t k = 0; k < n; k++)
        state->peers[k].id = ids[k];
    state->peer_count = n;
    return ph_leader_partner(agent, &state->partner, &state->has_partner);
}

/* A float log variable, looked up once (`fallback` when the firmware has none). */
static float log_float(logVarId_t *id, bool *ready, const char *group, const char *name,
                       float fallback)
{
    if (!*ready) {
        *id = logGetVarId(group, name);
        *ready = true;
    }
    return logVarIdIsValid(*id) ? logGetFloat(*id) : fallback;
}

/* A log variable of the state estimator (0 when the firmware has none). */
static float estimate(logVarId_t *id, bool *ready, const char *name)
{
    return log_float(id, ready, "stateEstimate", name, 0.0f);
}

void formation_read_velocity(float velocity[2])
{
    static logVarId_t vx, vy;
    static bool rx, ry;
    velocity[0] = estimate(&vx, &rx, "vx");
    velocity[1] = estimate(&vy, &ry, "vy");
}

void formation_read_position(float position[2])
{
    static logVarId_t x, y;
    static bool rx, ry;
    position[0] = estimate(&x, &rx, "x");
    position[1] = estimate(&y, &ry, "y");
}

size_t formation_position_packet(const ph_agent *agent, const float position[2],
                                 uint64_t counter, uint8_t *out, size_t capacity)
{
    size_t n = 0;
    return ph_position_encode(agent, position, counter, out, capacity, &n) == PH_OK ? n : 0;
}

bool formation_position_received(formation_state *state, const ph_agent *agent,
                                 const uint8_t *bytes, size_t len, uint32_t now_ms)
{
    uint8_t sender = 0;
    if (ph_position_sender(bytes, len, &sender) != PH_OK)
        return false;
    for (size_t k = 0; k < state->peer_count; k++) {
        formation_peer *peer = &state->peers[k];
        if (peer->id != sender)
            continue;
        float p[2];
        uint8_t from = 0;
        /* Integrity, finite values, and (auth) a counter above the last: the core's. */
        if (ph_position_decode(agent, bytes, len, &peer->link, &from, p) != PH_OK ||
            from != sender)
            return false;
        peer->heard = 1;
        peer->time_ms = now_ms;
        peer->position[0] = p[0];
        peer->position[1] = p[1];
        return true;
    }
    return false; /* not a neighbour: broadcast radio */
}

static bool is_fresh(const formation_peer *peer, uint32_t now_ms)
{
    return peer->heard && (uint32_t)(now_ms - peer->time_ms) <= FORMATION_POSITION_MAX_AGE_MS;
}

static const formation_peer *fresh(const formation_state *state, uint8_t id, uint32_t now_ms)
{
    for (size_t k = 0; k < state->peer_count; k++) {
        const formation_peer *peer = &state->peers[k];
        if (peer->id == id)
            return is_fresh(peer, now_ms) ? peer : NULL;
    }
    return NULL;
}

void formation_expire(formation_state *state, uint32_t now_ms)
{
    for (size_t k = 0; k < state->peer_count; k++)
        if (!is_fresh(&state->peers[k], now_ms))
            state->peers[k].heard = 0;
}

uint8_t formation_heard(const formation_state *state, uint32_t now_ms)
{
    uint8_t n = 0;
    for (size_t k = 0; k < state->peer_count; k++)
        n += is_fresh(&state->peers[k], now_ms) ? 1u : 0u;
    return n;
}

size_t formation_read_bearings(const formation_state *state, const float own[2],
                               uint32_t now_ms, ph_bearing *out, size_t capacity)
{
    size_t written = 0;
    for (size_t k = 0; k < state->peer_count && written < capacity; k++) {
        const formation_peer *peer = fresh(state, state->peers[k].id, now_ms);
        if (peer == NULL)
            continue;
        /* SPEC S2: the bearing g_ij = (q_j - q_i) / |q_j - q_i|, world frame. */
        float dx = peer->position[0] - own[0], dy = peer->position[1] - own[1];
        float d = __builtin_sqrtf(dx * dx + dy * dy);
        if (!(d >= (float)PH_COINCIDENT_M)) /* coincident: no bearing (the core's rule) */
            continue;
        ph_bearing *b = &out[written++];
        b->neighbour = peer->id;
        b->flags = 0;
        b->direction[0] = dx / d;
        b->direction[1] = dy / d;
        b->rate[0] = b->rate[1] = 0.0f;
        b->range = 0.0f;
    }
    return written;
}

bool formation_read_partner_offset(const formation_state *state, const float own[2],
                                   uint32_t now_ms, float offset[2])
{
    if (!state->has_partner)
        return false;
    const formation_peer *peer = fresh(state, state->partner, now_ms);
    if (peer == NULL)
        return false;
    offset[0] = peer->position[0] - own[0];
    offset[1] = peer->position[1] - own[1];
    return true;
}

bool formation_positioning_locked(void)
{
    static logVarId_t px, py;
    static bool rx, ry;
    float vx = log_float(&px, &rx, "kalman", "varPX", __builtin_inff());
    float vy = log_float(&py, &ry, "kalman", "varPY", __builtin_inff());
    return vx < FORMATION_POSITION_VAR && vy < FORMATION_POSITION_VAR; /* false for NaN */
}

#ifdef FORMATION_USE_STRUCT
/* crazyflie-app/formation.toml's [[agents]] positions, by id (checked by
 * controller-ffi/tests/crazyflie_app.rs). */
static const float starts[][2] = {{0.0f, 0.0f}, {0.45f, 1.1f}, {1.1f, 1.4f}, {0.9f, 0.55f},
                                  {1.55f, 0.95f}};

bool formation_policy(uint8_t id, flight_policy *p)
{
    if (id < 1 || id >= sizeof starts / sizeof starts[0])
        return false;
    __builtin_memset(p, 0, sizeof *p);
    p->core.hold_timeout_ms = FORMATION_HOLD_TIMEOUT_MS;
    p->core.fence = 1;
    p->core.fence_min[0] = FORMATION_FENCE_MIN_X;
    p->core.fence_min[1] = FORMATION_FENCE_MIN_Y;
    p->core.fence_max[0] = FORMATION_FENCE_MAX_X;
    p->core.fence_max[1] = FORMATION_FENCE_MAX_Y;
    p->core.battery_land = FORMATION_VBAT_LAND;
    p->core.battery_ms = FORMATION_VBAT_MS;
    p->core.min_separation = FORMATION_MIN_SEPARATION;
    p->start_tolerance = FORMATION_START_TOLERANCE;
    p->start[0] = starts[id][0];
    p->start[1] = starts[id][1];
    return true;
}
#else
/* The policies `host-sim export` wrote into agent `id`'s blob from formation.toml's
 * [policy] (ph_blob_policy): one configuration, the scenario's, for the simulator and
 * the app. A blob without them (a scenario without [policy]) gives no policy: the app
 * refuses to start (app.c) rather than fly unguarded. */
bool formation_policy(uint8_t id, flight_policy *p)
{
    const uint8_t *blob = NULL;
    size_t len = 0;
    __builtin_memset(p, 0, sizeof *p);
    if (formation_blob(id, &blob, &len) != PH_OK)
        return false;
    return ph_blob_policy(blob, len, &p->core, p->start, &p->start_tolerance) == PH_OK;
}
#endif

void formation_guard(const formation_state *state, uint32_t now_ms, ph_policy *policy,
                     const ph_policy_config *config, const float own[2], float setpoint[2])
{
    float near[PH_MAX_NEIGHBOURS][2];
    size_t n = 0;
    for (size_t k = 0; k < state->peer_count && n < PH_MAX_NEIGHBOURS; k++) {
        const formation_peer *peer = &state->peers[k];
        if (!is_fresh(peer, now_ms))
            continue;
        near[n][0] = peer->position[0];
        near[n][1] = peer->position[1];
        n++;
    }
    if (ph_separation_guard(policy, config, own, &near[0][0], n, setpoint) != PH_OK)
        setpoint[0] = setpoint[1] = 0.0f; /* refused settings: no motion */
}
