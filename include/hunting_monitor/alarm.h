/*
 * hunting_monitor - safety margins and alarm levels from the estimator's output and the boundary tables.
 *
 * At the conicity in use (the estimate when valid and confident enough, else the configured one) the table
 * gives the Hopf speed, the lowest speed with a cycle, the unstable cycle bounding the basin of the stable origin
 * (the edge) and the stable cycle beyond it. The level:
 *   NO_DATA  acceleration or speed stale or missing (immediately; margins are then not presented as current)
 *   ALARM    a standard criterion met (sliding r.m.s., consecutive peaks), or the speed at or above the Hopf
 *            speed, or the displacement amplitude at or beyond the edge
 *   WARN     amplitude above warn_amplitude_fraction of the edge, or speed within warn_speed_margin_kmh of Hopf
 *   WATCH    speed inside the bistable band [lowest cycle speed, Hopf speed)
 *   OK       otherwise
 * Thresholds of the current (or a higher) level are relaxed by the hysteresis (hysteresis_kmh on speeds,
 * hysteresis_amplitude_fraction of the edge on amplitudes), a higher level is taken at once, and a lower one only
 * after the conditions for it have held for min_hold_s: no chatter. Every change carries a reason code.
 */
#ifndef HUNTING_MONITOR_ALARM_H
#define HUNTING_MONITOR_ALARM_H

#include <stddef.h>

#include "hunting_monitor/estimator.h"
#include "hunting_monitor/status.h"
#include "hunting_monitor/tables.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
  HM_LEVEL_NO_DATA = 0,
  HM_LEVEL_OK = 1,
  HM_LEVEL_WATCH = 2,
  HM_LEVEL_WARN = 3,
  HM_LEVEL_ALARM = 4
} hm_level;

typedef enum {
  HM_REASON_STARTUP = 0,            /* no evaluation yet */
  HM_REASON_NO_ACCEL = 1,           /* NO_DATA: acceleration stale or missing */
  HM_REASON_NO_SPEED = 2,           /* NO_DATA: speed stale or missing */
  HM_REASON_BELOW_LOWEST_CYCLE = 3, /* OK: no limit cycle exists at this speed */
  HM_REASON_BISTABLE_BAND = 4,      /* WATCH: cycles exist; a large disturbance could start hunting */
  HM_REASON_NEAR_HOPF = 5,          /* WARN: within the margin of the linear critical speed */
  HM_REASON_AMPLITUDE_NEAR_EDGE = 6,/* WARN: amplitude approaching the unstable cycle */
  HM_REASON_ABOVE_HOPF = 7,         /* ALARM: the origin is unstable */
  HM_REASON_AMPLITUDE_BEYOND_EDGE = 8, /* ALARM: amplitude at or beyond the unstable cycle */
  HM_REASON_RMS_CRITERION = 9,      /* ALARM: sliding r.m.s. above its limit */
  HM_REASON_PEAKS_CRITERION = 10    /* ALARM: consecutive peaks above their limit */
} hm_reason;

const char *hm_level_name(hm_level level);   /* "NO_DATA", "OK", ... */
const char *hm_reason_text(hm_reason reason); /* a short English sentence */

typedef struct {
  double warn_amplitude_fraction;       /* WARN above this fraction of the edge amplitude */
  double warn_speed_margin_kmh;         /* WARN within this of the Hopf speed */
  double hysteresis_kmh;
  double hysteresis_amplitude_fraction;
  double min_hold_s;                    /* a lower level needs its conditions this long */
  int use_conicity_estimate;
  double conicity_min_confidence;       /* the estimate is used from this confidence on, until it falls below half */
  double conicity_fallback;             /* lambda(0) used otherwise */
} hm_alarm_config;

/* Defaults: 0.5, 10 km/h, 3 km/h, 0.1, 3 s, estimate on at confidence 0.5, fallback 0.1358. */
void hm_alarm_config_default(hm_alarm_config *cfg);
hm_status hm_alarm_config_validate(const hm_alarm_config *cfg, char *why, size_t why_len);

typedef struct {
  hm_level level;
  hm_reason reason;
  double level_since_s;
  int changed;                      /* the level changed in this update */
  double conicity;                  /* in use */
  int conicity_from_estimate;
  int boundaries_valid;             /* 0 with NO_DATA: nothing below is current */
  hm_table_lookup_result boundaries;
  double margin_hopf_kmh;           /* Hopf speed - speed */
  double margin_lowest_cycle_kmh;   /* lowest cycle speed - speed */
  double amplitude_m;               /* measured displacement amplitude used */
  double amplitude_margin_m;        /* edge - amplitude (0 if no edge) */
} hm_assessment;

typedef struct hm_alarm_s *hm_alarm;

/* The table is borrowed and must outlive the alarm. NULL on bad arguments or out of memory. */
hm_alarm hm_alarm_create(const hm_alarm_config *cfg, const hm_table table);
void hm_alarm_destroy(hm_alarm alarm);

/* Evaluate at time now_s; out always filled (never NaN). HM_EINVAL for NULL arguments or a non-finite now. */
hm_status hm_alarm_update(hm_alarm alarm, const hm_estimate *est, double now_s, hm_assessment *out);

#ifdef __cplusplus
}
#endif

#endif
