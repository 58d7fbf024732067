/* Start-up services of the C firmware (startup.c). */
#ifndef STARTUP_H
#define STARTUP_H

#include <stdint.h>

/* Semihosting (QEMU -semihosting-config enable=on, or a debugger). */
void semihost_write(const char *text);
void semihost_exit(int success) __attribute__((noreturn));

/* Fill the free stack below the caller with a pattern; stack_used() is then the
 * deepest use since (bytes from the top of RAM). */
void stack_paint(void);
uint32_t stack_used(void);

#endif /* STARTUP_H */
