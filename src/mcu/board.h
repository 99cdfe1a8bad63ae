/* board.h -- what the co-processor firmware needs of a board: two non-blocking UARTs, a microsecond clock, an idle wait, the stack's high-water mark; one implementation per board (board_an500.c, board_f405.c), each with its vector table. */
#ifndef SONAR_MCU_BOARD_H
#define SONAR_MCU_BOARD_H

#include <stddef.h>
#include <stdint.h>

#define BOARD_UART_SONAR 0 /* Ping Protocol to the Ping360 */
#define BOARD_UART_HOST 1  /* co-processor frames to the onboard computer */
#define BOARD_SONAR_BAUD 115200u /* both UARTs' bit rate: the Ping360's serial default (the host does not set it) */

/*
 * Large, streamed state (the pipeline's background, 480 KB at 400 x 1200) goes in this section, which
 * a board's linker script places in its big RAM bank (an STM32H743's AXI SRAM: h743.ld); the rest
 * of the static state and the stack stay in the fast bank. Zeroed at reset like .bss.
 */
#define BOARD_LARGE __attribute__((section(".bss.large")))

/* Clocks, UARTs (BOARD_SONAR_BAUD 8N1, receive by interrupt into a ring), the 1 kHz tick. */
void board_init(void);

/* Bytes received on uart (0 or 1) since the last call, at most cap; never blocks. */
size_t board_uart_read(int uart, uint8_t *buf, size_t cap);

/* Queues n bytes for uart; returns how many fit (the rest is the caller's to retry); never blocks. */
size_t board_uart_write(int uart, const uint8_t *buf, size_t n);

/* Moves queued bytes into the UARTs' transmitters; call it from the main loop. */
void board_uart_pump(void);

/* Bytes that board_uart_write can take now for uart. */
size_t board_uart_room(int uart);

/* Bytes written to uart and not yet handed to its transmitter. */
size_t board_uart_pending(int uart);

/* Microseconds since boot, monotonic. */
int64_t board_micros(void);

/* Sleeps until the next interrupt (a byte, or the 1 ms tick). */
void board_idle(void);

/* Stack high-water mark in bytes: the painted words overwritten since reset (startup.c paints them). */
uint32_t board_stack_used(void);

/* startup.c: the reset handler and the trap for unused exceptions, for each board's vector table. */
void Reset_Handler(void);
void Default_Handler(void);

/* The top of the stack (the linker script's), the vector table's first word. */
extern uint32_t _estack;

/* Ends the program: under QEMU with -semihosting, QEMU exits with code (0 or 1); elsewhere it halts. */
void board_exit(int code);

/* Receive overruns counted by the UART hardware (bytes lost), per uart. */
uint32_t board_uart_overruns(int uart);

#endif
