/*
 * The formation of this example: the paper's four agents (SPEC §9, triangles
 * {1,2,3} and {2,3,4}, the square 1-2-4-3), scaled for a room: leader edge
 * z* = q1 - q2 = (1, -1) m (a square of side 1.41 m), hovering (v* = 0), the
 * force limited to 2 N of the virtual unit mass. These numbers are a starting
 * point, not flight-tested: simulate them first (host-sim scenario with the same
 * values, radio loss and latency) and tune the gains there.
 *
 * Alternative to the C struct: a configuration blob from a host tool, loaded
 * with ph_agent_init_blob() (docs/c-api.md).
 *
 * The read functions are where the sensors plug in. As shipped, only the
 * velocity is wired (the state estimator); without bearings the controller
 * answers with its safe output (U = -safe_damping * v, fault
 * PH_FAULT_MISSING_BEARING), i.e. the app only damps the velocity.
 */
#include "formation.h"

#include "log.h"

#define COS_45 0.70710678f

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
    a->stiffness = 1000.0f;       /* c (S7) */
    a->damping = 10.0f;           /* d (S7) */
    a->estimator_gain = 1000.0f;  /* c_e (S9) */
}

ph_status formation_config(uint8_t id, ph_config *c)
{
    if (id < 1 || id > 4)
        return PH_ERR_CONFIG_NOT_IN_TRIANGLE;
    ph_status s = ph_config_default(c, id);
    if (s != PH_OK)
        return s;
    c->friction[0] = c->friction[1] = FORMATION_FRICTION;
    c->velocity_damping[0] = c->velocity_damping[1] = 1.8f;
    constant(&c->velocity_reference, 0.0f, 0.0f);
    c->limits.max_force = 2.0f;
    c->limits.neighbour_timeout = 0.1f; /* 10 ticks without a frame: safe output */
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
        c->leader.stiffness = 1.0f;
        c->leader.damping[0] = c->leader.damping[1] = 0.8f;
        constant(&c->leader.displacement, 1.0f, -1.0f);
    }
    return PH_OK;
}

/* Velocity: the state estimator's (Kalman filter with the flow deck, Lighthouse
 * or Loco positioning), world frame. */
void formation_read_velocity(float velocity[2])
{
    static logVarId_t vx, vy;
    static bool ready;
    if (!ready) {
        vx = logGetVarId("stateEstimate", "vx");
        vy = logGetVarId("stateEstimate", "vy");
        ready = true;
    }
    velocity[0] = logVarIdIsValid(vx) ? logGetFloat(vx) : 0.0f;
    velocity[1] = logVarIdIsValid(vy) ? logGetFloat(vy) : 0.0f;
}

/* Bearing to neighbour `id` as a unit vector in the WORLD frame, or false.
 *
 * Wire your sensor here, e.g.
 *  - a camera (AI deck) finding the neighbour's LED ring: pixel -> direction in
 *    the body frame, then rotate by the estimator's yaw (stateEstimate.yaw) into
 *    the world frame (the formation needs one shared orientation: S2);
 *  - a UWB angle-of-arrival deck: the AoA in the body frame, rotated likewise;
 *  - for a first test under a positioning system: (q_j - q_i) / |q_j - q_i| from
 *    the estimator's own position and the neighbour's (sent on another P2P port).
 * Set PH_BEARING_HAS_RATE with `rate` only if the sensor measures the bearing
 * rate; otherwise the controller differentiates successive bearings. */
static bool sensor_bearing(uint8_t id, float direction[2])
{
    (void)id;
    (void)direction;
    return false; /* not wired in this template */
}

size_t formation_read_bearings(const ph_agent *agent, ph_bearing *out, size_t capacity)
{
    uint8_t ids[PH_MAX_NEIGHBOURS];
    size_t n = 0, written = 0;
    if (ph_neighbours(agent, ids, PH_MAX_NEIGHBOURS, &n) != PH_OK)
        return 0;
    /* In ph_neighbours() order: the agent's fast path. */
    for (size_t k = 0; k < n && written < capacity; k++) {
        ph_bearing *b = &out[written];
        b->neighbour = ids[k];
        b->flags = 0;
        if (sensor_bearing(ids[k], b->direction))
            written++;
    }
    return written;
}

/* Leaders 1 and 2 need q_partner - q_self (S11): e.g. UWB two-way ranging plus
 * the bearing to the partner, or both positions from a positioning system. */
bool formation_read_partner_offset(float offset[2])
{
    (void)offset;
    return false; /* not wired in this template */
}
