/*
 * Minimal start-up of the C firmware on a Cortex-M4F (STM32F405): vector table,
 * reset handler (FPU on, .data copied, .bss zeroed, stack painted, main), fault
 * handlers that end a QEMU run, semihosting output and exit, stack measurement.
 */
#include <stdint.h>

#include "startup.h"

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _stack_bottom, _stack_top;
int main(void);

/* ------------------------------------------------------------ semihosting */

static int semihost(int op, const void *arg)
{
    register int r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

void semihost_write(const char *text)
{
    semihost(0x04, text); /* SYS_WRITE0: a NUL-terminated string */
}

void semihost_exit(int success)
{
    /* SYS_EXIT (angel_SWIreason_ReportException, 0x18) with the reason
     * ADP_Stopped_ApplicationExit (0x20026): QEMU exits with 0; any other
     * reason (here ADP_Stopped_RunTimeErrorUnknown, 0x20023) with 1. */
    semihost(0x18, (const void *)(uintptr_t)(success ? 0x20026u : 0x20023u));
    for (;;) {
    }
}

/* ------------------------------------------------------------------ stack */

#define PAINT 0xCCCCCCCCu

static uint32_t *current_sp(void)
{
    uint32_t *sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    return sp;
}

void stack_paint(void)
{
    /* Below the caller's frames, with a margin for this function's own. */
    uint32_t *end = current_sp() - 16;
    for (uint32_t *p = &_stack_bottom; p < end; p++)
        *p = PAINT;
}

uint32_t stack_used(void)
{
    uint32_t *p = &_stack_bottom;
    while (p < &_stack_top && *p == PAINT)
        p++;
    return (uint32_t)((uintptr_t)&_stack_top - (uintptr_t)p);
}

/* ------------------------------------------------------------------ reset */

/* Runs after the FPU is on: copies .data, zeroes .bss, paints the stack,
 * calls main and exits with its verdict. */
__attribute__((noreturn, used)) void reset_c(void)
{
    for (uint32_t *src = &_sidata, *dst = &_sdata; dst < &_edata;)
        *dst++ = *src++;
    for (uint32_t *dst = &_sbss; dst < &_ebss;)
        *dst++ = 0;
    stack_paint();
    semihost_exit(main() == 0);
}

/* The first code: enable CP10/CP11 (the FPU) in CPACR before any
 * floating-point instruction can run (the hard-float ABI uses the FPU
 * registers in ordinary code), then continue in C. */
__attribute__((naked, noreturn)) void Reset_Handler(void)
{
    __asm__ volatile(
        "ldr r0, =0xE000ED88\n" /* SCB->CPACR */
        "ldr r1, [r0]\n"
        "orr r1, r1, #(0xF << 20)\n"
        "str r1, [r0]\n"
        "dsb\n"
        "isb\n"
        "b reset_c\n");
}

/* ------------------------------------------------------------- exceptions */

static void fault(const char *what)
{
    semihost_write(what);
    semihost_exit(0);
}

void HardFault_Handler(void)
{
    fault("c-firmware: HardFault\n");
}

void Default_Handler(void)
{
    fault("c-firmware: unexpected exception\n");
}

typedef void (*vector)(void);

__attribute__((section(".isr_vector"), used)) const vector vector_table[16] = {
    (vector)(uintptr_t)&_stack_top, /* initial SP */
    Reset_Handler,
    Default_Handler, /* NMI */
    HardFault_Handler,
    Default_Handler, /* MemManage */
    Default_Handler, /* BusFault */
    Default_Handler, /* UsageFault */
    0, 0, 0, 0,
    Default_Handler, /* SVCall */
    Default_Handler, /* DebugMonitor */
    0,
    Default_Handler, /* PendSV */
    Default_Handler, /* SysTick */
};
