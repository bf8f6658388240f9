/* Distance to the Hopf speed from identified hunting modes, model-based and model-free (see margin.h). */
#include "hunting_monitor/margin.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hunting_monitor/linear.h"

/* The Hopf speed reported when the linear model is stable at every speed at a conicity. */
static const double NO_HOPF_KMH = 1e4;

typedef struct {
  double t_end_s, speed_kmh;
  double sigma, sigma_stat;     /* decay rate and its statistical error [1/s] */
  double lambda, lambda_se;     /* the window's conicity and its total error */
  double lambda_stat, lambda_sys; /* the statistical and systematic parts of that error */
} window;

struct hm_margin_s {
  hm_margin_config cfg;
  hm_vehicle veh;
  hm_linear_coef coef;
  window w[HM_MARGIN_MAX_WINDOWS];
  size_t head, n;
  double last_end_s;
  window pending;               /* the current steady stretch, not yet committed */
  int have_pending;
};

void hm_margin_config_default(hm_margin_config *c) {
  c->frequency_model_error = 0.01;
  c->decay_rate_model_error = 0.10;
  c->max_speed_spread_kmh = 10.0;
  c->min_speed_kmh = 200.0;
  c->memory_s = 900.0;
  c->min_speed_span_kmh = 20.0;
  c->max_extrapolation_kmh = 150.0;
  c->interval_z = 2.0;
}

hm_status hm_margin_config_validate(const hm_margin_config *c, char *why, size_t len) {
  if (!c) return HM_EINVAL;
  const struct {
    const char *name;
    double v, lo, hi;
  } f[] = {{"frequency_model_error", c->frequency_model_error, 0.0, 0.5},
           {"decay_rate_model_error", c->decay_rate_model_error, 0.0, 1.0},
           {"max_speed_spread_kmh", c->max_speed_spread_kmh, 0.0, 200.0},
           {"min_speed_kmh", c->min_speed_kmh, 0.0, 1000.0},
           {"memory_s", c->memory_s, 1.0, 1e6},
           {"min_speed_span_kmh", c->min_speed_span_kmh, 1.0, 1000.0},
           {"max_extrapolation_kmh", c->max_extrapolation_kmh, 1.0, 1000.0},
           {"interval_z", c->interval_z, 0.5, 10.0}};
  for (size_t i = 0; i < sizeof f / sizeof f[0]; ++i)
    if (!(f[i].v >= f[i].lo && f[i].v <= f[i].hi)) {
      if (why && len) snprintf(why, len, "%s: must be in %g..%g (got %g)", f[i].name, f[i].lo, f[i].hi, f[i].v);
      return HM_EDOMAIN;
    }
  return HM_OK;
}

hm_status hm_margin_create(const hm_margin_config *cfg, const hm_vehicle *veh, hm_margin *out, char *why, size_t len) {
  if (!cfg || !veh || !out) return HM_EINVAL;
  hm_status st = hm_margin_config_validate(cfg, why, len);
  if (st == HM_OK) st = hm_vehicle_validate(veh, why, len);
  if (st != HM_OK) return st;
  hm_margin m = calloc(1, sizeof *m);
  if (!m) return HM_ENOMEM;
  m->cfg = *cfg;
  m->veh = *veh;
  hm_linear_coef_from_vehicle(veh, &m->coef);
  hm_margin_reset(m);
  *out = m;
  return HM_OK;
}

void hm_margin_destroy(hm_margin m) { free(m); }

void hm_margin_reset(hm_margin m) {
  if (!m) return;
  m->head = m->n = 0;
  m->last_end_s = -INFINITY;
  m->have_pending = 0;
}

double hm_margin_hopf_kmh(const hm_margin m, double conicity) {
  double v_mps;
  if (!m || !(conicity > 0.0) || hm_linear_critical_speed(&m->veh, conicity, &v_mps) != HM_OK) return NO_HOPF_KMH;
  return fmin(hm_kmh_from_mps(v_mps), NO_HOPF_KMH);
}

/* A window's checks and inversion into *w; the verdict says whether it can be used. */
static hm_window_verdict prepare(const hm_margin m, double t_end, double speed_kmh, double spread_kmh,
                                 const hm_mode_estimate *mode, window *w) {
  const hm_margin_config *c = &m->cfg;
  if (!mode->valid) return HM_WINDOW_MODE_INVALID;
  if (spread_kmh > c->max_speed_spread_kmh) return HM_WINDOW_SPEED_VARIED;
  if (speed_kmh < c->min_speed_kmh) return HM_WINDOW_TOO_SLOW;
  if (t_end - mode->window_s < m->last_end_s - 1e-9) return HM_WINDOW_OVERLAPS;
  /* statistical and systematic errors of the measured mode */
  const double sys_sigma = c->decay_rate_model_error * fabs(mode->decay_rate_1_s);
  const double sys_f = c->frequency_model_error * mode->frequency_hz;
  const double e_sigma = hypot(mode->decay_rate_se_1_s, sys_sigma), e_f = hypot(mode->frequency_se_hz, sys_f);
  hm_conicity_inversion inv;
  if (hm_conicity_from_mode(&m->coef, speed_kmh, mode->decay_rate_1_s, e_sigma, mode->frequency_hz, e_f, 1e-9, 60,
                            &inv) != HM_OK)
    return HM_WINDOW_NO_INVERSION;
  /* the systematic part of the conicity's error: the weighted sensitivities applied to the systematic errors */
  const double js = inv.dsigma_dconicity / (e_sigma * e_sigma), jf = inv.dfrequency_dconicity / (e_f * e_f);
  const double info = inv.dsigma_dconicity * js + inv.dfrequency_dconicity * jf;
  const double lambda_sys = hypot(js * sys_sigma, jf * sys_f) / info;
  w->t_end_s = t_end;
  w->speed_kmh = speed_kmh;
  w->sigma = mode->decay_rate_1_s;
  w->sigma_stat = mode->decay_rate_se_1_s;
  w->lambda = inv.conicity;
  w->lambda_se = inv.conicity_se;
  w->lambda_sys = fmin(lambda_sys, inv.conicity_se);
  w->lambda_stat = sqrt(fmax(inv.conicity_se * inv.conicity_se - w->lambda_sys * w->lambda_sys, 0.0));
  return HM_WINDOW_USED;
}

/* Keep a window (the ring drops the oldest beyond its size); any provisional one is superseded. */
static void store(hm_margin m, const window *w) {
  m->w[m->head] = *w;
  m->head = (m->head + 1) % HM_MARGIN_MAX_WINDOWS;
  if (m->n < HM_MARGIN_MAX_WINDOWS) ++m->n;
  m->last_end_s = w->t_end_s;
  m->have_pending = 0;
}

hm_status hm_margin_add_window(hm_margin m, double t_end, double speed_kmh, double spread_kmh,
                               const hm_mode_estimate *mode, hm_window_verdict *verdict) {
  if (!m || !mode || !verdict || !isfinite(t_end) || !isfinite(speed_kmh) || !isfinite(spread_kmh)) return HM_EINVAL;
  window w;
  *verdict = prepare(m, t_end, speed_kmh, spread_kmh, mode, &w);
  if (*verdict != HM_WINDOW_USED) return HM_OK;
  store(m, &w);
  return HM_OK;
}

hm_status hm_margin_set_pending(hm_margin m, double t_end, double speed_kmh, double spread_kmh,
                                const hm_mode_estimate *mode, hm_window_verdict *verdict) {
  if (!m || !mode || !verdict || !isfinite(t_end) || !isfinite(speed_kmh) || !isfinite(spread_kmh)) return HM_EINVAL;
  window w;
  *verdict = prepare(m, t_end, speed_kmh, spread_kmh, mode, &w);
  m->have_pending = *verdict == HM_WINDOW_USED;
  if (m->have_pending) m->pending = w;
  return HM_OK;
}

void hm_margin_commit_pending(hm_margin m) {
  if (!m || !m->have_pending) return;
  store(m, &m->pending);
}

/* (a): inverse-variance mean of the windows' conicities; systematic errors do not average out. */
static void model_based(const hm_margin m, const window *const *ws, size_t n, hm_margin_estimate *r) {
  double sw = 0.0, swl = 0.0, sw2stat = 0.0, swsys = 0.0;
  for (size_t k = 0; k < n; ++k) {
    const double wk = 1.0 / (ws[k]->lambda_se * ws[k]->lambda_se);
    sw += wk;
    swl += wk * ws[k]->lambda;
    sw2stat += wk * wk * ws[k]->lambda_stat * ws[k]->lambda_stat;
    swsys += wk * ws[k]->lambda_sys;
  }
  if (n == 0 || !(sw > 0.0)) return;
  r->conicity_valid = 1;
  r->conicity = swl / sw;
  r->conicity_se = hypot(sqrt(sw2stat) / sw, swsys / sw);
  const double z = m->cfg.interval_z;
  r->hopf_model_valid = 1;
  r->hopf_model_kmh = hm_margin_hopf_kmh(m, r->conicity);
  r->conicity_low = fmax(r->conicity - z * r->conicity_se, 1e-6);
  r->conicity_high = r->conicity + z * r->conicity_se;
  r->hopf_model_low_kmh = hm_margin_hopf_kmh(m, r->conicity_high);
  r->hopf_model_high_kmh = hm_margin_hopf_kmh(m, r->conicity_low);
}

/* (b): weighted least squares of sigma on x = 1000 / v; the zero of the line with a delta-method interval. */
static void model_free(const hm_margin m, const window *const *ws, size_t n, hm_margin_estimate *r) {
  const hm_margin_config *c = &m->cfg;
  if (n < 2 || r->speed_max_kmh - r->speed_min_kmh < c->min_speed_span_kmh) return;
  double s0 = 0.0, s1 = 0.0, s2 = 0.0, t0 = 0.0, t1 = 0.0;
  for (size_t k = 0; k < n; ++k) {
    const double wk = 1.0 / (ws[k]->sigma_stat * ws[k]->sigma_stat), x = 1000.0 / ws[k]->speed_kmh;
    s0 += wk, s1 += wk * x, s2 += wk * x * x, t0 += wk * ws[k]->sigma, t1 += wk * x * ws[k]->sigma;
  }
  const double det = s0 * s2 - s1 * s1;
  if (!(det > 0.0)) return;
  const double beta = (s0 * t1 - s1 * t0) / det, alpha = (s2 * t0 - s1 * t1) / det;
  double var_a = s2 / det, var_b = s0 / det, cov_ab = -s1 / det;
  if (n > 2) { /* scale by the residual variance when there are degrees of freedom (never below the stated errors) */
    double chi2 = 0.0;
    for (size_t k = 0; k < n; ++k) {
      const double d = (ws[k]->sigma - alpha - beta * 1000.0 / ws[k]->speed_kmh) / ws[k]->sigma_stat;
      chi2 += d * d;
    }
    const double f = fmax(1.0, chi2 / (double)(n - 2));
    var_a *= f, var_b *= f, cov_ab *= f;
  }
  const double z = c->interval_z;
  if (!(beta + z * sqrt(var_b) < 0.0)) return; /* no significant approach to zero with speed */
  const double xh = -alpha / beta;
  /* d xh / d alpha = -1/beta, d xh / d beta = alpha / beta^2 */
  const double var_x = (var_a + xh * xh * var_b + 2.0 * xh * cov_ab) / (beta * beta);
  if (!(xh > 0.0) || !isfinite(var_x)) return;
  const double se_x = sqrt(var_x), vh = 1000.0 / xh;
  if (vh > r->speed_max_kmh + c->max_extrapolation_kmh) return;
  r->hopf_free_valid = 1;
  r->hopf_free_kmh = vh;
  r->hopf_free_low_kmh = 1000.0 / (xh + z * se_x);
  r->hopf_free_high_kmh = xh - z * se_x > 1000.0 / NO_HOPF_KMH ? 1000.0 / (xh - z * se_x) : NO_HOPF_KMH;
}

void hm_margin_read(const hm_margin m, double now, hm_margin_estimate *out) {
  if (!m || !out) return;
  hm_margin_estimate r;
  memset(&r, 0, sizeof r);
  const window *ws[HM_MARGIN_MAX_WINDOWS];
  size_t n = 0;
  r.speed_min_kmh = INFINITY;
  r.speed_max_kmh = -INFINITY;
  for (size_t k = 0; k < m->n; ++k) {
    const window *w = &m->w[(m->head + HM_MARGIN_MAX_WINDOWS - 1 - k) % HM_MARGIN_MAX_WINDOWS];
    if (isfinite(now) && now - w->t_end_s > m->cfg.memory_s) continue;
    ws[n++] = w;
    r.speed_min_kmh = fmin(r.speed_min_kmh, w->speed_kmh);
    r.speed_max_kmh = fmax(r.speed_max_kmh, w->speed_kmh);
  }
  if (m->have_pending && n < HM_MARGIN_MAX_WINDOWS) { /* the current stretch counts, provisionally */
    ws[n++] = &m->pending;
    r.speed_min_kmh = fmin(r.speed_min_kmh, m->pending.speed_kmh);
    r.speed_max_kmh = fmax(r.speed_max_kmh, m->pending.speed_kmh);
  }
  r.n_windows = (unsigned)n;
  if (n == 0) r.speed_min_kmh = r.speed_max_kmh = 0.0;
  model_based(m, ws, n, &r);
  model_free(m, ws, n, &r);
  r.model_mismatch = r.hopf_model_valid && r.hopf_free_valid &&
                     (r.hopf_model_high_kmh < r.hopf_free_low_kmh || r.hopf_free_high_kmh < r.hopf_model_low_kmh);
  *out = r;
}
