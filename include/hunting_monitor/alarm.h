/*
 * hunting_monitor - safety margins and alarm levels from the estimator, the hunting-mode margin and the boundary
 * tables (docs/MODEL.md sections 4-7, issue #9).
 *
 * The conicity in use is the margin's model-based estimate (margin.h) when there is one with a standard error of at
 * most conicity_max_se, else conicity_fallback (0: the vehicle's own lambda(0)). The Hopf speed then has an
 * interval [hopf_low, hopf_high]: the estimate's (its conicity -+ 2 standard errors), or the table's stated error
 * around the fallback's. The table gives, at the conicity in use and the current speed, the lowest speed with a
 * cycle, the unstable cycle bounding the basin of the stable origin (the edge) and the stable cycle beyond it.
 * Where the origin is unstable at the conicity in use but the speed is still inside the Hopf interval, the edge
 * is taken at the interval's optimistic end (the conicity whose Hopf speed is hopf_high): the amplitude decides.
 *
 * The levels, and what each asks of the driver:
 *   NO_DATA  acceleration or speed stale or missing, or a sample rate the filters cannot use: the monitor cannot
 *            judge. Margins are not presented as current. Drive by the line's rules; report the fault.
 *   ALARM    hunting or its onset: a standard criterion met (sliding r.m.s., consecutive peaks, with the limits of
 *            the measurement point), the speed above the Hopf interval (the origin is unstable), or the displacement
 *            amplitude at or beyond the edge. Reduce speed now, below the lower end of the Hopf interval.
 *   WARN     close to the boundary: the speed inside the Hopf interval or within warn_speed_margin_kmh below it, or
 *            the amplitude above warn_amplitude_fraction of the edge. Do not accelerate; reduce speed by the margin.
 *   WATCH    the speed within watch_speed_margin_kmh of the Hopf interval, or the vehicle not behaving like its
 *            model (the model-based and model-free Hopf speeds disagree), or the sensor at another rate than
 *            configured. No action; have the wheels' conicity or the sensor checked at the next stop.
 *   OK       normal running. The bistable band (a large disturbance could start flange-contact hunting above the
 *            lowest cycle speed, docs/MODEL.md section 7) is stated in the status fields, not as a level: on good track
 *            at service speed it is permanent and a level that never changes tells a driver nothing.
 * Thresholds of the current (or a higher) level are relaxed by the hysteresis (hysteresis_kmh on speeds,
 * hysteresis_amplitude_fraction of the edge on amplitudes), a higher level is taken at once, and a lower one only
 * after the conditions for it have held for min_hold_s: no chatter. Every change carries a reason code.
 */
#ifndef HUNTING_MONITOR_ALARM_H
#define HUNTING_MONITOR_ALARM_H

#include <stddef.h>

#include "hunting_monitor/estimator.h"
#include "hunting_monitor/margin.h"
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
  HM_REASON_NORMAL = 4,             /* OK: normal running (cycles may exist: the bistable band, in the fields) */
  HM_REASON_NEAR_HOPF = 5,          /* WARN: inside or just below the Hopf interval */
  HM_REASON_AMPLITUDE_NEAR_EDGE = 6,/* WARN: amplitude approaching the unstable cycle */
  HM_REASON_ABOVE_HOPF = 7,         /* ALARM: above the Hopf interval: the origin is unstable */
  HM_REASON_AMPLITUDE_BEYOND_EDGE = 8, /* ALARM: amplitude at or beyond the unstable cycle */
  HM_REASON_RMS_CRITERION = 9,      /* ALARM: sliding r.m.s. above its limit */
  HM_REASON_PEAKS_CRITERION = 10,   /* ALARM: consecutive peaks above their limit */
  HM_REASON_APPROACHING_HOPF = 11,  /* WATCH: within watch_speed_margin_kmh of the Hopf interval */
  HM_REASON_MODEL_MISMATCH = 12,    /* WATCH: model-based and model-free Hopf speeds disagree */
  HM_REASON_RATE_MISMATCH = 13,     /* WATCH: the sensor delivers another rate than configured */
  HM_REASON_BAD_SAMPLE_RATE = 14    /* NO_DATA: a sample rate the filters cannot be designed for */
} hm_reason;

const char *hm_level_name(hm_level level);   /* "NO_DATA", "OK", ... */
const char *hm_reason_text(hm_reason reason); /* a short English sentence */

typedef struct {
  double warn_amplitude_fraction;       /* WARN above this fraction of the edge amplitude */
  double warn_speed_margin_kmh;         /* WARN within this below the Hopf interval */
  double watch_speed_margin_kmh;        /* WATCH within this below the Hopf interval (>= the WARN margin) */
  double hysteresis_kmh;
  double hysteresis_amplitude_fraction;
  double min_hold_s;                    /* a lower level needs its conditions this long */
  int use_conicity_estimate;
  double conicity_max_se;               /* the estimate is used when its standard error is at most this */
  double conicity_fallback;             /* lambda(0) used otherwise; 0: the vehicle's own lambda(0) */
} hm_alarm_config;

/* Defaults: 0.5, 10 km/h, 30 km/h, 3 km/h, 0.1, 3 s, estimate used up to a standard error of 0.01, fallback 0
 * (the vehicle's). */
void hm_alarm_config_default(hm_alarm_config *cfg);
hm_status hm_alarm_config_validate(const hm_alarm_config *cfg, char *why, size_t why_len);

typedef struct {
  hm_level level;
  hm_reason reason;
  double level_since_s;
  int changed;                      /* the level changed in this update */
  double conicity;                  /* in use */
  double conicity_se;               /* its standard error (0 for the fallback) */
  int conicity_from_estimate;
  int boundaries_valid;             /* 0 with NO_DATA: nothing below is current */
  hm_table_lookup_result boundaries;/* at the conicity in use and the current speed */
  double hopf_low_kmh, hopf_high_kmh; /* the Hopf interval the level uses */
  double edge_used_m;               /* the edge amplitude the amplitude rules use (0: none) */
  double margin_hopf_kmh;           /* Hopf speed - speed */
  double margin_lowest_cycle_kmh;   /* lowest cycle speed - speed (negative: inside the bistable band) */
  double amplitude_m;               /* measured displacement amplitude used */
  double amplitude_margin_m;        /* edge - amplitude (0 if no edge) */
} hm_assessment;

typedef struct hm_alarm_s *hm_alarm;

/* The table is borrowed and must outlive the alarm; the fallback conicity 0 becomes veh's lambda(0). HM_EDOMAIN
 * (reason in why) for a bad configuration; *out untouched on failure. */
hm_status hm_alarm_create(const hm_alarm_config *cfg, const hm_vehicle *veh, const hm_table table, hm_alarm *out,
                          char *why, size_t why_len);
void hm_alarm_destroy(hm_alarm alarm);
/* Back to NO_DATA / starting (the stream was restarted). */
void hm_alarm_reset(hm_alarm alarm);
/* New settings from the next update on, the level and its hold kept (validated as at create: HM_EDOMAIN with the
 * reason in why, and nothing changes); the fallback conicity 0 becomes veh's lambda(0). */
hm_status hm_alarm_set_config(hm_alarm alarm, const hm_alarm_config *cfg, const hm_vehicle *veh, char *why,
                              size_t why_len);
/* Look boundaries up in this table from the next update on (borrowed, as at create; the level is kept). */
void hm_alarm_set_table(hm_alarm alarm, const hm_table table);

/* Evaluate at time now_s with the estimator's output and the margin's (margin may be NULL: no estimate).
 * HM_EINVAL for NULL arguments or a non-finite now; the table lookup's status if it fails. The alarm's state and
 * *out are untouched on failure. */
hm_status hm_alarm_update(hm_alarm alarm, const hm_estimate *est, const hm_margin_estimate *margin, double now_s,
                          hm_assessment *out);

#ifdef __cplusplus
}
#endif

#endif
