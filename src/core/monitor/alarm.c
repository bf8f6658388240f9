/* Margins and alarm levels with hysteresis and hold time (see alarm.h). */
#include "hunting_monitor/alarm.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "validate.h"

struct hm_alarm_s {
  hm_alarm_config cfg;
  hm_level level;
  hm_reason reason;
  double since;
  int lower_pending;      /* the conditions for a lower level hold since lower_since */
  double lower_since;
  int latched;            /* an oscillation ALARM held (alarm.h) */
  hm_reason latch_cause;  /* what latched it, when, and the latest time the oscillation met a criterion (or was beyond
                             the edge) since; NAN: on a time line that restarted */
  double latch_since_s, latch_last_met_s;
  int calm;               /* the release conditions hold since calm_since */
  double calm_since;
  double displacement_limit_m; /* the displacement criterion's limit (0: off) */
  double hunted_at_kmh;   /* the lowest speed at which a criterion was met, during the latch and for memory_s after
                             it (INFINITY: none) */
  double hunted_t_s;      /* when (the latest time it was met there or lower); NAN: on a time line that restarted,
                             its age counts from the next update */
  double hunted_mem_s;    /* when its memory_s started: hunted_t_s, or the latch's release if later (alarm.h: for
                             memory_s after the release; a latch longer than memory_s had dropped it at once) */
  double memory_s;        /* how long a hunted-at speed bounds the interval (hm_alarm_set_memory) */
  double v_prev_kmh, t_prev_s, dvdt_kmh_s; /* the speed's trend: an exponential average of dv/dt over ~5 s */
  int have_trend;
  /* a sustained acceleration (alarm.h): the last speed, the mean of the block being filled and of the full blocks of
   * the last HM_ALARM_ACCEL_SPAN_S */
  double v_last_kmh, block_sum_kmh, block_sum_t_s, block_t0_s, block_last_s;
  unsigned block_n, n_blocks;
  double block_v_kmh[HM_ALARM_ACCEL_MAX_BLOCKS], block_t_s[HM_ALARM_ACCEL_MAX_BLOCKS]; /* oldest first */
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

/* Appends to buf at *n (as snprintf: *n grows by the whole length, buf gets what fits). */
static void append(char *buf, size_t len, size_t *n, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  const int k = vsnprintf(*n < len ? buf + *n : NULL, *n < len ? len - *n : 0, fmt, ap);
  va_end(ap);
  if (k > 0) *n += (size_t)k;
}

/* " at T s" from the origin, or " A s ago" with the origin NAN; nothing for an unknown time. */
static void append_when(char *buf, size_t len, size_t *n, double t_s, double now_s, double origin_s) {
  if (!isfinite(t_s)) return;
  if (isnan(origin_s)) append(buf, len, n, " %.1f s ago", now_s - t_s);
  else append(buf, len, n, " at %.1f s", t_s - origin_s);
}

/* Why the speeds that arrive are refused, after "no current speed". */
static void append_refusal(char *buf, size_t len, size_t *n, hm_speed_refusal r) {
  if (r != HM_SPEED_ACCEPTED) append(buf, len, n, " (speeds arrive, refused: %s)", hm_speed_refusal_text(r));
}

size_t hm_assessment_reason_text(const hm_assessment *s, double origin_s, char *buf, size_t len) {
  size_t n = 0;
  if (buf && len) buf[0] = '\0';
  if (!buf) len = 0;
  if (!s) return 0;
  if (!s->latched || !s->held) {
    append(buf, len, &n, "%s", hm_reason_text(s->reason));
    if (s->reason == HM_REASON_NO_SPEED) append_refusal(buf, len, &n, s->speed_refused);
    return n;
  }
  append(buf, len, &n, "held (%s", hm_reason_text(s->hold_cause));
  append_when(buf, len, &n, s->hold_since_s, s->time_s, origin_s);
  if (isfinite(s->hold_last_met_s) && s->hold_last_met_s != s->hold_since_s) {
    append(buf, len, &n, ", last met");
    append_when(buf, len, &n, s->hold_last_met_s, s->time_s, origin_s);
  }
  append(buf, len, &n, "):");
  if (isfinite(s->hunted_at_kmh)) {
    append(buf, len, &n, " hunting seen down to %.1f km/h", s->hunted_at_kmh);
    append_when(buf, len, &n, s->hunted_at_s, s->time_s, origin_s);
    append(buf, len, &n, ";");
  }
  if (isfinite(s->hold_release_below_kmh))
    append(buf, len, &n, " releases below %.1f km/h after %.0f s calm", s->hold_release_below_kmh, s->calm_needed_s);
  else
    append(buf, len, &n, " releases below the Hopf interval after %.0f s calm", s->calm_needed_s);
  if (s->hold_waits & HM_HOLD_WAITS_DATA) {
    append(buf, len, &n, " (%s", hm_reason_text(s->hold_no_data));
    if (s->hold_no_data == HM_REASON_NO_SPEED) append_refusal(buf, len, &n, s->speed_refused);
    append(buf, len, &n, ": the calm is seen only with data)");
    return n;
  }
  append(buf, len, &n, " (calm %.1f s", s->calm_s);
  if (s->hold_waits & (HM_HOLD_WAITS_SPEED | HM_HOLD_WAITS_OSCILLATION)) append(buf, len, &n, ": waits for");
  if (s->hold_waits & HM_HOLD_WAITS_SPEED) append(buf, len, &n, " the speed, %.1f km/h", s->speed_kmh);
  if ((s->hold_waits & HM_HOLD_WAITS_SPEED) && (s->hold_waits & HM_HOLD_WAITS_OSCILLATION)) append(buf, len, &n, ",");
  if (s->hold_waits & HM_HOLD_WAITS_OSCILLATION)
    append(buf, len, &n, " the oscillation, %.2f mm (calm below %.2f mm)", 1e3 * s->amplitude_m,
           1e3 * s->hold_release_amplitude_m);
  append(buf, len, &n, ")");
  return n;
}

void hm_alarm_config_default(hm_alarm_config *c) {
  c->warn_amplitude_fraction = 0.5;
  c->warn_speed_margin_kmh = 10.0;
  c->warn_standard_errors = 1.0;
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
  if (!c) return HM_EINVAL;
  const hm_field_check f[] = {
      {"warn_amplitude_fraction", c->warn_amplitude_fraction, HM_RULE_OPEN, 0.0, 1.0},
      {"warn_speed_margin_kmh", c->warn_speed_margin_kmh, HM_RULE_RANGE, 0.0, 500.0},
      {"warn_standard_errors", c->warn_standard_errors, HM_RULE_RANGE, 0.0, 5.0},
      {"watch_speed_margin_kmh", c->watch_speed_margin_kmh, HM_RULE_RANGE, 0.0, 500.0},
      {"hysteresis_kmh", c->hysteresis_kmh, HM_RULE_RANGE, 0.0, 100.0},
      {"hysteresis_amplitude_fraction", c->hysteresis_amplitude_fraction, HM_RULE_RANGE, 0.0, 1.0},
      {"min_hold_s", c->min_hold_s, HM_RULE_RANGE, 0.0, 3600.0}};
  const hm_field_check after[] = { /* (the interval's fields are checked between, in the settings' order) */
      {"blind_fraction", c->blind_fraction, HM_RULE_RANGE_OPEN, 0.0, 1.0},
      {"release_s", c->release_s, HM_RULE_RANGE, 0.0, 3600.0},
      {"release_amplitude_fraction", c->release_amplitude_fraction, HM_RULE_RANGE_OPEN, 0.0, 1.0}};
  hm_interval_config ic;
  hm_alarm_interval_config(c, &ic);
  hm_status st = hm_check_fields(f, HM_COUNT_OF(f), why, len);
  if (st == HM_OK) st = hm_interval_config_validate(&ic, why, len);
  if (st == HM_OK) st = hm_check_fields(after, HM_COUNT_OF(after), why, len);
  if (st != HM_OK) return st;
  if (!(c->watch_speed_margin_kmh >= c->warn_speed_margin_kmh))
    return hm_reject(why, len, "watch_speed_margin_kmh", "must be at least warn_speed_margin_kmh",
                     c->watch_speed_margin_kmh);
  if (!(c->hysteresis_amplitude_fraction < c->warn_amplitude_fraction))
    return hm_reject(why, len, "hysteresis_amplitude_fraction", "must be below warn_amplitude_fraction",
                     c->hysteresis_amplitude_fraction);
  return HM_OK;
}

void hm_alarm_interval_config(const hm_alarm_config *c, hm_interval_config *out) {
  if (!c || !out) return;
  out->use_conicity_estimate = c->use_conicity_estimate;
  out->conicity_max_se = c->conicity_max_se;
  out->conicity_fallback = c->conicity_fallback;
  out->conicity_prior_low = c->conicity_prior_low;
  out->conicity_prior_high = c->conicity_prior_high;
}

hm_status hm_alarm_create(const hm_alarm_config *cfg, hm_alarm *out, char *why, size_t why_len) {
  if (!cfg || !out) return HM_EINVAL;
  hm_alarm a = calloc(1, sizeof *a);
  if (!a) return HM_ENOMEM;
  const hm_status st = hm_alarm_set_config(a, cfg, why, why_len);
  if (st != HM_OK) {
    free(a);
    return st;
  }
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
  a->hunted_t_s = a->hunted_mem_s = NAN; /* its age counts again from the next update */
  a->latch_since_s = a->latch_last_met_s = NAN;
  a->have_trend = 0;
  a->dvdt_kmh_s = 0.0;
  a->block_n = a->n_blocks = 0;
}

void hm_alarm_shift_time(hm_alarm a, double delta_s) {
  if (!a || !isfinite(delta_s)) return;
  a->since += delta_s;
  a->lower_since += delta_s;
  a->calm_since += delta_s;
  a->t_prev_s += delta_s;
  a->hunted_t_s += delta_s;
  a->hunted_mem_s += delta_s;
  a->latch_since_s += delta_s;
  a->latch_last_met_s += delta_s;
  a->block_t0_s += delta_s;
  a->block_last_s += delta_s;
  for (unsigned k = 0; k < a->n_blocks; ++k) a->block_t_s[k] += delta_s;
}

void hm_alarm_set_memory(hm_alarm a, double memory_s) {
  if (a && isfinite(memory_s) && memory_s > 0.0) a->memory_s = memory_s;
}

void hm_alarm_set_displacement_limit(hm_alarm a, double limit_m) {
  if (a && isfinite(limit_m) && limit_m >= 0.0) a->displacement_limit_m = limit_m;
}

/* An ALARM caused by the oscillation itself (latched), not by the speed alone. */
static int oscillation_reason(hm_reason r) {
  return r == HM_REASON_RMS_CRITERION || r == HM_REASON_PEAKS_CRITERION || r == HM_REASON_DISPLACEMENT_CRITERION ||
         r == HM_REASON_AMPLITUDE_BEYOND_EDGE;
}

/* The latch's release conditions (alarm.h) in s: the speed below the Hopf interval by the hysteresis (the ALARM
 * level's thresholds are relaxed by it, as everywhere), the displacement amplitude below release_amplitude_fraction of
 * the displacement limit (or of the edge) and no criterion met; what is not met yet goes to s->hold_waits. */
static void release_conditions(const hm_alarm a, const hm_estimate *e, hm_assessment *s) {
  const double limit = a->displacement_limit_m > 0.0 ? a->displacement_limit_m : s->edge_used_m;
  s->hold_release_below_kmh = s->hopf_low_kmh - a->cfg.hysteresis_kmh;
  s->hold_release_amplitude_m =
      a->cfg.release_amplitude_fraction * (limit > 0.0 ? limit : HM_ESTIMATOR_WHEELSET_DISPLACEMENT_M);
  s->hold_waits = 0;
  if (e->rms_exceeded || e->peaks_exceeded || e->displacement_exceeded ||
      !(s->amplitude_m < s->hold_release_amplitude_m))
    s->hold_waits |= HM_HOLD_WAITS_OSCILLATION;
  if (!(e->speed_kmh < s->hold_release_below_kmh)) s->hold_waits |= HM_HOLD_WAITS_SPEED;
}

hm_status hm_alarm_set_config(hm_alarm a, const hm_alarm_config *cfg, char *why, size_t why_len) {
  if (!a || !cfg) return HM_EINVAL;
  const hm_status st = hm_alarm_config_validate(cfg, why, why_len);
  if (st != HM_OK) return st;
  a->cfg = *cfg;
  return HM_OK;
}

/* The level the conditions call for, with the thresholds of levels at or below `current` relaxed. */
static hm_level raw_level(const hm_alarm a, const hm_estimate *e, const hm_hopf_interval *iv, const hm_assessment *s,
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
  if (s->model_mismatch) return *reason = HM_REASON_MODEL_MISMATCH, HM_LEVEL_WATCH;
  if (iv->outside_prior) return *reason = HM_REASON_OUTSIDE_PRIOR, HM_LEVEL_WATCH;
  if (s->narrow_peak_ambiguous) return *reason = HM_REASON_NARROW_PEAK, HM_LEVEL_WATCH;
  if (e->sample_rate_mismatch) return *reason = HM_REASON_RATE_MISMATCH, HM_LEVEL_WATCH;
  if (e->loss_fraction > c->blind_fraction) return *reason = HM_REASON_PARTLY_BLIND, HM_LEVEL_WATCH;
  if (v < s->boundaries.lowest_cycle_speed_kmh) return *reason = HM_REASON_BELOW_LOWEST_CYCLE, HM_LEVEL_OK;
  return *reason = HM_REASON_NORMAL, HM_LEVEL_OK;
}

/* The block being filled joins the full ones (the oldest dropped when the ring is full). */
static void close_block(hm_alarm a) {
  if (a->n_blocks == HM_ALARM_ACCEL_MAX_BLOCKS) {
    memmove(a->block_v_kmh, a->block_v_kmh + 1, (HM_ALARM_ACCEL_MAX_BLOCKS - 1) * sizeof(double));
    memmove(a->block_t_s, a->block_t_s + 1, (HM_ALARM_ACCEL_MAX_BLOCKS - 1) * sizeof(double));
    --a->n_blocks;
  }
  a->block_v_kmh[a->n_blocks] = a->block_sum_kmh / a->block_n;
  a->block_t_s[a->n_blocks] = a->block_t0_s + a->block_sum_t_s / a->block_n;
  ++a->n_blocks;
  a->block_n = 0;
}

/* The least-squares slope of the full blocks' mean speeds on their mean times [km/h/s]; 0 for fewer than two. */
static double blocks_slope(const hm_alarm a) {
  double st = 0.0, sv = 0.0;
  for (unsigned k = 0; k < a->n_blocks; ++k) st += a->block_t_s[k], sv += a->block_v_kmh[k];
  const double n = (double)a->n_blocks, tm = st / n, vm = sv / n;
  double stt = 0.0, stv = 0.0;
  for (unsigned k = 0; k < a->n_blocks; ++k) {
    const double dt = a->block_t_s[k] - tm;
    stt += dt * dt;
    stv += dt * (a->block_v_kmh[k] - vm);
  }
  return a->n_blocks >= 2 && stt > 0.0 ? stv / stt : 0.0;
}

/* The sustained acceleration [km/h/s] (alarm.h): the speed goes into blocks of HM_ALARM_ACCEL_BLOCK_S (updates
 * further apart than a block give a block each), and the least-squares slope of the mean speeds of the full blocks of
 * the last HM_ALARM_ACCEL_SPAN_S, once they span HM_ALARM_ACCEL_MIN_SPAN_S, is the acceleration, clamped to [0,
 * HM_ALARM_MAX_ACCEL_KMH_S]. A step of the signal (a change between updates beyond HM_ALARM_STEP_RATE_KMH_S times their
 * interval plus HM_ALARM_STEP_NOISE_KMH), a time step back or a silence of HM_ALARM_ACCEL_SILENCE_S starts again (a
 * step taken out by its own increment would leave two samples' noise as a level shift: 1.3 km/h of anticipation). */
static double sustained_acceleration(hm_alarm a, double now, double v_kmh) {
  if (a->block_n + a->n_blocks > 0 &&
      (now < a->block_last_s || now - a->block_last_s > HM_ALARM_ACCEL_SILENCE_S ||
       fabs(v_kmh - a->v_last_kmh) > HM_ALARM_STEP_RATE_KMH_S * (now - a->block_last_s) + HM_ALARM_STEP_NOISE_KMH))
    a->block_n = a->n_blocks = 0;
  a->v_last_kmh = v_kmh;
  if (a->block_n > 0 && now - a->block_t0_s >= HM_ALARM_ACCEL_BLOCK_S) close_block(a);
  a->block_last_s = now;
  if (a->block_n == 0) a->block_t0_s = now, a->block_sum_kmh = a->block_sum_t_s = 0.0;
  a->block_sum_kmh += v_kmh;
  a->block_sum_t_s += now - a->block_t0_s;
  ++a->block_n;
  unsigned old = 0; /* full blocks older than the span */
  while (old < a->n_blocks && a->block_t_s[old] < now - HM_ALARM_ACCEL_SPAN_S) ++old;
  if (old > 0) {
    memmove(a->block_v_kmh, a->block_v_kmh + old, (a->n_blocks - old) * sizeof(double));
    memmove(a->block_t_s, a->block_t_s + old, (a->n_blocks - old) * sizeof(double));
    a->n_blocks -= old;
  }
  if (a->n_blocks < 2 || a->block_t_s[a->n_blocks - 1] - a->block_t_s[0] < HM_ALARM_ACCEL_MIN_SPAN_S) return 0.0;
  return fmin(fmax(blocks_slope(a), 0.0), HM_ALARM_MAX_ACCEL_KMH_S);
}

/* WARN from an identified Hopf speed (alarm.h): the point less the larger of the margin and k standard errors, the
 * lower half-width (point - low) being z of them. */
static double warn_below_point(double point_kmh, double low_kmh, double margin_kmh, double z, double k) {
  return point_kmh - fmax(margin_kmh, fmin(k * (point_kmh - low_kmh) / z, HM_ALARM_WARN_MAX_BELOW_KMH));
}

/* The speed margins (alarm.h): added to a range's lower end; below an identified interval WATCH in quadrature with
 * its lower half-width h, WARN from the point less the larger of the margin and one standard error (h / z); an
 * estimate too uncertain to be used alone (the vehicle behaving like its model) gives its own WARN threshold so, and
 * the more cautious of it and the prior's range counts. warn_risk: what the WARN rule risks (the interval read as
 * normal, its lower half-width interval_z standard errors). */
static void speed_thresholds(const hm_alarm a, const hm_hopf_interval *iv, hm_assessment *s) {
  const hm_alarm_config *c = &a->cfg;
  const int precise = iv->conicity_from_estimate;
  const hm_table_lookup_result *b = &s->boundaries;
  const double h = precise ? b->hopf_speed_kmh - s->hopf_low_kmh : 0.0;
  const double from = precise ? b->hopf_speed_kmh : s->hopf_low_kmh;
  const double z = iv->interval_z;
  s->warn_from_kmh =
      warn_below_point(from, precise ? s->hopf_low_kmh : from, c->warn_speed_margin_kmh, z, c->warn_standard_errors);
  if (iv->estimate_with_prior)
    s->warn_from_kmh = fmin(iv->prior_hopf_low_kmh - c->warn_speed_margin_kmh,
                            warn_below_point(iv->estimate_hopf_kmh, iv->estimate_low_kmh, c->warn_speed_margin_kmh, z,
                                             c->warn_standard_errors));
  s->watch_from_kmh = from - hypot(h, c->watch_speed_margin_kmh);
  s->warn_risk = precise && h > 0.0 ? 0.5 * erfc((from - s->warn_from_kmh) / (h / z) / sqrt(2.0)) : NAN;
  /* (the cap makes it larger than one standard error's 0.159 where the error exceeds the cap) */
}

/* The interval's numbers into the assessment. */
static void take_interval(const hm_hopf_interval *iv, hm_assessment *s) {
  s->conicity = iv->conicity;
  s->conicity_se = iv->conicity_se;
  s->conicity_from_estimate = iv->conicity_from_estimate;
  s->conicity_from_prior = iv->conicity_from_prior;
  s->model_interval_used = iv->model_interval_used;
  s->model_mismatch = iv->model_mismatch;
  s->hopf_free_used = iv->hopf_free_used;
  s->narrow_peak_ambiguous = iv->narrow_peak_ambiguous;
  s->conicity_outside_table = iv->conicity_outside_table;
  s->boundaries = iv->boundaries;
  s->hopf_low_kmh = iv->hopf_low_kmh;
  s->hopf_high_kmh = iv->hopf_high_kmh;
  s->edge_used_m = iv->edge_used_m;
}

/* WARN and WATCH from at most basis_kmh less their margins (the published fields agree, alarm.h); warn_risk is not
 * stated for a WARN speed the interval did not set. */
static void below(const hm_alarm a, hm_assessment *s, double basis_kmh) {
  const double warn_from = basis_kmh - a->cfg.warn_speed_margin_kmh;
  if (warn_from < s->warn_from_kmh) s->warn_from_kmh = warn_from, s->warn_risk = NAN;
  s->watch_from_kmh = fmin(s->watch_from_kmh, basis_kmh - a->cfg.watch_speed_margin_kmh);
}

/* Hunting met a criterion at a speed below the interval: the vehicle's Hopf speed (or, after a large disturbance, its
 * lowest cycle speed) may be no higher. The lowest such speed of the latch bounds the interval's lower end, and the
 * WARN and WATCH thresholds below it by their margins (also where it lies inside the interval), while the ALARM is
 * held and for memory_s after it (alarm.h); the latch is released only below it. While held, WARN and WATCH lie below
 * the interval's lower end by their margins. */
static void hunted_bound(hm_alarm a, const hm_estimate *e, double now, hm_assessment *s) {
  if (e->rms_exceeded || e->peaks_exceeded || e->displacement_exceeded) {
    if (!a->latched && a->hunted_at_kmh < INFINITY && !(now - a->hunted_mem_s <= a->memory_s))
      a->hunted_at_kmh = INFINITY; /* a new episode after the memory of the last one ran out */
    if (e->speed_kmh <= a->hunted_at_kmh) a->hunted_at_kmh = e->speed_kmh, a->hunted_t_s = a->hunted_mem_s = now;
  }
  if (isnan(a->hunted_t_s) && a->hunted_at_kmh < INFINITY) a->hunted_t_s = now; /* a restarted time line */
  if (isnan(a->hunted_mem_s) && a->hunted_at_kmh < INFINITY) a->hunted_mem_s = now;
  if (!a->latched && !(now - a->hunted_mem_s <= a->memory_s)) a->hunted_at_kmh = INFINITY;
  s->hunted_at_kmh = a->hunted_at_kmh < INFINITY ? a->hunted_at_kmh : NAN;
  s->hunted_at_s = a->hunted_at_kmh < INFINITY ? a->hunted_t_s : NAN;
  if (a->hunted_at_kmh < INFINITY) { /* the thresholds below it by their margins, also inside the interval */
    below(a, s, a->hunted_at_kmh);
    if (a->hunted_at_kmh < s->hopf_low_kmh) {
      s->hopf_low_kmh = a->hunted_at_kmh;
      s->hopf_low_from_hunting = 1;
      s->warn_risk = NAN; /* the interval read as normal is not what the level uses */
    }
  }
  if (a->latched) below(a, s, s->hopf_low_kmh); /* during a hold from the held interval's lower end */
}

/* The latch (alarm.h) with data: an oscillation ALARM latches (its first cause and time kept); a latched one holds,
 * with that cause, until the release conditions have held for release_s. 1 when it was released now (the level
 * then falls at once: the calm release_s was its hold, and min_hold_s more showed an ALARM neither latched nor held
 * with a criterion's reason that no longer held, issue #27). */
static int latch(hm_alarm a, const hm_estimate *e, double now, hm_assessment *s, hm_level *target, hm_reason *reason,
                 int kept) {
  int released = 0;
  /* (a level kept by the look-ahead carries the level's reason, the latch's cause: no criterion met now) */
  const int oscillation = !kept && *target == HM_LEVEL_ALARM && oscillation_reason(*reason);
  if (a->latched || oscillation) release_conditions(a, e, s);
  if (oscillation) {
    if (!a->latched) a->latch_cause = *reason, a->latch_since_s = now;
    a->latched = 1;
    a->latch_last_met_s = now;
    a->calm = 0;
  } else if (a->latched) {
    if (s->hold_waits) a->calm = 0;
    else if (!a->calm) a->calm = 1, a->calm_since = now;
    if (a->calm && now - a->calm_since >= a->cfg.release_s) {
      a->latched = 0; /* the hunted-at speed stays a bound for memory_s from now */
      if (a->hunted_at_kmh < INFINITY) a->hunted_mem_s = fmax(a->hunted_mem_s, now);
      released = 1;
    } else {
      *target = HM_LEVEL_ALARM;
      *reason = a->latch_cause;
      s->held = 1;
      if (a->calm) s->hold_waits = HM_HOLD_WAITS_TIME;
    }
  }
  s->latched = a->latched;
  return released;
}

/* The hold in numbers (alarm.h): while latched its cause, times, calm so far and needed; else none. */
static void hold_numbers(const hm_alarm a, double now, hm_assessment *s) {
  if (a->latched) {
    s->hold_cause = a->latch_cause;
    s->hold_since_s = a->latch_since_s;
    s->hold_last_met_s = a->latch_last_met_s;
    s->calm_needed_s = a->cfg.release_s;
    s->calm_s = s->held && a->calm ? now - a->calm_since : 0.0;
    s->release_in_s = s->calm_needed_s - s->calm_s;
  } else {
    s->hold_cause = HM_REASON_STARTUP;
    s->hold_since_s = s->hold_last_met_s = s->hold_release_below_kmh = s->hold_release_amplitude_m = NAN;
    s->hold_waits = 0;
  }
}

/* Without current data: NO_DATA for the missing input, or a latched ALARM held through it (alarm.h); the level
 * wanted, its reason in *reason. */
static hm_level target_without_data(hm_alarm a, const hm_estimate *e, hm_assessment *s, hm_reason *reason) {
  *reason = !e->sample_rate_supported ? HM_REASON_BAD_SAMPLE_RATE
            : !e->accel_valid         ? HM_REASON_NO_ACCEL
                                      : HM_REASON_NO_SPEED;
  s->speed_refused = e->speed_refused; /* (HM_SPEED_ACCEPTED while the speed is current: estimator.h) */
  a->block_n = a->n_blocks = 0; /* no speed: the acceleration starts again */
  if (!a->latched) return HM_LEVEL_NO_DATA;
  /* a held ALARM outlives its data: nothing says the oscillation has gone (alarm.h) */
  s->hold_no_data = *reason;
  *reason = a->latch_cause;
  a->calm = 0;
  s->latched = s->held = 1;
  s->hold_release_below_kmh = s->hold_release_amplitude_m = NAN; /* no current boundaries */
  s->hold_waits = HM_HOLD_WAITS_DATA;
  if (a->hunted_at_kmh < INFINITY) /* (it counts while held) */
    s->hunted_at_kmh = a->hunted_at_kmh, s->hunted_at_s = a->hunted_t_s;
  return HM_LEVEL_ALARM;
}

/* The speed's trend, smoothed over HM_ALARM_TREND_S (accelerating toward a threshold makes a lower level
 * short-lived). */
static void follow_trend(hm_alarm a, double now, double v_kmh) {
  if (a->have_trend && now > a->t_prev_s) {
    const double dt = now - a->t_prev_s, w = fmin(dt / HM_ALARM_TREND_S, 1.0);
    a->dvdt_kmh_s += w * ((v_kmh - a->v_prev_kmh) / dt - a->dvdt_kmh_s);
  }
  a->have_trend = 1;
  a->v_prev_kmh = v_kmh;
  a->t_prev_s = now;
}

/* With current data: the interval's boundaries and the margins into s, the level wanted into *target with its reason;
 * *released when the latch let go. */
static void target_with_data(hm_alarm a, const hm_estimate *e, const hm_hopf_interval *iv, double now,
                             hm_assessment *s, hm_level *target, hm_reason *reason, int *released) {
  take_interval(iv, s);
  speed_thresholds(a, iv, s);
  s->boundaries_valid = 1;
  s->margin_hopf_kmh = s->boundaries.hopf_speed_kmh - e->speed_kmh;
  s->margin_lowest_cycle_kmh = s->boundaries.lowest_cycle_speed_kmh - e->speed_kmh;
  s->amplitude_m = e->oscillation_valid ? e->amplitude_displacement_m : 0.0;
  s->amplitude_margin_m = s->edge_used_m > 0.0 ? s->edge_used_m - s->amplitude_m : 0.0;
  hunted_bound(a, e, now, s);
  follow_trend(a, now, e->speed_kmh);
  /* (an identified interval only: the prior's range is already the cautious end of the wheels' wear) */
  const double accel_kmh_s = sustained_acceleration(a, now, e->speed_kmh);
  s->anticipation_kmh = s->conicity_from_estimate ? accel_kmh_s * HM_ALARM_RAISE_LOOKAHEAD_S : 0.0;
  *target = raw_level(a, e, iv, s, a->level, reason);
  int kept = 0;
  if (*target < a->level && a->dvdt_kmh_s > 0.0) {
    /* a lower level only if it would still hold at the speed the present acceleration reaches in
     * HM_ALARM_LOWER_LOOKAHEAD_S: a train accelerating past a threshold just lowered would raise the level again */
    hm_estimate ahead = *e;
    ahead.speed_kmh += a->dvdt_kmh_s * HM_ALARM_LOWER_LOOKAHEAD_S;
    hm_reason r_ahead;
    if (raw_level(a, &ahead, iv, s, a->level, &r_ahead) >= a->level) *target = a->level, *reason = a->reason, kept = 1;
  }
  *released = latch(a, e, now, s, target, reason, kept);
}

/* The level moves to target: at once when higher, to NO_DATA or from it, or released; lower only after its
 * conditions held for min_hold_s. s->changed says whether it moved. */
static void move_level(hm_alarm a, double now, hm_level target, hm_reason reason, int released, hm_assessment *s) {
  s->changed = 0;
  if (target >= a->level || target == HM_LEVEL_NO_DATA || a->level == HM_LEVEL_NO_DATA || released) {
    a->lower_pending = 0;
    if (target != a->level) {
      a->level = target;
      a->since = now;
      s->changed = 1;
    }
    a->reason = reason; /* the level's current cause */
    return;
  }
  if (!a->lower_pending) {
    a->lower_pending = 1;
    a->lower_since = now;
  }
  if (now - a->lower_since >= a->cfg.min_hold_s) {
    a->level = target;
    a->reason = reason;
    a->since = now;
    a->lower_pending = 0;
    s->changed = 1;
  }
}

hm_status hm_alarm_update(hm_alarm a, const hm_estimate *e, const hm_hopf_interval *iv, double now,
                          hm_assessment *out) {
  if (!a || !e || !out || !isfinite(now)) return HM_EINVAL;
  const int data = e->accel_valid && e->speed_valid;
  if (data && !iv) return HM_EINVAL;
  hm_assessment s;
  memset(&s, 0, sizeof s);
  s.time_s = now;
  s.speed_kmh = e->speed_valid ? e->speed_kmh : 0.0;
  s.hunted_at_kmh = s.hunted_at_s = NAN;
  hm_reason reason = HM_REASON_STARTUP;
  hm_level target = HM_LEVEL_NO_DATA;
  int released = 0;
  if (!data) target = target_without_data(a, e, &s, &reason);
  else target_with_data(a, e, iv, now, &s, &target, &reason, &released);
  hold_numbers(a, now, &s);
  /* (with no data the latch is kept: nothing says the oscillation has gone) */
  move_level(a, now, target, reason, released, &s);
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
  s.latch_reason = a->latched ? a->latch_cause : HM_REASON_STARTUP;
  /* the hunted-at speed while it counts (hunted_bound): held, on a restarted line, or within memory_s */
  const int counts = a->hunted_at_kmh < INFINITY &&
                     (a->latched || isnan(a->hunted_mem_s) || now - a->hunted_mem_s <= a->memory_s);
  s.hunted_at_kmh = counts ? a->hunted_at_kmh : INFINITY;
  s.hunted_age_s = counts && !isnan(a->hunted_mem_s) ? fmax(now - a->hunted_mem_s, 0.0) : counts ? NAN : 0.0;
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
  if (a->latched) { /* its times, like a restarted time line's, are unknown (NAN): the hold says so (alarm.h) */
    a->latch_cause = s->latch_reason, a->level = HM_LEVEL_ALARM, a->reason = s->latch_reason;
    a->latch_since_s = a->latch_last_met_s = NAN;
  }
  a->hunted_at_kmh = s->hunted_at_kmh;
  a->hunted_t_s = a->hunted_mem_s =
      s->hunted_at_kmh < INFINITY && !isnan(s->hunted_age_s) ? now - s->hunted_age_s : NAN;
  return HM_OK;
}
