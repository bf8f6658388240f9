/* Sensor streams of a simulated run (see sensor_sim.h). */
#include "hunting_monitor/sensor_sim.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hunting_monitor/excitation.h"
#include "hunting_monitor/integrate.h"
#include "hunting_monitor/linear.h"
#include "rng.h"
#include "validate.h"

struct hm_sensor_sim_s {
  hm_sensor_sim_config cfg;
  hm_excited_model em;      /* the wheelset's equations; for a system only its speed profile and distance */
  int generic;              /* 1: a system (sys, point) instead of the wheelset */
  hm_system sys;
  hm_sensor_point point;
  size_t n;                 /* states */
  hm_track track;           /* owned; NULL on a perfect track */
  hm_dopri integ;
  double t_s, x[HM_SYSTEM_MAX_DIM];
  uint64_t accel_k, speed_k; /* index of the next sample of each stream */
  uint64_t rng;
  const hm_sensor_sink *sink;
  double t_end_s;
  int stopped;
  hm_status failed;         /* a sample's acceleration could not be computed: the run stops with this status */
};

void hm_sensor_sim_config_default(hm_sensor_sim_config *cfg) {
  cfg->v_start_kmh = 450.0;
  cfg->v_end_kmh = 450.0;
  cfg->ramp_s = 0.0;
  cfg->n_profile = 0;
  cfg->irregularity_scale = 0.0;
  cfg->wavelength_min_m = 3.0;
  cfg->wavelength_max_m = 120.0;
  cfg->track_seed = 1;
  cfg->noise_seed = 1;
  cfg->accel_rate_hz = 2000.0;
  cfg->accel_noise_mps2 = 0.05;
  cfg->speed_rate_hz = 10.0;
  cfg->rtol = 1e-8;
  cfg->atol = 1e-11;
  cfg->max_step_s = 2e-3;
}

static hm_status refuse(char *why, size_t len, hm_status st, const char *fmt, ...) {
  if (why && len) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(why, len, fmt, ap);
    va_end(ap);
  }
  return st;
}

/* The settings' checks (validate.h), common to both kinds of run; n the state dimension of x0 (may be NULL). */
static hm_status check_config(const hm_sensor_sim_config *c, const double *x0, size_t n, char *why, size_t why_len) {
  const hm_field_check f[] = {{"v_start_kmh", c->v_start_kmh, HM_RULE_POSITIVE, 0.0, 0.0},
                              {"v_end_kmh", c->v_end_kmh, HM_RULE_POSITIVE, 0.0, 0.0},
                              {"ramp_s", c->ramp_s, HM_RULE_NONNEG, 0.0, 0.0},
                              {"irregularity_scale", c->irregularity_scale, HM_RULE_NONNEG, 0.0, 0.0},
                              {"wavelength_min_m", c->wavelength_min_m, HM_RULE_RANGE, 0.2, 1000.0},
                              {"wavelength_max_m", c->wavelength_max_m, HM_RULE_RANGE, 0.2, 1000.0},
                              {"accel_rate_hz", c->accel_rate_hz, HM_RULE_RANGE_OPEN, 0.0, 1e6},
                              {"speed_rate_hz", c->speed_rate_hz, HM_RULE_RANGE_OPEN, 0.0, 1e6},
                              {"accel_noise_mps2", c->accel_noise_mps2, HM_RULE_NONNEG, 0.0, 0.0},
                              {"rtol", c->rtol, HM_RULE_POSITIVE, 0.0, 0.0},
                              {"atol", c->atol, HM_RULE_NONNEG, 0.0, 0.0},
                              {"max_step_s", c->max_step_s, HM_RULE_NONNEG, 0.0, 0.0}};
  const hm_status st = hm_check_fields(f, HM_COUNT_OF(f), why, why_len);
  if (st != HM_OK) return st;
  if (!(c->wavelength_max_m > c->wavelength_min_m))
    return hm_reject(why, why_len, "wavelength_max_m", "must be above wavelength_min_m", c->wavelength_max_m);
  if (c->n_profile && !hm_speed_profile_valid(c->profile_t_s, c->profile_v_kmh, c->n_profile))
    return refuse(why, why_len, HM_EDOMAIN, "the speed profile needs at most %d points, speeds > 0 km/h at times "
                  "increasing from 0 s", HM_SPEED_PROFILE_MAX);
  if (x0)
    for (size_t i = 0; i < n; ++i)
      if (!isfinite(x0[i])) return refuse(why, why_len, HM_EDOMAIN, "initial state not finite");
  return HM_OK;
}

/* The run over veh's profile (for a system: veh only carries the profile), n states from x0. */
static hm_status create_run(const hm_vehicle *veh, const hm_sensor_sim_config *c, const double *x0, size_t n,
                            hm_sensor_sim *out, char *why, size_t why_len) {
  hm_sensor_sim s = calloc(1, sizeof *s);
  if (!s) return refuse(why, why_len, HM_ENOMEM, "out of memory");
  s->cfg = *c;
  s->n = n;
  hm_status st = HM_OK;
  if (c->irregularity_scale > 0.0)
    st = hm_track_create(c->wavelength_min_m, c->wavelength_max_m, c->irregularity_scale, c->track_seed, &s->track);
  if (st == HM_OK)
    st = c->n_profile ? hm_excited_model_init_profile(&s->em, veh, s->track, c->profile_t_s, c->profile_v_kmh, c->n_profile)
                      : hm_excited_model_init(&s->em, veh, s->track, c->v_start_kmh, c->v_end_kmh, c->ramp_s);
  if (st == HM_OK && !(s->integ = hm_dopri_create(n))) st = HM_ENOMEM;
  if (st != HM_OK) {
    hm_sensor_sim_destroy(s);
    return refuse(why, why_len, st, st == HM_ENOMEM ? "out of memory" : "cannot set up the run");
  }
  if (x0) memcpy(s->x, x0, n * sizeof(double));
  s->rng = c->noise_seed * 0x9E3779B97F4A7C15ull + 0x632BE59BD9B4E019ull;
  *out = s;
  return HM_OK;
}

hm_status hm_sensor_sim_create(const hm_vehicle *veh, const hm_sensor_sim_config *cfg, const double x0[4],
                               hm_sensor_sim *out, char *why, size_t why_len) {
  if (!veh || !cfg || !out) return refuse(why, why_len, HM_EINVAL, "missing argument");
  hm_status st = hm_vehicle_validate(veh, why, why_len);
  if (st == HM_OK) st = check_config(cfg, x0, 4, why, why_len);
  return st == HM_OK ? create_run(veh, cfg, x0, 4, out, why, why_len) : st;
}

hm_status hm_sensor_sim_create_system(const hm_system *sys, const hm_sensor_point *point,
                                      const hm_sensor_sim_config *cfg, const double *x0, hm_sensor_sim *out,
                                      char *why, size_t why_len) {
  if (!sys || !point || !cfg || !out) return refuse(why, why_len, HM_EINVAL, "missing argument");
  if (hm_system_validate(sys) != HM_OK) return refuse(why, why_len, HM_EINVAL, "not a valid model");
  if (!hm_sensor_point_valid(sys, point)) return refuse(why, why_len, HM_EINVAL, "the sensor is not on the model");
  hm_status st = check_config(cfg, x0, sys->dim, why, why_len);
  hm_vehicle profile_only;
  hm_vehicle_default(&profile_only);
  hm_sensor_sim s = NULL;
  if (st == HM_OK) st = create_run(&profile_only, cfg, x0, sys->dim, &s, why, why_len);
  if (st != HM_OK) return st;
  s->generic = 1;
  s->sys = *sys;
  s->point = *point;
  *out = s;
  return HM_OK;
}

size_t hm_sensor_sim_dim(const hm_sensor_sim s) { return s ? s->n : 0; }

void hm_sensor_sim_destroy(hm_sensor_sim s) {
  if (!s) return;
  hm_dopri_destroy(s->integ);
  hm_track_destroy(s->track);
  free(s);
}

/* A system's right-hand side along the profile over the track: wheelset i meets the track at the distance of the
 * leading one less their spacing. */
static hm_status system_rhs(double t, const double *x, double *dxdt, void *ctx) {
  const hm_sensor_sim s = (hm_sensor_sim)ctx;
  double yt[HM_SYSTEM_MAX_WHEELSETS] = {0.0};
  if (s->track) {
    const double d = hm_excited_distance_m(&s->em, t);
    for (size_t i = 0; i < s->sys.n_wheelsets; ++i)
      yt[i] = hm_track_at(s->track, d - (s->sys.wheelset_x_m[0] - s->sys.wheelset_x_m[i]));
  }
  return s->sys.rhs_track(s->sys.model, hm_mps_from_kmh(hm_excited_speed_kmh(&s->em, t)), x, yt, dxdt);
}

/* The true acceleration at the sensor from the state x at t. */
static hm_status true_accel(hm_sensor_sim s, double t, double *x, double *a) {
  double dx[HM_SYSTEM_MAX_DIM];
  if (!s->generic) {
    hm_status st = hm_excited_rhs(t, x, dx, &s->em);
    *a = dx[1];
    return st;
  }
  hm_status st = system_rhs(t, x, dx, s);
  double sum = 0.0;
  for (size_t j = 0; j < s->point.n_terms; ++j) sum += s->point.weight[j] * dx[s->point.state[j]];
  *a = sum;
  return st;
}

/* Deliver every sample due by t_hi from the state x(t) given by at(t); 1 if a callback stopped. A sample within
 * 1e-9 of a sample period past t_hi counts as due (k / rate may round above an end time that is a multiple). */
static int deliver(hm_sensor_sim s, double t_hi, hm_status (*at)(void *, double, double *), void *at_ctx) {
  const hm_sensor_sink *k = s->sink;
  const double slack = 1e-9 / s->cfg.accel_rate_hz;
  for (;;) {
    const double ta = (double)s->accel_k / s->cfg.accel_rate_hz;
    if (ta > t_hi + slack || ta > s->t_end_s + slack) return 0;
    for (;;) { /* the speed samples due by then */
      const double tv = (double)s->speed_k / s->cfg.speed_rate_hz;
      if (tv > ta) break;
      ++s->speed_k;
      if (k && k->speed && k->speed(k->ctx, tv, hm_excited_speed_kmh(&s->em, tv))) return 1;
    }
    double x[HM_SYSTEM_MAX_DIM], a = 0.0;
    if (at(at_ctx, ta, x) != HM_OK) return 1;
    const hm_status st = true_accel(s, ta, x, &a);
    if (st != HM_OK || !isfinite(a)) { /* never a 0 for a sample that could not be computed */
      s->failed = st != HM_OK ? st : HM_ENONFINITE;
      return 1;
    }
    const double noise = s->cfg.accel_noise_mps2 > 0.0 ? s->cfg.accel_noise_mps2 * hm_rng_gaussian(&s->rng) : 0.0;
    ++s->accel_k;
    if (k && k->accel && k->accel(k->ctx, ta, a + noise, a, x)) return 1;
  }
}

typedef struct {
  hm_dopri integ;
  double t_old, t_new;
} dense_ctx;

static hm_status dense_at(void *ctx, double t, double *x) {
  const dense_ctx *d = (const dense_ctx *)ctx;
  return hm_dopri_dense(d->integ, fmin(fmax(t, d->t_old), d->t_new), x);
}

static hm_status state_at(void *ctx, double t, double *x) {
  (void)t;
  const hm_sensor_sim s = (hm_sensor_sim)ctx;
  memcpy(x, s->x, s->n * sizeof(double));
  return HM_OK;
}

static int observer(hm_dopri integ, double t_old, double t_new, const double *x_new, void *ctx) {
  (void)x_new;
  hm_sensor_sim s = (hm_sensor_sim)ctx;
  dense_ctx d = {integ, t_old, t_new};
  if (deliver(s, t_new, dense_at, &d)) {
    s->stopped = 1;
    return 1;
  }
  return 0;
}

hm_status hm_sensor_sim_run(hm_sensor_sim s, double t_end_s, const hm_sensor_sink *sink) {
  if (!s || !(t_end_s >= s->t_s) || !isfinite(t_end_s)) return HM_EINVAL;
  s->sink = sink;
  s->t_end_s = t_end_s;
  s->stopped = 0;
  s->failed = HM_OK;
  /* the samples due now (the first one at t = 0), from the current state */
  if (deliver(s, s->t_s, state_at, s)) return s->failed;
  if (t_end_s == s->t_s) return HM_OK;
  const hm_ode_system sys = s->generic ? (hm_ode_system){s->n, system_rhs, NULL, s}
                                       : (hm_ode_system){4, hm_excited_rhs, NULL, &s->em};
  const hm_dopri_options opt = {s->cfg.rtol, s->cfg.atol, 0.0, s->cfg.max_step_s, 0, 0};
  double x[HM_SYSTEM_MAX_DIM], t_reached = s->t_s;
  memcpy(x, s->x, s->n * sizeof(double));
  hm_status st = hm_dopri_integrate(s->integ, &sys, &opt, s->t_s, t_end_s, x, &t_reached, observer, s, NULL);
  if (st != HM_OK) return st;
  if (s->failed != HM_OK) return s->failed;
  memcpy(s->x, x, s->n * sizeof(double));
  s->t_s = t_reached;
  return HM_OK;
}

double hm_sensor_sim_time(const hm_sensor_sim s) { return s ? s->t_s : NAN; }

void hm_sensor_sim_state(const hm_sensor_sim s, double *x) {
  if (s && x) memcpy(x, s->x, s->n * sizeof(double));
}

hm_status hm_sensor_sim_set_state(hm_sensor_sim s, const double *x) {
  if (!s || !x) return HM_EINVAL;
  for (size_t i = 0; i < s->n; ++i)
    if (!isfinite(x[i])) return HM_EINVAL;
  memcpy(s->x, x, s->n * sizeof(double));
  return HM_OK;
}

double hm_sensor_sim_speed_kmh(const hm_sensor_sim s, double t_s) {
  return s ? hm_excited_speed_kmh(&s->em, t_s) : NAN;
}

double hm_sensor_sim_track_rms_m(const hm_sensor_sim s) { return s ? hm_track_rms_m(s->track) : 0.0; }
