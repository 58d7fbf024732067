/*
 * The Crazyflie app's code on the Crazyflie's MCU (STM32F405, QEMU
 * netduinoplus2), with controller-ffi/c/firmware's start-up (semihosting, painted
 * stack). Besides swarm.h's lines it prints the app's stack peaks:
 *
 *   CFAPP stack init_bytes=<n> tick_bytes=<n>
 *
 * init: the four agent_loop_init() calls (blob lookup, ph_agent_init_blob,
 * ph_actuator_init, the neighbour table), what appMain runs before its loop;
 * tick: every agent_loop_receive() and agent_loop_tick() of the run. Both count
 * from the top of RAM, so they include this program's start-up and main frames
 * (a few dozen bytes more than the app task's appMain).
 */
#include "startup.h"
#include "swarm.h"

void demo_out(const char *text)
{
    semihost_write(text);
}

void ph_panic_hook(void)
{
    semihost_write("cfapp-firmware: ph_panic_hook: the controller panicked\n");
    semihost_exit(0);
}

int main(void)
{
    if (ph_abi_version() != PH_ABI_VERSION || ph_agent_size() != PH_AGENT_SIZE)
        return 1;
    stack_paint();
    ph_status s = swarm_init();
    uint32_t init = stack_used();
    if (s != PH_OK) {
        demo_out("CFAPP init failed: ");
        demo_out(ph_status_str(s));
        demo_out("\n");
        return 1;
    }
    stack_paint();
    swarm_result r;
    swarm_run(&r);
    uint32_t tick = stack_used();
    swarm_print(&r);
    demo_out("CFAPP stack init_bytes=");
    demo_out_u32(init);
    demo_out(" tick_bytes=");
    demo_out_u32(tick);
    demo_out("\n");
    return r.converged ? 0 : 1;
}
