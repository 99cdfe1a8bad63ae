/* board_common.c -- what every board shares: the UART rings and board.h's UART calls on them, the idle wait, the semihosting exit; O(bytes), no RAM of its own. */
#include "board_common.h"

#include "board.h"

void board_rx_put(struct board_rx *r, uint8_t c, uint32_t *overruns)
{
    uint16_t next = (uint16_t)((r->head + 1u) % BOARD_RX_RING);
    if (next == r->tail) {
        (*overruns)++; /* the main loop fell behind by a whole ring */
        return;
    }
    r->b[r->head] = c;
    r->head = next;
}

size_t board_rx_take(struct board_rx *r, uint8_t *buf, size_t cap)
{
    size_t n = 0;
    while (n < cap && r->tail != r->head) {
        buf[n++] = r->b[r->tail];
        r->tail = (uint16_t)((r->tail + 1u) % BOARD_RX_RING);
    }
    return n;
}

size_t board_tx_queue(struct board_tx *t, const uint8_t *buf, size_t n)
{
    size_t k = 0;
    while (k < n) {
        uint16_t next = (uint16_t)((t->head + 1u) % t->size);
        if (next == t->tail)
            break;
        t->b[t->head] = buf[k++];
        t->head = next;
    }
    return k;
}

size_t board_tx_room(const struct board_tx *t)
{
    return t->size - 1u - (size_t)((t->head + t->size - t->tail) % t->size);
}

size_t board_tx_pending(const struct board_tx *t)
{
    return (size_t)((t->head + t->size - t->tail) % t->size);
}

int board_tx_next(struct board_tx *t)
{
    uint8_t c;
    if (t->tail == t->head)
        return -1;
    c = t->b[t->tail];
    t->tail = (uint16_t)((t->tail + 1u) % t->size);
    return c;
}

void board_uarts_init(struct board_uarts *u)
{
    u->tx[0].b = u->tx0;
    u->tx[0].size = BOARD_SONAR_TX_RING;
    u->tx[1].b = u->tx1;
    u->tx[1].size = BOARD_HOST_TX_RING;
}

size_t board_uart_read(int uart, uint8_t *buf, size_t cap)
{
    return board_rx_take(&board_uarts()->rx[uart], buf, cap);
}

size_t board_uart_write(int uart, const uint8_t *buf, size_t n)
{
    size_t k = board_tx_queue(&board_uarts()->tx[uart], buf, n);
    board_uart_pump();
    return k;
}

void board_uart_pump(void)
{
    /* The transmit interrupt pumps too: mask it while the main loop does, so tail has one writer at a time. */
    __asm__ volatile("cpsid i" ::: "memory");
    board_uart_kick(0);
    board_uart_kick(1);
    __asm__ volatile("cpsie i" ::: "memory");
}

size_t board_uart_room(int uart)
{
    return board_tx_room(&board_uarts()->tx[uart]);
}

size_t board_uart_pending(int uart)
{
    return board_tx_pending(&board_uarts()->tx[uart]);
}

uint32_t board_uart_overruns(int uart)
{
    return board_uarts()->overruns[uart];
}

void board_idle(void)
{
    __asm__ volatile("wfi");
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
