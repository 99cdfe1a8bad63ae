/* board_an500.c -- the board of QEMU's mps2-an500 (Cortex-M7): CMSDK APB UARTs 0 and 1 at 25 MHz, CMSDK timer 0 as the microsecond clock, SysTick at 1 kHz; register level, no vendor HAL; RAM: 2 x (1 KiB rx + 8 KiB tx) rings. */
#include "board.h"

#include <stdint.h>

#include "board_common.h"

#define SYSCLK_HZ 25000000u
#define BAUD BOARD_SONAR_BAUD

#define REG(a) (*(volatile uint32_t *)(uintptr_t)(a))
/* CMSDK APB UART */
#define UART_BASE(n) (0x40004000u + 0x1000u * (uint32_t)(n))
#define UART_DATA(n) REG(UART_BASE(n) + 0x00u)
#define UART_STATE(n) REG(UART_BASE(n) + 0x04u)
#define UART_CTRL(n) REG(UART_BASE(n) + 0x08u)
#define UART_INT(n) REG(UART_BASE(n) + 0x0Cu)
#define UART_BAUDDIV(n) REG(UART_BASE(n) + 0x10u)
#define STATE_TX_FULL 0x1u
#define STATE_RX_FULL 0x2u
#define STATE_RX_OVERRUN 0x8u
#define CTRL_TX_EN 0x1u
#define CTRL_RX_EN 0x2u
#define CTRL_TX_INT 0x4u
#define CTRL_RX_INT 0x8u
#define INT_TX 0x1u
#define INT_RX 0x2u
/* CMSDK APB timer 0 */
#define TIMER_CTRL REG(0x40000000u)
#define TIMER_VALUE REG(0x40000004u)
#define TIMER_RELOAD REG(0x40000008u)
/* SysTick, NVIC */
#define SYST_CSR REG(0xE000E010u)
#define SYST_RVR REG(0xE000E014u)
#define SYST_CVR REG(0xE000E018u)
#define NVIC_ISER0 REG(0xE000E100u)
#define UART_RX_IRQ(n) (2u * (uint32_t)(n)) /* UART0 RX is IRQ 0 and TX 1; UART1 RX 2 and TX 3 */
#define UART_TX_IRQ(n) (2u * (uint32_t)(n) + 1u)

/* The hardware's state: the interrupt handlers reach it, so it cannot live in a caller's struct. */
static struct an500 {
    struct board_uarts u;
    uint32_t last_ticks;
    uint64_t ticks_hi; /* timer ticks elapsed before last_ticks, extended past 32 bits */
} hw;

static void board_uart0_rx_irq(void);
static void board_uart1_rx_irq(void);
static void board_uart0_tx_irq(void);
static void board_uart1_tx_irq(void);
static void board_systick_irq(void);

/* 16 system exceptions, then the MPS2 IRQs: 0 UART0 RX, 1 UART0 TX, 2 UART1 RX, ... */
__attribute__((section(".isr_vector"), used)) static void (*const vectors[16 + 32])(void) = {
    (void (*)(void))(uintptr_t)&_estack, Reset_Handler, Default_Handler, Default_Handler, Default_Handler,
    Default_Handler, Default_Handler, 0, 0, 0, 0, Default_Handler, Default_Handler, 0, Default_Handler,
    board_systick_irq,
    [16 + 0] = board_uart0_rx_irq, [16 + 1] = board_uart0_tx_irq, [16 + 2] = board_uart1_rx_irq,
    [16 + 3] = board_uart1_tx_irq,
};

/* Moves queued bytes of uart n into its transmitter while it has room (interrupts masked by the caller). */
static void pump(int n)
{
    while (board_tx_pending(&hw.u.tx[n]) > 0 && !(UART_STATE(n) & STATE_TX_FULL))
        UART_DATA(n) = (uint32_t)board_tx_next(&hw.u.tx[n]);
}

/* The transmitter emptied: the next byte goes out from here, so a frame never waits for the main loop. */
static void tx_irq(int n)
{
    UART_INT(n) = INT_TX;
    pump(n);
}

static void board_uart0_tx_irq(void) { tx_irq(0); }
static void board_uart1_tx_irq(void) { tx_irq(1); }

static void rx_irq(int n)
{
    /* Clear first, then drain: a byte arriving after the drain raises a fresh interrupt, where
     * clearing last would swallow it and leave the receiver full and silent. */
    UART_INT(n) = INT_RX;
    while (UART_STATE(n) & STATE_RX_FULL)
        board_rx_put(&hw.u.rx[n], (uint8_t)UART_DATA(n), &hw.u.overruns[n]);
    if (UART_STATE(n) & STATE_RX_OVERRUN) {
        hw.u.overruns[n]++;
        UART_STATE(n) = STATE_RX_OVERRUN; /* write 1 to clear */
    }
}

static void board_uart0_rx_irq(void) { rx_irq(0); }
static void board_uart1_rx_irq(void) { rx_irq(1); }
static void board_systick_irq(void) { /* only wakes board_idle */ }

void board_init(void)
{
    int n;
    board_uarts_init(&hw.u);
    for (n = 0; n < 2; n++) {
        UART_BAUDDIV(n) = SYSCLK_HZ / BAUD;
        UART_CTRL(n) = CTRL_TX_EN | CTRL_RX_EN | CTRL_RX_INT | CTRL_TX_INT;
        NVIC_ISER0 = 1u << UART_RX_IRQ(n) | 1u << UART_TX_IRQ(n);
    }
    TIMER_RELOAD = 0xFFFFFFFFu;
    TIMER_VALUE = 0xFFFFFFFFu;
    TIMER_CTRL = 1u; /* enable, counting down at SYSCLK */
    hw.last_ticks = 0;
    SYST_RVR = SYSCLK_HZ / 1000u - 1u;
    SYST_CVR = 0;
    SYST_CSR = 7u; /* processor clock, interrupt, enable */
}

int64_t board_micros(void)
{
    /* The timer counts down from 2^32 - 1 at 25 MHz (wraps every 171 s); called far more often than that. */
    uint32_t ticks = 0xFFFFFFFFu - TIMER_VALUE;
    hw.ticks_hi += (uint32_t)(ticks - hw.last_ticks);
    hw.last_ticks = ticks;
    return (int64_t)(hw.ticks_hi / (SYSCLK_HZ / 1000000u));
}

struct board_uarts *board_uarts(void)
{
    return &hw.u;
}

void board_uart_kick(int n)
{
    pump(n);
}
