/*
 * The paper's four-agent formation (SPEC §9, `paper` gains) driven through the
 * C API of controller-ffi, with its plant in C: the same demo as the Rust
 * firmware-example/src/boards/demo.rs (double integrator with friction, RK4
 * at 1 ms, exact bearings, a broadcast radio with one tick of latency, 100 Hz
 * control), so that host and target runs can be compared with qemu-demo and
 * host-sim.
 *
 * Shared by the host test program (c/host/main.c) and the STM32F405 firmware
 * (c/firmware/main.c). No libc: the platform provides demo_out().
 */
#ifndef PAPER_DEMO_H
#define PAPER_DEMO_H

#include <stdint.h>

#include "ph_formation.h"

/* Robots (ids 1..4). */
#define DEMO_N 4

/* Converged: every angle within DEMO_ANGLE_TOL rad, |(q1 - q2) - z*| below
 * DEMO_LEADER_TOL m and every |v - v*| below DEMO_VELOCITY_TOL m/s (the
 * thresholds of qemu-demo). */
#define DEMO_ANGLE_TOL 1.0e-4f
#define DEMO_LEADER_TOL 1.0e-3f
#define DEMO_VELOCITY_TOL 1.0e-3f
/* Give up after this many simulated seconds. */
#define DEMO_MAX_TIME_S 150u

/* The controller configuration of robot i (0..3, id i + 1). */
void demo_paper_config(int i, ph_config *config);

/* Optional hooks around the C API work of one robot's tick (ph_receive of
 * its inbox, ph_step, ph_frames*): the firmware marks instruction-count
 * regions there. Any may be NULL. */
typedef struct {
    void (*tick_begin)(int robot, uint32_t tick);
    void (*tick_end)(int robot, uint32_t tick, uint32_t rx_frames, uint32_t tx_frames);
} demo_hooks;

typedef struct {
    int converged;            /* all the conditions of demo_run() */
    float time;               /* s, at the end */
    float rel[DEMO_N][2];     /* q_i - q_1 at the end (m) */
    float angle_error;        /* rad */
    float leader_error;       /* m */
    float velocity_error;     /* m/s */
    uint32_t ticks;           /* control ticks run */
    uint32_t late_safe;       /* safe outputs after the first tick */
    uint32_t bad_frames;      /* rejected for another reason than "not a neighbour" */
    uint32_t lost;            /* frames that did not fit the air or an inbox */
    ph_status error;          /* first C API error (PH_OK if none) */
} demo_result;

/* Runs the four robots whose agents are already initialised until
 * converged or DEMO_MAX_TIME_S. Converged means: the metrics within the
 * tolerances at one tick, no safe output after the first tick, no frame lost
 * or rejected except as "not a neighbour", and no API error. Returns
 * result->converged. */
int demo_run(ph_agent *agents[DEMO_N], const demo_hooks *hooks, demo_result *result);

/* Prints the result as the two lines of qemu-demo:
 *   DEMO final t=<s> rel=<x1>,<y1>;...;<x4>,<y4>
 *   DEMO result converged=<true|false> t=... angle_error=... ...            */
void demo_print(const demo_result *result);

/* Text output, provided by the platform (stdout, semihosting). */
void demo_out(const char *text);

/* Helpers for the platform's own lines. */
void demo_out_u32(uint32_t v);
void demo_out_f32(float v);

#endif /* PAPER_DEMO_H */
