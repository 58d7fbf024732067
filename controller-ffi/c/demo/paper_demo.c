/*
 * The paper's formation through the C API: configuration, plant, radio and
 * control loop (see paper_demo.h). Mirrors firmware-example/src/boards/demo.rs
 * and firmware-example/src/paper.rs.
 */
#include "paper_demo.h"

#include <stddef.h>

/* ---------------------------------------------------------------- scenario */

#define PLANT_HZ 1000u
#define CONTROL_HZ 100u
#define SUBSTEPS (PLANT_HZ / CONTROL_HZ)

static const float MASS = 1.0f;            /* kg */
static const float FRICTION = 0.5f;        /* D^r, N s/m */
static const float VELOCITY_DAMPING = 1.8f;/* D^v */
static const float V_STAR[2] = {3.0f, 3.0f};
static const float Z_STAR[2] = {10.0f, -10.0f}; /* q1 - q2 */
static const float INITIAL_POSITIONS[DEMO_N][2] = {
    {0.9f, 2.2f}, {2.2f, 2.8f}, {1.8f, 1.1f}, {3.1f, 1.9f}};
#define COS_45 0.70710678118654752f
#define COS_90 0.0f

/* The four controlled angles: triangle, apex and far vertices (indices),
 * cos and sin of the desired angle. */
typedef struct {
    int triangle, apex, far[2];
    float cos, sin;
} demo_angle;

static const int TRIANGLES[2][3] = {{0, 1, 2}, {1, 2, 3}};
static const demo_angle ANGLES[4] = {
    {0, 0, {1, 2}, COS_90, 1.0f},   /* theta1 = 90 deg at 1 in {1,2,3} */
    {0, 2, {0, 1}, COS_45, COS_45}, /* phi1 = 45 deg at 3 in {1,2,3} */
    {1, 1, {2, 3}, COS_45, COS_45}, /* theta2 = 45 deg at 2 in {2,3,4} */
    {1, 2, {1, 3}, COS_45, COS_45}, /* phi2 = 45 deg at 3 in {2,3,4} */
};

static void constant(ph_schedule *s, const float value[2])
{
    s->count = 1;
    s->steps[0].from = 0.0f;
    s->steps[0].value[0] = value[0];
    s->steps[0].value[1] = value[1];
}

void demo_paper_config(int i, ph_config *c)
{
    ph_config_default(c, (uint8_t)(i + 1));
    c->initial_estimate = 1.0f;
    c->min_estimate = 0.1f;
    c->friction[0] = c->friction[1] = FRICTION;
    c->velocity_damping[0] = c->velocity_damping[1] = VELOCITY_DAMPING;
    constant(&c->velocity_reference, V_STAR);
    /* The core's default (1e3 N) saturates the first ticks (c = 1000 with
     * r(0) = 1); host-sim's paper scenario and qemu-demo use 1e5. */
    c->limits.max_force = 1.0e5f;
    c->triangle_count = 0;
    for (int t = 0; t < 2; t++) {
        const int *v = TRIANGLES[t];
        if (v[0] != i && v[1] != i && v[2] != i)
            continue;
        ph_triangle *tri = &c->triangles[c->triangle_count++];
        for (int k = 0; k < 3; k++)
            tri->vertices[k] = (uint8_t)(v[k] + 1);
        int a = 0;
        for (int k = 0; k < 4; k++) {
            if (ANGLES[k].triangle != t)
                continue;
            ph_angle *an = &tri->angles[a++];
            an->apex = (uint8_t)(ANGLES[k].apex + 1);
            an->cos_desired = ANGLES[k].cos;
            an->stiffness = 1000.0f;
            an->damping = 10.0f;
            an->estimator_gain = 1000.0f;
        }
    }
    c->has_leader = (i == 0 || i == 1);
    if (c->has_leader) {
        c->leader.role = i == 0 ? PH_LEADER_A : PH_LEADER_B;
        c->leader.partner = i == 0 ? 2 : 1;
        c->leader.stiffness = 1.0f;
        c->leader.damping[0] = c->leader.damping[1] = 0.8f;
        constant(&c->leader.displacement, Z_STAR);
    }
}

/* ------------------------------------------------------------------- plant */

/* Positions in a frame moving at v* (absolute positions grow by 3 m/s and
 * f32 would lose the 1 ms increments), as compensated (Kahan) sums, and
 * velocities relative to that frame: see boards/demo.rs. */
typedef struct {
    float p[DEMO_N][2], p_lo[DEMO_N][2], w[DEMO_N][2];
    uint32_t ticks; /* plant steps, PLANT_HZ per second */
} plant;

static float norm2(float x, float y)
{
    return __builtin_sqrtf(x * x + y * y);
}

static void plant_init(plant *pl)
{
    for (int i = 0; i < DEMO_N; i++)
        for (int k = 0; k < 2; k++) {
            pl->p[i][k] = INITIAL_POSITIONS[i][k];
            pl->p_lo[i][k] = 0.0f;
            pl->w[i][k] = -V_STAR[k];
        }
    pl->ticks = 0;
}

/* q_j - q_i */
static void offset(const plant *pl, int i, int j, float out[2])
{
    for (int k = 0; k < 2; k++)
        out[k] = (pl->p[j][k] - pl->p[i][k]) + (pl->p_lo[j][k] - pl->p_lo[i][k]);
}

static void bearing(const plant *pl, int i, int j, float out[2])
{
    float d[2];
    offset(pl, i, j, d);
    float r = norm2(d[0], d[1]);
    out[0] = d[0] / r;
    out[1] = d[1] / r;
}

/* One RK4 step of h seconds of one axis: p' = w, m w' = f - D^r (v* + w). */
static void rk4_axis(float *p, float *p_lo, float *w, float f, float vs, float h)
{
    float force = f - FRICTION * vs;
#define ACC(x) ((force - FRICTION * (x)) / MASS)
    float k1 = ACC(*w);
    float w2 = *w + 0.5f * h * k1;
    float k2 = ACC(w2);
    float w3 = *w + 0.5f * h * k2;
    float k3 = ACC(w3);
    float w4 = *w + h * k3;
    float k4 = ACC(w4);
#undef ACC
    float dp = h / 6.0f * (*w + 2.0f * w2 + 2.0f * w3 + w4);
    float w_next = *w + h / 6.0f * (k1 + 2.0f * k2 + 2.0f * k3 + k4);
    float y = dp + *p_lo;
    float t = *p + y;
    *p_lo = y - (t - *p);
    *p = t;
    *w = w_next;
}

static void plant_step(plant *pl, float force[DEMO_N][2], float h)
{
    for (int i = 0; i < DEMO_N; i++)
        for (int k = 0; k < 2; k++)
            rk4_axis(&pl->p[i][k], &pl->p_lo[i][k], &pl->w[i][k], force[i][k], V_STAR[k], h);
    pl->ticks++;
}

static float plant_time(const plant *pl)
{
    return (float)pl->ticks / (float)PLANT_HZ;
}

static void metrics(const plant *pl, demo_result *r)
{
    float e_angle = 0.0f, e_vel = 0.0f;
    for (int k = 0; k < 4; k++) {
        const demo_angle *a = &ANGLES[k];
        float sv[2], sw[2];
        bearing(pl, a->apex, a->far[0], sv);
        bearing(pl, a->apex, a->far[1], sw);
        /* |sin(alpha - alpha*)|, see firmware-example/src/paper.rs */
        float c = sv[0] * sw[0] + sv[1] * sw[1];
        float s = __builtin_fabsf(sv[0] * sw[1] - sv[1] * sw[0]);
        float e = __builtin_fabsf(s * a->cos - c * a->sin);
        if (e > e_angle)
            e_angle = e;
    }
    float z[2];
    offset(pl, 1, 0, z); /* q1 - q2 */
    for (int i = 0; i < DEMO_N; i++) {
        float e = norm2(pl->w[i][0], pl->w[i][1]);
        if (e > e_vel)
            e_vel = e;
    }
    r->angle_error = e_angle;
    r->leader_error = norm2(z[0] - Z_STAR[0], z[1] - Z_STAR[1]);
    r->velocity_error = e_vel;
}

/* ------------------------------------------------------------------- radio */

#define AIR_CAPACITY 8
#define INBOX_CAPACITY 8

typedef struct {
    uint8_t len;
    uint8_t bytes[PH_MAX_FRAME_LEN];
} packet;

typedef struct {
    packet air[AIR_CAPACITY];
    int air_from[AIR_CAPACITY];
    int air_len;
    packet inbox[DEMO_N][INBOX_CAPACITY];
    int inbox_len[DEMO_N];
    uint32_t lost;
} radio;

typedef struct {
    radio *bus;
    int from;
} sender;

static void radio_send(radio *bus, int from, const uint8_t *bytes, size_t len)
{
    if (bus->air_len >= AIR_CAPACITY || len > PH_MAX_FRAME_LEN) {
        bus->lost++;
        return;
    }
    packet *p = &bus->air[bus->air_len];
    bus->air_from[bus->air_len++] = from;
    p->len = (uint8_t)len;
    for (size_t k = 0; k < len; k++)
        p->bytes[k] = bytes[k];
}

/* ph_send_fn of ph_frames_cb */
static void send_cb(void *ctx, const uint8_t *bytes, size_t len)
{
    sender *s = ctx;
    radio_send(s->bus, s->from, bytes, len);
}

/* Frames sent this tick reach every other robot's inbox. */
static void radio_deliver(radio *bus)
{
    for (int a = 0; a < bus->air_len; a++)
        for (int j = 0; j < DEMO_N; j++) {
            if (j == bus->air_from[a])
                continue;
            if (bus->inbox_len[j] >= INBOX_CAPACITY) {
                bus->lost++;
                continue;
            }
            bus->inbox[j][bus->inbox_len[j]++] = bus->air[a];
        }
    bus->air_len = 0;
}

/* -------------------------------------------------------------- the loop */

typedef struct {
    ph_agent *agent;
    uint8_t neighbours[PH_MAX_NEIGHBOURS];
    size_t n_neighbours;
} robot;

static void note(demo_result *r, ph_status s)
{
    if (s != PH_OK && r->error == PH_OK)
        r->error = s;
}

/* One control tick of robot `me`: measure, then receive, step, broadcast
 * (the C API work, between the hooks), then actuate. Robots 0 and 2 use
 * ph_frames (buffer), 1 and 3 ph_frames_cb (callback). */
static void robot_tick(robot *rb, int me, const plant *pl, radio *bus, uint32_t tick,
                       const demo_hooks *hooks, float force[2], demo_result *r)
{
    ph_bearing bearings[PH_MAX_NEIGHBOURS];
    ph_measurements m = {0};
    size_t n = 0;
    for (size_t k = 0; k < rb->n_neighbours; k++) {
        int j = rb->neighbours[k] - 1;
        if (j < 0 || j >= DEMO_N)
            continue;
        ph_bearing *b = &bearings[n++];
        b->neighbour = rb->neighbours[k];
        b->flags = 0; /* no rates: the agent takes finite differences */
        bearing(pl, me, j, b->direction);
    }
    m.time = plant_time(pl);
    m.dt = tick == 0 ? 0.0f : 1.0f / (float)CONTROL_HZ;
    m.velocity[0] = pl->w[me][0] + V_STAR[0];
    m.velocity[1] = pl->w[me][1] + V_STAR[1];
    m.bearings = bearings;
    m.bearing_count = n;
    if (me == 0 || me == 1) {
        m.has_partner_offset = 1;
        offset(pl, me, 1 - me, m.partner_offset);
    }

    if (hooks && hooks->tick_begin)
        hooks->tick_begin(me, tick);
    uint32_t rx = 0;
    for (int k = 0; k < bus->inbox_len[me]; k++, rx++) {
        const packet *p = &bus->inbox[me][k];
        ph_status s = ph_receive(rb->agent, p->bytes, p->len);
        if (s != PH_OK && s != PH_ERR_FRAME_UNKNOWN_SENDER)
            r->bad_frames++;
    }
    bus->inbox_len[me] = 0;
    ph_output out;
    note(r, ph_step(rb->agent, &m, &out));
    size_t sent = 0;
    if (me % 2 == 0) {
        uint8_t frames[PH_MAX_FRAMES_PER_TICK][PH_MAX_FRAME_LEN];
        uint8_t lens[PH_MAX_FRAMES_PER_TICK];
        note(r, ph_frames(rb->agent, frames, lens, PH_MAX_FRAMES_PER_TICK, &sent));
        for (size_t k = 0; k < sent; k++)
            radio_send(bus, me, frames[k], lens[k]);
    } else {
        sender s = {bus, me};
        note(r, ph_frames_cb(rb->agent, send_cb, &s, &sent));
    }
    if (hooks && hooks->tick_end)
        hooks->tick_end(me, tick, rx, (uint32_t)sent);

    if (out.status != PH_OUTPUT_NOMINAL && tick > 0)
        r->late_safe++;
    force[0] = out.force[0];
    force[1] = out.force[1];
}

int demo_run(ph_agent *agents[DEMO_N], const demo_hooks *hooks, demo_result *r)
{
    static plant pl;
    static radio bus;
    static robot robots[DEMO_N];
    float force[DEMO_N][2] = {{0}};

    *r = (demo_result){0};
    r->error = PH_OK;
    plant_init(&pl);
    bus = (radio){0};
    for (int i = 0; i < DEMO_N; i++) {
        robots[i].agent = agents[i];
        note(r, ph_neighbours(agents[i], robots[i].neighbours, PH_MAX_NEIGHBOURS,
                              &robots[i].n_neighbours));
    }

    const uint32_t max_ticks = DEMO_MAX_TIME_S * CONTROL_HZ;
    const float h = 1.0f / (float)PLANT_HZ;
    int within = 0;
    uint32_t tick = 0;
    while (tick < max_ticks && !within) {
        for (int i = 0; i < DEMO_N; i++)
            robot_tick(&robots[i], i, &pl, &bus, tick, hooks, force[i], r);
        radio_deliver(&bus);
        for (unsigned k = 0; k < SUBSTEPS; k++)
            plant_step(&pl, force, h);
        tick++;
        metrics(&pl, r);
        within = r->angle_error < DEMO_ANGLE_TOL && r->leader_error < DEMO_LEADER_TOL &&
                 r->velocity_error < DEMO_VELOCITY_TOL;
    }
    r->ticks = tick;
    r->time = plant_time(&pl);
    r->lost = bus.lost;
    for (int i = 0; i < DEMO_N; i++)
        offset(&pl, 0, i, r->rel[i]);
    r->converged = within && r->late_safe == 0 && r->bad_frames == 0 && r->lost == 0 &&
                   r->error == PH_OK;
    return r->converged;
}
