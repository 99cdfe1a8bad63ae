/* board_common.h -- what every board file shares: the UART rings (interrupt in, main loop out) and the semihosting exit; RAM: the rings are the board's. */
#ifndef SONAR_MCU_BOARD_COMMON_H
#define SONAR_MCU_BOARD_COMMON_H

#include <stddef.h>
#include <stdint.h>

#define BOARD_RX_RING 1024u
/* Transmit rings: the sonar gets 24-byte requests; the host gets whole frames (a detections frame is up to 4 KB). */
#ifndef BOARD_SONAR_TX_RING
#define BOARD_SONAR_TX_RING 256u
#endif
#ifndef BOARD_HOST_TX_RING
#define BOARD_HOST_TX_RING 8192u
#endif

struct board_rx {
    uint8_t b[BOARD_RX_RING];
    volatile uint16_t head, tail; /* head: written by the interrupt; tail: by the main loop */
};

struct board_tx {
    uint8_t *b;
    uint16_t size;
    volatile uint16_t head, tail; /* head: the main loop; tail: whoever pumps (interrupts masked in the main loop) */
};

/* The receive interrupt's byte c into r; a full ring counts it in *overruns and drops it. */
void board_rx_put(struct board_rx *r, uint8_t c, uint32_t *overruns);

/* At most cap bytes out of r (main loop). */
size_t board_rx_take(struct board_rx *r, uint8_t *buf, size_t cap);

/* Queues up to n bytes on t (main loop); returns how many fit. */
size_t board_tx_queue(struct board_tx *t, const uint8_t *buf, size_t n);

/* Bytes t can still take, and bytes waiting in it. */
size_t board_tx_room(const struct board_tx *t);
size_t board_tx_pending(const struct board_tx *t);

/* The next byte to transmit from t, -1 when empty (the pump's side). */
int board_tx_next(struct board_tx *t);

/* Both UARTs' rings and overrun counts (uart 0 the sonar, 1 the host). */
struct board_uarts {
    struct board_rx rx[2];
    struct board_tx tx[2];
    uint32_t overruns[2];
    uint8_t tx0[BOARD_SONAR_TX_RING], tx1[BOARD_HOST_TX_RING];
};

/* Empty rings, the transmit rings on their buffers: first thing in board_init. */
void board_uarts_init(struct board_uarts *u);

/*
 * What each board file provides to board_common.c, which implements board.h's UART calls on top:
 * its rings, and moving queued bytes of uart n into its transmitter (called with interrupts masked).
 */
struct board_uarts *board_uarts(void);
void board_uart_kick(int n);

#endif
