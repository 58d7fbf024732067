/*
 * Text output of the demo without libc (the firmware has none): integers,
 * floats with 7 significant digits (float arithmetic only: no soft-float
 * double routines on the Cortex-M4F), and the result lines.
 */
#include "paper_demo.h"

void demo_out_u32(uint32_t v)
{
    char buf[11];
    int n = 10;
    buf[n] = '\0';
    do {
        buf[--n] = (char)('0' + v % 10u);
        v /= 10u;
    } while (v != 0 && n > 0);
    demo_out(&buf[n]);
}

/* Scientific notation, 7 significant digits (the last one may be off by one:
 * the scaling is done in float): -1.234568e-05. NaN and infinities as text. */
void demo_out_f32(float v)
{
    if (v != v) {
        demo_out("NaN");
        return;
    }
    if (v < 0.0f) {
        demo_out("-");
        v = -v;
    }
    if (v > 3.4e38f) {
        demo_out("inf");
        return;
    }
    if (v == 0.0f) {
        demo_out("0.0");
        return;
    }
    /* Scale to [1e6, 1e7), then print the integer with a decimal point after
     * its first digit. */
    int exp10 = 6;
    while (v >= 1e7f) {
        v /= 10.0f;
        exp10++;
    }
    while (v < 1e6f) {
        v *= 10.0f;
        exp10--;
    }
    uint32_t digits = (uint32_t)(v + 0.5f);
    if (digits >= 10000000u) {
        digits /= 10u;
        exp10++;
    }
    char buf[10];
    int n = 9;
    buf[n] = '\0';
    for (int k = 0; k < 7; k++) {
        buf[--n] = (char)('0' + digits % 10u);
        digits /= 10u;
        if (k == 5)
            buf[--n] = '.';
    }
    demo_out(&buf[n]);
    demo_out("e");
    if (exp10 < 0) {
        demo_out("-");
        exp10 = -exp10;
    }
    demo_out_u32((uint32_t)exp10);
}

void demo_print(const demo_result *r)
{
    demo_out("DEMO final t=");
    demo_out_f32(r->time);
    demo_out(" rel=");
    for (int i = 0; i < DEMO_N; i++) {
        if (i > 0)
            demo_out(";");
        demo_out_f32(r->rel[i][0]);
        demo_out(",");
        demo_out_f32(r->rel[i][1]);
    }
    demo_out("\nDEMO result converged=");
    demo_out(r->converged ? "true" : "false");
    demo_out(" t=");
    demo_out_f32(r->time);
    demo_out(" ticks=");
    demo_out_u32(r->ticks);
    demo_out(" angle_error=");
    demo_out_f32(r->angle_error);
    demo_out(" leader_error=");
    demo_out_f32(r->leader_error);
    demo_out(" velocity_error=");
    demo_out_f32(r->velocity_error);
    demo_out(" late_safe=");
    demo_out_u32(r->late_safe);
    demo_out(" bad_frames=");
    demo_out_u32(r->bad_frames);
    demo_out(" lost=");
    demo_out_u32(r->lost);
    demo_out(" error=");
    demo_out(ph_status_str(r->error));
    demo_out("\n");
}
