/* feed_device.c -- sonar-feed's Ping360: a CSV recording (nearest row by angle) or a scene rendered per beam, requests answered at the device's pace (19.4 ms + 6 ms a gradian + 2R/c), auto-transmit streamed. */
#define _GNU_SOURCE
#include "feed.h"

int feed_load_csv(struct recording *r, const char *path, double range_m)
{
    struct csv_reader *rd = calloc(1, sizeof(*rd));
    struct csv_row *row = calloc(1, sizeof(*row));
    struct sonar_sweep sw;
    char err[128];
    uint32_t cap = 0;
    int got;
    if (rd == NULL || row == NULL || csv_open(rd, path) != 0) {
        perror(path);
        return -1;
    }
    if (sonar_sweep_init(&sw, 20, 400) != SONAR_OK)
        return -1;
    memset(r, 0, sizeof(*r));
    r->range_m = range_m;
    while ((got = csv_next(rd, row, err, sizeof(err))) != 0) {
        if (got < 0)
            continue;
        if (r->rows_n == cap) {
            cap = cap ? cap * 2 : 1024;
            r->rows = realloc(r->rows, cap * sizeof(*r->rows));
            r->angle = realloc(r->angle, cap * sizeof(*r->angle));
            r->sweep_start = realloc(r->sweep_start, (cap + 1) * sizeof(*r->sweep_start));
            if (r->rows == NULL || r->angle == NULL || r->sweep_start == NULL)
                return -1;
        }
        /* the first row opens sweep 0 (step returns SAME for it); a cut opens the next */
        if (sonar_sweep_step(&sw, row->angle) != SONAR_SWEEP_SAME || r->rows_n == 0)
            r->sweep_start[r->sweeps++] = r->rows_n;
        memcpy(r->rows[r->rows_n], row->samples, row->n);
        r->angle[r->rows_n] = row->angle;
        r->n = row->n;
        if (row->range_m > 0 && range_m <= 0)
            r->range_m = row->range_m;
        r->rows_n++;
    }
    r->sweep_start[r->sweeps] = r->rows_n;
    csv_close(rd);
    free(rd);
    free(row);
    if (r->rows_n == 0 || r->range_m <= 0) {
        fprintf(stderr, "sonar_feed: %s: no usable rows, or no range (give --range)\n", path);
        return -1;
    }
    return 0;
}

/* us since the epoch: the clock sonard stamps beams with. */
static long long wall_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    return (long long)ts.tv_sec * 1000000LL + ts.tv_nsec / 1000;
}

/* --truth: the beam served at scene time t, and every 0.1 s the objects (in range; visible unless faded). */
static void feed_truth(struct feed *f, double t, int sweep, uint16_t a, double range)
{
    long long now = wall_us();
    int k, first = 1;
    fprintf(f->truth, "{\"t_us\":%lld,\"beam\":%u}\n", now, a);
    if (t < f->truth_next)
        return;
    while (f->truth_next <= t)
        f->truth_next += 0.1;
    fprintf(f->truth, "{\"t_us\":%lld,\"t\":%.3f,\"objects\":[", now, t);
    for (k = 0; k < f->scene.nobj; k++) {
        const struct scene_object *o = &f->scene.obj[k];
        double x, y, vx, vy, bx, by;
        int faded;
        if (!scene_object_at(&f->scene, k, sweep, t, &x, &y, &vx, &vy))
            continue;
        scene_to_body(&f->scene, t, x, y, &bx, &by);
        if (hypot(bx, by) > range)
            continue;
        faded = sweep < 64 && ((o->fade >> sweep) & 1u);
        fprintf(f->truth, "%s{\"id\":\"%s\",\"x\":%.3f,\"y\":%.3f,\"vx\":%.3f,\"vy\":%.3f,\"bx\":%.3f,\"by\":%.3f,\"radius\":%.2f,\"visible\":%d}",
                first ? "" : ",", o->id, x, y, vx, vy, bx, by, o->r, !faded);
        first = 0;
    }
    fputs("]}\n", f->truth);
}

/* The beam the device would send for angle a in the current sweep. */
void feed_render(struct feed *f, uint16_t a, uint8_t *out, uint16_t *n, uint16_t *sp)
{
    if (f->use_scene) {
        double range = sonar_geometry_range_m(f->sp, f->n, f->c);
        /* The scene's clock: by default timed objects move with the sweep count of the requests, at
           a nominal 10 s a sweep; on the wall clock (a moving vehicle, --scene-clock wall) they
           move in real time whatever the order of requests, and a "sweep" of the scene's
           per-sweep events is 10 s of it. */
        double t = 10.0 * (double)f->sweep.index;
        int sweep = (int)f->sweep.index;
        if (f->scene.veh.nwp > 0 || f->wall_clock) {
            if (f->scene_t0 == 0.0)
                f->scene_t0 = feed_now();
            t = feed_now() - f->scene_t0;
            if (f->wall_clock)
                sweep = (int)(t / 10.0);
        }
        scene_beam(&f->scene, sweep, t, a, range, f->n, &f->rng, out);
        if (f->gain_ref >= 0 && f->gain != f->gain_ref) {
            /* The receiver's gain: about 6 dB a setting; high clips what was bright, low loses what was faint. */
            int up = (int)f->gain - (int)f->gain_ref, i;
            for (i = 0; i < f->n; i++) {
                int v = up > 0 ? out[i] << up : out[i] >> -up;
                out[i] = (uint8_t)(v > 255 ? 255 : v);
            }
        }
        if (f->truth != NULL)
            feed_truth(f, t, sweep, a, range);
        *n = f->n;
        *sp = f->sp;
    } else {
        struct recording *r = &f->rec;
        uint32_t s = f->sweep.index % r->sweeps, i, best = r->sweep_start[s];
        int bd = 999;
        for (i = r->sweep_start[s]; i < r->sweep_start[s + 1]; i++) {
            int d = abs(sonar_frame_delta(r->angle[i], a));
            if (d < bd) {
                bd = d;
                best = i;
            }
        }
        /* A Ping360 answers with the samples asked for: the recording's row over the same range, taken at the
           nearest of its samples when the count asked differs (none asked yet: the row as recorded). */
        uint16_t want = !f->as_recorded && f->n >= SONAR_DEVICE_MIN_SAMPLES && f->n <= SONAR_MAX_SAMPLES ? f->n : r->n;
        if (want == r->n) {
            memcpy(out, r->rows[best], r->n);
        } else {
            for (i = 0; i < want; i++)
                out[i] = r->rows[best][(uint32_t)i * r->n / want];
        }
        *n = want;
        if (sonar_geometry_sample_period(r->range_m, want, f->c, sp) != SONAR_OK)
            *sp = f->sp; /* a range the device could not do: report the requested period */
    }
}

void feed_queue(struct feed *f, uint16_t id, const uint8_t *payload, uint16_t len, double delay)
{
    int w = sonar_ping_encode(f->out, sizeof(f->out), id, payload, len);
    if (w < 0)
        return;
    f->out_len = (size_t)w;
    f->due = feed_now() + (f->device_pace ? delay / f->pace_speedup : 0.0);
}

double feed_beam_time(const struct feed *f, uint16_t from, uint16_t to)
{
    double range = sonar_geometry_range_m(f->sp, f->n, f->c);
    return 0.0194 + 0.006 * abs(sonar_frame_delta(from, to)) + 2.0 * range / f->c;
}

void feed_queue_beam(struct feed *f, uint16_t a, int is_auto, double delay)
{
    static uint8_t q[20 + 1200];
    uint16_t n = 0, sp = 0, fixed = is_auto ? 20 : 14;
    if (sonar_sweep_step(&f->sweep, a) != SONAR_SWEEP_SAME && f->log)
        feed_log(f, "%s %ld\n", "sweep", (long)f->sweep.index);
    feed_render(f, a, q + fixed, &n, &sp);
    q[0] = 1;
    q[1] = f->gain;
    q[2] = (uint8_t)(a & 0xff);
    q[3] = (uint8_t)(a >> 8);
    q[4] = (uint8_t)(f->tx & 0xff);
    q[5] = (uint8_t)(f->tx >> 8);
    q[6] = (uint8_t)(sp & 0xff);
    q[7] = (uint8_t)(sp >> 8);
    q[8] = (uint8_t)(f->freq & 0xff);
    q[9] = (uint8_t)(f->freq >> 8);
    if (is_auto) {
        q[10] = (uint8_t)(f->a_start & 0xff);
        q[11] = (uint8_t)(f->a_start >> 8);
        q[12] = (uint8_t)(f->a_stop & 0xff);
        q[13] = (uint8_t)(f->a_stop >> 8);
        q[14] = (uint8_t)f->a_step;
        q[15] = 0;
    }
    q[fixed - 4] = (uint8_t)(n & 0xff);
    q[fixed - 3] = (uint8_t)(n >> 8);
    q[fixed - 2] = (uint8_t)(n & 0xff);
    q[fixed - 1] = (uint8_t)(n >> 8);
    f->beams++;
    f->out_is_beam = 1;
    feed_queue(f, is_auto ? SONAR_PING360_AUTO_DEVICE_DATA : SONAR_PING360_DEVICE_DATA, q, (uint16_t)(fixed + n), delay);
}

void feed_auto_next(struct feed *f, double delay)
{
    uint16_t prev = f->angle;
    int next = (int)f->angle + f->a_dir * f->a_step;
    if (f->a_start == 0 && f->a_stop == 399) {
        next = (next + 400) % 400;
    } else if (next > f->a_stop || next < f->a_start) {
        f->a_dir = -f->a_dir;
        next = (int)f->angle + f->a_dir * f->a_step;
    }
    f->angle = (uint16_t)next;
    feed_queue_beam(f, f->angle, 1, delay > 0 ? delay : feed_beam_time(f, prev, f->angle));
}

void feed_handle_frame(struct feed *f, const struct sonar_ping_frame *fr)
{
    const uint8_t *p = fr->payload;
    uint8_t q[16];
    f->requests++;
    switch (fr->id) {
    case SONAR_PING_GENERAL_REQUEST: {
        uint16_t id = fr->payload_len >= 2 ? (uint16_t)(p[0] | p[1] << 8) : 0;
        if (id == SONAR_PING_DEVICE_INFORMATION) {
            uint8_t d[6] = {2, 0, f->fw[0], f->fw[1], f->fw[2], 0};
            feed_queue(f, id, d, 6, 0.002);
        } else if (id == SONAR_PING_PROTOCOL_VERSION) {
            uint8_t d[4] = {1, 1, 0, 0};
            feed_queue(f, id, d, 4, 0.002);
        } else if (id == SONAR_PING360_DEVICE_DATA) {
            uint8_t d[14] = {1, f->gain, (uint8_t)f->angle, (uint8_t)(f->angle >> 8), (uint8_t)f->tx, (uint8_t)(f->tx >> 8),
                             (uint8_t)f->sp, (uint8_t)(f->sp >> 8), (uint8_t)f->freq, (uint8_t)(f->freq >> 8),
                             (uint8_t)f->n, (uint8_t)(f->n >> 8), 0, 0};
            feed_queue(f, id, d, 14, 0.002);
        } else {
            q[0] = (uint8_t)(id & 0xff);
            q[1] = (uint8_t)(id >> 8);
            memcpy(q + 2, "unknown", 7);
            f->nacks_sent++;
            feed_queue(f, SONAR_PING_NACK, q, 9, 0.002);
        }
        break;
    }
    case SONAR_PING360_TRANSDUCER: {
        uint16_t a = (uint16_t)(p[2] | p[3] << 8), prev = f->angle;
        if (fr->payload_len != 14 || a > 399) {
            q[0] = (uint8_t)(fr->id & 0xff);
            q[1] = (uint8_t)(fr->id >> 8);
            f->nacks_sent++;
            feed_queue(f, SONAR_PING_NACK, q, 2, 0.002);
            break;
        }
        f->streaming = 0;
        if (!f->gain_fixed || !f->gain_set)
            f->gain = p[1];
        f->gain_set = 1;
        f->tx = (uint16_t)(p[4] | p[5] << 8);
        f->sp = (uint16_t)(p[6] | p[7] << 8);
        f->freq = (uint16_t)(p[8] | p[9] << 8);
        f->n = (uint16_t)(p[10] | p[11] << 8);
        if (f->n > 1200)
            f->n = 1200;
        f->angle = a;
        if (p[12])
            feed_queue_beam(f, a, 0, feed_beam_time(f, prev, a));
        else {
            uint8_t d[14] = {1, f->gain, (uint8_t)a, (uint8_t)(a >> 8), p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11], 0, 0};
            feed_queue(f, SONAR_PING360_DEVICE_DATA, d, 14, 0.006 * abs(sonar_frame_delta(prev, a)));
        }
        break;
    }
    case SONAR_PING360_AUTO_TRANSMIT:
        if (fr->payload_len != 16)
            break;
        if (!f->gain_fixed || !f->gain_set)
            f->gain = p[1];
        f->gain_set = 1;
        f->tx = (uint16_t)(p[2] | p[3] << 8);
        f->sp = (uint16_t)(p[4] | p[5] << 8);
        f->freq = (uint16_t)(p[6] | p[7] << 8);
        f->n = (uint16_t)(p[8] | p[9] << 8);
        f->a_start = (uint16_t)(p[10] | p[11] << 8);
        f->a_stop = (uint16_t)(p[12] | p[13] << 8);
        f->a_step = p[14] ? p[14] : 1;
        f->a_dir = 1;
        /* one step before the start, mod 400: the first beam is at start_angle (a full turn's 0, not 336) */
        f->angle = (uint16_t)((f->a_start + 400u - f->a_step) % 400u);
        f->streaming = 1;
        feed_auto_next(f, 0.0);
        break;
    case SONAR_PING360_MOTOR_OFF:
        f->streaming = 0;
        f->motor_offs++;
        feed_log(f, "%s %ld\n", "motor_off", f->motor_offs);
        if (f->arrive && f->motor_offs == 1) {
            /* the survey's run has ended: the people arrive, and the scene's first sweep is the next run's */
            f->scene = f->full;
            f->scene_t0 = 0.0;
            if (sonar_sweep_init(&f->sweep, 20, 400) != SONAR_OK)
                f->arrive = 0;
            feed_log(f, "%s %ld\n", "arrived", f->motor_offs);
        }
        q[0] = (uint8_t)(SONAR_PING360_MOTOR_OFF & 0xff);
        q[1] = (uint8_t)(SONAR_PING360_MOTOR_OFF >> 8);
        feed_queue(f, SONAR_PING_ACK, q, 2, 0.001);
        if (f->exit_after_motor_off) {
            f->stop_after = 1;
            f->stop_at = feed_now() + 0.3;
        }
        break;
    default:
        q[0] = (uint8_t)(fr->id & 0xff);
        q[1] = (uint8_t)(fr->id >> 8);
        memcpy(q + 2, "unsupported", 11);
        f->nacks_sent++;
        feed_queue(f, SONAR_PING_NACK, q, 13, 0.002);
        break;
    }
}
