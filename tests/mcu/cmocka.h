/* cmocka.h (co-processor) -- the subset of CMocka's API the core's tests use, for running the same test files on the Cortex-M7 in QEMU (tests/mcu/runner.c reports over semihosting); CMocka itself needs an OS. */
#ifndef SONAR_MCU_CMOCKA_H
#define SONAR_MCU_CMOCKA_H

#include <setjmp.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

struct CMUnitTest {
    const char *name;
    void (*test_func)(void **state);
};

#define cmocka_unit_test(f) {#f, f}
#define cmocka_run_group_tests(tests, setup, teardown) mcu_run_tests((tests), sizeof(tests) / sizeof((tests)[0]))

int mcu_run_tests(const struct CMUnitTest *tests, size_t n);
void mcu_fail(const char *file, int line, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((noreturn, format(printf, 3, 4)))
#endif
    ;

/* newlib-nano's printf has no %ll: integer failures are formatted by the runner. */
void mcu_fail_int(const char *file, int line, unsigned long long a, const char *op, unsigned long long b)
#if defined(__GNUC__)
    __attribute__((noreturn))
#endif
    ;

#define MCU_U(x) ((unsigned long long)(x))
#define assert_true(c) ((c) ? (void)0 : mcu_fail(__FILE__, __LINE__, "%s is false", #c))
#define assert_false(c) (!(c) ? (void)0 : mcu_fail(__FILE__, __LINE__, "%s is true", #c))
#define assert_int_equal(a, b)                                                                                   \
    (MCU_U(a) == MCU_U(b) ? (void)0 : mcu_fail_int(__FILE__, __LINE__, MCU_U(a), "!=", MCU_U(b)))
#define assert_int_not_equal(a, b)                                                                               \
    (MCU_U(a) != MCU_U(b) ? (void)0 : mcu_fail_int(__FILE__, __LINE__, MCU_U(a), "==", MCU_U(b)))
#define assert_in_range(v, lo, hi)                                                                               \
    (MCU_U(v) >= MCU_U(lo) && MCU_U(v) <= MCU_U(hi) ? (void)0                                                    \
                                                     : mcu_fail_int(__FILE__, __LINE__, MCU_U(v), "not in range", MCU_U(lo)))
#define assert_memory_equal(a, b, n)                                                                             \
    (memcmp((a), (b), (n)) == 0 ? (void)0 : mcu_fail(__FILE__, __LINE__, "%s and %s differ", #a, #b))
#define assert_non_null(p) ((p) != NULL ? (void)0 : mcu_fail(__FILE__, __LINE__, "%s is NULL", #p))
#define assert_null(p) ((p) == NULL ? (void)0 : mcu_fail(__FILE__, __LINE__, "%s is not NULL", #p))
#define assert_string_equal(a, b)                                                                                \
    (strcmp((a), (b)) == 0 ? (void)0 : mcu_fail(__FILE__, __LINE__, "\"%s\" != \"%s\"", (a), (b)))
#define fail_msg(...) mcu_fail(__FILE__, __LINE__, __VA_ARGS__)
#define fail() mcu_fail(__FILE__, __LINE__, "failed")

#endif
