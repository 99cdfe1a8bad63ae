/* test_edge.c -- a beam's strongest echo and its leading edge: the wall, past a ring-down's tail, not a weaker echo before it, none in an empty beam. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/edge.h"

#define N 1200

static uint8_t s[N];

/* Quiet water (level 10), and level v over samples [a, b]. */
static void water(void) { memset(s, 10, sizeof(s)); }
static void echo(int a, int b, uint8_t v)
{
    int i;
    for (i = a; i <= b; i++)
        s[i] = v;
}

/* A wall at sample 800: the edge is where its return rises, whatever lies behind it. */
static void test_wall_is_the_edge(void **state)
{
    uint8_t top;
    (void)state;
    water();
    echo(800, 830, 180);
    echo(850, 900, 120); /* the wall's tail and echoes behind it, weaker */
    assert_int_equal(sonar_edge_leading(s, 120, N, &top), 800);
    assert_int_equal(top, 180);
    assert_int_equal(sonar_edge_strongest(s, 120, N), 800);
    /* A ramp: the edge is where the level first reaches half the strongest (90). */
    echo(790, 799, 60);
    echo(795, 799, 100);
    assert_int_equal(sonar_edge_leading(s, 120, N, &top), 795);
}

/* A buoy before the wall as strong as half the wall or more takes the edge; a weaker echo does not. */
static void test_nearer_echo(void **state)
{
    uint8_t top;
    (void)state;
    water();
    echo(800, 830, 180);
    echo(500, 520, 70); /* weaker than half the wall: the water's speck, a rope */
    assert_int_equal(sonar_edge_leading(s, 120, N, &top), 800);
    echo(500, 520, 150); /* a buoy */
    assert_int_equal(sonar_edge_leading(s, 120, N, &top), 500);
    assert_int_equal(top, 180);
}

/* The ring-down's tail still strong where the judging starts: passed, and the edge is the wall beyond. */
static void test_ring_down_tail(void **state)
{
    uint8_t top;
    int i;
    (void)state;
    water();
    for (i = 0; i < 200; i++)
        s[i] = (uint8_t)(250 - i); /* decaying through `from` (120: level 130) to 51 */
    echo(200, 260, 30);            /* quiet only from here (a quarter of 130 is 32) */
    echo(600, 620, 100);
    assert_int_equal(sonar_edge_leading(s, 120, N, &top), 600);
    assert_int_equal(top, 130);
    /* Without the wall, the tail itself is no edge: nothing rises after it. */
    echo(600, 620, 30);
    assert_int_equal(sonar_edge_leading(s, 120, N, &top), N);
}

/* An empty beam (all 0 or 1 beyond from), from at or past n, a beam of one sample. */
static void test_none(void **state)
{
    uint8_t top = 99;
    (void)state;
    memset(s, 0, sizeof(s));
    assert_int_equal(sonar_edge_leading(s, 120, N, &top), N);
    assert_int_equal(top, 0);
    memset(s, 1, sizeof(s));
    assert_int_equal(sonar_edge_leading(s, 120, N, &top), N);
    water();
    assert_int_equal(sonar_edge_leading(s, N, N, &top), N);
    assert_int_equal(sonar_edge_strongest(s, N, N), N);
    s[0] = 5;
    assert_int_equal(sonar_edge_leading(s, 0, 1, &top), 1); /* the whole beam is its strongest: no rise */
}

/* Every length and start (the 32-sample blocks and the rest): the same as a plain scan. */
static void test_blocks_agree_with_a_scan(void **state)
{
    uint16_t n, from, i;
    (void)state;
    for (n = 1; n <= 200; n = (uint16_t)(n + 7))
        for (from = 0; from < n; from = (uint16_t)(from + 5)) {
            uint8_t top = 0, t, half, quiet;
            uint16_t want = n;
            for (i = 0; i < n; i++)
                s[i] = (uint8_t)((i * 37u + n * 11u + from) % 97u + (i % 23u == 7u ? 150u : 0u));
            for (i = from; i < n; i++)
                top = s[i] > top ? s[i] : top;
            half = (uint8_t)((top + 1u) / 2u);
            quiet = (uint8_t)(top / 4u);
            if (half > 1u) {
                for (i = from; i < n && s[i] > quiet; i++)
                    ;
                for (; i < n && s[i] < half; i++)
                    ;
                want = i;
            }
            assert_int_equal(sonar_edge_leading(s, from, n, &t), want);
            assert_int_equal(t, top);
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_wall_is_the_edge),
        cmocka_unit_test(test_nearer_echo),
        cmocka_unit_test(test_ring_down_tail),
        cmocka_unit_test(test_none),
        cmocka_unit_test(test_blocks_agree_with_a_scan),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
