/* The Hopf interval the evidence gives (evidence.h; the rules in alarm.h). */
#include "evidence.h"

#include <math.h>

static int sticky(hm_sticky_flag *f, int condition, double now) {
  if (condition) {
    f->on = 1;
    f->false_since_s = NAN;
  } else if (f->on) {
    if (isnan(f->false_since_s)) f->false_since_s = now;
    if (now - f->false_since_s >= HM_ALARM_FLAG_CLEAR_S) f->on = 0;
  }
  return f->on;
}

/* The estimate's use alone (alarm.h): at once the first time, at once dropped, and once dropped taken again only after
 * its condition has held for HM_ALARM_FLAG_CLEAR_S. */
static int regained(hm_evidence *ev, int condition, double now) {
  if (!condition) {
    if (ev->precise) ev->precise_lost = 1;
    ev->precise_since = NAN;
    return 0;
  }
  if (isnan(ev->precise_since)) ev->precise_since = now;
  if (ev->precise_lost && now - ev->precise_since < HM_ALARM_FLAG_CLEAR_S) return 0;
  ev->precise_lost = 0;
  return 1;
}

void hm_evidence_restart(hm_evidence *ev) {
  if (!ev) return;
  ev->precise = ev->precise_lost = ev->se_ok = 0;
  ev->precise_since = NAN;
  ev->mismatch.on = ev->free_beside.on = 0;
}

void hm_evidence_shift_time(hm_evidence *ev, double delta_s) {
  if (!ev) return;
  ev->precise_since += delta_s;
  ev->mismatch.false_since_s += delta_s;
  ev->free_beside.false_since_s += delta_s;
}

/* Which estimates count (alarm.h), each flag held against its chatter. */
static void weigh(hm_evidence *ev, const hm_evidence_config *c, const hm_margin_estimate *g, double now,
                  hm_evidence_interval *iv) {
  const int have = c->use_conicity_estimate && g && g->conicity_valid && g->hopf_model_valid;
  /* the margin's flags as the level uses them, held against the provisional window's chatter (alarm.h) */
  iv->mismatch = sticky(&ev->mismatch, g && g->model_mismatch, now);
  /* the model-based interval counts from an axle-box sensor on a vehicle that behaves like its model (alarm.h) */
  const int usable_model = have && c->axle && !iv->mismatch;
  /* the standard error within conicity_max_se, once so within HM_ALARM_SE_HYSTERESIS times it (its own hysteresis,
   * whatever else keeps the estimate from being used alone) */
  const double max_se = ev->se_ok ? HM_ALARM_SE_HYSTERESIS * c->conicity_max_se : c->conicity_max_se;
  ev->se_ok = usable_model && g->conicity_se <= max_se;
  const int unconfirmed_change = g && g->n_changes > 0 && g->windows_since_change < 2;
  /* an estimate enters alone when precise, inside the prior and not a change's first window (once it stopped being
   * so, only after it has been so again for HM_ALARM_FLAG_CLEAR_S, meanwhile combined with the prior); otherwise
   * combined with the prior (the more cautious): one precise but above the prior's range (its Hopf speed lower: worn
   * beyond the prior), or any with a lightly damped mode held (alarm.h) */
  const int alone = ev->se_ok && !g->outside_prior && !unconfirmed_change;
  iv->precise = regained(ev, alone, now); /* (ev->precise: the caller's, once the update has its boundaries) */
  const int cautious_precise = ev->se_ok && g->outside_prior > 0;
  /* a change's first window, precise, is the evidence of the change (margin.h): combined with the prior (the more
   * cautious) whatever its distance from the Hopf speed (issue #27: 0.12 -> 0.18 +- 0.008 at 300 km/h had left the
   * prior alone, WATCH at 450 km/h above the new Hopf speed of 444.9) */
  const int change_evidence = ev->se_ok && unconfirmed_change;
  iv->usable = iv->precise || alone || cautious_precise || change_evidence || (usable_model && g->near_evidence);
  /* the model-free interval's lower end counts when the model-based one does not (a mismatch, a sensor off the axle
   * box; then its upper end too: it is the only evidence of where the vehicle's Hopf speed lies, and on a bogie 40-60
   * km/h less stable than the model it gave WARN a median 20 s before 3 mm, 5 s without), and beside it when its
   * regression has residuals to check it (three windows or more) and a lightly damped mode is held: a zero crossing
   * extrapolated from decay rates of -5..-11 1/s alone is wide (on a ramp from 271 to 301 km/h, 322 [309, ...] for a
   * Hopf speed of 357) and its lower end is no evidence */
  iv->free_alone = g && (iv->mismatch || !c->axle);
  const int free_valid = g && g->hopf_free_valid;
  if (free_valid) ev->free_low_kmh = g->hopf_free_low_kmh, ev->free_high_kmh = g->hopf_free_high_kmh;
  const int free_beside = sticky(&ev->free_beside,
                                 free_valid && g->n_windows >= HM_ALARM_FREE_MIN_WINDOWS && g->near_evidence &&
                                     !iv->free_alone,
                                 now);
  iv->free_counts = (free_valid && iv->free_alone) || free_beside; /* (held: its last valid interval) */
}

void hm_evidence_weigh(hm_evidence *ev, const hm_evidence_config *c, const hm_margin_estimate *g, double now_s,
                       hm_evidence_interval *out) {
  if (!ev || !c || !out) return;
  hm_evidence_interval iv;
  weigh(ev, c, g, now_s, &iv);
  /* the interval from the prior's, and the conicity in use with the interval's optimistic end */
  iv.conicity = c->conicity_fallback, iv.conicity_opt = c->conicity_prior_low, iv.conicity_se = 0.0;
  iv.low_kmh = c->prior_hopf_low_kmh, iv.high_kmh = c->prior_hopf_high_kmh;
  iv.from_prior = !iv.precise;
  if (iv.precise) {
    iv.conicity = g->conicity;
    iv.conicity_opt = g->conicity_low;
    iv.low_kmh = g->hopf_model_low_kmh;
    iv.high_kmh = g->hopf_model_high_kmh;
    iv.conicity_se = g->conicity_se;
  } else if (iv.usable) {
    if (g->hopf_model_kmh < c->fallback_hopf_kmh) iv.conicity = g->conicity, iv.conicity_se = g->conicity_se;
    iv.low_kmh = fmin(iv.low_kmh, g->hopf_model_low_kmh);
    if (g->hopf_model_high_kmh < iv.high_kmh) iv.high_kmh = g->hopf_model_high_kmh, iv.conicity_opt = g->conicity_low;
    /* the prior sets the interval only where the estimate moved neither end */
    iv.from_prior = iv.low_kmh == c->prior_hopf_low_kmh && iv.high_kmh == c->prior_hopf_high_kmh;
  }
  if (iv.free_counts) {
    iv.low_kmh = fmin(iv.low_kmh, ev->free_low_kmh);
    if (iv.free_alone && ev->free_high_kmh < iv.high_kmh) iv.high_kmh = ev->free_high_kmh;
  }
  *out = iv;
}
