/* clutter.h -- the site's clutter map: how often each place of the polar plane gives a detection that no track turns out to explain, learnt as sonard runs; RAM: sizeof(struct sonar_clutter) = 1 624 B at 16 x 25 cells (config.h); a look O(cells), a query O(1). */
#ifndef SONAR_CLUTTER_H
#define SONAR_CLUTTER_H

#include <stddef.h>
#include <stdint.h>

#include "sonar/config.h"
#include "sonar/err.h"

/*
 * The water's own echoes (the surface, bubbles, a wake) give detections that come and go. A track
 * is only as believable as the chance that its detections are not such echoes, and that chance
 * depends on the place: near the sonar and under a splashing surface they flicker every look, in
 * still water far off hardly ever. So the map keeps, per cell of range band x bearing sector about
 * the sonar, the rate of detections a look that were taught to it: each detection that only a
 * tentative track took, a newborn's included (never a confirmed track's; docs/decisions.md says
 * why not weighed by the track's existence). The rate is a running mean over the
 * cell's first looks, then a moving average over SONAR_CLUTTER_MEMORY looks: it forgets. One look
 * teaches a cell SONAR_CLUTTER_BURST detections at most (someone jumping in, a boat's wake: a
 * burst must not make a place clutter for good). A cell with few looks leans on the site's mean
 * (a Gamma-Poisson shrinkage, SONAR_CLUTTER_PRIOR_LOOKS looks of it), and no place is ever
 * cleaner than SONAR_CLUTTER_FLOOR: a map that has learnt nothing says "hardly any clutter".
 *
 * Positions are metres about the sonar in the tracks' frame (x forward or north, y right or east);
 * bearings in gradians from the x axis, clockwise, as the tracker's cover map.
 */

#define SONAR_CLUTTER_MEMORY 64      /* looks the moving average spans, <= 255 */
#define SONAR_CLUTTER_BURST 2        /* detections one look may teach a cell */
#define SONAR_CLUTTER_PRIOR_LOOKS 16 /* looks' worth of the site's mean each cell starts from */
#define SONAR_CLUTTER_FLOOR 1.0e-4f  /* the least clutter density anywhere, detections per m^2 a look */
#define SONAR_CLUTTER_PEND_ONE 16u   /* a cell's pending teaching is held in 1/16 detections (<= 15.9) */
#define SONAR_CLUTTER_RATE_ONE 4096u /* a cell's rate is held in 1/4096 detections a look (<= 15.99) */
#define SONAR_CLUTTER_MAX_RANGE 1000.0f /* range_m: 0 (nothing learnt) or 0.1 .. 1000 m */

struct sonar_clutter_cell {
    uint16_t rate; /* detections a look, x SONAR_CLUTTER_RATE_ONE */
    uint8_t looks; /* looks that saw the cell (saturating at 255) */
    uint8_t pend;  /* detections taught since its last look, x SONAR_CLUTTER_PEND_ONE (saturating) */
};

struct sonar_clutter {
    float range_m;   /* the range the bands divide, m; 0: no look yet */
    float site;      /* the cells' mean density (each weighted by its area), detections per m^2 a look */
    uint32_t looks;  /* looks taken */
    float taught;    /* detections taught (weighed) */
    float capped;    /* taught beyond SONAR_CLUTTER_BURST in one cell's look: left out */
    uint32_t resets; /* times the range scanned changed and the map started again */
    struct sonar_clutter_cell c[SONAR_CLUTTER_BANDS][SONAR_CLUTTER_SECTORS];
};

/* A summary for a status message: cells looked at, the site's mean, the densest cell. */
struct sonar_clutter_summary {
    uint16_t cells_seen;   /* cells with at least one look */
    uint32_t looks;        /* as the map's */
    float site;            /* detections per m^2 a look */
    float peak;            /* the densest cell's density (shrunk as sonar_clutter_density gives it), per m^2 a look */
    float peak_range_m;    /* its centre: range, m ... */
    float peak_bearing_g;  /* ... and bearing, gradians */
    float per_look;        /* the rate summed over every cell: false detections a look the map expects */
};

/* Empties m: no range, nothing learnt. */
void sonar_clutter_init(struct sonar_clutter *m);

/*
 * One look's end: every cell in view (its sector touched by cover, a 400-bit map of the gradians
 * scanned as sonar_tracker_cover makes, NULL everywhere; its band within min_r .. max_r metres) or
 * taught since its last look moves its rate toward what was taught (at most SONAR_CLUTTER_BURST)
 * and counts a look. max_r is the range scanned: a change of more than 1 % empties the map first
 * (resets counted), its bands no longer the same places. Returns SONAR_OK, or SONAR_ERR_ARG (m
 * NULL, or max_r not in 0.1 .. SONAR_CLUTTER_MAX_RANGE: nothing changed).
 */
SONAR_CHECK int sonar_clutter_look(struct sonar_clutter *m, const uint8_t *cover, float min_r, float max_r);

/*
 * Teaches n detections (0 .. 16, in 1/16ths: a detection that was clutter with probability n; a cell
 * saturates at 15.9 a look) at x, y metres about the sonar; outside the range, or n not above 0:
 * ignored. NULL m: nothing.
 */
void sonar_clutter_teach(struct sonar_clutter *m, float x, float y, float n);

/*
 * The clutter density at x, y metres about the sonar, detections per m^2 a look: the cell's rate
 * over its area, shrunk toward the site's mean by SONAR_CLUTTER_PRIOR_LOOKS looks, and never below
 * SONAR_CLUTTER_FLOOR (m NULL, nothing learnt, or beyond the range: the floor).
 */
float sonar_clutter_density(const struct sonar_clutter *m, float x, float y);

/*
 * Cell (band, sector)'s density as sonar_clutter_density gives it, per m^2 a look; 0 for a cell
 * never looked at, or band / sector outside the grid (0..SONAR_CLUTTER_BANDS-1, 0..SONAR_CLUTTER_SECTORS-1).
 */
float sonar_clutter_cell(const struct sonar_clutter *m, int band, int sector);

/* The map at a glance (s filled; m NULL: zeros). */
void sonar_clutter_summarise(const struct sonar_clutter *m, struct sonar_clutter_summary *s);

/* Bytes sonar_clutter_encode writes: a header of 28 B and 4 B a cell. */
#define SONAR_CLUTTER_WIRE (28u + 4u * SONAR_CLUTTER_BANDS * SONAR_CLUTTER_SECTORS)

/*
 * The learnt map as bytes for a file (little-endian: "SCM1", bands, sectors, range_m, looks,
 * taught, a CRC-32 of the cells, then each cell's rate and looks; nothing pending). Returns the
 * bytes written (SONAR_CLUTTER_WIRE) or SONAR_ERR_SPACE (cap too small) / SONAR_ERR_ARG.
 */
SONAR_CHECK int sonar_clutter_encode(const struct sonar_clutter *m, uint8_t *buf, size_t cap);

/*
 * A map from sonar_clutter_encode's bytes into m. Returns SONAR_OK; SONAR_ERR_ID (not a map, or
 * another grid: m untouched), SONAR_ERR_LENGTH (len wrong), SONAR_ERR_RANGE (its CRC, range or a
 * rate is wrong: damaged, m untouched) or SONAR_ERR_ARG.
 */
SONAR_CHECK int sonar_clutter_decode(struct sonar_clutter *m, const uint8_t *buf, size_t len);

#endif
