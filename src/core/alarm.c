/* Margins and alarm levels with hysteresis and hold time (see alarm.h). */
#include "hunting_monitor/alarm.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hunting_monitor/linear.h"

struct hm_alarm_s {
  hm_alarm_config cfg;            /* fallback and prior resolved for the vehicle */
  hm_vehicle veh;
  double prior_hopf_low_kmh, prior_hopf_high_kmh; /* closed-form Hopf speeds at the prior's high and low ends */
  hm_table table;
  hm_level level;
  hm_reason reason;
  double since;
  int lower_pending;      /* the conditions for a lower level hold since lower_since */
  double lower_since;
  int latched;            /* an oscillation ALARM held (alarm.h) */
  hm_reason latch_reason;
  int calm;               /* the release conditions hold since calm_since */
  double calm_since;
  double displacement_limit_m; /* the displacement criterion's limit (0: off) */
  hm_measurement_point point; /* where the accelerometer is */
  double hunted_at_kmh;   /* the lowest speed at which a criterion was met, during the latch and for memory_s after
                             it (INFINITY: none) */
  double hunted_t_s;      /* when (the latest time it was met there or lower); NAN: on a time line that restarted,
                             its age counts from the next update */
  double memory_s;        /* how long a hunted-at speed bounds the interval (hm_alarm_set_memory) */
  int precise;            /* the estimate was used alone at the last update with data (its hysteresis) */
  double v_prev_kmh, t_prev_s, dvdt_kmh_s; /* the speed's trend: an exponential average of dv/dt over ~5 s */
  int have_trend;
  /* a sustained acceleration (alarm.h): the mean speed of the block being filled and of the last full blocks */
  double block_sum_kmh, block_sum_t_s, block_t0_s, block_last_s;
  unsigned block_n, n_blocks;
  double block_v_kmh[HM_ALARM_ACCEL_BLOCKS + 1], block_t_s[HM_ALARM_ACCEL_BLOCKS + 1]; /* oldest first */
  /* the last table lookups (at the conicity in use and at the interval's optimistic end), reused while their
   * conicity and the speed are unchanged */
  struct {
    int valid;
    double conicity, speed_kmh;
    hm_table_lookup_result r;
  } cache[2];
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
    case HM_REASON_NORMAL: return "normal running";
    case HM_REASON_NEAR_HOPF: return "near the linear critical (Hopf) speed";
    case HM_REASON_AMPLITUDE_NEAR_EDGE: return "oscillation approaching the unstable cycle";
    case HM_REASON_ABOVE_HOPF: return "above the linear critical (Hopf) speed";
    case HM_REASON_AMPLITUDE_BEYOND_EDGE: return "oscillation at or beyond the unstable cycle";
    case HM_REASON_RMS_CRITERION: return "sliding r.m.s. criterion exceeded";
    case HM_REASON_PEAKS_CRITERION: return "consecutive peaks criterion exceeded";
    case HM_REASON_APPROACHING_HOPF: return "approaching the linear critical (Hopf) speed";
    case HM_REASON_MODEL_MISMATCH: return "the vehicle does not behave like its model";
    case HM_REASON_RATE_MISMATCH: return "the sensor delivers another sample rate than configured";
    case HM_REASON_BAD_SAMPLE_RATE: return "acceleration at a sample rate the filters cannot use";
    case HM_REASON_DISPLACEMENT_CRITERION: return "displacement amplitude criterion exceeded";
    case HM_REASON_PARTLY_BLIND: return "partly blind: samples of the last 10 s lost";
    case HM_REASON_OUTSIDE_PRIOR: return "the identified conicity lies outside the prior's range";
    case HM_REASON_NARROW_PEAK: return "a narrow peak at the hunting frequency: a line, or the mode at its Hopf speed";
  }
  return "?";
}

void hm_alarm_config_default(hm_alarm_config *c) {
  c->warn_amplitude_fraction = 0.5;
  c->warn_speed_margin_kmh = 10.0;
  c->watch_speed_margin_kmh = 30.0;
  c->hysteresis_kmh = 3.0;
  c->hysteresis_amplitude_fraction = 0.1;
  c->min_hold_s = 3.0;
  c->use_conicity_estimate = 1;
  c->conicity_max_se = 0.01;
  c->conicity_fallback = 0.0;
  c->conicity_prior_low = 0.0;
  c->conicity_prior_high = 0.0;
  c->release_s = 10.0;
  c->release_amplitude_fraction = 0.5;
  c->blind_fraction = 0.2;
}

hm_status hm_alarm_config_validate(const hm_alarm_config *c, char *why, size_t len) {
  const char *field = NULL, *rule = NULL;
  double got = 0.0;
  if (!c) return HM_EINVAL;
  if (!(c->warn_amplitude_fraction > 0.0 && c->warn_amplitude_fraction < 1.0))
    field = "warn_amplitude_fraction", rule = "must be in (0, 1)", got = c->warn_amplitude_fraction;
  else if (!(c->warn_speed_margin_kmh >= 0.0 && c->warn_speed_margin_kmh <= 500.0))
    field = "warn_speed_margin_kmh", rule = "must be in [0, 500]", got = c->warn_speed_margin_kmh;
  else if (!(c->watch_speed_margin_kmh >= c->warn_speed_margin_kmh && c->watch_speed_margin_kmh <= 500.0))
    field = "watch_speed_margin_kmh", rule = "must be at least warn_speed_margin_kmh and at most 500",
    got = c->watch_speed_margin_kmh;
  else if (!(c->hysteresis_kmh >= 0.0 && c->hysteresis_kmh <= 100.0))
    field = "hysteresis_kmh", rule = "must be in [0, 100]", got = c->hysteresis_kmh;
  else if (!(c->hysteresis_amplitude_fraction >= 0.0 && c->hysteresis_amplitude_fraction < c->warn_amplitude_fraction))
    field = "hysteresis_amplitude_fraction", rule = "must be at least 0 and below warn_amplitude_fraction",
    got = c->hysteresis_amplitude_fraction;
  else if (!(c->min_hold_s >= 0.0 && c->min_hold_s <= 3600.0))
    field = "min_hold_s", rule = "must be in [0, 3600]", got = c->min_hold_s;
  else if (!(c->conicity_max_se > 0.0 && c->conicity_max_se <= 1.0))
    field = "conicity_max_se", rule = "must be in (0, 1]", got = c->conicity_max_se;
  else if (!(c->conicity_fallback >= 0.0 && c->conicity_fallback <= 10.0))
    field = "conicity_fallback", rule = "must be in [0, 10]", got = c->conicity_fallback;
  else if (!(c->conicity_prior_low >= 0.0 && c->conicity_prior_low <= 10.0))
    field = "conicity_prior_low", rule = "must be in [0, 10]", got = c->conicity_prior_low;
  else if (!(c->conicity_prior_high >= 0.0 && c->conicity_prior_high <= 10.0))
    field = "conicity_prior_high", rule = "must be in [0, 10]", got = c->conicity_prior_high;
  else if (!(c->blind_fraction > 0.0 && c->blind_fraction <= 1.0))
    field = "blind_fraction", rule = "must be in (0, 1]", got = c->blind_fraction;
  else if (!(c->release_s >= 0.0 && c->release_s <= 3600.0))
    field = "release_s", rule = "must be in [0, 3600]", got = c->release_s;
  else if (!(c->release_amplitude_fraction > 0.0 && c->release_amplitude_fraction <= 1.0))
    field = "release_amplitude_fraction", rule = "must be in (0, 1]", got = c->release_amplitude_fraction;
  else if ((c->conicity_prior_low == 0.0) != (c->conicity_prior_high == 0.0) ||
           (c->conicity_prior_high != 0.0 && !(c->conicity_prior_high > c->conicity_prior_low)))
    field = "conicity_prior_high", rule = "must be above conicity_prior_low (or both 0: the fallback -+ 0.03)",
    got = c->conicity_prior_high;
  if (!field) return HM_OK;
  if (why && len) snprintf(why, len, "%s: out of range: %s (got %g)", field, rule, got);
  return HM_EDOMAIN;
}

/* The configuration with the fallback and the prior resolved for the vehicle, and the prior's Hopf speeds; HM_EDOMAIN
 * (reason in why) for a prior that does not hold the fallback. */
static hm_status resolve(const hm_alarm_config *cfg, const hm_vehicle *veh, hm_alarm_config *out, double *hopf_low,
                         double *hopf_high, char *why, size_t len) {
  hm_status st = hm_alarm_config_validate(cfg, why, len);
  if (st != HM_OK) return st;
  hm_alarm_config c = *cfg;
  if (c.conicity_fallback == 0.0) hm_conicity_eval(&veh->conicity, 0.0, &c.conicity_fallback, NULL);
  if (c.conicity_prior_low == 0.0 && c.conicity_prior_high == 0.0) {
    c.conicity_prior_low = fmax(c.conicity_fallback - HM_ALARM_PRIOR_HALFWIDTH, 0.5 * c.conicity_fallback);
    c.conicity_prior_high = c.conicity_fallback + HM_ALARM_PRIOR_HALFWIDTH;
  }
  if (!(c.conicity_prior_low <= c.conicity_fallback && c.conicity_fallback <= c.conicity_prior_high)) {
    if (why && len)
      snprintf(why, len, "conicity_prior_low, conicity_prior_high: must hold the fallback conicity %g (got %g..%g)",
               c.conicity_fallback, c.conicity_prior_low, c.conicity_prior_high);
    return HM_EDOMAIN;
  }
  *out = c;
  *hopf_low = hm_linear_hopf_kmh(veh, c.conicity_prior_high);
  *hopf_high = hm_linear_hopf_kmh(veh, c.conicity_prior_low);
  return HM_OK;
}

hm_status hm_alarm_create(const hm_alarm_config *cfg, const hm_vehicle *veh, const hm_table table, hm_alarm *out,
                          char *why, size_t why_len) {
  if (!cfg || !veh || !table || !out) return HM_EINVAL;
  hm_alarm a = calloc(1, sizeof *a);
  if (!a) return HM_ENOMEM;
  const hm_status st = hm_alarm_set_config(a, cfg, veh, why, why_len);
  if (st != HM_OK) {
    free(a);
    return st;
  }
  a->table = table;
  a->hunted_at_kmh = INFINITY;
  a->memory_s = 900.0;
  a->level = HM_LEVEL_NO_DATA;
  a->reason = HM_REASON_STARTUP;
  *out = a;
  return HM_OK;
}

void hm_alarm_destroy(hm_alarm a) { free(a); }

void hm_alarm_reset(hm_alarm a) {
  if (!a) return;
  a->latched = 0;
  a->hunted_at_kmh = INFINITY;
  hm_alarm_restart(a);
  a->level = HM_LEVEL_NO_DATA;
  a->reason = HM_REASON_STARTUP;
}

void hm_alarm_restart(hm_alarm a) {
  if (!a) return;
  if (!a->latched) a->level = HM_LEVEL_NO_DATA, a->reason = HM_REASON_STARTUP;
  a->since = 0.0;
  a->lower_pending = 0;
  a->calm = 0;
  a->hunted_t_s = NAN; /* its age counts again from the next update */
  a->precise = 0;
  a->have_trend = 0;
  a->dvdt_kmh_s = 0.0;
  a->block_n = a->n_blocks = 0;
  a->cache[0].valid = a->cache[1].valid = 0;
}

void hm_alarm_shift_time(hm_alarm a, double delta_s) {
  if (!a || !isfinite(delta_s)) return;
  a->since += delta_s;
  a->lower_since += delta_s;
  a->calm_since += delta_s;
  a->t_prev_s += delta_s;
  a->hunted_t_s += delta_s;
  a->block_t0_s += delta_s;
  a->block_last_s += delta_s;
  for (unsigned k = 0; k < a->n_blocks; ++k) a->block_t_s[k] += delta_s;
}

void hm_alarm_set_memory(hm_alarm a, double memory_s) {
  if (a && isfinite(memory_s) && memory_s > 0.0) a->memory_s = memory_s;
}

void hm_alarm_set_measurement_point(hm_alarm a, hm_measurement_point point) {
  if (a && (point == HM_POINT_WHEELSET || point == HM_POINT_BOGIE_FRAME)) a->point = point;
}

void hm_alarm_prior(const hm_alarm a, double *lo, double *hi) {
  if (!a) return;
  if (lo) *lo = a->cfg.conicity_prior_low;
  if (hi) *hi = a->cfg.conicity_prior_high;
}

void hm_alarm_set_displacement_limit(hm_alarm a, double limit_m) {
  if (a && isfinite(limit_m) && limit_m >= 0.0) a->displacement_limit_m = limit_m;
}

/* An ALARM caused by the oscillation itself (latched), not by the speed alone. */
static int oscillation_reason(hm_reason r) {
  return r == HM_REASON_RMS_CRITERION || r == HM_REASON_PEAKS_CRITERION || r == HM_REASON_DISPLACEMENT_CRITERION ||
         r == HM_REASON_AMPLITUDE_BEYOND_EDGE;
}

/* The latch's release conditions: no criterion, the oscillation small, the speed below the Hopf interval by the
 * hysteresis (the ALARM level's thresholds are relaxed by it, as everywhere). */
static int calm_now(const hm_alarm a, const hm_estimate *e, const hm_assessment *s) {
  const double f = a->cfg.release_amplitude_fraction;
  const double limit = a->displacement_limit_m > 0.0 ? a->displacement_limit_m : s->edge_used_m;
  const int small = s->amplitude_m < f * (limit > 0.0 ? limit : HM_ESTIMATOR_WHEELSET_DISPLACEMENT_M);
  return !e->rms_exceeded && !e->peaks_exceeded && !e->displacement_exceeded && small &&
         e->speed_kmh < s->hopf_low_kmh - a->cfg.hysteresis_kmh;
}

hm_status hm_alarm_set_config(hm_alarm a, const hm_alarm_config *cfg, const hm_vehicle *veh, char *why,
                              size_t why_len) {
  if (!a || !cfg || !veh) return HM_EINVAL;
  hm_alarm_config c;
  double lo, hi;
  const hm_status st = resolve(cfg, veh, &c, &lo, &hi, why, why_len);
  if (st != HM_OK) return st;
  a->cfg = c;
  a->veh = *veh;
  a->prior_hopf_low_kmh = lo;
  a->prior_hopf_high_kmh = hi;
  a->cache[0].valid = a->cache[1].valid = 0; /* the conicity in use may change with the settings */
  return HM_OK;
}

void hm_alarm_set_table(hm_alarm a, const hm_table table) {
  if (!a || !table) return;
  a->table = table;
  a->cache[0].valid = a->cache[1].valid = 0; /* the cached lookups were the old table's */
}

/* The level the conditions call for, with the thresholds of levels at or below `current` relaxed. */
static hm_level raw_level(const hm_alarm a, const hm_estimate *e, const hm_margin_estimate *g, const hm_assessment *s,
                          hm_level current, hm_reason *reason) {
  const hm_alarm_config *c = &a->cfg;
  const double v = e->speed_kmh, amp = s->amplitude_m, edge = s->edge_used_m;
  const double hv_alarm = current >= HM_LEVEL_ALARM ? c->hysteresis_kmh : 0.0;
  const double hv_warn = current >= HM_LEVEL_WARN ? c->hysteresis_kmh : 0.0;
  const double hv_watch = current >= HM_LEVEL_WATCH ? c->hysteresis_kmh : 0.0;
  const double ha_alarm = current >= HM_LEVEL_ALARM ? c->hysteresis_amplitude_fraction : 0.0;
  const double ha_warn = current >= HM_LEVEL_WARN ? c->hysteresis_amplitude_fraction : 0.0;
  if (e->rms_exceeded) return *reason = HM_REASON_RMS_CRITERION, HM_LEVEL_ALARM;
  if (e->peaks_exceeded) return *reason = HM_REASON_PEAKS_CRITERION, HM_LEVEL_ALARM;
  if (e->displacement_exceeded) return *reason = HM_REASON_DISPLACEMENT_CRITERION, HM_LEVEL_ALARM;
  if (v > s->hopf_high_kmh - hv_alarm) return *reason = HM_REASON_ABOVE_HOPF, HM_LEVEL_ALARM;
  if (edge > 0.0 && amp >= edge * (1.0 - ha_alarm)) return *reason = HM_REASON_AMPLITUDE_BEYOND_EDGE, HM_LEVEL_ALARM;
  if (edge > 0.0 && amp >= edge * (c->warn_amplitude_fraction - ha_warn))
    return *reason = HM_REASON_AMPLITUDE_NEAR_EDGE, HM_LEVEL_WARN;
  const double v_ahead = v + s->anticipation_kmh; /* the speed thresholds anticipate a sustained acceleration */
  if (v_ahead >= s->warn_from_kmh - hv_warn) return *reason = HM_REASON_NEAR_HOPF, HM_LEVEL_WARN;
  if (v_ahead >= s->watch_from_kmh - hv_watch)
    return *reason = HM_REASON_APPROACHING_HOPF, HM_LEVEL_WATCH;
  if (g && g->model_mismatch) return *reason = HM_REASON_MODEL_MISMATCH, HM_LEVEL_WATCH;
  if (g && g->conicity_valid && g->outside_prior && c->use_conicity_estimate)
    return *reason = HM_REASON_OUTSIDE_PRIOR, HM_LEVEL_WATCH;
  if (s->narrow_peak_ambiguous) return *reason = HM_REASON_NARROW_PEAK, HM_LEVEL_WATCH;
  if (e->sample_rate_mismatch) return *reason = HM_REASON_RATE_MISMATCH, HM_LEVEL_WATCH;
  if (e->loss_fraction > c->blind_fraction) return *reason = HM_REASON_PARTLY_BLIND, HM_LEVEL_WATCH;
  if (v < s->boundaries.lowest_cycle_speed_kmh) return *reason = HM_REASON_BELOW_LOWEST_CYCLE, HM_LEVEL_OK;
  return *reason = HM_REASON_NORMAL, HM_LEVEL_OK;
}

/* The table's boundaries at (conicity, speed) through cache slot k; the Hopf speed is the closed form's where the
 * conicity lies outside the table (a clamped lookup's would belong to another conicity). */
static hm_status lookup(hm_alarm a, int k, double conicity, double speed_kmh, hm_table_lookup_result *out) {
  if (a->cache[k].valid && a->cache[k].conicity == conicity && a->cache[k].speed_kmh == speed_kmh) {
    *out = a->cache[k].r;
    return HM_OK;
  }
  hm_table_lookup_result r;
  const hm_status st = hm_table_lookup(a->table, conicity, speed_kmh, &r);
  if (st != HM_OK) return st;
  if (r.conicity != conicity) r.hopf_speed_kmh = hm_linear_hopf_kmh(&a->veh, conicity);
  a->cache[k].valid = 1;
  a->cache[k].conicity = conicity;
  a->cache[k].speed_kmh = speed_kmh;
  a->cache[k].r = r;
  *out = r;
  return HM_OK;
}

/* The block being filled joins the last ones (the oldest dropped beyond HM_ALARM_ACCEL_BLOCKS + 1). */
static void close_block(hm_alarm a) {
  if (a->n_blocks == HM_ALARM_ACCEL_BLOCKS + 1) {
    memmove(a->block_v_kmh, a->block_v_kmh + 1, HM_ALARM_ACCEL_BLOCKS * sizeof(double));
    memmove(a->block_t_s, a->block_t_s + 1, HM_ALARM_ACCEL_BLOCKS * sizeof(double));
    --a->n_blocks;
  }
  a->block_v_kmh[a->n_blocks] = a->block_sum_kmh / a->block_n;
  a->block_t_s[a->n_blocks] = a->block_t0_s + a->block_sum_t_s / a->block_n;
  ++a->n_blocks;
  a->block_n = 0;
}

/* The speed into the block being filled; a full block (HM_ALARM_ACCEL_BLOCK_S) joins the last ones. The sustained
 * acceleration [km/h/s]: the least of the slopes between consecutive block means over the last
 * HM_ALARM_ACCEL_BLOCKS of them, 0 unless all are positive, at most HM_ALARM_MAX_ACCEL_KMH_S (alarm.h). Updates
 * further apart than a block give a block each (the one in progress is closed first); a time step back or a silence
 * as long as the blocks' whole span starts again. */
static double sustained_acceleration(hm_alarm a, double now, double v_kmh) {
  const double block_s = HM_ALARM_ACCEL_BLOCK_S;
  if (a->block_n + a->n_blocks > 0 &&
      (now < a->block_last_s || now - a->block_last_s > HM_ALARM_ACCEL_BLOCKS * block_s))
    a->block_n = a->n_blocks = 0;
  if (a->block_n > 0 && now - a->block_t0_s >= block_s) close_block(a);
  a->block_last_s = now;
  if (a->block_n == 0) a->block_t0_s = now, a->block_sum_kmh = a->block_sum_t_s = 0.0;
  a->block_sum_kmh += v_kmh;
  a->block_sum_t_s += now - a->block_t0_s;
  ++a->block_n;
  if (a->n_blocks < HM_ALARM_ACCEL_BLOCKS + 1) return 0.0;
  double least = HM_ALARM_MAX_ACCEL_KMH_S;
  for (unsigned k = 0; k < HM_ALARM_ACCEL_BLOCKS; ++k) {
    const double dt = a->block_t_s[k + 1] - a->block_t_s[k];
    least = fmin(least, dt > 0.0 ? (a->block_v_kmh[k + 1] - a->block_v_kmh[k]) / dt : 0.0);
  }
  return fmax(least, 0.0);
}

/* WARN from an identified Hopf speed (alarm.h): the point less the larger of the margin and one standard error, the
 * lower half-width (point - low) being z of them. */
static double warn_below_point(double point_kmh, double low_kmh, double margin_kmh, double z) {
  return point_kmh - fmax(margin_kmh, fmin((point_kmh - low_kmh) / z, HM_ALARM_WARN_MAX_BELOW_KMH));
}

/* The conicity in use, the Hopf interval and the boundaries at the current speed; the table's status on failure. */
static hm_status assess(hm_alarm a, const hm_estimate *e, const hm_margin_estimate *g, hm_assessment *s) {
  const hm_alarm_config *c = &a->cfg;
  const int axle = a->point == HM_POINT_WHEELSET;
  const int have = c->use_conicity_estimate && g && g->conicity_valid && g->hopf_model_valid;
  /* the model-based interval counts from an axle-box sensor on a vehicle that behaves like its model (alarm.h) */
  const int usable_model = have && axle && !g->model_mismatch;
  const double max_se = a->precise ? HM_ALARM_SE_HYSTERESIS * c->conicity_max_se : c->conicity_max_se;
  const int unconfirmed_change = g && g->n_changes > 0 && g->windows_since_change < 2;
  /* an estimate enters alone when precise, inside the prior and not a change's first window; otherwise combined with
   * the prior (the more cautious): one precise but above the prior's range (its Hopf speed lower: worn beyond the
   * prior), or any with a lightly damped mode held (alarm.h) */
  const int precise = usable_model && g->conicity_se <= max_se && !g->outside_prior && !unconfirmed_change;
  const int cautious_precise = usable_model && g->conicity_se <= max_se && g->outside_prior > 0;
  const int usable = precise || cautious_precise || (usable_model && g->near_evidence);
  /* the prior's interval, and the uncertain estimate's where it is the more cautious */
  double lambda = c->conicity_fallback, lambda_opt = c->conicity_prior_low;
  double lo = a->prior_hopf_low_kmh, hi = a->prior_hopf_high_kmh;
  s->conicity_from_estimate = precise;
  s->conicity_from_prior = !precise;
  s->model_interval_used = usable;
  s->conicity_se = 0.0;
  if (precise) {
    lambda = g->conicity;
    lambda_opt = g->conicity_low;
    lo = g->hopf_model_low_kmh;
    hi = g->hopf_model_high_kmh;
    s->conicity_se = g->conicity_se;
  } else if (usable) {
    if (g->hopf_model_kmh < hm_linear_hopf_kmh(&a->veh, lambda)) lambda = g->conicity, s->conicity_se = g->conicity_se;
    lo = fmin(lo, g->hopf_model_low_kmh);
    if (g->hopf_model_high_kmh < hi) hi = g->hopf_model_high_kmh, lambda_opt = g->conicity_low;
  }
  /* the model-free interval's lower end counts when the model-based one does not (a mismatch, a sensor off the axle
   * box; then its upper end too: it is the only evidence of where the vehicle's Hopf speed lies, and on a bogie 40-60
   * km/h less stable than the model it gave WARN a median 20 s before 3 mm, 5 s without), and beside it when its
   * regression has residuals to check it (three windows or more) and a lightly damped mode is held: a zero crossing
   * extrapolated from decay rates of -5..-11 1/s alone is wide (on a ramp from 271 to 301 km/h, 322 [309, ...] for a
   * Hopf speed of 357) and its lower end is no evidence */
  const int free_alone = g && (g->model_mismatch || !axle);
  const int free_counts =
      g && g->hopf_free_valid && (free_alone || (g->n_windows >= HM_ALARM_FREE_MIN_WINDOWS && g->near_evidence));
  if (free_counts) {
    lo = fmin(lo, g->hopf_free_low_kmh);
    if (free_alone && g->hopf_free_high_kmh < hi) hi = g->hopf_free_high_kmh;
  }
  s->conicity = lambda;
  hm_table_lookup_result b, bo;
  hm_status st = lookup(a, 0, lambda, e->speed_kmh, &b);
  if (st != HM_OK) return st;
  if (!precise) { /* the table's value at the point is inside the interval it is shown with */
    lo = fmin(lo, b.hopf_speed_kmh - b.error_speed_kmh);
    hi = fmax(hi, b.hopf_speed_kmh + b.error_speed_kmh);
  }
  s->hopf_low_kmh = fmin(lo, b.hopf_speed_kmh);
  s->hopf_high_kmh = fmax(hi, b.hopf_speed_kmh);
  s->boundaries = b;
  /* the speed margins (alarm.h): added to a range's lower end; below an identified interval WATCH in quadrature with
   * its lower half-width h, WARN from the point less the larger of the margin and one standard error (h / z); an
   * estimate too uncertain to be used alone (the vehicle behaving like its model) gives its own WARN threshold so,
   * and the more cautious of it and the prior's range counts */
  const double h = precise ? b.hopf_speed_kmh - s->hopf_low_kmh : 0.0;
  const double from = precise ? b.hopf_speed_kmh : s->hopf_low_kmh;
  const double z = g && g->interval_z > 0.0 ? g->interval_z : 1.0;
  s->warn_from_kmh = warn_below_point(from, precise ? s->hopf_low_kmh : from, c->warn_speed_margin_kmh, z);
  if (usable && !precise) {
    const double lo_e = free_counts ? fmin(g->hopf_model_low_kmh, g->hopf_free_low_kmh) : g->hopf_model_low_kmh;
    s->warn_from_kmh = fmin(a->prior_hopf_low_kmh - c->warn_speed_margin_kmh,
                            warn_below_point(g->hopf_model_kmh, lo_e, c->warn_speed_margin_kmh, z));
  }
  s->watch_from_kmh = from - hypot(h, c->watch_speed_margin_kmh);
  /* what the WARN rule risks (alarm.h): the interval read as normal, its lower half-width interval_z standard errors */
  s->warn_risk = precise && h > 0.0 ? 0.5 * erfc((from - s->warn_from_kmh) / (h / z) / sqrt(2.0)) : NAN;
  /* (the cap makes it larger than one standard error's 0.159 where the error exceeds the cap) */
  /* the edge: at the conicity in use where the origin is stable there; inside the Hopf interval above the point
   * estimate, at the interval's optimistic end (found by the lookup at the conicity whose Hopf speed is hopf_high,
   * which the table's affine 1/V^2 makes exact) */
  s->edge_used_m = b.has_edge ? b.edge_amp_m : 0.0;
  if (!b.origin_stable && e->speed_kmh <= s->hopf_high_kmh) {
    st = lookup(a, 1, lambda_opt, e->speed_kmh, &bo);
    if (st != HM_OK) return st;
    s->edge_used_m = bo.origin_stable && bo.has_edge ? bo.edge_amp_m : 0.0;
  }
  a->precise = precise;
  return HM_OK;
}

/* Hunting met a criterion at a speed below the interval: the vehicle's Hopf speed (or, after a large disturbance, its
 * lowest cycle speed) may be no higher. The lowest such speed of the latch bounds the interval's lower end, and the
 * WARN and WATCH thresholds below it by their margins, while the ALARM is held and for memory_s after it (alarm.h);
 * the latch is released only below it. */
static void hunted_bound(hm_alarm a, const hm_estimate *e, double now, hm_assessment *s) {
  if (e->rms_exceeded || e->peaks_exceeded || e->displacement_exceeded) {
    if (!a->latched && a->hunted_at_kmh < INFINITY && !(now - a->hunted_t_s <= a->memory_s))
      a->hunted_at_kmh = INFINITY; /* a new episode after the memory of the last one ran out */
    if (e->speed_kmh <= a->hunted_at_kmh) a->hunted_at_kmh = e->speed_kmh, a->hunted_t_s = now;
  }
  if (isnan(a->hunted_t_s) && a->hunted_at_kmh < INFINITY) a->hunted_t_s = now; /* a restarted time line */
  if (!a->latched && !(now - a->hunted_t_s <= a->memory_s)) a->hunted_at_kmh = INFINITY;
  s->hunted_at_kmh = a->hunted_at_kmh < INFINITY ? a->hunted_at_kmh : NAN;
  if (!(a->hunted_at_kmh < s->hopf_low_kmh)) return;
  s->hopf_low_kmh = a->hunted_at_kmh;
  s->hopf_low_from_hunting = 1;
  s->warn_from_kmh = fmin(s->warn_from_kmh, a->hunted_at_kmh - a->cfg.warn_speed_margin_kmh);
  s->watch_from_kmh = fmin(s->watch_from_kmh, a->hunted_at_kmh - a->cfg.watch_speed_margin_kmh);
}

hm_status hm_alarm_update(hm_alarm a, const hm_estimate *e, const hm_margin_estimate *g, double now, hm_assessment *out) {
  if (!a || !e || !out || !isfinite(now)) return HM_EINVAL;
  const hm_alarm_config *c = &a->cfg;
  hm_assessment s;
  memset(&s, 0, sizeof s);
  hm_reason reason;
  hm_level target;
  if (!e->accel_valid || !e->speed_valid) {
    target = HM_LEVEL_NO_DATA;
    reason = !e->sample_rate_supported ? HM_REASON_BAD_SAMPLE_RATE
             : !e->accel_valid         ? HM_REASON_NO_ACCEL
                                       : HM_REASON_NO_SPEED;
    a->block_n = a->n_blocks = 0; /* no speed: the acceleration starts again */
    if (a->latched) { /* a held ALARM outlives its data: nothing says the oscillation has gone (alarm.h) */
      target = HM_LEVEL_ALARM;
      reason = a->latch_reason;
      a->calm = 0;
      s.latched = 1;
      s.release_in_s = c->release_s;
    }
  } else {
    const hm_status st = assess(a, e, g, &s);
    if (st != HM_OK) return st;
    s.boundaries_valid = 1;
    s.narrow_peak_ambiguous = g && g->ambiguous_at_s > 0.0 && now - g->ambiguous_at_s <= HM_ALARM_NARROW_HOLD_S;
    s.margin_hopf_kmh = s.boundaries.hopf_speed_kmh - e->speed_kmh;
    s.margin_lowest_cycle_kmh = s.boundaries.lowest_cycle_speed_kmh - e->speed_kmh;
    s.amplitude_m = e->oscillation_valid ? e->amplitude_displacement_m : 0.0;
    s.amplitude_margin_m = s.edge_used_m > 0.0 ? s.edge_used_m - s.amplitude_m : 0.0;
    hunted_bound(a, e, now, &s);
    /* the speed's trend (accelerating toward a threshold makes a lower level short-lived) */
    if (a->have_trend && now > a->t_prev_s) {
      const double dt = now - a->t_prev_s, w = fmin(dt / HM_ALARM_TREND_S, 1.0);
      a->dvdt_kmh_s += w * ((e->speed_kmh - a->v_prev_kmh) / dt - a->dvdt_kmh_s);
    }
    a->have_trend = 1;
    a->v_prev_kmh = e->speed_kmh;
    a->t_prev_s = now;
    /* (an identified interval only: the prior's range is already the cautious end of the wheels' wear) */
    const double accel_kmh_s = sustained_acceleration(a, now, e->speed_kmh);
    s.anticipation_kmh = s.conicity_from_estimate ? accel_kmh_s * HM_ALARM_RAISE_LOOKAHEAD_S : 0.0;
    target = raw_level(a, e, g, &s, a->level, &reason);
    if (target < a->level && a->dvdt_kmh_s > 0.0) {
      /* a lower level only if it would still hold at the speed the present acceleration reaches in
       * HM_ALARM_LOWER_LOOKAHEAD_S: a train accelerating past a threshold just lowered would raise the level again */
      hm_estimate ahead = *e;
      ahead.speed_kmh += a->dvdt_kmh_s * HM_ALARM_LOWER_LOOKAHEAD_S;
      hm_reason r_ahead;
      if (raw_level(a, &ahead, g, &s, a->level, &r_ahead) >= a->level) target = a->level, reason = a->reason;
    }
    if (target == HM_LEVEL_ALARM && oscillation_reason(reason)) {
      a->latched = 1;
      a->latch_reason = reason;
      a->calm = 0;
    } else if (a->latched) {
      /* held until calm for release_s */
      const int calm = calm_now(a, e, &s);
      if (!calm) a->calm = 0;
      else if (!a->calm) a->calm = 1, a->calm_since = now;
      if (a->calm && now - a->calm_since >= c->release_s) {
        a->latched = 0; /* the hunted-at speed stays a bound for memory_s */
      } else {
        target = HM_LEVEL_ALARM;
        reason = a->latch_reason;
        s.release_in_s = a->calm ? c->release_s - (now - a->calm_since) : c->release_s;
      }
    }
    s.latched = a->latched;
  }
  /* (with no data the latch is kept: nothing says the oscillation has gone) */
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

/* ---- what the alarm holds through a restart (alarm.h's hm_alarm_snapshot; state.h) ---- */

void hm_alarm_take_snapshot(const hm_alarm a, double now, hm_alarm_snapshot *out) {
  if (!a || !out || !isfinite(now)) return;
  hm_alarm_snapshot s;
  memset(&s, 0, sizeof s);
  s.latched = a->latched;
  s.latch_reason = a->latched ? a->latch_reason : HM_REASON_STARTUP;
  /* the hunted-at speed while it counts (hunted_bound): held, on a restarted line, or within memory_s */
  const int counts = a->hunted_at_kmh < INFINITY &&
                     (a->latched || isnan(a->hunted_t_s) || now - a->hunted_t_s <= a->memory_s);
  s.hunted_at_kmh = counts ? a->hunted_at_kmh : INFINITY;
  s.hunted_age_s = counts && !isnan(a->hunted_t_s) ? fmax(now - a->hunted_t_s, 0.0) : counts ? NAN : 0.0;
  s.precise = a->precise;
  *out = s;
}

hm_status hm_alarm_snapshot_validate(const hm_alarm_snapshot *s, char *why, size_t len) {
  if (!s) return HM_EINVAL;
  const char *field = NULL;
  if (s->latched != 0 && s->latched != 1) field = "latched: 0 or 1";
  else if (s->latched && !oscillation_reason(s->latch_reason))
    field = "latch_reason: an oscillation's (r.m.s., peaks, displacement, beyond the unstable cycle)";
  else if (!(s->hunted_at_kmh > 0.0 && s->hunted_at_kmh <= 2000.0) && s->hunted_at_kmh != INFINITY)
    field = "hunted_at_kmh: in (0, 2000] or INFINITY";
  else if (s->hunted_at_kmh != INFINITY && !isnan(s->hunted_age_s) &&
           !(isfinite(s->hunted_age_s) && s->hunted_age_s >= 0.0))
    field = "hunted_age_s: finite and >= 0, or NAN";
  else if (s->precise != 0 && s->precise != 1) field = "precise: 0 or 1";
  if (!field) return HM_OK;
  if (why && len) snprintf(why, len, "alarm: %s", field);
  return HM_EDOMAIN;
}

hm_status hm_alarm_restore(hm_alarm a, double now, const hm_alarm_snapshot *s, char *why, size_t len) {
  if (!a || !s || !isfinite(now)) return HM_EINVAL;
  const hm_status st = hm_alarm_snapshot_validate(s, why, len);
  if (st != HM_OK) return st;
  hm_alarm_reset(a);
  a->latched = s->latched;
  if (a->latched) a->latch_reason = s->latch_reason, a->level = HM_LEVEL_ALARM, a->reason = s->latch_reason;
  a->hunted_at_kmh = s->hunted_at_kmh;
  a->hunted_t_s = s->hunted_at_kmh < INFINITY && !isnan(s->hunted_age_s) ? now - s->hunted_age_s : NAN;
  a->precise = s->precise;
  return HM_OK;
}
