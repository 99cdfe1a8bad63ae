/* board_f405.c -- the board of an STM32F405 (Cortex-M4F; QEMU's netduinoplus2): USART1 to the sonar, USART2 to the host, SysTick as the 1 kHz tick and the microsecond clock; register level, no vendor HAL; RAM: 2 x 1 KiB rx rings, 256 B + 8 KiB tx rings (BOARD_LARGE, beside the background). */
#include "board.h"

#include <stdint.h>

#include "board_common.h"

/*
 * The clock tree is taken as set up for 168 MHz (HSE through the PLL: PCLK2 84 MHz for USART1,
 * PCLK1 42 MHz for USART2), which is what QEMU models. A real board sets the PLL first
 * (docs/coprocessor.md); QEMU leaves RCC and the GPIOs unimplemented and ignores the writes below.
 */
#define SYSCLK_HZ 168000000u
#define PCLK2_HZ 84000000u
#define PCLK1_HZ 42000000u
#define BAUD BOARD_SONAR_BAUD

#define REG(a) (*(volatile uint32_t *)(uintptr_t)(a))
/* USART1 (APB2) and USART2 (APB1): SR, DR, BRR, CR1 */
#define USART_BASE(n) ((n) == 0 ? 0x40011000u : 0x40004400u)
#define USART_SR(n) REG(USART_BASE(n) + 0x00u)
#define USART_DR(n) REG(USART_BASE(n) + 0x04u)
#define USART_BRR(n) REG(USART_BASE(n) + 0x08u)
#define USART_CR1(n) REG(USART_BASE(n) + 0x0Cu)
#define SR_ORE 0x08u
#define SR_RXNE 0x20u
#define SR_TXE 0x80u
#define CR1_RE 0x0004u
#define CR1_TE 0x0008u
#define CR1_RXNEIE 0x0020u
#define CR1_TXEIE 0x0080u
#define CR1_UE 0x2000u
#define USART_IRQ(n) ((n) == 0 ? 37u : 38u)
/* RCC clock enables and GPIOA: PA9/PA10 USART1 (AF7), PA2/PA3 USART2 (AF7) */
#define RCC_AHB1ENR REG(0x40023830u)
#define RCC_APB1ENR REG(0x40023840u)
#define RCC_APB2ENR REG(0x40023844u)
#define GPIOA_MODER REG(0x40020000u)
#define GPIOA_AFRL REG(0x40020020u)
#define GPIOA_AFRH REG(0x40020024u)
/* SysTick, NVIC */
#define SYST_CSR REG(0xE000E010u)
#define SYST_RVR REG(0xE000E014u)
#define SYST_CVR REG(0xE000E018u)
#define NVIC_ISER(i) REG(0xE000E100u + 4u * (uint32_t)(i))

/* The hardware's state: the interrupt handlers reach it, so it cannot live in a caller's struct. */
static struct f405 {
    struct board_uarts u;
    volatile uint32_t ms; /* SysTick interrupts since boot */
} hw BOARD_LARGE;

static void usart1_irq(void);
static void usart2_irq(void);
static void systick_irq(void);

/* 16 system exceptions, then the STM32F405's 82 IRQs: USART1 is 37, USART2 38. */
__attribute__((section(".isr_vector"), used)) static void (*const vectors[16 + 82])(void) = {
    (void (*)(void))(uintptr_t)&_estack, Reset_Handler, Default_Handler, Default_Handler, Default_Handler,
    Default_Handler, Default_Handler, 0, 0, 0, 0, Default_Handler, Default_Handler, 0, Default_Handler,
    systick_irq,
    [16 + 37] = usart1_irq, [16 + 38] = usart2_irq,
};

/* Moves queued bytes of usart n into its transmitter while it is empty; TXEIE only while bytes wait. */
static void pump(int n)
{
    while (board_tx_pending(&hw.u.tx[n]) > 0 && (USART_SR(n) & SR_TXE))
        USART_DR(n) = (uint32_t)board_tx_next(&hw.u.tx[n]);
    if (board_tx_pending(&hw.u.tx[n]) > 0)
        USART_CR1(n) |= CR1_TXEIE;
    else
        USART_CR1(n) &= ~CR1_TXEIE;
}

static void usart_irq(int n)
{
    uint32_t sr = USART_SR(n);
    if (sr & SR_ORE)
        hw.u.overruns[n]++; /* a byte lost in the hardware; reading DR below clears it */
    if (sr & (SR_RXNE | SR_ORE)) {
        uint8_t c = (uint8_t)USART_DR(n);
        if (sr & SR_RXNE)
            board_rx_put(&hw.u.rx[n], c, &hw.u.overruns[n]);
    }
    if (USART_CR1(n) & CR1_TXEIE)
        pump(n);
}

static void usart1_irq(void) { usart_irq(0); }
static void usart2_irq(void) { usart_irq(1); }
static void systick_irq(void) { hw.ms++; }

void board_init(void)
{
    int n;
    board_uarts_init(&hw.u);
    RCC_AHB1ENR |= 1u << 0;  /* GPIOA */
    RCC_APB2ENR |= 1u << 4;  /* USART1 */
    RCC_APB1ENR |= 1u << 17; /* USART2 */
    /* PA2, PA3, PA9, PA10 alternate function 7 */
    GPIOA_MODER = (GPIOA_MODER & ~(3u << 4 | 3u << 6 | 3u << 18 | 3u << 20)) | (2u << 4 | 2u << 6 | 2u << 18 | 2u << 20);
    GPIOA_AFRL = (GPIOA_AFRL & ~(0xFu << 8 | 0xFu << 12)) | (7u << 8 | 7u << 12);
    GPIOA_AFRH = (GPIOA_AFRH & ~(0xFu << 4 | 0xFu << 8)) | (7u << 4 | 7u << 8);
    for (n = 0; n < 2; n++) {
        USART_BRR(n) = ((n == 0 ? PCLK2_HZ : PCLK1_HZ) + BAUD / 2u) / BAUD; /* oversampling by 16 */
        USART_CR1(n) = CR1_UE | CR1_TE | CR1_RE | CR1_RXNEIE;
        NVIC_ISER(USART_IRQ(n) / 32u) = 1u << (USART_IRQ(n) % 32u);
    }
    SYST_RVR = SYSCLK_HZ / 1000u - 1u;
    SYST_CVR = 0;
    SYST_CSR = 7u; /* processor clock, interrupt, enable */
}

int64_t board_micros(void)
{
    /* Milliseconds from the tick, microseconds from SysTick's down-counter; read again if a tick came between. */
    uint32_t ms, cvr;
    do {
        ms = hw.ms;
        cvr = SYST_CVR;
    } while (ms != hw.ms);
    return (int64_t)ms * 1000 + (int64_t)((SYST_RVR - cvr) / (SYSCLK_HZ / 1000000u));
}

struct board_uarts *board_uarts(void)
{
    return &hw.u;
}

void board_uart_kick(int n)
{
    pump(n);
}
