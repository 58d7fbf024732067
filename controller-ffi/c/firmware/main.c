/*
 * c-firmware: the paper's four-agent formation through the C API of
 * controller-ffi on an STM32F405 (QEMU netduinoplus2), the plant simulated in C
 * (c/demo/paper_demo.c). Exits through semihosting: 0 when converged, 1
 * otherwise (or on a fault). Output (semihosting SYS_WRITE0):
 *
 *   DEMO final ... / DEMO result ...            (paper_demo.h)
 *   CABI region id=<k> name=<what> tick=<n> rx_frames=<n> tx_frames=<n>
 *   CABI stack init_bytes=<n> run_bytes=<n>
 *   CABI agent_size=<PH_AGENT_SIZE> agents=4
 *
 * Instruction counts: region k (1..4) is robot k's whole tick through the C API
 * at tick MEASURE_TICK (ph_receive of its inbox, ph_step, ph_frames or
 * ph_frames_cb), region 0 the empty calibration region (marker overhead). The
 * markers are stores to PH_INSN_MARKERS, watched by tools/qemu-insn (see
 * firmware-example/src/measure.rs); without the plugin they are plain stores.
 */
#include "paper_demo.h"
#include "startup.h"

/* Tick of the measured regions: t = 30 s, every output nominal. */
#define MEASURE_TICK 3000u
#define REGIONS 32

__attribute__((section(".uninit"), used)) volatile uint32_t PH_INSN_MARKERS[2 * REGIONS];

static uint32_t rx_seen[DEMO_N], tx_seen[DEMO_N];

void demo_out(const char *text)
{
    semihost_write(text);
}

/* A panic inside the library would call this before it traps. */
void ph_panic_hook(void)
{
    semihost_write("c-firmware: ph_panic_hook: the controller panicked\n");
    semihost_exit(0);
}

static void tick_begin(int robot, uint32_t tick)
{
    if (tick == MEASURE_TICK)
        PH_INSN_MARKERS[2 * (robot + 1)] = (uint32_t)(robot + 1);
}

static void tick_end(int robot, uint32_t tick, uint32_t rx, uint32_t tx)
{
    if (tick == MEASURE_TICK) {
        PH_INSN_MARKERS[2 * (robot + 1) + 1] = (uint32_t)(robot + 1);
        if (robot >= 0) {
            rx_seen[robot] = rx;
            tx_seen[robot] = tx;
        }
    }
}

static const demo_hooks hooks = {tick_begin, tick_end};

static uint8_t memory[DEMO_N][PH_AGENT_SIZE] __attribute__((aligned(PH_AGENT_ALIGN)));
static ph_config config;

int main(void)
{
    semihost_write("c-firmware: paper formation, 4 agents through the C API\n");
    if (ph_abi_version() != PH_ABI_VERSION || ph_agent_size() != PH_AGENT_SIZE ||
        ph_agent_align() != PH_AGENT_ALIGN) {
        semihost_write("c-firmware: ph_formation.h does not match the library\n");
        return 1;
    }
    ph_agent *agents[DEMO_N];
    for (int i = 0; i < DEMO_N; i++) {
        agents[i] = (ph_agent *)memory[i];
        demo_paper_config(i, &config);
        ph_status s = ph_agent_init(agents[i], sizeof memory[i], &config);
        if (s != PH_OK) {
            demo_out("c-firmware: ph_agent_init: ");
            demo_out(ph_status_str(s));
            demo_out("\n");
            return 1;
        }
    }
    uint32_t stack_init = stack_used();
    stack_paint();

    /* Calibration: an empty region through the same hooks (region 0). */
    tick_begin(-1, MEASURE_TICK);
    tick_end(-1, MEASURE_TICK, 0, 0);

    demo_result r;
    demo_run(agents, &hooks, &r);
    uint32_t stack_run = stack_used();
    demo_print(&r);

    demo_out("CABI region id=0 name=overhead\n");
    for (int i = 0; i < DEMO_N; i++) {
        demo_out("CABI region id=");
        demo_out_u32((uint32_t)(i + 1));
        demo_out(" name=robot");
        demo_out_u32((uint32_t)(i + 1));
        demo_out(" tick=");
        demo_out_u32(MEASURE_TICK);
        demo_out(" rx_frames=");
        demo_out_u32(rx_seen[i]);
        demo_out(" tx_frames=");
        demo_out_u32(tx_seen[i]);
        demo_out("\n");
    }
    demo_out("CABI stack init_bytes=");
    demo_out_u32(stack_init);
    demo_out(" run_bytes=");
    demo_out_u32(stack_run);
    demo_out("\nCABI agent_size=");
    demo_out_u32(PH_AGENT_SIZE);
    demo_out(" agents=4\n");
    return r.converged ? 0 : 1;
}
