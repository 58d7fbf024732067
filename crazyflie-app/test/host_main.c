/*
 * The Crazyflie app's code on the host (swarm.h): prints the swarm's lines;
 * exits 0 when it converged.
 */
#include <stdio.h>

#include "swarm.h"

void demo_out(const char *text)
{
    fputs(text, stdout);
}

int main(void)
{
    if (ph_abi_version() != PH_ABI_VERSION || ph_agent_size() != PH_AGENT_SIZE)
        return 1;
    ph_status s = swarm_init();
    if (s != PH_OK) {
        printf("CFAPP init failed: %s\n", ph_status_str(s));
        return 1;
    }
    swarm_result r;
    swarm_run(&r);
    swarm_print(&r);
    return r.converged ? 0 : 1;
}
