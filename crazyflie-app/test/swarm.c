/*
 * Four Crazyflie apps against simulated vehicles (swarm.h).
 */
#include "swarm.h"

#include "agent_loop.h"
#include "log.h"

#define TICK_S 0.01f
#define INBOX 16

typedef struct {
    uint8_t port;
    uint8_t len;
    uint8_t bytes[PH_MAX_FRAME_LEN];
} packet;

typedef struct {
    packet items[INBOX];
    uint32_t count;
} inbox;

static uint8_t memory[SWARM_N][PH_AGENT_SIZE] __attribute__((aligned(PH_AGENT_ALIGN)));
static agent_loop loops[SWARM_N];
static ph_config scratch;
/* The vehicles: position and velocity (world frame). crazyflie-app/formation.toml's
 * initial positions. */
static float q[SWARM_N][2] = {{0.45f, 1.1f}, {1.1f, 1.4f}, {0.9f, 0.55f}, {1.55f, 0.95f}};
static float v[SWARM_N][2];
/* The simulated Crazyflies (the firmware's PID cascade, ph_vehicle_* of the C API's
 * sim-vehicle build: the one model host-sim's world = "crazyflie" flies too); q and v
 * above are their positions and velocities after each tick. */
static ph_vehicle vehicles[SWARM_N];
/* Inboxes: filled during a tick, delivered at the next one. */
static inbox air[2][SWARM_N];
static int current;   /* the robot whose app runs (its state estimator) */
static float noise;   /* position noise (m), swarm_run_with() */
static uint32_t start_ms; /* the control clock at tick 0, swarm_run_with() */
static uint32_t rng = 0x9e3779b9u;

/* Approximately standard normal: the sum of 12 uniforms minus 6 (xorshift32; no
 * libm on the MCU). */
static float gauss(void)
{
    float sum = 0.0f;
    for (int k = 0; k < 12; k++) {
        rng ^= rng << 13;
        rng ^= rng >> 17;
        rng ^= rng << 5;
        sum += (float)(rng >> 8) * (1.0f / 16777216.0f);
    }
    return sum - 6.0f;
}
static int sending;   /* the inbox generation being filled */
static uint32_t lost; /* packets that did not fit an inbox */

/* The firmware's log API (crazyflie-app/stub/log.h): the state estimator of the
 * robot whose app runs. */
logVarId_t logGetVarId(const char *group, const char *name)
{
    (void)group;
    if (name[0] == 'x' && name[1] == '\0')
        return 0;
    if (name[0] == 'y' && name[1] == '\0')
        return 1;
    if (name[0] == 'v' && name[1] == 'x' && name[2] == '\0')
        return 2;
    if (name[0] == 'v' && name[1] == 'y' && name[2] == '\0')
        return 3;
    return 0xffffu;
}

float logGetFloat(logVarId_t id)
{
    if (id < 2)
        return q[current][id] + (noise > 0.0f ? noise * gauss() : 0.0f);
    return id < 4 ? v[current][id - 2] : 0.0f;
}

/* agent_loop_send_fn: broadcast to the three others, delivered next tick. */
static void broadcast(void *ctx, uint8_t port, const uint8_t *bytes, size_t len)
{
    int from = *(const int *)ctx;
    for (int j = 0; j < SWARM_N; j++) {
        inbox *b = &air[sending][j];
        if (j == from)
            continue;
        if (b->count >= INBOX || len > PH_MAX_FRAME_LEN) {
            lost++;
            continue;
        }
        packet *p = &b->items[b->count++];
        p->port = port;
        p->len = (uint8_t)len;
        __builtin_memcpy(p->bytes, bytes, len);
    }
}

ph_status swarm_init(void)
{
    for (int i = 0; i < SWARM_N; i++) {
        ph_status s =
            agent_loop_init(&loops[i], memory[i], sizeof memory[i], (uint8_t)(i + 1), &scratch);
        if (s == PH_OK)
            s = ph_vehicle_init(&vehicles[i], q[i], v[i]);
        if (s != PH_OK)
            return s;
    }
    return PH_OK;
}

static float norm(float x, float y)
{
    return __builtin_sqrtf(x * x + y * y);
}

/* The square 1-2-4-3 as q_i - q_1: z* = q1 - q2 = (1, -1). */
static const float square[SWARM_N][2] = {{0.0f, 0.0f}, {-1.0f, 1.0f}, {1.0f, 1.0f}, {0.0f, 2.0f}};

static int converged(float *max_speed)
{
    int ok = 1;
    *max_speed = 0.0f;
    for (int i = 0; i < SWARM_N; i++) {
        float dx = q[i][0] - q[0][0] - square[i][0], dy = q[i][1] - q[0][1] - square[i][1];
        if (!(norm(dx, dy) <= SWARM_SHAPE_TOL) || !(norm(v[i][0], v[i][1]) <= SWARM_SPEED_TOL))
            ok = 0;
    }
    return ok;
}

static float shape_error(void)
{
    float worst = 0.0f;
    for (int i = 0; i < SWARM_N; i++) {
        float e = norm(q[i][0] - q[0][0] - square[i][0], q[i][1] - q[0][1] - square[i][1]);
        if (e > worst)
            worst = e;
    }
    return worst;
}

static void run(uint32_t max_ticks, int stop_when_converged, swarm_result *r,
                swarm_shape_error *error);

int swarm_run(swarm_result *r)
{
    run(SWARM_MAX_TIME_S * 100u, 1, r, NULL);
    return r->converged;
}

void swarm_run_with(const swarm_options *options, swarm_result *r, swarm_shape_error *error)
{
    noise = options->position_noise;
    start_ms = options->start_ms;
    if (options->seconds == 0) {
        run(SWARM_MAX_TIME_S * 100u, 1, r, error);
        return;
    }
    run(options->seconds * 100u, 0, r, error);
}

static void run(uint32_t max_ticks, int stop_when_converged, swarm_result *r,
                swarm_shape_error *error)
{
    __builtin_memset(r, 0, sizeof *r);
    float sum_sq = 0.0f, worst = 0.0f;
    uint32_t samples = 0;
    uint32_t tick = 0;
    for (; tick < max_ticks; tick++) {
        uint32_t now = start_ms + tick * 10u; /* ms, wraps modulo 2^32 */
        int receiving = sending;
        sending = 1 - sending;
        for (int i = 0; i < SWARM_N; i++) {
            inbox *b = &air[receiving][i];
            current = i;
            for (uint32_t k = 0; k < b->count; k++)
                agent_loop_receive(&loops[i], b->items[k].port, b->items[k].bytes,
                                   b->items[k].len, now);
            b->count = 0;
            ph_status s = agent_loop_tick(&loops[i], now, broadcast, &i);
            if (s != PH_OK && r->error == PH_OK)
                r->error = s;
            float speed = norm(loops[i].setpoint[0], loops[i].setpoint[1]);
            if (speed > r->max_setpoint_speed)
                r->max_setpoint_speed = speed;
        }
        /* The vehicles fly toward their setpoints for one tick (the cascade's own
         * 100 Hz and 500 Hz ticks inside). */
        for (int i = 0; i < SWARM_N; i++) {
            ph_status s = ph_vehicle_step(&vehicles[i], loops[i].setpoint, TICK_S);
            if (s != PH_OK && r->error == PH_OK)
                r->error = s;
            for (int k = 0; k < 2; k++) {
                q[i][k] = vehicles[i].q[k];
                v[i][k] = vehicles[i].v[k];
            }
        }
        if (tick + 1000u >= max_ticks) { /* the last 10 s */
            float e = shape_error();
            sum_sq += e * e;
            worst = e > worst ? e : worst;
            samples++;
        }
        float unused;
        if (stop_when_converged && tick > 100u && converged(&unused)) {
            tick++;
            break;
        }
    }
    r->ticks = tick;
    r->time = (float)tick * TICK_S;
    for (int i = 0; i < SWARM_N; i++) {
        r->rel[i][0] = q[i][0] - q[0][0];
        r->rel[i][1] = q[i][1] - q[0][1];
        r->safe_ticks += loops[i].safe_ticks;
    }
    float unused;
    r->converged = converged(&unused) && r->error == PH_OK && lost == 0;
    if (error != NULL) {
        error->rms = samples > 0 ? __builtin_sqrtf(sum_sq / (float)samples) : shape_error();
        error->max = samples > 0 ? worst : shape_error();
    }
}

void swarm_print(const swarm_result *r)
{
    demo_out("DEMO final t=");
    demo_out_f32(r->time);
    demo_out(" rel=");
    for (int i = 0; i < SWARM_N; i++) {
        demo_out_f32(r->rel[i][0]);
        demo_out(",");
        demo_out_f32(r->rel[i][1]);
        demo_out(i + 1 < SWARM_N ? ";" : "\n");
    }
    demo_out("CFAPP result converged=");
    demo_out(r->converged ? "true" : "false");
    demo_out(" t=");
    demo_out_f32(r->time);
    demo_out(" ticks=");
    demo_out_u32(r->ticks);
    demo_out(" safe_ticks=");
    demo_out_u32(r->safe_ticks);
    demo_out(" max_setpoint_speed=");
    demo_out_f32(r->max_setpoint_speed);
    demo_out(" lost=");
    demo_out_u32(lost);
    demo_out(" error=");
    demo_out(ph_status_str(r->error));
    demo_out("\n");
}
