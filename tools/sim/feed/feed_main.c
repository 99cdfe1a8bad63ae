/* feed_main.c -- sonar-feed: a simulated Ping360 serving a scene or a recording over TCP, UDP or a pty, with faults, an autopilot and discovery; the options (one table) and the poll loop. */
#define _GNU_SOURCE
#include "feed.h"

static volatile sig_atomic_t quit;

static void on_signal(int s)
{
    (void)s;
    quit = 1;
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
    char *end;
    double x = v[0] == 'x' ? strtod(v + 1, &end) : 0.0;
    f->pace_speedup = 1.0;
    if (v[0] == 'x') {
        if (v[1] == '\0' || *end != '\0' || !(x >= 1.0 && x <= 1000.0)) {
            snprintf(err, n, "--pace: '%s' is not xN with N in 1..1000", v);
            return HOST_ERR_CONFIG;
        }
        f->device_pace = 1;
        f->pace_speedup = x;
        return HOST_OK;
    }
    if (strcmp(v, "fast") != 0 && strcmp(v, "device") != 0) {
        snprintf(err, n, "--pace: '%s' is not device, fast or xN", v);
        return HOST_ERR_CONFIG;
    }
    f->device_pace = strcmp(v, "device") == 0;
    return HOST_OK;
}

#define FO(field) offsetof(struct feed, field)
static const struct opt_spec feed_spec[] = {
    {"device", NULL, OPT_SECTION, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, NULL},
    {"listen", "URL", OPT_CUSTOM, 0, 0, 0, 0, 0, "tcp:HOST:PORT | udp:HOST:PORT | pty:PATH", NULL, "where to act as a Ping360 (loopback only)", NULL, parse_listen},
    {"scene", "NAME", OPT_STR, 0, 0, FO(scene_name), 0, 0, "a sonar-sim scene (sonar-sim --help lists them)", NULL, "a simulated scene", NULL, NULL},
    {"empty", NULL, OPT_FLAG, 0, 0, FO(empty), 0, 0, NULL, "off", "the scene with nobody in it (walls, ropes, structure): a site to survey", NULL, NULL},
    {"arrive-at-motor-off", NULL, OPT_FLAG, 0, 0, FO(arrive), 0, 0, NULL, "off",
     "the site empty until the first motor_off (a survey's run ends), then the\nscene's people, its sweeps counted from 0: a survey recorded, then used", NULL, NULL},
    {"csv", "FILE", OPT_STR, 0, 0, FO(csv_path), 0, 0, "file", NULL, "play a recording instead", NULL, NULL},
    {"range", "M", OPT_F64, 0, 0, FO(csv_range), 1, 60, "metres", "the file's", "range of the recording", NULL, NULL},
    {"samples-as-recorded", NULL, OPT_FLAG, 0, 0, FO(as_recorded), 0, 0, NULL, "off",
     "a recording's rows as they are, whatever number of samples is asked (a sonar\nthat answers with other than asked); without it, the nearest sample of the row", NULL, NULL},
    {"pace", "device|fast|xN", OPT_CUSTOM, 0, 0, 0, 0, 0, "device, fast or xN", "device",
     "device: 19.4 ms + 6 ms a gradian + 2R/c a beam; xN: N times\nfaster; fast: at once", NULL, parse_pace},
    {"firmware", "X.Y.Z", OPT_CUSTOM, 0, 0, 0, 0, 0, "X.Y.Z", "3.3.8", "firmware version reported", NULL, parse_firmware},
    {"seed", "S", OPT_CUSTOM, 0, 0, 0, 0, 0, "whole number", "0", "scene and fault random seed", NULL, parse_seed},
    {"scene-clock", "sweeps|wall", OPT_CHOICE, 0, 0, FO(wall_clock), 0, 0, "sweeps or wall", "sweeps",
     "sweeps: timed objects move 10 s a sweep of requests; wall: on the wall clock\nfrom the first beam, whatever angles are asked (a planner's)", "sweeps=0|wall=1", NULL},
    {"gain-model", "G", OPT_LONG, 0, 0, FO(gain_ref), -1, 2, "setting 0..2 (-1 off)", "-1",
     "the scene as drawn is what gain G gives; each setting above doubles the\nechoes (saturating at 255), each below halves them (the floor)", NULL, NULL},
    {"gain-fixed", NULL, OPT_FLAG, 0, 0, FO(gain_fixed), 0, 0, NULL, "off",
     "keep the first gain asked: later requests' gain is ignored (replies say so)", NULL, NULL},
    {"truth", "FILE", OPT_STR, 0, 0, FO(truth_path), 0, 0, "file", NULL,
     "with --scene-clock wall: the objects every 0.1 s and each beam served,\nJSON lines timed on the wall clock (us since the epoch)", NULL, NULL},
    {"log", "FILE", OPT_STR, 0, 0, FO(log_path), 0, 0, "file", NULL, "requests, faults and a summary line", NULL, NULL},
    {"max-seconds", "T", OPT_F64, 0, 0, FO(max_s), 0.1, 1e7, "seconds", "600", "exit after T", NULL, NULL},
    {"exit-after-motor-off", NULL, OPT_FLAG, 0, 0, FO(exit_after_motor_off), 0, 0, NULL, "off", "exit 0.3 s after motor_off", NULL, NULL},
    {"max-beams", "N", OPT_LONG, 0, 0, FO(max_beams), 1, 1e12, "beams", "no limit", "exit after N beams sent intact (soak)", NULL, NULL},
    {"mavlink", "URL", OPT_STR, 0, 0, FO(mavlink), 0, 0, "udpout:127.x.x.x:PORT", NULL,
     "the scene's autopilot (an ArduPilot stand-in): HEARTBEAT, ATTITUDE and\nLOCAL_POSITION_NED, honouring SET_MESSAGE_INTERVAL", NULL, NULL},
    {"mavlink-rate", "HZ", OPT_F64, 0, 0, FO(mav_rate0), 0.1, 50, "messages a second", "1",
     "the pose streams' rate until SET_MESSAGE_INTERVAL changes it (ArduPilot's\nwithout a ground station)", NULL, NULL},
    {"mavlink-refuse", NULL, OPT_FLAG, 0, 0, FO(mav_refuse), 0, 0, NULL, "off",
     "answer SET_MESSAGE_INTERVAL with MAV_RESULT_DENIED", NULL, NULL},
    {"discovery", "URL", OPT_CUSTOM, 0, 0, 0, 0, 0, "udp:127.x.x.x:PORT", NULL,
     "answer Ping360 discovery (\"Discovery\" -> the device's text reply) here", NULL, parse_discovery},
    {"mac", "XX-XX-XX-XX-XX-XX", OPT_CUSTOM, 0, 0, 0, 0, 0, "six hex pairs", "54-10-EC-00-00-01", "MAC address in the discovery reply", NULL, parse_mac},
    {"claim-ip", "A.B.C.D", OPT_STR, 0, 0, FO(claim_ip), 0, 20, "IPv4", "the --listen host", "IP address the discovery reply claims", NULL, NULL},
    {"faults", NULL, OPT_SECTION, 0, 0, 0, 0, 0, NULL, NULL, NULL, NULL, NULL},
    {"drop", "P", OPT_F64, 0, 0, FO(drop), 0, 1, "probability", "0", "drop a reply", NULL, NULL},
    {"drop-at", "N", OPT_LONG, 0, 0, FO(drop_at), 1, 1e12, "replies", NULL, "drop reply N", NULL, NULL},
    {"corrupt", "P", OPT_F64, 0, 0, FO(corrupt), 0, 1, "probability", "0", "flip a byte of a reply", NULL, NULL},
    {"garbage", "P", OPT_F64, 0, 0, FO(garbage), 0, 1, "probability", "0", "send 1..40 junk bytes before a reply", NULL, NULL},
    {"ping1d", "P", OPT_F64, 0, 0, FO(ping1d), 0, 1, "probability", "0",
     "send a Ping1D's frame before a reply (its device_information or\ndistance_simple), as a BlueOS bridge shared with one relays it", NULL, NULL},
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
    const struct opt_schema schema = {feed_spec, sizeof(feed_spec) / sizeof(feed_spec[0]), "sonar_feed", NULL, 0};
    const char *csv, *scene;
    double range, t0;
    char err[256];
    int action;
    f.device_pace = 1;
    f.pace_speedup = 1.0;
    f.fw[0] = 3;
    f.fw[1] = 3;
    f.fw[2] = 8;
    f.c = 1500.0;
    f.max_s = 600;
    f.mav_rate0 = 1.0;
    f.csv_range = -1;
    f.gain_ref = -1;
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
            fprintf(stderr, "sonar_feed: --scene: '%s' is not a scene of sonar-sim's (sonar-sim --help lists them)\n", scene);
            return 2;
        }
        f.full = f.scene;
        if (f.empty || f.arrive)
            scene_empty(&f.scene);
        f.use_scene = 1;
    } else if (f.arrive) {
        fprintf(stderr, "sonar_feed: --arrive-at-motor-off goes with --scene NAME (a recording cannot be emptied)\n");
        return 2;
    } else if (feed_load_csv(&f.rec, csv, range) != 0) {
        return 2;
    }
    if (f.truth_path != NULL) {
        if (!f.use_scene || !f.wall_clock) {
            fprintf(stderr, "sonar_feed: --truth goes with --scene NAME --scene-clock wall (the truth is timed on the wall clock)\n");
            return 2;
        }
        if ((f.truth = fopen(f.truth_path, "w")) == NULL) {
            fprintf(stderr, "sonar_feed: --truth %s: %s\n", f.truth_path, strerror(errno));
            return 2;
        }
    }
    f.mfd = -1;
    if (f.mavlink != NULL && feed_open_mavlink(&f) != 0)
        return 2;
    f.att_s = f.pos_s = 1.0 / f.mav_rate0;
    if (f.log_path != NULL && (f.log = fopen(f.log_path, "w")) == NULL) {
        perror(f.log_path);
        return 2;
    }
    if (sonar_ping_parser_init(&f.parser, 0) != SONAR_OK || sonar_sweep_init(&f.sweep, 20, 400) != SONAR_OK ||
        feed_setup(&f) != 0)
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
    t0 = feed_now();
    while (!quit) {
        struct pollfd pfd[3];
        struct timespec ts = {0, 200000000};
        int np = 0, r;
        double now = feed_now();
        if (now - t0 > f.max_s || (f.stop_after && now > f.stop_at) || (f.max_beams > 0 && f.beams_intact >= f.max_beams))
            break;
        if (f.mfd >= 0 && now >= f.next_pose)
            feed_autopilot(&f, now);
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
                feed_answer_discovery(&f);
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
                    feed_close_client(&f);
                    f.out_len = 0;
                }
            } else if (got > 0) {
                const uint8_t *in = buf;
                size_t len = (size_t)got;
                struct sonar_ping_frame fr;
                while (sonar_ping_parser_next(&f.parser, &in, &len, &fr) == 1)
                    feed_handle_frame(&f, &fr);
            }
        }
        if (f.out_len > 0 && feed_now() >= f.due) {
            int was_auto = f.streaming;
            feed_flush_reply(&f);
            if (was_auto && f.streaming && f.out_len == 0)
                feed_auto_next(&f, 0.0);
        }
    }
    fprintf(stderr,
            "sonar_feed: requests %ld, beams %ld (intact %ld), replies %ld, dropped %ld, corrupted %ld, garbage %ld, "
            "disconnects %ld, stalls %ld, nacks %ld, motor_off %ld, ping1d frames %ld\n",
            f.requests, f.beams, f.beams_intact, f.replies, f.dropped, f.corrupted, f.garbage_runs, f.disconnects, f.stalls, f.nacks_sent,
            f.motor_offs, f.ping1d_frames);
    if (f.mfd >= 0)
        fprintf(stderr, "sonar_feed: mavlink %s: %ld poses sent, %ld intervals set, %ld refused, %ld acks\n", f.mavlink,
                f.poses_sent, f.intervals_set, f.intervals_refused, f.acks_sent);
    if (f.dfd >= 0)
        fprintf(stderr, "sonar_feed: discovery %s:%d: %ld replies\n", f.disc_host, f.disc_port, f.discoveries);
    if (f.log != NULL) {
        fprintf(f.log, "summary requests %ld beams %ld replies %ld dropped %ld corrupted %ld garbage %ld disconnects %ld stalls %ld nacks %ld motor_off %ld intact %ld\n",
                f.requests, f.beams, f.replies, f.dropped, f.corrupted, f.garbage_runs, f.disconnects, f.stalls, f.nacks_sent,
                f.motor_offs, f.beams_intact);
        fclose(f.log);
    }
    if (f.truth != NULL)
        fclose(f.truth);
    if (f.transport == T_PTY)
        unlink(f.pty_link);
    return 0;
}
