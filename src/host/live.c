/* live.c -- the poll loop: the link's descriptor, a signalfd and the timers (driver, reconnect, line break, 1 Hz status, stop deadline), the host's stalls measured and given back to the source's timers; O(1) per wake. */
#define _GNU_SOURCE
#include "live.h"

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/signalfd.h>
#include <time.h>
#include <unistd.h>

#define STATUS_US 1000000
#define STOP_GRACE_US 1500000
#define STALL_GIVE_MAX_US 2000000 /* the most a stall gives back: a longer one is a lost link, not a pause */
#define STALL_SLICE_MS 10          /* the longest poll while a reply is awaited: a stall is seen to within it */

static int64_t now_us(const struct app *a)
{
    return app_mono_us(a);
}

/* The loop's CPU time (its own thread's), us. */
static int64_t cpu_us(void)
{
    struct timespec t;
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t) != 0)
        return 0;
    return (int64_t)t.tv_sec * 1000000 + t.tv_nsec / 1000;
}

/*
 * One iteration's stall: its wall time less its CPU time and the poll's timeout is a lower bound of the time sonard
 * was kept from running (the poll may have slept less than its timeout); counted when LIVE_STALL_MIN_US or more. The
 * source's timers are then held for the upper bound, the wall time less the CPU time, since the part of the stall
 * inside the poll's timeout cannot be told apart. Returns the time they are held until (`held` when no stall).
 */
static int64_t stalled(struct live_stalls *st, int64_t wall_us, int64_t cpu, int poll_ms, int64_t now, int64_t held)
{
    int64_t lost = wall_us - cpu - (int64_t)poll_ms * 1000, most = wall_us - cpu;
    if (lost < LIVE_STALL_MIN_US)
        return held;
    st->n++;
    st->total_us += lost;
    if (lost > st->longest_us)
        st->longest_us = lost;
    most = most > STALL_GIVE_MAX_US ? STALL_GIVE_MAX_US : most;
    return now + most > held ? now + most : held;
}

/* Long: the one event loop (signals, the source, its aux descriptors, status ticks, the stop's deadline, the stall
   measure before the timers) reads as one poll cycle; issue 36 asks for one loop around every link, which will take
   the source and aux parts out. */
int live_run(struct app *a, const struct live_source *src, const struct live_aux *aux, unsigned naux,
             live_reload_fn reload, void *reload_user, struct live_stalls *stalls)
{
    struct sonar_status st;
    struct live_stalls lost = {0, 0, 0};
    int64_t held = 0, src_wake = 0, iter_at, iter_cpu; /* the source's timers held until `held` after a stall */
    const struct live_io_ops *io = &src->ops->io;
    sigset_t mask;
    unsigned k;
    int sigfd, stop = 0, interrupted = 0, ms = 0; /* ms: the last poll's timeout */
    int64_t next_status, stop_deadline = INT64_MAX;
    /* Signals arrive as readable bytes on a descriptor, so the loop never runs code in a handler. */
    sigemptyset(&mask);
    sigaddset(&mask, SIGINT);
    sigaddset(&mask, SIGTERM);
    sigaddset(&mask, SIGHUP);
    sigprocmask(SIG_BLOCK, &mask, NULL);
    signal(SIGPIPE, SIG_IGN);
    if ((sigfd = signalfd(-1, &mask, SFD_NONBLOCK | SFD_CLOEXEC)) < 0) {
        fprintf(stderr, "sonard: signalfd: %s\n", strerror(errno));
        return HOST_ERR_IO;
    }
    if (naux > LIVE_MAX_AUX)
        naux = LIVE_MAX_AUX;
    next_status = now_us(a) + STATUS_US;
    io->start(src->self, a, now_us(a));
    for (k = 0; k < naux; k++)
        aux[k].ops->start(aux[k].self, a, now_us(a));
    iter_at = now_us(a);
    iter_cpu = cpu_us();
    for (;;) {
        struct pollfd pfd[2 + LIVE_MAX_AUX];
        int slot[2 + LIVE_MAX_AUX]; /* which aux source a descriptor belongs to */
        int64_t now = now_us(a), wake, cpu = cpu_us();
        int np = 1, src_at = -1, i;
        short events;
        /* The stall is measured here, just before the source's timers run at `now`: measured after the poll, a pause
           while the last reply was handled would reach the timers unseen and time their request out. */
        held = stalled(&lost, now - iter_at, cpu - iter_cpu, ms, now, held);
        iter_at = now;
        iter_cpu = cpu;
        if (!stop && app_done(a)) {
            stop = 1;
            stop_deadline = now + STOP_GRACE_US;
            src->ops->stop(src->self, now);
        }
        if (stop && (src->ops->stopped(src->self) || now >= stop_deadline))
            break;
        if (src->ops->stopped(src->self))
            break; /* the source gave up by itself (a co-processor refused the configuration) */
        /* After a stall the source's timers wait the lost time out: the sonar's reply (a real one goes on answering
           while the host is paused) is read before its request is declared timed out. */
        if (now >= held)
            src_wake = io->timers(src->self, now);
        wake = now >= held || src_wake > held ? src_wake : held;
        for (k = 0; k < naux; k++) {
            int64_t w = aux[k].ops->timers(aux[k].self, now);
            wake = w < wake ? w : wake;
        }
        if (next_status < wake)
            wake = next_status;
        if (stop_deadline < wake)
            wake = stop_deadline;
        now = now_us(a);
        ms = wake <= now ? 0 : (wake - now) / 1000 + 1 > 1000 ? 1000 : (int)((wake - now) / 1000 + 1);
        /* While the source waits on a reply, the poll sleeps in slices, so that a stall inside the wait is seen. */
        if (src_wake < now + STALL_GIVE_MAX_US && ms > STALL_SLICE_MS)
            ms = STALL_SLICE_MS;
        pfd[0].fd = sigfd;
        pfd[0].events = POLLIN;
        pfd[0].revents = 0;
        if ((pfd[1].fd = io->fd(src->self, &events)) >= 0) {
            pfd[1].events = events;
            pfd[1].revents = 0;
            src_at = 1;
            np = 2;
        }
        for (k = 0; k < naux; k++)
            if ((pfd[np].fd = aux[k].ops->fd(aux[k].self, &events)) >= 0) {
                pfd[np].events = events;
                pfd[np].revents = 0;
                slot[np++] = (int)k;
            }
        if (poll(pfd, (nfds_t)np, ms) < 0 && errno != EINTR)
            break;
        now = now_us(a);
        if (pfd[0].revents & POLLIN) {
            struct signalfd_siginfo si;
            while (read(sigfd, &si, sizeof(si)) == (ssize_t)sizeof(si)) {
                if (si.ssi_signo == SIGHUP) {
                    if (reload != NULL)
                        (void)reload(reload_user); /* it reports its own errors; the running settings stay */
                } else if (!stop) {
                    stop = interrupted = 1;
                    stop_deadline = now + STOP_GRACE_US;
                    src->ops->stop(src->self, now);
                }
            }
        }
        if (src_at == 1 && pfd[1].revents != 0)
            io->ready(src->self, pfd[1].revents, now);
        for (i = src_at == 1 ? 2 : 1; i < np; i++)
            if (pfd[i].revents != 0)
                aux[slot[i]].ops->ready(aux[slot[i]].self, pfd[i].revents, now);
        if (now >= next_status) {
            if (src->ops->state != NULL)
                app_report_status(a, src->ops->state(src->self), &st);
            next_status = now + STATUS_US;
        }
    }
    /* An interrupted sweep is still worth publishing; a --sweeps run already has all it asked for. */
    if (interrupted && app_finish(a) != HOST_OK)
        fprintf(stderr, "sonard: finishing the last sweep failed\n");
    if (src->ops->state != NULL)
        app_report_status(a, src->ops->state(src->self), &st);
    io->close(src->self);
    for (k = 0; k < naux; k++)
        aux[k].ops->close(aux[k].self);
    close(sigfd);
    if (stalls != NULL)
        *stalls = lost;
    return HOST_OK;
}
