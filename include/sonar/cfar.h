/* cfar.h -- range-adaptive detection threshold along a beam: order-statistic CFAR over 8-sample blocks; O(n) per beam, stack ~0.3 KB at 1200 samples, no state. */
#ifndef SONAR_CFAR_H
#define SONAR_CFAR_H

#include <stdint.h>

#include "sonar/config.h"
#include "sonar/err.h"

/*
 * A beam's foreground is cut into blocks of SONAR_CFAR_BLOCK samples (the last one may be shorter;
 * its sum is scaled to a full block). A block passes when the mean level of the window around it
 * (the block and `cut` blocks each side) exceeds scale times the noise level plus floor grey
 * levels. The noise level is an order statistic of the block means in the training cells: `train`
 * blocks each side, beyond `guard` blocks from the window, the rank16/16 quantile of them
 * (8 = the median). Training blocks that run off either end of the beam are left out and the rank
 * is taken over those that remain; with none, the noise is 0 and only the floor applies.
 *
 * Why these choices (docs/results.md, section 7): an extended target (a person is 15-35 samples
 * deep at the Ping360's usual settings, whose transmit pulse follows the sample period) is tested
 * as a whole window rather than cell by cell, which integrates its weak, speckled cells; the order
 * statistic ignores a neighbouring echo or a clutter edge that takes up to half the training
 * blocks, where a mean would be raised by it; and the windows are counted in samples, not metres,
 * so a recording whose range is unknown gives the same decisions whatever range is assumed.
 *
 * Everything is integer arithmetic (scale is taken in sixteenths, rounded), so host and
 * Cortex-M give the same bits.
 */
#define SONAR_CFAR_BLOCK 8 /* samples per block */
#define SONAR_CFAR_MAX_BLOCKS ((SONAR_MAX_SAMPLES + SONAR_CFAR_BLOCK - 1) / SONAR_CFAR_BLOCK)
#define SONAR_CFAR_CUT_MAX 4     /* cut 0..4 blocks */
#define SONAR_CFAR_GUARD_MAX 8   /* guard 0..8 blocks */
#define SONAR_CFAR_TRAIN_MAX 8   /* train 1..8 blocks each side */
#define SONAR_CFAR_SCALE_MIN 0.5 /* scale 0.5..16 */
#define SONAR_CFAR_SCALE_MAX 16

struct sonar_cfar_config {
    uint8_t across; /* beams each side in the window, 0 or 1 (the caller passes their sums: sonar_cfar_blocks_across) */
    uint8_t cut;    /* blocks each side of the block under test in its window, 0..4 */
    uint8_t guard;  /* blocks between the window and the training blocks, each side, 0..8 */
    uint8_t train;  /* training blocks each side, 1..8 */
    uint8_t rank16; /* order statistic of the training block means, sixteenths: 1..16 (8 = median, 16 = largest) */
    float scale;    /* noise multiplier, 0.5..16 */
    uint8_t floor;  /* grey levels added to the threshold, 0..254 */
};

/* NULL when c is valid, else a static "field: rule" string naming the first bad field. c must not be NULL. */
const char *sonar_cfar_config_check(const struct sonar_cfar_config *c);

/*
 * The block sums of a beam as sonar_cfar_blocks_across takes a neighbour's: sums[b] = the sum of
 * samples b*8 .. b*8+7, a short last block scaled to 8 (at most 2040). sums: (n + 7) / 8 values.
 * Returns the block count, or SONAR_ERR_ARG (NULL, n outside 1..SONAR_MAX_SAMPLES).
 */
SONAR_CHECK int sonar_cfar_sums(const uint8_t *fg, uint16_t n, uint16_t *sums);

/*
 * The test with the window spread over neighbouring beams too: each block's level is the sum of
 * the beam's own block and the same block of prev and next (either NULL: none; their sums from
 * sonar_cfar_sums of beams of the same n), and the window, the training blocks and the floor are
 * taken over that many beams. A speck in one beam is then diluted by its empty neighbours, while an
 * echo two or more beams wide keeps its level. Otherwise as sonar_cfar_blocks (which is this with
 * no neighbours); the same returns.
 */
SONAR_CHECK int sonar_cfar_blocks_across(const struct sonar_cfar_config *c, const uint16_t *prev, const uint8_t *fg,
                                         const uint16_t *next, uint16_t n, uint8_t *on, uint8_t *thr);

/* The same with the beam's own block sums given (own, from sonar_cfar_sums of fg): a caller that has them saves a pass. */
SONAR_CHECK int sonar_cfar_blocks_sums(const struct sonar_cfar_config *c, const uint16_t *prev, const uint16_t *own,
                                       const uint16_t *next, uint16_t n, uint8_t *on, uint8_t *thr);

/*
 * Tests the blocks of one beam: on[b] = 1 when block b (samples b*8 .. b*8+7) passes, else 0;
 * thr, when not NULL, gets each block's threshold on the window's mean level in grey levels
 * (saturating at 255). fg: n samples, 1..SONAR_MAX_SAMPLES; on and thr: at least
 * (n + 7) / 8 bytes each. Returns the number of blocks that passed, or SONAR_ERR_ARG (NULL, n
 * outside 1..SONAR_MAX_SAMPLES, an invalid c; nothing written).
 */
SONAR_CHECK int sonar_cfar_blocks(const struct sonar_cfar_config *c, const uint8_t *fg, uint16_t n, uint8_t *on,
                                  uint8_t *thr);

#endif
