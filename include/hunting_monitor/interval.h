/*
 * hunting_monitor - the Hopf interval and the boundaries a level is decided on (issue #28: the margin hands the alarm
 * its intervals, the alarm only decides levels).
 *
 * At each update with data: which of the margin's estimates count (the evidence rules, stated in alarm.h, each flag
 * held against its chatter), the conicity in use and the Hopf interval [hopf_low, hopf_high] they and the prior give,
 * and the boundary table's values at the current speed:
 *  - the prior: conicity_fallback (0: the vehicle's own lambda(0)) within [conicity_prior_low, conicity_prior_high]
 *    (both 0: the fallback -+ HM_ALARM_PRIOR_HALFWIDTH), its Hopf speeds the closed form's (a bogie's or car's model:
 *    the model's critical speeds) at the range's ends, resolved once for the vehicle (a range that does not hold the
 *    fallback is refused);
 *  - the table (borrowed) at the conicity in use and the speed: the lowest speed with a cycle, the unstable cycle
 *    bounding the stable origin's basin (the edge) and the stable cycle beyond it; outside the table's conicities the
 *    widened lookup (hm_table_lookup_widened, said by conicity_outside_table), where that has no Hopf speed the
 *    clamped one with the closed-form Hopf speed; with a model its Hopf curve (exact to HM_MODE_MODEL_CURVE_ERR_KMH)
 *    in place of the table's interpolation. Where the interval is the prior's, it is widened to hold the table's value
 *    at the conicity in use with its error. Lookups are cached while the conicity and the speed are unchanged;
 *  - the edge the amplitude rules use: at the conicity in use where the origin is stable there; where it is not but
 *    the speed is still inside the Hopf interval, at the interval's optimistic end (the conicity whose Hopf speed is
 *    hopf_high); else none.
 * The accelerometer's place decides whether the model-based interval can count: on an axle box, or anywhere with a
 * bogie's or car's model that holds the sensor's point (hm_interval_set_measurement_point, hm_interval_set_model).
 * Nothing here decides a level: alarm.h's hm_alarm_update takes the result.
 */
#ifndef HUNTING_MONITOR_INTERVAL_H
#define HUNTING_MONITOR_INTERVAL_H

#include <stddef.h>

#include "hunting_monitor/estimator.h"
#include "hunting_monitor/margin.h"
#include "hunting_monitor/mode_model.h"
#include "hunting_monitor/status.h"
#include "hunting_monitor/tables.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The settings the interval is weighed by: the alarm's section of the settings (alarm.h, hm_alarm_interval_config). */
typedef struct {
  int use_conicity_estimate;
  double conicity_max_se;     /* the estimate is used alone up to this standard error */
  double conicity_fallback;   /* the prior's point; 0: the vehicle's own lambda(0) */
  double conicity_prior_low;  /* the range the wheels may have worn to; both 0: the fallback -+ */
  double conicity_prior_high; /* HM_ALARM_PRIOR_HALFWIDTH (alarm.h) */
} hm_interval_config;

/* One update's interval. */
typedef struct {
  double conicity;                  /* in use */
  double conicity_se;               /* its standard error (0 for the prior's) */
  int conicity_from_estimate;       /* the identified conicity alone (else the prior, or the more cautious of both) */
  int conicity_from_prior;          /* the prior's range set the interval */
  int model_interval_used;          /* the model-based interval entered (alone or with the prior) */
  int model_mismatch;               /* the margin's model_mismatch, held against its chatter */
  int hopf_free_used;               /* the model-free interval's lower end entered (held) */
  int outside_prior;                /* an identified conicity outside the prior's range by more than its error */
  int narrow_peak_ambiguous;        /* a window of the last HM_ALARM_NARROW_HOLD_S had an ambiguous narrow peak */
  int conicity_outside_table;       /* +1 / -1: the conicity in use above / below the table's range (widened) */
  hm_table_lookup_result boundaries;/* at the conicity in use and the speed */
  double hopf_low_kmh, hopf_high_kmh; /* the interval */
  double edge_used_m;               /* the edge the amplitude rules use (0: none) */
  double interval_z;                /* the identified interval's half-widths in standard errors (1 if unknown) */
  int estimate_with_prior;          /* an estimate counts but not alone: its own WARN threshold (alarm.h) */
  double estimate_hopf_kmh, estimate_low_kmh; /* then its point and lower end (the model-free one where it counts) */
  double prior_hopf_low_kmh;        /* the prior's Hopf interval's lower end */
} hm_hopf_interval;

/* What the weighing remembers across a restart (state.h): whether the estimate was used alone, its standard error
 * within its limit, and whether it had stopped being used alone (each 0 or 1). */
typedef struct {
  int precise, se_ok, precise_lost;
} hm_interval_snapshot;

typedef struct hm_interval_s *hm_interval;

/* HM_EDOMAIN with "field: reason" in why: use_conicity_estimate 0 or 1, conicity_max_se in (0, 1], the conicities
 * in [0, 10], the prior's high end above its low end (or both 0). */
hm_status hm_interval_config_validate(const hm_interval_config *cfg, char *why, size_t why_len);
/* HM_EDOMAIN with the reason in why for invalid settings or a prior that does not hold the fallback once resolved for
 * the vehicle; the table is borrowed and must outlive the interval. *out untouched on failure. */
hm_status hm_interval_create(const hm_interval_config *cfg, const hm_vehicle *veh, const hm_table table,
                             hm_interval *out, char *why, size_t why_len);
void hm_interval_destroy(hm_interval iv);
/* New settings (validated as at create; nothing changes on failure). */
hm_status hm_interval_set_config(hm_interval iv, const hm_interval_config *cfg, const hm_vehicle *veh, char *why,
                                 size_t why_len);
/* A new table (borrowed), the cached lookups dropped. */
void hm_interval_set_table(hm_interval iv, const hm_table table);
/* A bogie's or car's model (borrowed; NULL: the wheelset's closed forms): the prior's Hopf speeds and the Hopf curve
 * become the model's. */
hm_status hm_interval_set_model(hm_interval iv, hm_mode_model model);
void hm_interval_set_measurement_point(hm_interval iv, hm_measurement_point point);
/* The prior's range as resolved for the vehicle (conicities). */
void hm_interval_prior(const hm_interval iv, double *low, double *high);
/* The time line restarted: the flags held against chatter and the cached lookups start again. */
void hm_interval_restart(hm_interval iv);
/* The time line moved by delta_s: the flags' times move with it. */
void hm_interval_shift_time(hm_interval iv, double delta_s);
/* The interval at speed_kmh from the margin's estimate g (NULL: the prior alone) at now_s; the table's status on
 * failure (*out untouched). */
hm_status hm_interval_update(hm_interval iv, double speed_kmh, const hm_margin_estimate *g, double now_s,
                             hm_hopf_interval *out);
void hm_interval_take_snapshot(const hm_interval iv, hm_interval_snapshot *out);
/* Each field 0 or 1 (HM_EDOMAIN, "interval: field: 0 or 1" in why). */
hm_status hm_interval_snapshot_validate(const hm_interval_snapshot *snap, char *why, size_t why_len);
/* The flags restarted, then snap's memory (validated first: iv untouched on failure). */
hm_status hm_interval_restore(hm_interval iv, const hm_interval_snapshot *snap, char *why, size_t why_len);

#ifdef __cplusplus
}
#endif

#endif
