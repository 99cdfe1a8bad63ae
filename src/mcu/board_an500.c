/* board_an500.c -- the board of QEMU's mps2-an500 (Cortex-M7): CMSDK APB UARTs 0 and 1 at 25 MHz, CMSDK timer 0 as the microsecond clock, SysTick at 1 kHz; register level, no vendor HAL; RAM: 2 x (1 KiB rx + 8 KiB tx) rings. */
#include "board.h"

#include <stdint.h>

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

#define RX_RING 1024u
/* Transmit rings: the sonar gets 24-byte requests; the host gets whole frames (a detections frame is up to 4 KB). */
#ifndef BOARD_SONAR_TX_RING
#define BOARD_SONAR_TX_RING 256u
#endif
#ifndef BOARD_HOST_TX_RING
#define BOARD_HOST_TX_RING 8192u
#endif

struct ring_rx {
    uint8_t b[RX_RING];
    volatile uint16_t head, tail; /* head: written by the interrupt; tail: by the main loop */
};

struct ring_tx {
    uint8_t *b;
    uint16_t size, head, tail;
};

/* The hardware's state: the interrupt handlers reach it, so it cannot live in a caller's struct. */
static struct an500 {
    struct ring_rx rx[2];
    struct ring_tx tx[2];
    uint8_t tx0[BOARD_SONAR_TX_RING], tx1[BOARD_HOST_TX_RING];
    uint32_t overruns[2];
    uint32_t last_ticks;
    uint64_t ticks_hi; /* timer ticks elapsed before last_ticks, extended past 32 bits */
} hw;

void board_uart0_rx_irq(void);
void board_uart1_rx_irq(void);
void board_uart0_tx_irq(void);
void board_uart1_tx_irq(void);
void board_systick_irq(void);

/* Moves queued bytes of uart n into its transmitter while it has room (interrupts masked by the caller). */
static void pump(int n)
{
    struct ring_tx *t = &hw.tx[n];
    while (t->tail != t->head && !(UART_STATE(n) & STATE_TX_FULL)) {
        UART_DATA(n) = t->b[t->tail];
        t->tail = (uint16_t)((t->tail + 1u) % t->size);
    }
}

/* The transmitter emptied: the next byte goes out from here, so a frame never waits for the main loop. */
static void tx_irq(int n)
{
    UART_INT(n) = INT_TX;
    pump(n);
}

void board_uart0_tx_irq(void) { tx_irq(0); }
void board_uart1_tx_irq(void) { tx_irq(1); }

static void rx_irq(int n)
{
    struct ring_rx *r = &hw.rx[n];
    /* Clear first, then drain: a byte arriving after the drain raises a fresh interrupt, where
     * clearing last would swallow it and leave the receiver full and silent. */
    UART_INT(n) = INT_RX;
    while (UART_STATE(n) & STATE_RX_FULL) {
        uint8_t c = (uint8_t)UART_DATA(n);
        uint16_t next = (uint16_t)((r->head + 1u) % RX_RING);
        if (next == r->tail)
            hw.overruns[n]++; /* the main loop fell behind by a whole ring */
        else {
            r->b[r->head] = c;
            r->head = next;
        }
    }
    if (UART_STATE(n) & STATE_RX_OVERRUN) {
        hw.overruns[n]++;
        UART_STATE(n) = STATE_RX_OVERRUN; /* write 1 to clear */
    }
}

void board_uart0_rx_irq(void) { rx_irq(0); }
void board_uart1_rx_irq(void) { rx_irq(1); }
void board_systick_irq(void) { /* only wakes board_idle */ }

void board_init(void)
{
    int n;
    hw.tx[0].b = hw.tx0;
    hw.tx[0].size = BOARD_SONAR_TX_RING;
    hw.tx[1].b = hw.tx1;
    hw.tx[1].size = BOARD_HOST_TX_RING;
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

size_t board_uart_read(int uart, uint8_t *buf, size_t cap)
{
    struct ring_rx *r = &hw.rx[uart];
    size_t n = 0;
    while (n < cap && r->tail != r->head) {
        buf[n++] = r->b[r->tail];
        r->tail = (uint16_t)((r->tail + 1u) % RX_RING);
    }
    return n;
}

size_t board_uart_write(int uart, const uint8_t *buf, size_t n)
{
    struct ring_tx *t = &hw.tx[uart];
    size_t k = 0;
    while (k < n) {
        uint16_t next = (uint16_t)((t->head + 1u) % t->size);
        if (next == t->tail)
            break;
        t->b[t->head] = buf[k++];
        t->head = next;
    }
    board_uart_pump();
    return k;
}

void board_uart_pump(void)
{
    /* The TX interrupt pumps too: mask it while the main loop does, so tail has one writer at a time. */
    __asm__ volatile("cpsid i" ::: "memory");
    pump(0);
    pump(1);
    __asm__ volatile("cpsie i" ::: "memory");
}

size_t board_uart_room(int uart)
{
    const struct ring_tx *t = &hw.tx[uart];
    return t->size - 1u - (size_t)((t->head + t->size - t->tail) % t->size);
}

size_t board_uart_pending(int uart)
{
    const struct ring_tx *t = &hw.tx[uart];
    return (size_t)((t->head + t->size - t->tail) % t->size);
}

int64_t board_micros(void)
{
    /* The timer counts down from 2^32 - 1 at 25 MHz (wraps every 171 s); called far more often than that. */
    uint32_t ticks = 0xFFFFFFFFu - TIMER_VALUE;
    hw.ticks_hi += (uint32_t)(ticks - hw.last_ticks);
    hw.last_ticks = ticks;
    return (int64_t)(hw.ticks_hi / (SYSCLK_HZ / 1000000u));
}

void board_idle(void)
{
    __asm__ volatile("wfi");
}

uint32_t board_uart_overruns(int uart)
{
    return hw.overruns[uart];
}

void board_exit(int code)
{
    /* Semihosting SYS_EXIT (0x18) with ADP_Stopped_ApplicationExit (0x20026) or RunTimeErrorUnknown (0x20023). */
    register uint32_t r0 __asm__("r0") = 0x18u;
    register uint32_t r1 __asm__("r1") = code == 0 ? 0x20026u : 0x20023u;
    __asm__ volatile("bkpt #0xAB" : : "r"(r0), "r"(r1) : "memory");
    for (;;)
        __asm__ volatile("wfi");
}
