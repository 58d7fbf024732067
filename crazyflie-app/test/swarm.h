/*
 * Four Crazyflie apps (agent_loop.c + formation.c, configured by their exported
 * blobs) against simulated vehicles and radio, with no FreeRTOS and no firmware:
 * the app's own per-tick code through the C API, run on the host
 * (host_main.c) and on the STM32F405 under QEMU (qemu_main.c), by
 * controller-ffi/tests/crazyflie_app.rs.
 *
 * Vehicles: each is a Crazyflie flying the firmware's PID cascade in velocity
 * mode (ph_vehicle_*, the C API's sim-vehicle build; docs/world.md); the state
 * estimator reads the true position and velocity. Radio: every packet a vehicle sends reaches the three others at
 * the next tick (10 ms), as P2P broadcast does.
 */
#ifndef SWARM_H
#define SWARM_H

#include <stdint.h>

#include "ph_formation.h"

#define SWARM_N 4
/* Give up after this many simulated seconds. */
#define SWARM_MAX_TIME_S 60u
/* Converged: every q_i - q_1 within SWARM_SHAPE_TOL m of the square 1-2-4-3 of
 * crazyflie-app/formation.toml and every speed below SWARM_SPEED_TOL m/s. */
#define SWARM_SHAPE_TOL 1.0e-3f
#define SWARM_SPEED_TOL 1.0e-3f

typedef struct {
    int converged;
    float time;                /* s, at the end */
    float rel[SWARM_N][2];     /* q_i - q_1 at the end (m) */
    float max_setpoint_speed;  /* m/s, over the run */
    uint32_t ticks;
    uint32_t safe_ticks;       /* all agents, after each one's first tick */
    ph_status error;           /* first init or step error (PH_OK if none) */
} swarm_result;

/* Position accuracy study (host only): Gaussian noise of this standard deviation
 * (m) on every position the state estimator gives (own position, and through the
 * position packets the neighbours'), and a run of fixed length. */
typedef struct {
    float position_noise; /* m, 0: exact */
    uint32_t seconds;     /* 0: until converged or SWARM_MAX_TIME_S */
    uint32_t start_ms;    /* the control clock at the start (ms; wraps modulo 2^32) */
} swarm_options;

/* RMS and largest distance of q_i - q_1 from the square over the last
 * 10 s of a fixed-length run (m). */
typedef struct {
    float rms;
    float max;
} swarm_shape_error;

/* Builds the four agents (agent_loop_init, as appMain does). */
ph_status swarm_init(void);

/* Runs them until converged or SWARM_MAX_TIME_S. Returns result->converged. */
int swarm_run(swarm_result *result);

/* A fixed-length run with options (host): the shape error of its last 10 s. */
void swarm_run_with(const swarm_options *options, swarm_result *result,
                    swarm_shape_error *error);

/* Prints "DEMO final t=... rel=..." (the format of paper_demo.h) and
 * "CFAPP result converged=... t=... ticks=... safe_ticks=... max_setpoint_speed=... error=...". */
void swarm_print(const swarm_result *result);

/* Text output, provided by the platform. */
void demo_out(const char *text);
void demo_out_u32(uint32_t v);
void demo_out_f32(float v);

#endif /* SWARM_H */
