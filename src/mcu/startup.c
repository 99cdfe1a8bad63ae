/* startup.c -- Cortex-M reset for every board: FPU on, .data copied, .bss (and the large bank) zeroed, the stack painted for the high-water mark, then main; each board file holds its vector table; no RAM of its own. */
#include <stdint.h>
#include <string.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _sbss_large, _ebss_large, _sstack, _estack;
int main(void);
uint32_t board_stack_used(void);
void Reset_Handler(void);
void Default_Handler(void);

#define STACK_PAINT 0xA5A5A5A5u

uint32_t board_stack_used(void)
{
    const uint32_t *p = &_sstack;
    /* The stack grows down from _estack: the first unpainted word from the bottom is the deepest use. */
    while (p < &_estack && *p == STACK_PAINT)
        p++;
    return (uint32_t)((uintptr_t)&_estack - (uintptr_t)p);
}

void Default_Handler(void)
{
    for (;;)
        __asm__ volatile("bkpt #0");
}

void Reset_Handler(void)
{
    uint32_t *p, *end = (uint32_t *)((uintptr_t)&_estack - 256u); /* spare the reset handler's own frame */
    /* CPACR: full access to CP10/CP11 (the FPU) before any float code runs. */
    *(volatile uint32_t *)0xE000ED88u |= 0xFu << 20;
    __asm__ volatile("dsb\n isb");
    memcpy(&_sdata, &_sidata, (size_t)((char *)&_edata - (char *)&_sdata));
    memset(&_sbss, 0, (size_t)((char *)&_ebss - (char *)&_sbss));
    memset(&_sbss_large, 0, (size_t)((char *)&_ebss_large - (char *)&_sbss_large)); /* BOARD_LARGE, in its bank */
    /* Paint the stack below the current frame: the lowest overwritten word gives the high-water mark. */
    for (p = &_sstack; p < end; p++)
        *p = STACK_PAINT;
    (void)main();
    for (;;)
        __asm__ volatile("wfi");
}
