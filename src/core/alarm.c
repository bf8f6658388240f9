/* Margins and alarm levels with hysteresis and hold time (see alarm.h). */
#include "hunting_monitor/alarm.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct hm_alarm_s {
  hm_alarm_config cfg;
  hm_table table;
  hm_level level;
  hm_reason reason;
  double since;
  int lower_pending;      /* the conditions for a lower level hold since lower_since */
  double lower_since;
  int using_estimate;     /* the conicity estimate is in use (entered at the confidence threshold, left below half) */
  int have_lookup;        /* the last table lookup, reused while conicity and speed are unchanged */
  double lookup_conicity, lookup_speed;
  hm_table_lookup_result lookup;
};

const char *hm_level_name(hm_level l) {
  static const char *const names[] = {"NO_DATA", "OK", "WATCH", "WARN", "ALARM"};
  return (unsigned)l <= HM_LEVEL_ALARM ? names[l] : "?";
}

const char *hm_reason_text(hm_reason r) {
  switch (r) {
    case HM_REASON_STARTUP: return "starting";
    case HM_REASON_NO_ACCEL: return "no current lateral acceleration";
    case HM_REASON_NO_SPEED: return "no current speed";
    case HM_REASON_BELOW_LOWEST_CYCLE: return "below the lowest speed with a limit cycle";
    case HM_REASON_BISTABLE_BAND: return "in the bistable band: a large disturbance can start hunting";
    case HM_REASON_NEAR_HOPF: return "near the linear critical (Hopf) speed";
    case HM_REASON_AMPLITUDE_NEAR_EDGE: return "oscillation approaching the unstable cycle";
    case HM_REASON_ABOVE_HOPF: return "at or above the linear critical (Hopf) speed";
    case HM_REASON_AMPLITUDE_BEYOND_EDGE: return "oscillation at or beyond the unstable cycle";
    case HM_REASON_RMS_CRITERION: return "sliding r.m.s. criterion exceeded";
    case HM_REASON_PEAKS_CRITERION: return "consecutive peaks criterion exceeded";
  }
  return "?";
}

void hm_alarm_config_default(hm_alarm_config *c) {
  c->warn_amplitude_fraction = 0.5;
  c->warn_speed_margin_kmh = 10.0;
  c->hysteresis_kmh = 3.0;
  c->hysteresis_amplitude_fraction = 0.1;
  c->min_hold_s = 3.0;
  c->use_conicity_estimate = 1;
  c->conicity_min_confidence = 0.5;
  c->conicity_fallback = 0.1358;
}

hm_status hm_alarm_config_validate(const hm_alarm_config *c, char *why, size_t len) {
  const char *field = NULL;
  double got = 0.0;
  if (!c) return HM_EINVAL;
  if (!(c->warn_amplitude_fraction > 0.0 && c->warn_amplitude_fraction < 1.0))
    field = "warn_amplitude_fraction", got = c->warn_amplitude_fraction;
  else if (!(c->warn_speed_margin_kmh >= 0.0) || !isfinite(c->warn_speed_margin_kmh))
    field = "warn_speed_margin_kmh", got = c->warn_speed_margin_kmh;
  else if (!(c->hysteresis_kmh >= 0.0) || !isfinite(c->hysteresis_kmh))
    field = "hysteresis_kmh", got = c->hysteresis_kmh;
  else if (!(c->hysteresis_amplitude_fraction >= 0.0 && c->hysteresis_amplitude_fraction < c->warn_amplitude_fraction))
    field = "hysteresis_amplitude_fraction", got = c->hysteresis_amplitude_fraction;
  else if (!(c->min_hold_s >= 0.0) || !isfinite(c->min_hold_s))
    field = "min_hold_s", got = c->min_hold_s;
  else if (!(c->conicity_min_confidence >= 0.0 && c->conicity_min_confidence <= 1.0))
    field = "conicity_min_confidence", got = c->conicity_min_confidence;
  else if (!(c->conicity_fallback > 0.0) || !isfinite(c->conicity_fallback))
    field = "conicity_fallback", got = c->conicity_fallback;
  if (!field) return HM_OK;
  if (why && len) snprintf(why, len, "%s: out of range (got %g)", field, got);
  return HM_EDOMAIN;
}

hm_alarm hm_alarm_create(const hm_alarm_config *cfg, const hm_table table) {
  if (!cfg || !table || hm_alarm_config_validate(cfg, NULL, 0) != HM_OK) return NULL;
  hm_alarm a = calloc(1, sizeof *a);
  if (!a) return NULL;
  a->cfg = *cfg;
  a->table = table;
  a->level = HM_LEVEL_NO_DATA;
  a->reason = HM_REASON_STARTUP;
  return a;
}

void hm_alarm_destroy(hm_alarm a) { free(a); }

/* The level the conditions call for, with the thresholds of levels at or below `current` relaxed. */
static hm_level raw_level(const hm_alarm a, const hm_estimate *e, const hm_assessment *s, hm_level current,
                          hm_reason *reason) {
  const hm_alarm_config *c = &a->cfg;
  const hm_table_lookup_result *b = &s->boundaries;
  const double v = e->speed_kmh, amp = s->amplitude_m;
  const double hv_alarm = current >= HM_LEVEL_ALARM ? c->hysteresis_kmh : 0.0;
  const double hv_warn = current >= HM_LEVEL_WARN ? c->hysteresis_kmh : 0.0;
  const double hv_watch = current >= HM_LEVEL_WATCH ? c->hysteresis_kmh : 0.0;
  const double ha_alarm = current >= HM_LEVEL_ALARM ? c->hysteresis_amplitude_fraction : 0.0;
  const double ha_warn = current >= HM_LEVEL_WARN ? c->hysteresis_amplitude_fraction : 0.0;
  const int edge = b->has_edge && b->edge_amp_m > 0.0;
  if (e->rms_exceeded) return *reason = HM_REASON_RMS_CRITERION, HM_LEVEL_ALARM;
  if (e->peaks_exceeded) return *reason = HM_REASON_PEAKS_CRITERION, HM_LEVEL_ALARM;
  if (v >= b->hopf_speed_kmh - hv_alarm) return *reason = HM_REASON_ABOVE_HOPF, HM_LEVEL_ALARM;
  if (edge && amp >= b->edge_amp_m * (1.0 - ha_alarm))
    return *reason = HM_REASON_AMPLITUDE_BEYOND_EDGE, HM_LEVEL_ALARM;
  if (edge && amp >= b->edge_amp_m * (c->warn_amplitude_fraction - ha_warn))
    return *reason = HM_REASON_AMPLITUDE_NEAR_EDGE, HM_LEVEL_WARN;
  if (v >= b->hopf_speed_kmh - c->warn_speed_margin_kmh - hv_warn) return *reason = HM_REASON_NEAR_HOPF, HM_LEVEL_WARN;
  if (v >= b->lowest_cycle_speed_kmh - hv_watch) return *reason = HM_REASON_BISTABLE_BAND, HM_LEVEL_WATCH;
  return *reason = HM_REASON_BELOW_LOWEST_CYCLE, HM_LEVEL_OK;
}

hm_status hm_alarm_update(hm_alarm a, const hm_estimate *e, double now, hm_assessment *out) {
  if (!a || !e || !out || !isfinite(now)) return HM_EINVAL;
  const hm_alarm_config *c = &a->cfg;
  hm_assessment s;
  memset(&s, 0, sizeof s);
  hm_reason reason;
  hm_level target;
  if (!e->accel_valid || !e->speed_valid) {
    target = HM_LEVEL_NO_DATA;
    reason = !e->accel_valid ? HM_REASON_NO_ACCEL : HM_REASON_NO_SPEED;
  } else {
    /* switch between the estimate and the fallback with hysteresis on the confidence, so that the boundaries
     * do not jump back and forth with it */
    const double need = a->using_estimate ? 0.5 * c->conicity_min_confidence : c->conicity_min_confidence;
    a->using_estimate = c->use_conicity_estimate && e->conicity_valid && e->conicity_confidence >= need;
    s.conicity_from_estimate = a->using_estimate;
    s.conicity = s.conicity_from_estimate ? e->conicity : c->conicity_fallback;
    if (!a->have_lookup || a->lookup_conicity != s.conicity || a->lookup_speed != e->speed_kmh) {
      if (hm_table_lookup(a->table, s.conicity, e->speed_kmh, &a->lookup) != HM_OK) return HM_EINVAL;
      a->have_lookup = 1;
      a->lookup_conicity = s.conicity;
      a->lookup_speed = e->speed_kmh;
    }
    s.boundaries = a->lookup;
    s.boundaries_valid = 1;
    s.margin_hopf_kmh = s.boundaries.hopf_speed_kmh - e->speed_kmh;
    s.margin_lowest_cycle_kmh = s.boundaries.lowest_cycle_speed_kmh - e->speed_kmh;
    s.amplitude_m = e->oscillation_valid ? e->amplitude_displacement_m : 0.0;
    s.amplitude_margin_m = s.boundaries.has_edge ? s.boundaries.edge_amp_m - s.amplitude_m : 0.0;
    target = raw_level(a, e, &s, a->level, &reason);
  }
  s.changed = 0;
  if (target >= a->level || target == HM_LEVEL_NO_DATA || a->level == HM_LEVEL_NO_DATA) {
    a->lower_pending = 0;
    if (target != a->level) {
      a->level = target;
      a->since = now;
      s.changed = 1;
    }
    a->reason = reason; /* the level's current cause */
  } else {
    /* a lower level is taken only after its conditions held for min_hold_s */
    if (!a->lower_pending) {
      a->lower_pending = 1;
      a->lower_since = now;
    }
    if (now - a->lower_since >= c->min_hold_s) {
      a->level = target;
      a->reason = reason;
      a->since = now;
      a->lower_pending = 0;
      s.changed = 1;
    }
  }
  s.level = a->level;
  s.reason = a->reason;
  s.level_since_s = a->since;
  *out = s;
  return HM_OK;
}
