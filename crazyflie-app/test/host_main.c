/*
 * The Crazyflie app's code on the host (swarm.h):
 *
 *   cfapp-host                                  until converged: prints the swarm's
 *                                               lines, exits 0 when it converged
 *   cfapp-host --position-noise SIGMA --seconds T
 *                                               a T-second run with Gaussian noise of
 *                                               SIGMA m on every estimated position;
 *                                               also prints
 *                                               CFAPP shape noise=<m> rms=<m> max=<m>
 *                                               (q_i - q_1 against the square, last 10 s)
 *   cfapp-host --start-ms MS                    the first, with the control clock
 *                                               starting at MS ms (modulo 2^32: a year
 *                                               of uptime is 31,536,000,000 ms)
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "swarm.h"

void demo_out(const char *text)
{
    fputs(text, stdout);
}

int main(int argc, char **argv)
{
    if (ph_abi_version() != PH_ABI_VERSION || ph_agent_size() != PH_AGENT_SIZE)
        return 1;
    swarm_options options = {0.0f, 0, 0};
    int study = 0;
    for (int k = 1; k + 1 < argc; k += 2) {
        char *end = NULL;
        double value = strtod(argv[k + 1], &end);
        if (end == argv[k + 1] || *end != '\0' || !(value >= 0.0)) {
            fprintf(stderr, "%s: %s: not a non-negative number\n", argv[k], argv[k + 1]);
            return 2;
        }
        if (strcmp(argv[k], "--position-noise") == 0)
            options.position_noise = (float)value;
        else if (strcmp(argv[k], "--seconds") == 0)
            options.seconds = (uint32_t)value;
        else if (strcmp(argv[k], "--start-ms") == 0) {
            /* The uptime at the start, modulo 2^32 ms (the clock's wrap). */
            options.start_ms = (uint32_t)(uint64_t)value;
            continue; /* not a study: the run until converged */
        }
        else {
            fprintf(stderr, "usage: %s [--position-noise M] [--seconds S] [--start-ms MS]\n",
                    argv[0]);
            return 2;
        }
        study = 1;
    }
    if (argc % 2 == 0) {
        fprintf(stderr, "usage: %s [--position-noise M] [--seconds S]\n", argv[0]);
        return 2;
    }
    ph_status s = swarm_init();
    if (s != PH_OK) {
        printf("CFAPP init failed: %s\n", ph_status_str(s));
        return 1;
    }
    swarm_result r;
    swarm_shape_error e;
    swarm_run_with(&options, &r, &e);
    swarm_print(&r);
    if (study) {
        printf("CFAPP shape noise=%g rms=%.4g max=%.4g\n", (double)options.position_noise,
               (double)e.rms, (double)e.max);
        return r.error == PH_OK ? 0 : 1;
    }
    return r.converged ? 0 : 1;
}
