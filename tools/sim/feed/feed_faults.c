/* feed_faults.c -- sonar-feed's fault injector: each reply may stall, disconnect, be dropped, get garbage before it or a flipped byte in it, at the rates and points the options give. */
#define _GNU_SOURCE
#include "feed.h"

/* Sends the pending reply, through the fault injector. */
void feed_flush_reply(struct feed *f)
{
    uint8_t buf[2 * 1300 + 64];
    size_t n = 0;
    int beam = f->out_is_beam, corrupt = 0;
    f->out_is_beam = 0;
    f->replies++;
    if ((f->stall_at > 0 && f->replies == f->stall_at) ||
        (f->stall_every > 0 && f->replies % f->stall_every == 0 && f->replies != f->last_fault)) {
        f->stalls++;
        feed_log(f, "%s %ld\n", "stall_ms", (long)(f->stall_s * 1000));
        f->due = feed_now() + f->stall_s;
        f->stall_at = 0;
        f->last_fault = f->replies;
        f->out_is_beam = beam; /* the same reply goes out after the stall */
        f->replies--;
        return;
    }
    if ((f->disconnect_after > 0 && f->replies == f->disconnect_after) ||
        (f->disconnect_every > 0 && f->replies % f->disconnect_every == 0)) {
        f->disconnects++;
        feed_log(f, "%s %ld\n", "disconnect_at_reply", f->replies);
        f->out_len = 0;
        feed_close_client(f);
        if (f->transport == T_PTY)
            (void)feed_open_pty(f);
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
    if (f->ping1d > 0 && scene_uniform(&f->fault_rng) < f->ping1d) {
        /* Another device behind the same bridge: a Ping1D's device_information (type 1) or distance_simple (1211). */
        static const uint8_t info[6] = {1, 1, 3, 29, 0, 0}, dist[9] = {0x10, 0x27, 0, 0, 100};
        int k = scene_uniform(&f->fault_rng) < 0.5;
        int len = sonar_ping_encode(buf + n, sizeof buf - n, k ? SONAR_PING_DEVICE_INFORMATION : 1211, k ? info : dist, k ? 6 : 5);
        if (len > 0) {
            buf[n + 6] = 1; /* src: the Ping1D's own device id */
            /* the checksum covers the header: redo it for the new src */
            {
                uint16_t sum = 0;
                int i;
                for (i = 0; i < len - 2; i++)
                    sum = (uint16_t)(sum + buf[n + (size_t)i]);
                buf[n + (size_t)len - 2] = (uint8_t)(sum & 0xff);
                buf[n + (size_t)len - 1] = (uint8_t)(sum >> 8);
            }
            n += (size_t)len;
            f->ping1d_frames++;
        }
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
    if (feed_send_bytes(f, buf, n) == 0 && beam && !corrupt)
        f->beams_intact++;
}
