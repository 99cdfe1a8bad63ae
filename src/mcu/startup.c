/* startup.c -- Cortex-M7 vector table and reset: FPU on, .data copied, .bss zeroed, the stack painted for the high-water mark, then main; no RAM of its own. */
#include <stdint.h>
#include <string.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _sbss_large, _ebss_large, _sstack, _estack;
int main(void);
uint32_t board_stack_used(void);
void Reset_Handler(void);
void Default_Handler(void);
void board_uart0_rx_irq(void);
void board_uart1_rx_irq(void);
void board_uart0_tx_irq(void);
void board_uart1_tx_irq(void);
void board_systick_irq(void);

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

/* 16 system exceptions, then the MPS2 IRQs: 0 UART0 RX, 1 UART0 TX, 2 UART1 RX, ... */
__attribute__((section(".isr_vector"), used)) static void (*const vectors[16 + 32])(void) = {
    (void (*)(void))(uintptr_t)&_estack, Reset_Handler, Default_Handler, Default_Handler, Default_Handler,
    Default_Handler, Default_Handler, 0, 0, 0, 0, Default_Handler, Default_Handler, 0, Default_Handler,
    board_systick_irq,
    [16 + 0] = board_uart0_rx_irq, [16 + 1] = board_uart0_tx_irq, [16 + 2] = board_uart1_rx_irq,
    [16 + 3] = board_uart1_tx_irq,
};
