/* The Hopf interval and the boundaries a level is decided on (interval.h; the evidence rules in alarm.h). */
#include "hunting_monitor/interval.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "hunting_monitor/alarm.h"
#include "hunting_monitor/linear.h"
#include "evidence.h"
#include "validate.h"

struct hm_interval_s {
  hm_interval_config cfg;         /* the fallback and the prior resolved for the vehicle */
  hm_vehicle veh;
  hm_mode_model model;            /* a bogie's or car's (borrowed), NULL: the wheelset's closed forms */
  double prior_hopf_low_kmh, prior_hopf_high_kmh; /* the Hopf speeds at the prior's high and low ends */
  double fallback_hopf_kmh;                       /* and at the fallback conicity */
  hm_table table;
  hm_measurement_point point;     /* where the accelerometer is */
  hm_evidence ev;                 /* which estimates count, and their flags' memory (evidence.h) */
  /* the last table lookups (at the conicity in use and at the interval's optimistic end), reused while their
   * conicity and the speed are unchanged */
  struct {
    int valid;
    double conicity, speed_kmh;
    hm_table_lookup_result r;
  } cache[2];
};

static double hopf_kmh(const hm_vehicle *veh, hm_mode_model model, double conicity) {
  return model ? hm_mode_model_hopf_kmh(model, conicity) : hm_linear_hopf_kmh(veh, conicity);
}

hm_status hm_interval_config_validate(const hm_interval_config *c, char *why, size_t len) {
  if (!c) return HM_EINVAL;
  const hm_field_check f[] = {
      {"use_conicity_estimate", (double)c->use_conicity_estimate, HM_RULE_FLAG, 0.0, 0.0},
      {"conicity_max_se", c->conicity_max_se, HM_RULE_RANGE_OPEN, 0.0, 1.0},
      {"conicity_fallback", c->conicity_fallback, HM_RULE_RANGE, 0.0, 10.0},
      {"conicity_prior_low", c->conicity_prior_low, HM_RULE_RANGE, 0.0, 10.0},
      {"conicity_prior_high", c->conicity_prior_high, HM_RULE_RANGE, 0.0, 10.0}};
  const hm_status st = hm_check_fields(f, HM_COUNT_OF(f), why, len);
  if (st != HM_OK) return st;
  if ((c->conicity_prior_low == 0.0) != (c->conicity_prior_high == 0.0) ||
      (c->conicity_prior_high != 0.0 && !(c->conicity_prior_high > c->conicity_prior_low)))
    return hm_reject(why, len, "conicity_prior_high",
                     "must be above conicity_prior_low (or both 0: the fallback -+ 0.03)", c->conicity_prior_high);
  return HM_OK;
}

/* The settings with the fallback and the prior resolved for the vehicle, and the prior's Hopf speeds; HM_EDOMAIN
 * (reason in why) for a prior that does not hold the fallback. */
static hm_status resolve(const hm_interval_config *cfg, const hm_vehicle *veh, hm_mode_model model,
                         hm_interval_config *out, double *hopf_low, double *hopf_high, double *hopf_fallback,
                         char *why, size_t len) {
  hm_status st = hm_interval_config_validate(cfg, why, len);
  if (st != HM_OK) return st;
  hm_interval_config c = *cfg;
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
  *hopf_low = hopf_kmh(veh, model, c.conicity_prior_high);
  *hopf_high = hopf_kmh(veh, model, c.conicity_prior_low);
  *hopf_fallback = hopf_kmh(veh, model, c.conicity_fallback);
  return HM_OK;
}

hm_status hm_interval_create(const hm_interval_config *cfg, const hm_vehicle *veh, const hm_table table,
                             hm_interval *out, char *why, size_t why_len) {
  if (!cfg || !veh || !table || !out) return HM_EINVAL;
  hm_interval iv = calloc(1, sizeof *iv);
  if (!iv) return HM_ENOMEM;
  const hm_status st = hm_interval_set_config(iv, cfg, veh, why, why_len);
  if (st != HM_OK) {
    free(iv);
    return st;
  }
  iv->table = table;
  iv->ev.precise_since = NAN;
  *out = iv;
  return HM_OK;
}

void hm_interval_destroy(hm_interval iv) { free(iv); }

/* Settings, vehicle and model taken together once the prior resolves for them (iv untouched otherwise); the cached
 * lookups dropped: the conicity in use and the Hopf curve may change with any of them. */
static hm_status apply(hm_interval iv, const hm_interval_config *cfg, const hm_vehicle *veh, hm_mode_model model,
                       char *why, size_t why_len) {
  hm_interval_config c;
  double lo, hi, at_fallback;
  const hm_status st = resolve(cfg, veh, model, &c, &lo, &hi, &at_fallback, why, why_len);
  if (st != HM_OK) return st;
  iv->cfg = c;
  iv->veh = *veh;
  iv->model = model;
  iv->prior_hopf_low_kmh = lo;
  iv->prior_hopf_high_kmh = hi;
  iv->fallback_hopf_kmh = at_fallback;
  iv->cache[0].valid = iv->cache[1].valid = 0;
  return HM_OK;
}

hm_status hm_interval_set_config(hm_interval iv, const hm_interval_config *cfg, const hm_vehicle *veh, char *why,
                                 size_t why_len) {
  if (!iv || !cfg || !veh) return HM_EINVAL;
  return apply(iv, cfg, veh, iv->model, why, why_len);
}

void hm_interval_set_table(hm_interval iv, const hm_table table) {
  if (!iv || !table) return;
  iv->table = table;
  iv->cache[0].valid = iv->cache[1].valid = 0; /* the cached lookups were the old table's */
}

hm_status hm_interval_set_model(hm_interval iv, hm_mode_model model) {
  if (!iv) return HM_EINVAL;
  const hm_interval_config cfg = iv->cfg; /* (a copy: apply writes iv->cfg) */
  const hm_vehicle veh = iv->veh;
  return apply(iv, &cfg, &veh, model, NULL, 0); /* the prior's Hopf speeds from the model */
}

void hm_interval_set_measurement_point(hm_interval iv, hm_measurement_point point) {
  if (iv && (point == HM_POINT_WHEELSET || point == HM_POINT_BOGIE_FRAME)) iv->point = point;
}

void hm_interval_prior(const hm_interval iv, double *lo, double *hi) {
  if (!iv) return;
  if (lo) *lo = iv->cfg.conicity_prior_low;
  if (hi) *hi = iv->cfg.conicity_prior_high;
}

void hm_interval_restart(hm_interval iv) {
  if (!iv) return;
  hm_evidence_restart(&iv->ev);
  iv->cache[0].valid = iv->cache[1].valid = 0;
}

void hm_interval_shift_time(hm_interval iv, double delta_s) {
  if (iv && isfinite(delta_s)) hm_evidence_shift_time(&iv->ev, delta_s);
}

/* The table's boundaries at (conicity, speed) through cache slot k. Outside the table's conicities the widened
 * lookup (tables.h: the cautious of the end conicity's and the extrapolated, not the end's alone); where the
 * extrapolation has no Hopf speed, the clamped lookup with the closed-form Hopf speed. */
static hm_status lookup(hm_interval iv, int k, double conicity, double speed_kmh, hm_table_lookup_result *out) {
  if (iv->cache[k].valid && iv->cache[k].conicity == conicity && iv->cache[k].speed_kmh == speed_kmh) {
    *out = iv->cache[k].r;
    return HM_OK;
  }
  hm_table_lookup_result r;
  hm_status st = hm_table_lookup_widened(iv->table, conicity, speed_kmh, &r);
  if (st == HM_EDOMAIN && isfinite(conicity) && isfinite(speed_kmh))
    st = hm_table_lookup(iv->table, conicity, speed_kmh, &r);
  if (st != HM_OK) return st;
  const int clamped = r.conicity != conicity && !r.widened;
  if (clamped || iv->model) {
    const double v = hopf_kmh(&iv->veh, iv->model, conicity);
    if (clamped) r.hopf_speed_kmh = v;
    /* a model's Hopf curve is exact to HM_MODE_MODEL_CURVE_ERR_KMH where the table interpolates */
    if (iv->model && v < HM_LINEAR_NO_HOPF_KMH) r.hopf_speed_kmh = v, r.error_speed_kmh = HM_MODE_MODEL_CURVE_ERR_KMH;
  }
  iv->cache[k].valid = 1;
  iv->cache[k].conicity = conicity;
  iv->cache[k].speed_kmh = speed_kmh;
  iv->cache[k].r = r;
  *out = r;
  return HM_OK;
}

/* The margin's estimate as the WARN rule of alarm.h reads it: its half-widths' z, and an estimate that counts but
 * not alone with its point and lower end. */
static void estimate_terms(const hm_interval iv, const hm_margin_estimate *g, const hm_evidence_interval *ev,
                           hm_hopf_interval *s) {
  s->interval_z = g && g->interval_z > 0.0 ? g->interval_z : 1.0;
  s->prior_hopf_low_kmh = iv->prior_hopf_low_kmh;
  s->estimate_with_prior = ev->usable && !ev->precise;
  s->estimate_hopf_kmh = s->estimate_low_kmh = NAN;
  if (s->estimate_with_prior) {
    s->estimate_hopf_kmh = g->hopf_model_kmh;
    s->estimate_low_kmh =
        ev->free_counts ? fmin(g->hopf_model_low_kmh, iv->ev.free_low_kmh) : g->hopf_model_low_kmh;
  }
}

hm_status hm_interval_update(hm_interval iv, double speed_kmh, const hm_margin_estimate *g, double now_s,
                             hm_hopf_interval *out) {
  if (!iv || !out || !isfinite(now_s)) return HM_EINVAL;
  const hm_interval_config *c = &iv->cfg;
  /* a bogie's or car's model holds the frame: a frame sensor shows one of its modes (issue #28) */
  const hm_evidence_config ec = {
      c->use_conicity_estimate, c->conicity_max_se, c->conicity_fallback, c->conicity_prior_low,
      iv->prior_hopf_low_kmh, iv->prior_hopf_high_kmh, iv->fallback_hopf_kmh,
      iv->point == HM_POINT_WHEELSET || (iv->model && hm_mode_model_kind(iv->model) != HM_MODEL_WHEELSET)};
  hm_evidence ev_next = iv->ev; /* (committed with the result: out untouched and nothing remembered on failure) */
  hm_evidence_interval ev;
  hm_evidence_weigh(&ev_next, &ec, g, now_s, &ev);
  const double lambda = ev.conicity, lambda_opt = ev.conicity_opt;
  double lo = ev.low_kmh, hi = ev.high_kmh;
  hm_hopf_interval s;
  s.conicity_from_estimate = ev.precise;
  s.conicity_from_prior = ev.from_prior;
  s.model_interval_used = ev.usable;
  s.conicity_se = ev.conicity_se;
  s.model_mismatch = ev.mismatch;
  s.hopf_free_used = ev.free_counts;
  s.conicity = lambda;
  s.outside_prior = g && g->conicity_valid && g->outside_prior && c->use_conicity_estimate;
  s.narrow_peak_ambiguous = g && g->ambiguous_at_s > 0.0 && now_s - g->ambiguous_at_s <= HM_ALARM_NARROW_HOLD_S;
  hm_table_lookup_result b, bo;
  hm_status st = lookup(iv, 0, lambda, speed_kmh, &b);
  if (st != HM_OK) return st;
  s.conicity_outside_table = b.conicity == lambda ? 0 : lambda > b.conicity ? 1 : -1;
  if (!ev.precise) { /* the table's value at the point is inside the interval it is shown with */
    lo = fmin(lo, b.hopf_speed_kmh - b.error_speed_kmh);
    hi = fmax(hi, b.hopf_speed_kmh + b.error_speed_kmh);
  }
  s.hopf_low_kmh = fmin(lo, b.hopf_speed_kmh);
  s.hopf_high_kmh = fmax(hi, b.hopf_speed_kmh);
  s.boundaries = b;
  /* the edge: at the conicity in use where the origin is stable there; inside the Hopf interval above the point
   * estimate, at the interval's optimistic end (found by the lookup at the conicity whose Hopf speed is hopf_high,
   * which the table's affine 1/V^2 makes exact) */
  s.edge_used_m = b.has_edge ? b.edge_amp_m : 0.0;
  if (!b.origin_stable && speed_kmh <= s.hopf_high_kmh) {
    st = lookup(iv, 1, lambda_opt, speed_kmh, &bo);
    if (st != HM_OK) return st;
    s.edge_used_m = bo.origin_stable && bo.has_edge ? bo.edge_amp_m : 0.0;
  }
  ev_next.precise = ev.precise;
  iv->ev = ev_next;
  estimate_terms(iv, g, &ev, &s);
  *out = s;
  return HM_OK;
}

void hm_interval_take_snapshot(const hm_interval iv, hm_interval_snapshot *out) {
  if (!iv || !out) return;
  out->precise = iv->ev.precise;
  out->se_ok = iv->ev.se_ok;
  out->precise_lost = iv->ev.precise_lost;
}

hm_status hm_interval_snapshot_validate(const hm_interval_snapshot *s, char *why, size_t len) {
  if (!s) return HM_EINVAL;
  const char *field = NULL;
  if (s->precise != 0 && s->precise != 1) field = "precise: 0 or 1";
  else if (s->se_ok != 0 && s->se_ok != 1) field = "se_ok: 0 or 1";
  else if (s->precise_lost != 0 && s->precise_lost != 1) field = "precise_lost: 0 or 1";
  if (!field) return HM_OK;
  if (why && len) snprintf(why, len, "interval: %s", field);
  return HM_EDOMAIN;
}

hm_status hm_interval_restore(hm_interval iv, const hm_interval_snapshot *s, char *why, size_t len) {
  if (!iv || !s) return HM_EINVAL;
  const hm_status st = hm_interval_snapshot_validate(s, why, len);
  if (st != HM_OK) return st;
  hm_interval_restart(iv);
  iv->ev.precise = s->precise;
  iv->ev.se_ok = s->se_ok;
  iv->ev.precise_lost = s->precise_lost; /* (precise_since NAN: the wait counts from the first update) */
  return HM_OK;
}
