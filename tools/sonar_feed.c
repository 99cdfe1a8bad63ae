/* sonar_feed.c -- a simulated Ping360: serves a scene or a CSV recording over TCP, UDP or a pty, answers the protocol like the device, injects faults; with a moving vehicle, sends its autopilot's ATTITUDE and LOCAL_POSITION_NED over MAVLink. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>
#include <arpa/inet.h>

#include "csv.h"
#include "discover.h"
#include "optschema.h"
#include "ardupilotmega/mavlink.h"
#include "scene.h"
#include "sonar/geometry.h"
#include "sonar/ping.h"
#include "sonar/sweep.h"

enum { T_TCP, T_UDP, T_PTY };

struct recording {
    uint8_t (*rows)[SONAR_MAX_SAMPLES];
    uint16_t *angle;
    uint32_t *sweep_start; /* first row of each sweep */
    uint32_t rows_n, sweeps;
    uint16_t n;
    double range_m;
};

struct feed {
    /* options */
    int transport;
    char host[64];
    int port;
    const char *pty_link;
    const char *log_path;
    int device_pace;
    double drop, corrupt, garbage;
    long disconnect_after, stall_at, drop_at;
    long disconnect_every, stall_every, max_beams; /* soak: faults every N replies; exit after N intact beams */
    double stall_s, max_s;
    const char *scene_name, *csv_path;
    double csv_range;
    int exit_after_motor_off;
    uint8_t fw[3];
    struct scene scene;
    int use_scene;
    struct recording rec;
    /* state */
    int lfd, cfd; /* listening socket (TCP), connection / UDP socket / pty master */
    struct sockaddr_in peer;
    int have_peer;
    struct sonar_ping_parser parser;
    struct sonar_sweep sweep;
    struct scene_rng rng, fault_rng;
    /* device settings, as the last command set them */
    uint8_t gain;
    uint16_t angle, tx, sp, freq, n;
    double c;
    /* a pending reply */
    uint8_t out[2 * 1300];
    size_t out_len;
    double due;
    /* auto-transmit */
    int streaming;
    uint16_t a_start, a_stop, a_step;
    int a_dir;
    /* counters */
    long replies, dropped, corrupted, garbage_runs, disconnects, stalls, motor_offs, requests, nacks_sent, beams;
    int stop_after;
    double stop_at;
    int out_is_beam;   /* the pending reply is device_data / auto_device_data */
    long beams_intact; /* beam replies sent whole and uncorrupted */
    long last_fault;   /* reply number of the last periodic stall (it is not counted twice) */
    FILE *log;
    /* the vehicle's autopilot (--mavlink udpout:HOST:PORT): a pose every 50 ms */
    const char *mavlink;
    int mfd;
    mavlink_status_t mstatus;
    double scene_t0;    /* when the first beam was served: the scene's clock starts then (a vehicle's path is timed) */
    double next_pose;
    long poses_sent;
    /* discovery (--discovery udp:127.x.x.x:PORT): answers "Discovery" as the device does */
    char disc_host[64];
    int disc_port, dfd;
    uint8_t mac[6];
    const char *claim_ip;  /* the address the reply claims; the --listen host by default */
    long discoveries;
};

static volatile sig_atomic_t quit;

static void on_signal(int s)
{
    (void)s;
    quit = 1;
}

static double now_s(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + (double)t.tv_nsec * 1e-9;
}

static void logf_(struct feed *f, const char *fmt, const char *what, long v)
{
    if (f->log != NULL) {
        fprintf(f->log, fmt, what, v);
        fflush(f->log);
    }
}

static int load_csv(struct recording *r, const char *path, double range_m)
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

/* The beam the device would send for angle a in the current sweep. */
static void render(struct feed *f, uint16_t a, uint8_t *out, uint16_t *n, uint16_t *sp)
{
    if (f->use_scene) {
        double range = sonar_geometry_range_m(f->sp, f->n, f->c);
        /* The scene's clock: sweeps of 400 beams at the feed's own pace are not modelled; timed
           objects move with the sweep count at a nominal 10 s a sweep. */
        double t = 10.0 * (double)f->sweep.index;
        if (f->scene.veh.nwp > 0) {
            /* A moving vehicle: the scene runs on the wall clock from the first beam, as its autopilot's poses do. */
            if (f->scene_t0 == 0.0)
                f->scene_t0 = now_s();
            t = now_s() - f->scene_t0;
        }
        scene_beam(&f->scene, (int)f->sweep.index, t, a, range, f->n, &f->rng, out);
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
        memcpy(out, r->rows[best], r->n);
        *n = r->n;
        if (sonar_geometry_sample_period(r->range_m, r->n, f->c, sp) != SONAR_OK)
            *sp = f->sp; /* a range the device could not do: report the requested period */
    }
}

/* The autopilot: ATTITUDE and LOCAL_POSITION_NED of the scene's vehicle now, as system 1, component 1. */
static void send_pose(struct feed *f)
{
    mavlink_message_t msg;
    uint8_t buf[MAVLINK_MAX_PACKET_LEN];
    double n, e, yaw, t = f->scene_t0 > 0.0 ? now_s() - f->scene_t0 : 0.0;
    uint32_t ms = (uint32_t)(t * 1000.0);
    uint16_t len;
    scene_vehicle_at(&f->scene, t, &n, &e, &yaw);
    mavlink_msg_attitude_pack_status(1, MAV_COMP_ID_AUTOPILOT1, &f->mstatus, &msg, ms, 0.0f, 0.0f,
                                     (float)((yaw > 180.0 ? yaw - 360.0 : yaw) * 3.14159265358979323846 / 180.0), 0.0f,
                                     0.0f, 0.0f);
    len = mavlink_msg_to_send_buffer(buf, &msg);
    if (send(f->mfd, buf, len, MSG_DONTWAIT) == (ssize_t)len)
        f->poses_sent++;
    mavlink_msg_local_position_ned_pack_status(1, MAV_COMP_ID_AUTOPILOT1, &f->mstatus, &msg, ms, (float)n, (float)e,
                                               0.0f, 0.0f, 0.0f, 0.0f);
    len = mavlink_msg_to_send_buffer(buf, &msg);
    (void)send(f->mfd, buf, len, MSG_DONTWAIT); /* best effort, like a telemetry link */
}

static int open_mavlink(struct feed *f)
{
    struct sockaddr_in a;
    char host[64];
    int port;
    if (sscanf(f->mavlink, "udpout:%63[^:]:%d", host, &port) != 2 || port <= 0 || port > 65535) {
        fprintf(stderr, "sonar_feed: --mavlink %s: udpout:HOST:PORT\n", f->mavlink);
        return -1;
    }
    memset(&a, 0, sizeof(a));
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)port);
    if (inet_pton(AF_INET, host, &a.sin_addr) != 1 || ntohl(a.sin_addr.s_addr) >> 24 != 127) {
        fprintf(stderr, "sonar_feed: --mavlink %s: a loopback address (127.x.x.x)\n", f->mavlink);
        return -1;
    }
    if ((f->mfd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0)) < 0 || connect(f->mfd, (struct sockaddr *)&a, sizeof(a)) != 0) {
        perror("sonar_feed: --mavlink");
        return -1;
    }
    return 0;
}

static void queue(struct feed *f, uint16_t id, const uint8_t *payload, uint16_t len, double delay)
{
    int w = sonar_ping_encode(f->out, sizeof(f->out), id, payload, len);
    if (w < 0)
        return;
    f->out_len = (size_t)w;
    f->due = now_s() + (f->device_pace ? delay : 0.0);
}

static double beam_time(const struct feed *f, uint16_t from, uint16_t to)
{
    double range = sonar_geometry_range_m(f->sp, f->n, f->c);
    return 0.0194 + 0.006 * abs(sonar_frame_delta(from, to)) + 2.0 * range / f->c;
}

static void queue_beam(struct feed *f, uint16_t a, int is_auto, double delay)
{
    static uint8_t q[20 + 1200];
    uint16_t n = 0, sp = 0, fixed = is_auto ? 20 : 14;
    if (sonar_sweep_step(&f->sweep, a) != SONAR_SWEEP_SAME && f->log)
        logf_(f, "%s %ld\n", "sweep", (long)f->sweep.index);
    render(f, a, q + fixed, &n, &sp);
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
    queue(f, is_auto ? SONAR_PING360_AUTO_DEVICE_DATA : SONAR_PING360_DEVICE_DATA, q, (uint16_t)(fixed + n), delay);
}

static int send_bytes(struct feed *f, const uint8_t *b, size_t n)
{
    ssize_t w;
    if (f->cfd < 0)
        return -1;
    if (f->transport == T_UDP) {
        if (!f->have_peer)
            return -1;
        w = sendto(f->cfd, b, n, 0, (const struct sockaddr *)&f->peer, sizeof(f->peer));
    } else {
        size_t off = 0;
        while (off < n) {
            w = write(f->cfd, b + off, n - off);
            if (w < 0 && (errno == EAGAIN || errno == EINTR)) {
                struct pollfd p = {f->cfd, POLLOUT, 0};
                poll(&p, 1, 100);
                continue;
            }
            if (w <= 0)
                return -1;
            off += (size_t)w;
        }
        return 0;
    }
    return w == (ssize_t)n ? 0 : -1;
}

static void close_client(struct feed *f);
static int open_pty(struct feed *f);

/* Sends the pending reply, through the fault injector. */
static void flush_reply(struct feed *f)
{
    uint8_t buf[2 * 1300 + 64];
    size_t n = 0;
    int beam = f->out_is_beam, corrupt = 0;
    f->out_is_beam = 0;
    f->replies++;
    if ((f->stall_at > 0 && f->replies == f->stall_at) ||
        (f->stall_every > 0 && f->replies % f->stall_every == 0 && f->replies != f->last_fault)) {
        f->stalls++;
        logf_(f, "%s %ld\n", "stall_ms", (long)(f->stall_s * 1000));
        f->due = now_s() + f->stall_s;
        f->stall_at = 0;
        f->last_fault = f->replies;
        f->out_is_beam = beam; /* the same reply goes out after the stall */
        f->replies--;
        return;
    }
    if ((f->disconnect_after > 0 && f->replies == f->disconnect_after) ||
        (f->disconnect_every > 0 && f->replies % f->disconnect_every == 0)) {
        f->disconnects++;
        logf_(f, "%s %ld\n", "disconnect_at_reply", f->replies);
        f->out_len = 0;
        close_client(f);
        if (f->transport == T_PTY)
            (void)open_pty(f);
        return;
    }
    if (scene_uniform(&f->fault_rng) < f->drop || (f->drop_at > 0 && f->replies == f->drop_at)) {
        f->dropped++;
        f->out_len = 0;
        return;
    }
    if (scene_uniform(&f->fault_rng) < f->garbage) {
        int k = 1 + (int)(scene_uniform(&f->fault_rng) * 40);
        f->garbage_runs++;
        while (k-- > 0)
            buf[n++] = (uint8_t)(scene_uniform(&f->fault_rng) < 0.2 ? 'B' : scene_uniform(&f->fault_rng) * 256);
    }
    memcpy(buf + n, f->out, f->out_len);
    if (scene_uniform(&f->fault_rng) < f->corrupt) {
        size_t at = n + 8 + (size_t)(scene_uniform(&f->fault_rng) * (double)(f->out_len - 10));
        buf[at] ^= (uint8_t)(1 + scene_uniform(&f->fault_rng) * 254);
        f->corrupted++;
        corrupt = 1;
    }
    n += f->out_len;
    f->out_len = 0;
    if (send_bytes(f, buf, n) == 0 && beam && !corrupt)
        f->beams_intact++;
}

static void auto_next(struct feed *f, double delay)
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
    queue_beam(f, f->angle, 1, delay > 0 ? delay : beam_time(f, prev, f->angle));
}

static void handle_frame(struct feed *f, const struct sonar_ping_frame *fr)
{
    const uint8_t *p = fr->payload;
    uint8_t q[16];
    f->requests++;
    switch (fr->id) {
    case SONAR_PING_GENERAL_REQUEST: {
        uint16_t id = fr->payload_len >= 2 ? (uint16_t)(p[0] | p[1] << 8) : 0;
        if (id == SONAR_PING_DEVICE_INFORMATION) {
            uint8_t d[6] = {2, 0, f->fw[0], f->fw[1], f->fw[2], 0};
            queue(f, id, d, 6, 0.002);
        } else if (id == SONAR_PING_PROTOCOL_VERSION) {
            uint8_t d[4] = {1, 1, 0, 0};
            queue(f, id, d, 4, 0.002);
        } else if (id == SONAR_PING360_DEVICE_DATA) {
            uint8_t d[14] = {1, f->gain, (uint8_t)f->angle, (uint8_t)(f->angle >> 8), (uint8_t)f->tx, (uint8_t)(f->tx >> 8),
                             (uint8_t)f->sp, (uint8_t)(f->sp >> 8), (uint8_t)f->freq, (uint8_t)(f->freq >> 8),
                             (uint8_t)f->n, (uint8_t)(f->n >> 8), 0, 0};
            queue(f, id, d, 14, 0.002);
        } else {
            q[0] = (uint8_t)(id & 0xff);
            q[1] = (uint8_t)(id >> 8);
            memcpy(q + 2, "unknown", 7);
            f->nacks_sent++;
            queue(f, SONAR_PING_NACK, q, 9, 0.002);
        }
        break;
    }
    case SONAR_PING360_TRANSDUCER: {
        uint16_t a = (uint16_t)(p[2] | p[3] << 8), prev = f->angle;
        if (fr->payload_len != 14 || a > 399) {
            q[0] = (uint8_t)(fr->id & 0xff);
            q[1] = (uint8_t)(fr->id >> 8);
            f->nacks_sent++;
            queue(f, SONAR_PING_NACK, q, 2, 0.002);
            break;
        }
        f->streaming = 0;
        f->gain = p[1];
        f->tx = (uint16_t)(p[4] | p[5] << 8);
        f->sp = (uint16_t)(p[6] | p[7] << 8);
        f->freq = (uint16_t)(p[8] | p[9] << 8);
        f->n = (uint16_t)(p[10] | p[11] << 8);
        if (f->n > 1200)
            f->n = 1200;
        f->angle = a;
        if (p[12])
            queue_beam(f, a, 0, beam_time(f, prev, a));
        else {
            uint8_t d[14] = {1, f->gain, (uint8_t)a, (uint8_t)(a >> 8), p[4], p[5], p[6], p[7], p[8], p[9], p[10], p[11], 0, 0};
            queue(f, SONAR_PING360_DEVICE_DATA, d, 14, 0.006 * abs(sonar_frame_delta(prev, a)));
        }
        break;
    }
    case SONAR_PING360_AUTO_TRANSMIT:
        if (fr->payload_len != 16)
            break;
        f->gain = p[1];
        f->tx = (uint16_t)(p[2] | p[3] << 8);
        f->sp = (uint16_t)(p[4] | p[5] << 8);
        f->freq = (uint16_t)(p[6] | p[7] << 8);
        f->n = (uint16_t)(p[8] | p[9] << 8);
        f->a_start = (uint16_t)(p[10] | p[11] << 8);
        f->a_stop = (uint16_t)(p[12] | p[13] << 8);
        f->a_step = p[14] ? p[14] : 1;
        f->a_dir = 1;
        f->angle = (uint16_t)(f->a_start - f->a_step);
        f->streaming = 1;
        auto_next(f, 0.0);
        break;
    case SONAR_PING360_MOTOR_OFF:
        f->streaming = 0;
        f->motor_offs++;
        logf_(f, "%s %ld\n", "motor_off", f->motor_offs);
        q[0] = (uint8_t)(SONAR_PING360_MOTOR_OFF & 0xff);
        q[1] = (uint8_t)(SONAR_PING360_MOTOR_OFF >> 8);
        queue(f, SONAR_PING_ACK, q, 2, 0.001);
        if (f->exit_after_motor_off) {
            f->stop_after = 1;
            f->stop_at = now_s() + 0.3;
        }
        break;
    default:
        q[0] = (uint8_t)(fr->id & 0xff);
        q[1] = (uint8_t)(fr->id >> 8);
        memcpy(q + 2, "unsupported", 11);
        f->nacks_sent++;
        queue(f, SONAR_PING_NACK, q, 13, 0.002);
        break;
    }
}

static void close_client(struct feed *f)
{
    if (f->transport == T_UDP) {
        f->have_peer = 0; /* UDP "disconnect": forget the host, which must send again */
        return;
    }
    if (f->cfd >= 0)
        close(f->cfd);
    f->cfd = -1;
}

static int open_pty(struct feed *f)
{
    struct termios t;
    char *name;
    int m = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
    if (m < 0 || grantpt(m) != 0 || unlockpt(m) != 0 || (name = ptsname(m)) == NULL) {
        perror("sonar_feed: pty");
        return -1;
    }
    if (tcgetattr(m, &t) == 0) {
        cfmakeraw(&t);
        tcsetattr(m, TCSANOW, &t);
    }
    unlink(f->pty_link);
    if (symlink(name, f->pty_link) != 0) {
        perror(f->pty_link);
        close(m);
        return -1;
    }
    f->cfd = m;
    return 0;
}

static int setup(struct feed *f)
{
    struct sockaddr_in a;
    int one = 1;
    f->cfd = f->lfd = -1;
    if (f->transport == T_PTY)
        return open_pty(f);
    memset(&a, 0, sizeof(a));
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)f->port);
    if (inet_pton(AF_INET, f->host, &a.sin_addr) != 1) {
        fprintf(stderr, "sonar_feed: '%s' is not an IPv4 address\n", f->host);
        return -1;
    }
    if (f->transport == T_UDP) {
        f->cfd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0);
        if (f->cfd < 0 || bind(f->cfd, (struct sockaddr *)&a, sizeof(a)) != 0) {
            perror("sonar_feed: udp");
            return -1;
        }
        return 0;
    }
    f->lfd = socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK, 0);
    setsockopt(f->lfd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
    if (f->lfd < 0 || bind(f->lfd, (struct sockaddr *)&a, sizeof(a)) != 0 || listen(f->lfd, 1) != 0) {
        perror("sonar_feed: tcp");
        return -1;
    }
    return 0;
}

static int parse_listen(void *base, const char *v, char *err, size_t n)
{
    struct feed *f = base;
    if (strncmp(v, "pty:", 4) == 0) {
        f->transport = T_PTY;
        f->pty_link = v + 4;
        return HOST_OK;
    }
    if ((strncmp(v, "tcp:", 4) == 0 || strncmp(v, "udp:", 4) == 0) && sscanf(v + 4, "%63[^:]:%d", f->host, &f->port) == 2 &&
        f->port > 0 && f->port < 65536) {
        f->transport = v[0] == 't' ? T_TCP : T_UDP;
        if (strncmp(f->host, "127.", 4) != 0) {
            snprintf(err, n, "--listen: '%s': only loopback addresses (127.x.x.x)", v);
            return HOST_ERR_CONFIG;
        }
        return HOST_OK;
    }
    snprintf(err, n, "--listen: '%s' is not tcp:HOST:PORT, udp:HOST:PORT or pty:PATH", v);
    return HOST_ERR_CONFIG;
}

static int parse_discovery(void *base, const char *v, char *err, size_t n)
{
    struct feed *f = base;
    if (strncmp(v, "udp:", 4) != 0 || sscanf(v + 4, "%63[^:]:%d", f->disc_host, &f->disc_port) != 2 || f->disc_port < 1 ||
        f->disc_port > 65535 || strncmp(f->disc_host, "127.", 4) != 0) {
        snprintf(err, n, "--discovery: '%s' is not udp:127.x.x.x:PORT (loopback only)", v);
        return HOST_ERR_CONFIG;
    }
    return HOST_OK;
}

static int parse_mac(void *base, const char *v, char *err, size_t n)
{
    struct feed *f = base;
    if (strchr(v, ' ') != NULL || discover_parse_mac(v, f->mac) != 0) {
        snprintf(err, n, "--mac: '%s' is not six hex pairs like 54-10-EC-00-00-01", v);
        return HOST_ERR_CONFIG;
    }
    return HOST_OK;
}

/* A datagram on the discovery port: "Discovery" gets the device's text reply; anything else is ignored, as the device does. */
static void answer_discovery(struct feed *f)
{
    char buf[256], reply[256];
    struct sockaddr_in from;
    socklen_t fl = sizeof(from);
    struct in_addr ip;
    ssize_t got = recvfrom(f->dfd, buf, sizeof(buf) - 1, 0, (struct sockaddr *)&from, &fl);
    size_t n;
    if (got < 0)
        return;
    buf[got] = '\0';
    if (strncmp(buf, "Discovery", 9) != 0)
        return;
    if (inet_pton(AF_INET, f->claim_ip != NULL ? f->claim_ip : f->host, &ip) != 1)
        ip.s_addr = htonl(INADDR_LOOPBACK);
    n = discover_format_reply(reply, sizeof(reply), f->mac, ntohl(ip.s_addr));
    if (sendto(f->dfd, reply, n, 0, (struct sockaddr *)&from, fl) == (ssize_t)n)
        f->discoveries++;
}

static int parse_firmware(void *base, const char *v, char *err, size_t n)
{
    struct feed *f = base;
    unsigned x, y, z;
    char tail;
    if (sscanf(v, "%u.%u.%u%c", &x, &y, &z, &tail) != 3 || x > 255 || y > 255 || z > 255) {
        snprintf(err, n, "--firmware: '%s' is not X.Y.Z (each 0..255)", v);
        return HOST_ERR_CONFIG;
    }
    f->fw[0] = (uint8_t)x;
    f->fw[1] = (uint8_t)y;
    f->fw[2] = (uint8_t)z;
    return HOST_OK;
}

static int parse_seed(void *base, const char *v, char *err, size_t n)
{
    struct feed *f = base;
    char *end;
    unsigned long long x = strtoull(v, &end, 0);
    if (*v == '\0' || *end != '\0') {
        snprintf(err, n, "--seed: '%s' is not a whole number", v);
        return HOST_ERR_CONFIG;
    }
    f->rng.s ^= x * 0xBF58476D1CE4E5B9ull;
    f->fault_rng.s ^= x * 0x94D049BB133111EBull;
    return HOST_OK;
}

static int parse_pace(void *base, const char *v, char *err, size_t n)
{
    struct feed *f = base;
    if (strcmp(v, "fast") != 0 && strcmp(v, "device") != 0) {
        snprintf(err, n, "--pace: '%s' is not device or fast", v);
        return HOST_ERR_CONFIG;
    }
    f->device_pace = strcmp(v, "device") == 0;
    return HOST_OK;
}

#define FO(field) offsetof(struct feed, field)
static const struct opt_spec feed_spec[] = {
    {"device", NULL, OPT_SECTION, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, NULL},
    {"listen", "URL", OPT_CUSTOM, 0, 0, 0, 0, 0, "tcp:HOST:PORT | udp:HOST:PORT | pty:PATH", NULL, "where to act as a Ping360 (loopback only)", NULL, parse_listen},
    {"scene", "NAME", OPT_STR, 0, 0, FO(scene_name), 0, 0, "pool, open, moving, sector or vehicle", NULL, "a simulated scene", NULL, NULL},
    {"csv", "FILE", OPT_STR, 0, 0, FO(csv_path), 0, 0, "file", NULL, "play a recording instead", NULL, NULL},
    {"range", "M", OPT_F64, 0, 0, FO(csv_range), 1, 60, "metres", "the file's", "range of the recording", NULL, NULL},
    {"pace", "device|fast", OPT_CUSTOM, 0, 0, 0, 0, 0, "device or fast", "device", "device: 19.4 ms + 6 ms a gradian + 2R/c a beam", NULL, parse_pace},
    {"firmware", "X.Y.Z", OPT_CUSTOM, 0, 0, 0, 0, 0, "X.Y.Z", "3.3.8", "firmware version reported", NULL, parse_firmware},
    {"seed", "S", OPT_CUSTOM, 0, 0, 0, 0, 0, "whole number", "0", "scene and fault random seed", NULL, parse_seed},
    {"log", "FILE", OPT_STR, 0, 0, FO(log_path), 0, 0, "file", NULL, "requests, faults and a summary line", NULL, NULL},
    {"max-seconds", "T", OPT_F64, 0, 0, FO(max_s), 0.1, 1e7, "seconds", "600", "exit after T", NULL, NULL},
    {"exit-after-motor-off", NULL, OPT_FLAG, 0, 0, FO(exit_after_motor_off), 0, 0, NULL, "off", "exit 0.3 s after motor_off", NULL, NULL},
    {"max-beams", "N", OPT_LONG, 0, 0, FO(max_beams), 1, 1e12, "beams", "no limit", "exit after N beams sent intact (soak)", NULL, NULL},
    {"mavlink", "URL", OPT_STR, 0, 0, FO(mavlink), 0, 0, "udpout:127.x.x.x:PORT", NULL,
     "a moving scene's autopilot: ATTITUDE and LOCAL_POSITION_NED at 20 Hz", NULL, NULL},
    {"discovery", "URL", OPT_CUSTOM, 0, 0, 0, 0, 0, "udp:127.x.x.x:PORT", NULL,
     "answer Ping360 discovery (\"Discovery\" -> the device's text reply) here", NULL, parse_discovery},
    {"mac", "XX-XX-XX-XX-XX-XX", OPT_CUSTOM, 0, 0, 0, 0, 0, "six hex pairs", "54-10-EC-00-00-01", "MAC address in the discovery reply", NULL, parse_mac},
    {"claim-ip", "A.B.C.D", OPT_STR, 0, 0, FO(claim_ip), 0, 20, "IPv4", "the --listen host", "IP address the discovery reply claims", NULL, NULL},
    {"faults", NULL, OPT_SECTION, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, NULL},
    {"drop", "P", OPT_F64, 0, 0, FO(drop), 0, 1, "probability", "0", "drop a reply", NULL, NULL},
    {"drop-at", "N", OPT_LONG, 0, 0, FO(drop_at), 1, 1e12, "replies", NULL, "drop reply N", NULL, NULL},
    {"corrupt", "P", OPT_F64, 0, 0, FO(corrupt), 0, 1, "probability", "0", "flip a byte of a reply", NULL, NULL},
    {"garbage", "P", OPT_F64, 0, 0, FO(garbage), 0, 1, "probability", "0", "send 1..40 junk bytes before a reply", NULL, NULL},
    {"disconnect-after", "N", OPT_LONG, 0, 0, FO(disconnect_after), 1, 1e12, "replies", NULL, "close the link at reply N", NULL, NULL},
    {"disconnect-every", "N", OPT_LONG, 0, 0, FO(disconnect_every), 1, 1e12, "replies", NULL, "close the link every N replies", NULL, NULL},
    {"stall-at", "N", OPT_LONG, 0, 0, FO(stall_at), 1, 1e12, "replies", NULL, "go quiet for --stall seconds at reply N", NULL, NULL},
    {"stall-every", "N", OPT_LONG, 0, 0, FO(stall_every), 1, 1e12, "replies", NULL, "go quiet every N replies", NULL, NULL},
    {"stall", "S", OPT_F64, 0, 0, FO(stall_s), 0, 3600, "seconds", "0", "length of a stall", NULL, NULL},
    {"help", NULL, OPT_ACTION, 0, 0, 0, 0, 0, NULL, NULL, "this text", NULL, NULL},
};

static void usage(const struct opt_schema *s)
{
    fprintf(stderr, "usage: sonar_feed --listen URL (--scene pool|open | --csv FILE [--range M]) [options]\n"
                    "Acts as a Ping360: device_information, protocol_version, transducer (with and without transmit),\n"
                    "auto_transmit streaming, motor_off with an ack, NACK for anything else.\n");
    opt_usage(s, stderr);
}

int main(int argc, char **argv)
{
    static struct feed f;
    const struct opt_schema schema = {feed_spec, sizeof(feed_spec) / sizeof(feed_spec[0]), "sonar_feed"};
    const char *csv, *scene;
    double range, t0;
    char err[256];
    int action;
    f.device_pace = 1;
    f.fw[0] = 3;
    f.fw[1] = 3;
    f.fw[2] = 8;
    f.c = 1500.0;
    f.max_s = 600;
    f.csv_range = -1;
    f.mac[0] = 0x54;
    f.mac[1] = 0x10;
    f.mac[2] = 0xEC;
    f.mac[5] = 0x01;
    f.dfd = -1;
    f.rng.s = 0x9E3779B97F4A7C15ull;
    f.fault_rng.s = 0x2545F4914F6CDD1Dull;
    if (opt_parse_argv(&schema, argc, argv, &f, NULL, &action, err, sizeof(err)) != HOST_OK) {
        fprintf(stderr, "sonar_feed: %s\n", err);
        return 2;
    }
    if (action >= 0) {
        usage(&schema);
        return 0;
    }
    csv = f.csv_path;
    scene = f.scene_name;
    range = f.csv_range;
    if ((scene == NULL) == (csv == NULL) || (f.transport != T_PTY && f.port == 0)) {
        usage(&schema);
        return 2;
    }
    if (scene != NULL) {
        if (scene_make(&f.scene, scene) != 0) {
            fprintf(stderr, "sonar_feed: --scene: '%s' is not pool, open, moving, sector or vehicle\n", scene);
            return 2;
        }
        f.use_scene = 1;
    } else if (load_csv(&f.rec, csv, range) != 0) {
        return 2;
    }
    f.mfd = -1;
    if (f.mavlink != NULL && open_mavlink(&f) != 0)
        return 2;
    if (f.log_path != NULL && (f.log = fopen(f.log_path, "w")) == NULL) {
        perror(f.log_path);
        return 2;
    }
    if (sonar_ping_parser_init(&f.parser, 0) != SONAR_OK || sonar_sweep_init(&f.sweep, 20, 400) != SONAR_OK ||
        setup(&f) != 0)
        return 2;
    if (f.disc_port > 0) {
        struct sockaddr_in a;
        memset(&a, 0, sizeof(a));
        a.sin_family = AF_INET;
        a.sin_port = htons((uint16_t)f.disc_port);
        if (inet_pton(AF_INET, f.disc_host, &a.sin_addr) != 1 || (f.dfd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0)) < 0 ||
            bind(f.dfd, (struct sockaddr *)&a, sizeof(a)) != 0) {
            perror("sonar_feed: --discovery");
            return 2;
        }
    }
    f.sp = 88;
    f.n = 1200;
    f.freq = 740;
    signal(SIGINT, on_signal);
    signal(SIGTERM, on_signal);
    signal(SIGPIPE, SIG_IGN);
    t0 = now_s();
    while (!quit) {
        struct pollfd pfd[3];
        struct timespec ts = {0, 200000000};
        int np = 0, r;
        double now = now_s();
        if (now - t0 > f.max_s || (f.stop_after && now > f.stop_at) || (f.max_beams > 0 && f.beams_intact >= f.max_beams))
            break;
        if (f.mfd >= 0 && now >= f.next_pose) {
            send_pose(&f);
            f.next_pose = now + 0.05;
        }
        if (f.mfd >= 0 && f.next_pose - now < 0.2) {
            double w = f.next_pose - now < 0 ? 0 : f.next_pose - now;
            ts.tv_sec = 0;
            ts.tv_nsec = (long)(w * 1e9);
        }
        if (f.out_len > 0 && (f.mfd < 0 || f.due - now < f.next_pose - now)) {
            /* nanosecond timeouts: the device pacing must not gain a millisecond a beam */
            double wait = f.due - now;
            if (wait < 0)
                wait = 0;
            ts.tv_sec = (time_t)wait;
            ts.tv_nsec = (long)((wait - (double)ts.tv_sec) * 1e9);
        }
        if (f.lfd >= 0 && f.cfd < 0) {
            pfd[np].fd = f.lfd;
            pfd[np++].events = POLLIN;
        }
        if (f.cfd >= 0) {
            pfd[np].fd = f.cfd;
            pfd[np++].events = POLLIN;
        }
        if (f.dfd >= 0) {
            /* last, so the indices above stay as they are */
            pfd[np].fd = f.dfd;
            pfd[np++].events = POLLIN;
        }
        r = ppoll(pfd, (nfds_t)np, &ts, NULL);
        if (r < 0 && errno != EINTR)
            break;
        if (f.dfd >= 0) {
            if (pfd[np - 1].revents & POLLIN)
                answer_discovery(&f);
            np--;
        }
        if (f.lfd >= 0 && f.cfd < 0 && np > 0 && (pfd[0].revents & POLLIN)) {
            f.cfd = accept(f.lfd, NULL, NULL);
            if (f.cfd >= 0)
                fcntl(f.cfd, F_SETFL, O_NONBLOCK);
            continue;
        }
        if (f.cfd >= 0 && np > 0 && (pfd[np - 1].revents & (POLLIN | POLLHUP | POLLERR))) {
            uint8_t buf[4096];
            ssize_t got;
            if (f.transport == T_UDP) {
                socklen_t al = sizeof(f.peer);
                got = recvfrom(f.cfd, buf, sizeof(buf), 0, (struct sockaddr *)&f.peer, &al);
                if (got >= 0)
                    f.have_peer = 1;
            } else {
                got = read(f.cfd, buf, sizeof(buf));
            }
            if (got == 0 || (got < 0 && errno != EAGAIN && errno != EINTR && errno != EIO)) {
                if (f.transport == T_TCP) {
                    close_client(&f);
                    f.out_len = 0;
                }
            } else if (got > 0) {
                const uint8_t *in = buf;
                size_t len = (size_t)got;
                struct sonar_ping_frame fr;
                while (sonar_ping_parser_next(&f.parser, &in, &len, &fr) == 1)
                    handle_frame(&f, &fr);
            }
        }
        if (f.out_len > 0 && now_s() >= f.due) {
            int was_auto = f.streaming;
            flush_reply(&f);
            if (was_auto && f.streaming && f.out_len == 0)
                auto_next(&f, 0.0);
        }
    }
    fprintf(stderr,
            "sonar_feed: requests %ld, beams %ld (intact %ld), replies %ld, dropped %ld, corrupted %ld, garbage %ld, "
            "disconnects %ld, stalls %ld, nacks %ld, motor_off %ld\n",
            f.requests, f.beams, f.beams_intact, f.replies, f.dropped, f.corrupted, f.garbage_runs, f.disconnects, f.stalls, f.nacks_sent,
            f.motor_offs);
    if (f.mfd >= 0)
        fprintf(stderr, "sonar_feed: mavlink %s: %ld poses sent\n", f.mavlink, f.poses_sent);
    if (f.dfd >= 0)
        fprintf(stderr, "sonar_feed: discovery %s:%d: %ld replies\n", f.disc_host, f.disc_port, f.discoveries);
    if (f.log != NULL) {
        fprintf(f.log, "summary requests %ld beams %ld replies %ld dropped %ld corrupted %ld garbage %ld disconnects %ld stalls %ld nacks %ld motor_off %ld intact %ld\n",
                f.requests, f.beams, f.replies, f.dropped, f.corrupted, f.garbage_runs, f.disconnects, f.stalls, f.nacks_sent,
                f.motor_offs, f.beams_intact);
        fclose(f.log);
    }
    if (f.transport == T_PTY)
        unlink(f.pty_link);
    return 0;
}
