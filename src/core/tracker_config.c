/* tracker_config.c -- the tracker's configuration: its defaults and the check that names a wrong field; O(1), no state. */
#include "sonar/tracker.h"

#include <string.h>

void sonar_tracker_defaults(struct sonar_tracker_config *cfg)
{
    memset(cfg, 0, sizeof(*cfg));
    cfg->accel_mps2 = 0.05f;
    cfg->manoeuvre_mps2 = 0.5f;
    cfg->meas_m = 0.15f;
    cfg->speed0_mps = 1.0f;
    cfg->max_speed_mps = 2.5f;
    cfg->gate = 9.21f;
    cfg->confirm_m = 2;
    cfg->confirm_n = 3;
    cfg->max_misses = 2;
    cfg->max_dt_s = 120.0f;
    cfg->imm = 1;
    cfg->defer = 1;
    cfg->existence = 0;
    cfg->walls = 1;
}

const char *sonar_tracker_config_check(const struct sonar_tracker_config *c)
{
    if (!(c->accel_mps2 >= 0.001f && c->accel_mps2 <= (float)SONAR_TRK_ACCEL_MAX))
        return "accel_mps2: 0.001.." SONAR_STR(SONAR_TRK_ACCEL_MAX) " m/s^2";
    if (!(c->manoeuvre_mps2 >= 0.0f && c->manoeuvre_mps2 <= (float)SONAR_TRK_ACCEL_MAX))
        return "manoeuvre_mps2: 0.." SONAR_STR(SONAR_TRK_ACCEL_MAX) " m/s^2";
    if (!(c->meas_m >= 0.01f && c->meas_m <= (float)SONAR_TRK_MEAS_MAX))
        return "meas_m: 0.01.." SONAR_STR(SONAR_TRK_MEAS_MAX) " metres";
    if (!(c->speed0_mps >= 0.01f && c->speed0_mps <= (float)SONAR_TRK_SPEED_MAX))
        return "speed0_mps: 0.01.." SONAR_STR(SONAR_TRK_SPEED_MAX) " m/s";
    if (!(c->max_speed_mps == 0.0f || (c->max_speed_mps >= 0.1f && c->max_speed_mps <= (float)SONAR_TRK_SPEED_MAX)))
        return "max_speed_mps: 0 (off) or 0.1.." SONAR_STR(SONAR_TRK_SPEED_MAX) " m/s";
    if (!(c->gate >= 1.0f && c->gate <= (float)SONAR_TRK_GATE_MAX))
        return "gate: 1.." SONAR_STR(SONAR_TRK_GATE_MAX) " (squared Mahalanobis distance)";
    if (c->confirm_n < 1 || c->confirm_n > SONAR_TRK_WINDOW_MAX)
        return "confirm_n: 1.." SONAR_STR(SONAR_TRK_WINDOW_MAX) " sweeps";
    if (c->confirm_m < 1 || c->confirm_m > c->confirm_n)
        return "confirm_m: 1..confirm_n hits";
    if (c->max_misses < 1 || c->max_misses > 127)
        return "max_misses: 1..127 sweeps";
    if (!(c->max_dt_s >= 1.0f && c->max_dt_s <= (float)SONAR_TRK_MAX_DT_MAX))
        return "max_dt_s: 1.." SONAR_STR(SONAR_TRK_MAX_DT_MAX) " seconds";
    if (c->imm > 1)
        return "imm: 0 (near constant velocity alone) or 1 (three models)";
    if (c->defer > 1)
        return "defer: 0 (each sweep final) or 1 (the next look decides)";
    if (c->existence > 1)
        return "existence: 0 (hit counts) or 1 (probability of existence)";
    if (c->walls > 1)
        return "walls: 0 (never turned) or 1 (turned at the site's walls)";
    return NULL;
}
