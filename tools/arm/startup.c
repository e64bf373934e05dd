/* A minimal bare-metal start for the Cortex-M4F (QEMU mps2-an386) and Cortex-M7 (mps2-an500):
 * the vector table, a reset handler that enables the FPU (CPACR: CP10 and CP11 full access),
 * copies .data, clears .bss and calls main, and semihosting output and exit (docs/arm.md). */
#include <stddef.h>
#include <stdint.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
int main(void);
void reset_handler(void);
void fault_handler(void);

__attribute__((section(".vectors"), used)) static const void *const vectors[16] = {
    &_estack, (const void *)reset_handler, (const void *)fault_handler,
    (const void *)fault_handler, (const void *)fault_handler, (const void *)fault_handler,
    (const void *)fault_handler, NULL, NULL, NULL, NULL, (const void *)fault_handler,
    (const void *)fault_handler, NULL, (const void *)fault_handler,
    (const void *)fault_handler};

/* A semihosting call (ARM: bkpt 0xab, the operation in r0, its argument in r1). */
static int semihost(int op, const void *arg) {
    register int r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

/* Prints a NUL-terminated string on the host's standard output (SYS_WRITE0). */
void host_print(const char *text) { (void)semihost(0x04, text); }

/* Ends the emulation: status 0 (ADP_Stopped_ApplicationExit) or 1 (RunTimeErrorUnknown). */
__attribute__((noreturn)) void host_exit(int status) {
    (void)semihost(0x18, (const void *)(uintptr_t)(status == 0 ? 0x20026u : 0x20023u));
    for (;;) {
    }
}

void fault_handler(void) {
    host_print("FAULT\n");
    host_exit(1);
}

void reset_handler(void) {
    volatile uint32_t *cpacr = (volatile uint32_t *)0xE000ED88u;
    *cpacr |= (0xFu << 20);
    __asm__ volatile("dsb\n\tisb" ::: "memory");
    const uint32_t *src = &_sidata;
    for (uint32_t *dst = &_sdata; dst < &_edata;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = &_sbss; dst < &_ebss;) {
        *dst++ = 0;
    }
    host_exit(main());
}

/* newlib's libm reports domain errors through errno: one static slot, no reentrancy. */
int *__errno(void);
int *__errno(void) {
    static int e;
    return &e;
}
