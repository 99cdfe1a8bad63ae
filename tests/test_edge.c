/* test_edge.c -- a beam's strongest echo and its leading edge (over the CFAR's block sums): the wall, past a ring-down's tail, not a weaker echo before it, none in an empty beam. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "sonar/cfar.h"
#include "sonar/edge.h"

#define N 1200

static uint8_t s[N];
static uint16_t sums[SONAR_CFAR_MAX_BLOCKS];

/* The leading edge of s[0 .. n) from `from`, over its block sums as the pipeline gives them. */
static uint16_t lead(uint16_t from, uint16_t n, uint8_t *top)
{
    assert_true(sonar_cfar_sums(s, n, sums) >= 0);
    return sonar_edge_leading(s, sums, from, n, top);
}

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
    assert_int_equal(lead(120, N, &top), 800);
    assert_int_equal(top, 180);
    assert_int_equal(sonar_edge_strongest(s, 120, N), 800);
    /* A ramp: the first 8-sample block reaching half the strongest block's mean (90), and in it the first sample that does. */
    echo(784, 791, 60);
    echo(792, 799, 100);
    assert_int_equal(lead(120, N, &top), 792);
    echo(792, 799, 60);
    echo(796, 799, 140); /* block 792..799: mean 100, its samples reach 90 at 796 */
    assert_int_equal(lead(120, N, &top), 796);
}

/* A buoy before the wall as strong as half the wall or more takes the edge; a weaker echo does not. */
static void test_nearer_echo(void **state)
{
    uint8_t top;
    (void)state;
    water();
    echo(800, 830, 180);
    echo(496, 520, 70); /* weaker than half the wall: the water's speck, a rope */
    assert_int_equal(lead(120, N, &top), 800);
    echo(496, 520, 150); /* a buoy */
    assert_int_equal(lead(120, N, &top), 496);
    /* Found to the block (8 samples): a buoy beginning mid-block is found where the block's mean reaches half. */
    echo(496, 499, 10);
    assert_int_equal(lead(120, N, &top), 504);
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
    assert_int_equal(lead(120, N, &top), 600);
    assert_int_equal(top, 126); /* the tail's block at from: 126.5 */
    /* Without the wall, the tail itself is no edge: nothing rises after it. */
    echo(600, 620, 30);
    assert_int_equal(lead(120, N, &top), N);
}

/* An empty beam (all 0 or 1 beyond from), from at or past n, a beam of one sample. */
static void test_none(void **state)
{
    uint8_t top = 99;
    (void)state;
    memset(s, 0, sizeof(s));
    assert_int_equal(lead(120, N, &top), N);
    assert_int_equal(top, 0);
    memset(s, 1, sizeof(s));
    assert_int_equal(lead(120, N, &top), N);
    water();
    assert_int_equal(lead(N, N, &top), N);
    assert_int_equal(sonar_edge_strongest(s, N, N), N);
    s[0] = 5;
    assert_int_equal(lead(0, 1, &top), 1); /* the whole beam is its strongest: no rise */
}

/* Every length and start (the lanes and the rest): the same as a plain scan of the blocks. */
/* The leading edge by a plain scan over the block sums (sums of s[0 .. n) already made), and the top block. */
static uint16_t plain_edge(uint16_t n, uint16_t from, unsigned *top)
{
    unsigned nb = (n + 7u) / 8u, b;
    uint16_t i;
    *top = 0;
    for (b = (from + 7u) / 8u; b < nb; b++)
        *top = sums[b] > *top ? sums[b] : *top;
    if (*top < 16u)
        return n;
    for (b = (from + 7u) / 8u; b < nb && sums[b] > *top / 4u; b++)
        ;
    for (; b < nb && sums[b] < *top / 2u; b++)
        ;
    for (i = (uint16_t)(b * 8u); i < n && s[i] * 16u < *top; i++)
        ;
    return b < nb && i < n ? i : n;
}

static void test_lanes_agree_with_a_scan(void **state)
{
    /* Block levels whose sums fall just above, on and just below a quarter and a half of the strongest's. */
    static const uint8_t level[] = {200, 51, 50, 49, 101, 100, 99, 0};
    uint16_t n, from, i;
    unsigned top, k;
    uint8_t t;
    (void)state;
    for (n = 1; n <= 400; n = (uint16_t)(n + 13))
        for (from = 0; from < n; from = (uint16_t)(from + 11)) {
            uint16_t want;
            for (i = 0; i < n; i++)
                s[i] = (uint8_t)((i * 37u + n * 11u + from) % 97u + (i % 53u == 7u ? 150u : 0u));
            assert_true(sonar_cfar_sums(s, n, sums) >= 0);
            want = plain_edge(n, from, &top);
            assert_int_equal(sonar_edge_leading(s, sums, from, n, &t), want);
            assert_int_equal(t, top / 8u);
            for (k = 0; k < 3; k++) {
                for (i = 0; i < n; i++)
                    s[i] = level[((i / 8u) * (k + 3u) + n + from) % 8u];
                s[n - 1u] = 200;
                assert_true(sonar_cfar_sums(s, n, sums) >= 0);
                want = plain_edge(n, from, &top);
                assert_int_equal(sonar_edge_leading(s, sums, from, n, &t), want);
                assert_int_equal(t, top / 8u);
            }
        }
    /* The strongest echo: its first sample, lanes or not. */
    for (n = 1; n <= 300; n = (uint16_t)(n + 7)) {
        memset(s, 3, n);
        s[n - 1] = 9;
        s[n / 2] = 9;
        assert_int_equal(sonar_edge_strongest(s, 0, n), n / 2);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_wall_is_the_edge),
        cmocka_unit_test(test_nearer_echo),
        cmocka_unit_test(test_ring_down_tail),
        cmocka_unit_test(test_none),
        cmocka_unit_test(test_lanes_agree_with_a_scan),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
