/* app_device.c -- the app on a live link: bytes to the device core, its beams to app_push, its timers and stop; O(bytes) per call. */
#include "app_internal.h"

static int on_event(struct app *a, struct sonar_device_event *ev)
{
    switch (ev->kind) {
    case SONAR_P360_EV_READY:
        app_say(a, "Ping360 firmware %u.%u.%u on %s", a->dev.drv.info.fw_major, a->dev.drv.info.fw_minor,
                a->dev.drv.info.fw_patch, a->link);
        app_say(a, "scanning (%s)", a->dev.drv.state == SONAR_P360_AUTO ? "auto_transmit" : "stepping");
        return APP_LINK_NONE;
    case SONAR_P360_EV_BEAM:
        ev->beam.utime = app_wall_us(a); /* a live beam is timed by its receipt */
        if (app_push(a, &ev->beam) != HOST_OK)
            return APP_LINK_NONE; /* counted in beams_rejected; the sinks still had the raw beam */
        return APP_LINK_NONE;
    case SONAR_P360_EV_LINK_LOST:
        return APP_LINK_LOST;
    case SONAR_P360_EV_STOPPED:
        return APP_LINK_STOPPED;
    default:
        return APP_LINK_NONE;
    }
}

int app_link_bytes(struct app *a, const uint8_t *buf, size_t len, int64_t now_us)
{
    const uint8_t *in = buf;
    struct sonar_device_event ev;
    while (sonar_device_bytes(&a->dev, &in, &len, now_us, &ev) == 1) {
        int r = on_event(a, &ev);
        if (r != APP_LINK_NONE)
            return r;
    }
    return APP_LINK_NONE;
}

int app_link_up(struct app *a, int64_t now_us)
{
    return sonar_device_up(&a->dev, now_us);
}

uint32_t app_link_down(struct app *a, int64_t now_us)
{
    return sonar_device_down(&a->dev, now_us);
}

int app_link_poll(struct app *a, int64_t now_us)
{
    struct sonar_device_event ev;
    if (!a->have_dev || sonar_device_poll(&a->dev, now_us, &ev) != 1)
        return APP_LINK_NONE;
    return on_event(a, &ev);
}

int64_t app_deadline(const struct app *a)
{
    return a->have_dev ? sonar_ping360_deadline(&a->dev.drv) : INT64_MAX;
}

int app_link_stop(struct app *a, int64_t now_us)
{
    int r = sonar_ping360_stop(&a->dev.drv, now_us);
    if (r != SONAR_OK)
        return r;
    return a->dev.drv.state == SONAR_P360_STOPPED;
}

const struct sonar_device *app_device(const struct app *a)
{
    return a->have_dev ? &a->dev : NULL;
}
