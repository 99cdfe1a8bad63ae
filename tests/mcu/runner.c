/* runner.c -- runs a core test file's CMocka cases on the Cortex-M7 (or the F405's M4F) in QEMU: setjmp per case, output and exit code over semihosting; a few KB of static text buffer. */
#include <stdarg.h>
#include <stdio.h>

#include "cmocka.h"

/* The board the runner was built for: only the F405's build sets the grid on the command line (F405_GRID). */
#if defined(SONAR_MAX_SAMPLES) && SONAR_MAX_SAMPLES < 1200
#define CORE_NAME "Cortex-M4F (STM32F405 grid)"
#else
#define CORE_NAME "Cortex-M7"
#endif

void board_exit(int code);

static jmp_buf current;

/* Semihosting SYS_WRITE0: a NUL-terminated string to the host's stdout. */
static void say(const char *s)
{
    register uint32_t r0 __asm__("r0") = 0x04u;
    register const char *r1 __asm__("r1") = s;
    __asm__ volatile("bkpt #0xAB" : "+r"(r0) : "r"(r1) : "memory");
}

void mcu_fail(const char *file, int line, const char *fmt, ...)
{
    char msg[256];
    va_list ap;
    int k = snprintf(msg, sizeof(msg), "[  ERROR   ] --- ");
    va_start(ap, fmt);
    k += vsnprintf(msg + k, sizeof(msg) - (size_t)k, fmt, ap);
    va_end(ap);
    snprintf(msg + k, sizeof(msg) - (size_t)k, "\n[   LINE   ] --- %s:%d: error: Failure!\n", file, line);
    say(msg);
    longjmp(current, 1);
}

static char *hex(char *p, unsigned long long v)
{
    char d[20];
    int i = 0;
    *p++ = '0';
    *p++ = 'x';
    do {
        d[i++] = "0123456789abcdef"[v & 15u];
        v >>= 4;
    } while (v != 0);
    while (i > 0)
        *p++ = d[--i];
    *p = '\0';
    return p;
}

void mcu_fail_int(const char *file, int line, unsigned long long a, const char *op, unsigned long long b)
{
    char x[24], y[24];
    hex(x, a);
    hex(y, b);
    mcu_fail(file, line, "%s %s %s", x, op, y);
}

int mcu_run_tests(const struct CMUnitTest *tests, size_t n)
{
    char line[160];
    volatile size_t failed = 0; /* kept across longjmp */
    volatile size_t i;
    snprintf(line, sizeof(line), "[==========] Running %u test(s) on the %s.\n", (unsigned)n, CORE_NAME);
    say(line);
    for (i = 0; i < n; i++) {
        void *state = NULL;
        snprintf(line, sizeof(line), "[ RUN      ] %s\n", tests[i].name);
        say(line);
        if (setjmp(current) == 0) {
            tests[i].test_func(&state);
            snprintf(line, sizeof(line), "[       OK ] %s\n", tests[i].name);
        } else {
            failed++;
            snprintf(line, sizeof(line), "[  FAILED  ] %s\n", tests[i].name);
        }
        say(line);
    }
    snprintf(line, sizeof(line), "[==========] %u test(s) run.\n%u passed, %u failed\n", (unsigned)n,
             (unsigned)(n - failed), (unsigned)failed);
    say(line);
    board_exit(failed ? 1 : 0);
    return (int)failed;
}
