/* The hunting mode of any vehicle model against the conicity (see mode_model.h). */
#include "hunting_monitor/mode_model.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hunting_monitor/excitation.h"
#include "hunting_monitor/linear.h"
#include "lapack.h"
#include "whittle.h"

enum { NMAX = HM_SYSTEM_MAX_DIM, NPM = HM_WHITTLE_MAX_NP, NREAD = HM_MODE_MODEL_READING_MAX_BINS };

struct hm_mode_model_s {
  hm_model_kind kind;
  hm_car params;         /* the car's, or its bogie's, or its bogie's wheelset's: the conicity set in place */
  hm_wheelset_system ws; /* the system of the kind, at the conicity last set */
  hm_bogie_model bogie;
  hm_car_model car;
  hm_system sys;
  double conicity;       /* the conicity the system holds (NAN: none yet) */
  hm_car given;          /* the parameters as created */
  double band_lo_hz, band_hi_hz; /* the least-damped root is sought in this band */
  double grid_hopf_kmh[HM_MODE_MODEL_GRID]; /* the Hopf curve: NAN not computed yet, +inf none, 0 unstable at all */
  double grid_f_hz[HM_MODE_MODEL_GRID];     /* its critical mode's frequency */
  int have_sensor;                          /* the reading's sensor (hm_mode_model_set_sensor) */
  hm_sensor_point sensor;
  hm_mode_model_gain_fn gain;               /* the measured signal's filters (NULL: none) and their context */
  const void *gain_ctx;
  double rd_f[NREAD], rd_w[NREAD], rd_u[NREAD], rd_p[NREAD]; /* the reading's bins and the model's spectrum */
};

/* 1 when every root decays (re < 0). */
static int stable_roots(const double *re, size_t n) {
  for (size_t i = 0; i < n; ++i)
    if (!(re[i] < 0.0)) return 0;
  return 1;
}

static hm_status set_conicity(hm_mode_model m, double conicity) {
  if (m->conicity == conicity) return HM_OK;
  hm_vehicle *w = &m->params.bogie.wheelset;
  hm_status st = hm_vehicle_set_conicity_at_zero(w, conicity);
  if (st != HM_OK) return st;
  switch (m->kind) {
    case HM_MODEL_WHEELSET: st = hm_wheelset_system_init(&m->ws, w, &m->sys); break;
    case HM_MODEL_BOGIE: st = hm_bogie_model_init(&m->bogie, &m->params.bogie, 0, &m->sys); break;
    case HM_MODEL_CAR: st = hm_car_model_init(&m->car, &m->params, 0, &m->sys); break;
    default: st = HM_EINVAL;
  }
  m->conicity = st == HM_OK ? conicity : NAN;
  return st;
}

static hm_status create(hm_model_kind kind, const hm_car *params, hm_mode_model *out) {
  if (!out) return HM_EINVAL;
  hm_mode_model m = calloc(1, sizeof *m);
  if (!m) return HM_ENOMEM;
  m->kind = kind;
  m->params = *params;
  m->given = *params;
  m->band_lo_hz = HM_MODE_MODEL_BAND_LOW_HZ;
  m->band_hi_hz = HM_MODE_MODEL_BAND_HIGH_HZ;
  m->conicity = NAN;
  for (size_t i = 0; i < HM_MODE_MODEL_GRID; ++i) m->grid_hopf_kmh[i] = NAN;
  double l0;
  hm_conicity_eval(&params->bogie.wheelset.conicity, 0.0, &l0, NULL);
  hm_status st = set_conicity(m, l0);
  if (st != HM_OK) {
    free(m);
    return st;
  }
  *out = m;
  return HM_OK;
}

hm_status hm_mode_model_create_wheelset(const hm_vehicle *veh, hm_mode_model *out) {
  if (!veh) return HM_EINVAL;
  hm_status st = hm_vehicle_validate(veh, NULL, 0);
  if (st != HM_OK) return st;
  hm_car c;
  hm_car_default(&c);
  c.bogie.wheelset = *veh;
  return create(HM_MODEL_WHEELSET, &c, out);
}

hm_status hm_mode_model_create_bogie(const hm_bogie *bogie, hm_mode_model *out) {
  if (!bogie) return HM_EINVAL;
  hm_status st = hm_bogie_validate(bogie, NULL, 0);
  if (st != HM_OK) return st;
  hm_car c;
  hm_car_default(&c);
  c.bogie = *bogie;
  return create(HM_MODEL_BOGIE, &c, out);
}

hm_status hm_mode_model_create_car(const hm_car *car, hm_mode_model *out) {
  if (!car) return HM_EINVAL;
  hm_status st = hm_car_validate(car, NULL, 0);
  if (st != HM_OK) return st;
  return create(HM_MODEL_CAR, car, out);
}

void hm_mode_model_destroy(hm_mode_model m) { free(m); }

hm_status hm_mode_model_create(hm_model_kind kind, const hm_car *params, hm_mode_model *out) {
  if (!params) return HM_EINVAL;
  switch (kind) {
    case HM_MODEL_WHEELSET: return hm_mode_model_create_wheelset(&params->bogie.wheelset, out);
    case HM_MODEL_BOGIE: return hm_mode_model_create_bogie(&params->bogie, out);
    case HM_MODEL_CAR: return hm_mode_model_create_car(params, out);
  }
  return HM_EINVAL;
}

hm_model_kind hm_mode_model_kind(const hm_mode_model m) { return m ? m->kind : HM_MODEL_WHEELSET; }

hm_status hm_mode_model_set_band(hm_mode_model m, double low_hz, double high_hz) {
  if (!m || !(low_hz >= 0.0) || !(high_hz > low_hz) || !isfinite(high_hz)) return HM_EINVAL;
  m->band_lo_hz = low_hz;
  m->band_hi_hz = high_hz;
  return HM_OK;
}

void hm_mode_model_params(const hm_mode_model m, hm_car *params) {
  if (m && params) *params = m->given;
}

/* The root with im > 0 nearest (sigma_ref, w_ref) in the metric of (e_sigma, e_w). */
static hm_status nearest_root(hm_mode_model m, double conicity, double v_kmh, double sigma_ref, double e_sigma,
                              double w_ref, double e_w, double *sigma, double *w) {
  hm_status st = set_conicity(m, conicity);
  if (st != HM_OK) return st;
  const size_t n = m->sys.dim;
  double re[NMAX], im[NMAX];
  if ((st = hm_system_eig(&m->sys, hm_mps_from_kmh(v_kmh), re, im, NULL)) != HM_OK) return st;
  double best = INFINITY;
  size_t k = n;
  for (size_t i = 0; i < n; ++i) {
    if (!(im[i] > 0.0)) continue;
    const double dr = (re[i] - sigma_ref) / e_sigma, di = (im[i] - w_ref) / e_w, d = dr * dr + di * di;
    if (d < best) best = d, k = i;
  }
  if (k == n) return HM_ENOCRIT;
  *sigma = re[k];
  *w = im[k];
  return HM_OK;
}

hm_status hm_mode_model_least_damped(hm_mode_model m, double conicity, double speed_kmh, double *sigma_1_s,
                                     double *omega_rad_s) {
  if (!m || !sigma_1_s || !omega_rad_s || !(speed_kmh > 0.0) || !isfinite(speed_kmh) || !isfinite(conicity) ||
      conicity < 0.0)
    return HM_EDOMAIN;
  hm_status st = set_conicity(m, conicity);
  if (st != HM_OK) return st;
  double re[NMAX], im[NMAX];
  if ((st = hm_system_eig(&m->sys, hm_mps_from_kmh(speed_kmh), re, im, NULL)) != HM_OK) return st;
  size_t k = m->sys.dim;
  const double w_lo = 2.0 * HM_PI * m->band_lo_hz, w_hi = 2.0 * HM_PI * m->band_hi_hz;
  for (size_t i = 0; i < m->sys.dim; ++i)
    if (im[i] > 0.0 && im[i] >= w_lo && im[i] <= w_hi && (k == m->sys.dim || re[i] > re[k])) k = i;
  if (k == m->sys.dim) return HM_ENOCRIT;
  *sigma_1_s = re[k];
  *omega_rad_s = im[k];
  return HM_OK;
}

static double grid_conicity(size_t i) {
  return HM_MODE_MODEL_LAMBDA_MIN *
         pow(HM_MODE_MODEL_LAMBDA_MAX / HM_MODE_MODEL_LAMBDA_MIN, (double)i / (double)(HM_MODE_MODEL_GRID - 1));
}

/* The curve's value at grid point i (computed now if not yet): the Hopf speed and its mode's frequency; +inf where
 * the origin is stable at every speed, 0 where it is unstable already at HM_MODE_MODEL_V_MIN_KMH (never "none" for
 * a vehicle that cannot run stably at all). */
static double grid_hopf(hm_mode_model m, size_t i) {
  if (isnan(m->grid_hopf_kmh[i])) {
    double v, f = NAN;
    const double l = grid_conicity(i);
    if (hm_mode_model_hopf(m, l, &v, &f, NULL) != HM_OK) {
      hm_system_spectrum s;
      v = set_conicity(m, l) == HM_OK &&
                  hm_system_spectrum_at(&m->sys, hm_mps_from_kmh(HM_MODE_MODEL_V_MIN_KMH), &s) == HM_OK &&
                  s.abscissa_1_s >= 0.0
              ? 0.0
              : INFINITY;
    }
    m->grid_hopf_kmh[i] = v;
    m->grid_f_hz[i] = f;
  }
  return m->grid_hopf_kmh[i];
}

double hm_mode_model_hopf_kmh(hm_mode_model m, double conicity) {
  if (!m || !(conicity >= HM_MODE_MODEL_LAMBDA_MIN && conicity <= HM_MODE_MODEL_LAMBDA_MAX))
    return HM_LINEAR_NO_HOPF_KMH;
  const double u = log(conicity / HM_MODE_MODEL_LAMBDA_MIN) / log(HM_MODE_MODEL_LAMBDA_MAX / HM_MODE_MODEL_LAMBDA_MIN);
  size_t i = (size_t)(u * (double)(HM_MODE_MODEL_GRID - 1));
  if (i >= HM_MODE_MODEL_GRID - 1) i = HM_MODE_MODEL_GRID - 2;
  const double v0 = grid_hopf(m, i), v1 = grid_hopf(m, i + 1);
  if (v0 == 0.0 || v1 == 0.0) return 0.0; /* unstable at every speed near there: the cautious reading */
  /* where the critical mode changes between the grid points (the bogie's wheelsets' mode and its frame's near 0.28)
   * the curve has a kink: the exact speed there instead of the interpolation (1.6 km/h off it) */
  if (!isfinite(v0) || !isfinite(v1) || !(fabs(m->grid_f_hz[i] - m->grid_f_hz[i + 1]) <= HM_MODE_MODEL_KINK_HZ)) {
    double v;
    if (hm_mode_model_hopf(m, conicity, &v, NULL, NULL) == HM_OK) return fmin(v, HM_LINEAR_NO_HOPF_KMH);
    return isfinite(v0) && isfinite(v1) ? fmin(v0, v1) : HM_LINEAR_NO_HOPF_KMH;
  }
  const double l0 = grid_conicity(i), l1 = grid_conicity(i + 1), f = (conicity - l0) / (l1 - l0);
  const double q = (1.0 - f) / (v0 * v0) + f / (v1 * v1); /* 1/V^2 linear in the conicity */
  return fmin(1.0 / sqrt(q), HM_LINEAR_NO_HOPF_KMH);
}

static int inputs_ok(double v_kmh, double e_sigma, double e_f) {
  return v_kmh > 0.0 && v_kmh < 1e4 && e_sigma > 0.0 && isfinite(e_sigma) && e_f > 0.0 && isfinite(e_f);
}

hm_status hm_mode_model_root(hm_mode_model m, double conicity, double speed_kmh, double sigma_ref, double e_sigma,
                             double f_ref_hz, double e_f, double *sigma_1_s, double *f_hz) {
  if (!m || !sigma_1_s || !f_hz || !inputs_ok(speed_kmh, e_sigma, e_f) || !isfinite(sigma_ref) ||
      !isfinite(f_ref_hz) || !isfinite(conicity) || conicity < 0.0)
    return HM_EDOMAIN;
  double s, w;
  hm_status st = nearest_root(m, conicity, speed_kmh, sigma_ref, e_sigma, 2.0 * HM_PI * f_ref_hz,
                              2.0 * HM_PI * e_f, &s, &w);
  if (st != HM_OK) return st;
  *sigma_1_s = s;
  *f_hz = w / (2.0 * HM_PI);
  return HM_OK;
}

hm_status hm_mode_model_hopf(hm_mode_model m, double conicity, double *speed_kmh, double *f_hz, int *body) {
  if (!m || !speed_kmh || !isfinite(conicity) || conicity < 0.0) return HM_EDOMAIN;
  hm_status st = set_conicity(m, conicity);
  if (st != HM_OK) return st;
  const hm_system_critical_options opt = {hm_mps_from_kmh(HM_MODE_MODEL_V_MIN_KMH), hm_mps_from_kmh(1500.0),
                                          hm_mps_from_kmh(5.0), hm_mps_from_kmh(1e-6)};
  double v;
  hm_system_spectrum s;
  if ((st = hm_system_critical_speed(&m->sys, &opt, &v, &s)) != HM_OK) return st;
  *speed_kmh = hm_kmh_from_mps(v);
  if (f_hz) *f_hz = s.frequency_hz;
  if (body) *body = s.dominant_body;
  return HM_OK;
}

/* ---- the inversion: the conicity whose mode (a root, or the model's reading) is nearest the measured one ---- */

/* The model's reading at a conicity (below): nearest the reference mode ref when given, warm-started from warm1/warm2
 * (a one- and a two-pair fit) when given; the fits made in th1_out, th2_out. */
typedef struct {
  double sigma, w, e_sigma, e_w;
} ref_mode;

static hm_status reading_fit(hm_mode_model m, double conicity, double v_kmh, unsigned poles, const ref_mode *ref,
                             const double *warm1, const double *warm2, double *th1_out, double *th2_out, double *sigma,
                             double *w);
static double ref_distance(const ref_mode *ref, double sigma, double w);

/* The misfit's residuals and their sensitivities at lambda, following the root from (*sr, *wr). */
typedef struct {
  double s, w, ds, dw; /* the root and d root / d lambda */
} root_point;

static hm_status root_with_slope(hm_mode_model m, double lambda, double v_kmh, double e_sigma, double e_w, double *sr,
                                 double *wr, root_point *p) {
  const double h = 1e-6 * fmax(lambda, 1e-3);
  double s0, w0, sp, wp, sm, wm;
  hm_status st = nearest_root(m, lambda, v_kmh, *sr, e_sigma, *wr, e_w, &s0, &w0);
  if (st == HM_OK) st = nearest_root(m, lambda + h, v_kmh, s0, e_sigma, w0, e_w, &sp, &wp);
  if (st == HM_OK) st = nearest_root(m, fmax(lambda - h, 0.0), v_kmh, s0, e_sigma, w0, e_w, &sm, &wm);
  if (st != HM_OK) return st;
  const double span = lambda + h - fmax(lambda - h, 0.0);
  *p = (root_point){s0, w0, (sp - sm) / span, (wp - wm) / span};
  *sr = s0, *wr = w0;
  return HM_OK;
}

/* The Gauss-Newton step in lambda of the weighted misfit of p from the measured mode, kept from taking lambda to or
 * below 0 (at most half of it down, half plus 0.01 up); 0 if the sensitivities vanish or are not finite. */
static int gauss_newton_step(const root_point *p, double lambda, double sigma_m, double e_sigma, double w_m,
                             double e_w, double *step) {
  const double jr = p->ds / e_sigma, ji = p->dw / e_w, rr = (p->s - sigma_m) / e_sigma, ri = (p->w - w_m) / e_w;
  const double jj = jr * jr + ji * ji;
  if (!(jj > 0.0) || !isfinite(jj)) return 0;
  *step = fmax(fmin(-(jr * rr + ji * ri) / jj, 0.5 * lambda + 0.01), -0.5 * lambda);
  return 1;
}

/* The inversion's result at its last point p (the misfit's sensitivities give the error, inversion.h's). */
static void inversion_result(const root_point *p, double lambda, double sigma_m, double e_sigma, double w_m, double e_w,
                             unsigned iterations, hm_conicity_inversion *out) {
  const double j1 = p->ds / e_sigma, j2 = p->dw / e_w, r1 = (p->s - sigma_m) / e_sigma, r2 = (p->w - w_m) / e_w;
  hm_conicity_inversion r;
  memset(&r, 0, sizeof r);
  r.conicity = lambda;
  r.conicity_se = 1.0 / sqrt(j1 * j1 + j2 * j2);
  r.chi2 = r1 * r1 + r2 * r2;
  r.model_decay_rate_1_s = p->s;
  r.model_frequency_hz = p->w / (2.0 * HM_PI);
  r.dsigma_dconicity = p->ds;
  r.dfrequency_dconicity = p->dw / (2.0 * HM_PI);
  r.iterations = iterations;
  *out = r;
}

hm_status hm_mode_model_invert(hm_mode_model m, double speed_kmh, double sigma_m, double e_sigma, double f_m,
                               double e_f, double tol, unsigned max_iter, hm_conicity_inversion *out) {
  if (!m || !out) return HM_EINVAL;
  if (!inputs_ok(speed_kmh, e_sigma, e_f) || !(sigma_m < 0.0) || !isfinite(sigma_m) || !(f_m > 0.0 && f_m < 1e3) ||
      !(tol > 0.0) || max_iter < 1)
    return HM_EDOMAIN;
  const double w_m = 2.0 * HM_PI * f_m, e_w = 2.0 * HM_PI * e_f;
  /* the start: the scanned conicity whose nearest root is nearest the measured mode */
  double lambda = NAN, best = INFINITY;
  for (int k = 0; k < HM_MODE_MODEL_SCAN; ++k) {
    const double l = 0.01 * pow(100.0, (double)k / (HM_MODE_MODEL_SCAN - 1)); /* 0.01..1, geometric */
    double s, w;
    if (nearest_root(m, l, speed_kmh, sigma_m, e_sigma, w_m, e_w, &s, &w) != HM_OK) continue;
    const double dr = (s - sigma_m) / e_sigma, di = (w - w_m) / e_w, d = dr * dr + di * di;
    if (d < best) best = d, lambda = l;
  }
  if (!isfinite(lambda)) return HM_ENOCONV;
  double sr = sigma_m, wr = w_m;
  for (unsigned it = 1; it <= max_iter; ++it) {
    root_point p;
    if (root_with_slope(m, lambda, speed_kmh, e_sigma, e_w, &sr, &wr, &p) != HM_OK) return HM_ENOCONV;
    double step;
    if (!gauss_newton_step(&p, lambda, sigma_m, e_sigma, w_m, e_w, &step)) return HM_ENOCONV;
    lambda += step;
    if (fabs(step) > tol) continue;
    if (!(lambda > 0.0 && lambda < 10.0)) return HM_ENOCONV;
    if (root_with_slope(m, lambda, speed_kmh, e_sigma, e_w, &sr, &wr, &p) != HM_OK) return HM_ENOCONV;
    inversion_result(&p, lambda, sigma_m, e_sigma, w_m, e_w, it, out);
    return HM_OK;
  }
  return HM_ENOCONV;
}

/* 1 when the model at conicity and speed is stable (every root decays); 0 also where it cannot be evaluated. */
static int stable_at(hm_mode_model m, double conicity, double v_kmh) {
  double re[NMAX], im[NMAX];
  return conicity > 0.0 && set_conicity(m, conicity) == HM_OK &&
         hm_system_eig(&m->sys, hm_mps_from_kmh(v_kmh), re, im, NULL) == HM_OK && stable_roots(re, m->sys.dim);
}

/* The reading and its slope at lambda (a difference of 1e-3 lambda, the second fit warm from the first: forward, or
 * backward where lambda is stable and lambda + h is not, as the reading's decay rate changes sign where its root
 * crosses into instability and a difference across that edge is no slope), the fits carried in th1/th2 (*have: warm). */
static hm_status reading_with_slope(hm_mode_model m, unsigned poles, double lambda, double v_kmh, const ref_mode *ref,
                                    double *th1, double *th2, int *have, root_point *p) {
  double h = 1e-3 * lambda;
  if (!stable_at(m, lambda + h, v_kmh) && stable_at(m, lambda, v_kmh)) h = -h;
  double s0, w0, s1, w1, t1[NPM], t2[NPM], u1[NPM], u2[NPM];
  hm_status st = reading_fit(m, lambda, v_kmh, poles, ref, *have ? th1 : NULL, *have && poles == 2 ? th2 : NULL, t1,
                             t2, &s0, &w0);
  if (st != HM_OK && *have) st = reading_fit(m, lambda, v_kmh, poles, ref, NULL, NULL, t1, t2, &s0, &w0);
  if (st != HM_OK) return st;
  if (reading_fit(m, lambda + h, v_kmh, poles, NULL, t1, t2, u1, u2, &s1, &w1) != HM_OK) {
    const ref_mode here = {s0, w0, ref->e_sigma, ref->e_w}; /* cold, the fit nearest the reading at lambda */
    if ((st = reading_fit(m, lambda + h, v_kmh, poles, &here, NULL, NULL, u1, u2, &s1, &w1)) != HM_OK) return st;
  }
  memcpy(th1, t1, sizeof t1);
  memcpy(th2, t2, sizeof t2);
  *have = 1;
  *p = (root_point){s0, w0, (s1 - s0) / h, (w1 - w0) / h};
  return HM_OK;
}

/* The last conicity on the way from lambda (stable at the speed) to lambda + step (not) where the model is still
 * stable: bisection to a relative width of rtol. */
static double stable_edge(hm_mode_model m, double lambda, double step, double v_kmh, double rtol) {
  double in = lambda, out = lambda + step;
  while (fabs(out - in) > rtol * fabs(in)) {
    const double mid = 0.5 * (in + out);
    if (stable_at(m, mid, v_kmh))
      in = mid;
    else
      out = mid;
  }
  return in;
}

/* 1 within the conicities the model is evaluated over (its Hopf curve's): a reading's slope below them is noise. */
static int in_range(double lambda) {
  return lambda >= HM_MODE_MODEL_LAMBDA_MIN && lambda <= HM_MODE_MODEL_LAMBDA_MAX;
}

/* The reading's inversion scans these conicities: 0.02..0.8, geometric. */
static double scan_conicity(int k) { return 0.02 * pow(40.0, (double)k / (HM_MODE_MODEL_READING_SCAN - 1)); }

/* The misfit of the model's (cold) reading nearest the measured mode at lambda; INFINITY where it fails. */
static double reading_misfit(hm_mode_model m, unsigned poles, double v_kmh, const ref_mode *ref, double lambda) {
  double th1[NPM], th2[NPM], s, w;
  if (reading_fit(m, lambda, v_kmh, poles, ref, NULL, NULL, th1, th2, &s, &w) != HM_OK) return INFINITY;
  return ref_distance(ref, s, w);
}

/* The stable pass's start: the scan's best stable conicity (index k, misfit d_k) refined by golden section over
 * its neighbours' span, cut at the stability edge, in HM_MODE_MODEL_START_EVALS readings. The scan's step (28%)
 * is wider than a precise reading's minimum, and near the edge a reading's decay rate sits at 0 (its root narrower
 * than the leakage) with no slope to follow: a two-pair reading of -0.73 1/s at 13.88 Hz, 512 km/h, started at the
 * scanned 0.143 (reading 0, misfit 11) went to the edge at 0.1433 where 0.1316 explains it (misfit 0.81). */
static double refined_start(hm_mode_model m, unsigned poles, double v_kmh, const ref_mode *ref, int k, double d_k) {
  double a = k > 0 ? scan_conicity(k - 1) : 0.5 * scan_conicity(0);
  double b = k + 1 < HM_MODE_MODEL_READING_SCAN ? scan_conicity(k + 1) : 1.5 * scan_conicity(k);
  const double l_k = scan_conicity(k);
  /* the bracket cut at the edges only roughly: it is a start, which the projected pass then refines */
  if (!stable_at(m, b, v_kmh)) b = stable_edge(m, l_k, b - l_k, v_kmh, HM_MODE_MODEL_START_EDGE_RTOL);
  if (!stable_at(m, a, v_kmh)) a = stable_edge(m, l_k, a - l_k, v_kmh, HM_MODE_MODEL_START_EDGE_RTOL);
  const double g = 0.5 * (sqrt(5.0) - 1.0);
  double best_l = l_k, best_d = d_k;
  double x1 = b - g * (b - a), x2 = a + g * (b - a);
  double f1 = reading_misfit(m, poles, v_kmh, ref, x1), f2 = reading_misfit(m, poles, v_kmh, ref, x2);
  for (int e = 2;; ++e) {
    if (f1 < best_d) best_d = f1, best_l = x1;
    if (f2 < best_d) best_d = f2, best_l = x2;
    if (e >= HM_MODE_MODEL_START_EVALS) break;
    if (f1 <= f2) {
      b = x2, x2 = x1, f2 = f1;
      x1 = b - g * (b - a);
      f1 = reading_misfit(m, poles, v_kmh, ref, x1);
    } else {
      a = x1, x1 = x2, f1 = f2;
      x2 = a + g * (b - a);
      f2 = reading_misfit(m, poles, v_kmh, ref, x2);
    }
  }
  return best_l;
}

/* Gauss-Newton on the reading from lambda, damped: a step to where the misfit grows or the reading fails is halved
 * from the point before it (the reading is far from linear in the conicity near a stability edge, where its decay
 * rate runs into 0, and a full step there oscillates). With stay_stable (lambda stable at the speed) it is projected
 * onto the conicities where the model is stable: a step that would leave them ends at their edge (stable_edge), and
 * a step so clipped below the tolerance ends the search there (the nearest a stable model comes to the reading). */
static hm_status gauss_newton_reading(hm_mode_model m, unsigned poles, double speed_kmh, const ref_mode *ref,
                                      double lambda, int stay_stable, double tol, unsigned max_iter,
                                      hm_conicity_inversion *out) {
  double th1[NPM], th2[NPM], pth1[NPM], pth2[NPM], prev = NAN, prev_chi2 = INFINITY, prev_step = 0.0;
  root_point prev_p = {0};
  int have = 0, phave = 0;
  for (unsigned it = 1; it <= max_iter; ++it) {
    root_point p;
    const int ok = in_range(lambda) && reading_with_slope(m, poles, lambda, speed_kmh, ref, th1, th2, &have, &p) == HM_OK;
    if (!ok && !isfinite(prev)) return HM_ENOCONV;
    const double chi2 = ok ? ref_distance(ref, p.s, p.w) : INFINITY;
    if (isfinite(prev) && !(chi2 <= prev_chi2)) { /* back to the point before, half the step */
      prev_step *= 0.5;
      if (fabs(prev_step) <= tol * fmax(prev, 1.0)) {
        inversion_result(&prev_p, prev, ref->sigma, ref->e_sigma, ref->w, ref->e_w, it, out);
        return HM_OK;
      }
      lambda = prev + prev_step;
      memcpy(th1, pth1, sizeof th1), memcpy(th2, pth2, sizeof th2), have = phave; /* warm from the point before */
      continue;
    }
    double step;
    if (!gauss_newton_step(&p, lambda, ref->sigma, ref->e_sigma, ref->w, ref->e_w, &step)) return HM_ENOCONV;
    const double eps = tol * fmax(lambda, 1.0);
    if (fabs(step) > eps && stay_stable && !stable_at(m, lambda + step, speed_kmh))
      step = stable_edge(m, lambda, step, speed_kmh, HM_MODE_MODEL_EDGE_RTOL) - lambda;
    if (fabs(step) <= eps) {
      inversion_result(&p, lambda, ref->sigma, ref->e_sigma, ref->w, ref->e_w, it, out);
      return HM_OK;
    }
    prev = lambda, prev_chi2 = chi2, prev_p = p, prev_step = step;
    memcpy(pth1, th1, sizeof th1), memcpy(pth2, th2, sizeof th2), phave = have;
    lambda += step;
  }
  return HM_ENOCONV;
}

hm_status hm_mode_model_invert_reading(hm_mode_model m, unsigned poles, double speed_kmh, double sigma_m,
                                       double e_sigma, double f_m, double e_f, double tol, unsigned max_iter,
                                       hm_conicity_inversion *out) {
  if (!m || !out) return HM_EINVAL;
  if (poles != 1 && poles != 2) return HM_EDOMAIN;
  if (!m->have_sensor) return hm_mode_model_invert(m, speed_kmh, sigma_m, e_sigma, f_m, e_f, tol, max_iter, out);
  if (!inputs_ok(speed_kmh, e_sigma, e_f) || !(sigma_m < 0.0) || !isfinite(sigma_m) || !(f_m > 0.0 && f_m < 1e3) ||
      !(tol > 0.0) || !isfinite(tol) || max_iter < 1)
    return HM_EDOMAIN;
  /* the start: the scanned conicity whose reading (the peak the measured mode lies on) is nearest it, then
   * Gauss-Newton on the reading. A decaying reading is never explained by a conicity at which the model is unstable
   * at this speed (any root, as the Hopf speed counts the first crossing of any mode: the vehicle ran there without
   * hunting; a bogie's one-pair reading at 523 km/h had been matched to a conicity whose wheelsets' mode grew at
   * +1.4 1/s, by a stable root's peak beside it): the search stays on the stable side (projected, from the nearest
   * scanned conicity there) unless the nearest scanned conicity of all is unstable and Gauss-Newton from it ends on a
   * stable one. */
  const double w_m = 2.0 * HM_PI * f_m, e_w = 2.0 * HM_PI * e_f;
  const ref_mode ref = {sigma_m, w_m, e_sigma, e_w};
  double lambda = NAN, best = INFINITY, lambda_st = NAN, best_st = INFINITY;
  int k_st = -1;
  for (int k = 0; k < HM_MODE_MODEL_READING_SCAN; ++k) {
    const double l = scan_conicity(k), d = reading_misfit(m, poles, speed_kmh, &ref, l);
    if (d < best) best = d, lambda = l;
    if (d < best_st && stable_at(m, l, speed_kmh)) best_st = d, lambda_st = l, k_st = k;
  }
  if (!isfinite(lambda)) return HM_ENOCONV;
  tol = fmax(tol, 1e-6);
  hm_conicity_inversion r;
  const unsigned first_iter = max_iter < HM_MODE_MODEL_UNSTABLE_START_ITER ? max_iter : HM_MODE_MODEL_UNSTABLE_START_ITER;
  if (lambda != lambda_st && gauss_newton_reading(m, poles, speed_kmh, &ref, lambda, 0, tol, first_iter, &r) == HM_OK &&
      stable_at(m, r.conicity, speed_kmh)) {
    *out = r;
    return HM_OK;
  }
  if (k_st < 0) return HM_ENOCONV;
  /* from the scanned start; where that fails, ends at the edge (the nearest a stable model comes, or a start where
   * the reading sat flat at 0) or misfits by more than HM_MODE_MODEL_RETRY_CHI2 (a local minimum), again from the
   * refined start, the better kept */
  int ok = gauss_newton_reading(m, poles, speed_kmh, &ref, lambda_st, 1, tol, max_iter, &r) == HM_OK &&
           stable_at(m, r.conicity, speed_kmh);
  if (!ok || r.chi2 > HM_MODE_MODEL_RETRY_CHI2 || !stable_at(m, r.conicity * (1.0 + 1e-6), speed_kmh)) {
    hm_conicity_inversion r2;
    const double l2 = refined_start(m, poles, speed_kmh, &ref, k_st, best_st);
    if (gauss_newton_reading(m, poles, speed_kmh, &ref, l2, 1, tol, max_iter, &r2) == HM_OK &&
        stable_at(m, r2.conicity, speed_kmh) && (!ok || r2.chi2 < r.chi2))
      r = r2, ok = 1;
  }
  if (!ok) return HM_ENOCONV;
  *out = r;
  return HM_OK;
}

/* ---- the spectrum at a sensor ---- */

hm_status hm_mode_model_sensor(hm_mode_model m, const char *where, hm_sensor_point *out) {
  if (!m || !where || !out) return HM_EINVAL;
  switch (m->kind) {
    case HM_MODEL_BOGIE: return hm_bogie_sensor(&m->bogie, where, out);
    case HM_MODEL_CAR: return hm_car_sensor(&m->car, where, out);
    default:
      if (strcmp(where, "axlebox") != 0) return HM_EINVAL;
      *out = (hm_sensor_point){1, {1, 0, 0, 0}, {1.0, 0.0, 0.0, 0.0}};
      return HM_OK;
  }
}

/* The shape at s = i w + shift: shift > 0 moves every pole left by it (each Lorentzian widened by shift, as a window's
 * leakage does, whittle.h); linearised at rest (motion NULL) or about the wheelsets' random motion (below); into
 * shape[], and where motion_out is given, each wheelset's displacement from the track per unit shape factor
 * (|R_i(w)|^2 S(w / v) / v) into motion_out[i * n + k]. */
static hm_status sensor_spectrum(hm_mode_model m, double conicity, double speed_kmh, const hm_sensor_point *point,
                                 const double *f_hz, size_t n, double shift, const double *motion_rms_m,
                                 double *shape, double *motion_out);

hm_status hm_mode_model_sensor_spectrum(hm_mode_model m, double conicity, double speed_kmh,
                                        const hm_sensor_point *point, const double *f_hz, size_t n, double *shape) {
  return sensor_spectrum(m, conicity, speed_kmh, point, f_hz, n, 0.0, NULL, shape, NULL);
}

/* The running's settings valid: a window of 0 (none) or > 0 s, the wheelsets' motion finite and >= 0. */
static int running_ok(const hm_mode_model m, const hm_running *run) {
  if (!run || !(run->window_s >= 0.0) || !isfinite(run->window_s)) return 0;
  for (size_t i = 0; i < m->sys.n_wheelsets; ++i)
    if (!(run->motion_rms_m[i] >= 0.0) || !isfinite(run->motion_rms_m[i])) return 0;
  return 1;
}

hm_status hm_mode_model_running_spectrum(hm_mode_model m, double conicity, double speed_kmh,
                                         const hm_sensor_point *point, const hm_running *run, const double *f_hz,
                                         size_t n, double *shape) {
  if (!m || !running_ok(m, run)) return HM_EDOMAIN;
  const double shift = run->window_s > 0.0 ? HM_WHITTLE_LEAKAGE / run->window_s : 0.0;
  return sensor_spectrum(m, conicity, speed_kmh, point, f_hz, n, shift, run->motion_rms_m, shape, NULL);
}

/* The track's wavelengths the wheelsets' motion is integrated over [m] (excitation.h's spectrum is fitted for 1-200 m
 * and the wheelsets follow longer ones: their displacement from the track there is nil) and the grid's points. */
#define MOTION_WL_MIN_M 1.0
#define MOTION_WL_MAX_M 200.0
enum { MOTION_GRID = 400 };

hm_status hm_mode_model_motion_rms(hm_mode_model m, double conicity, double speed_kmh, const hm_running *run,
                                   double amplitude, double *motion_rms_m) {
  if (!m || !motion_rms_m || !running_ok(m, run) || !(amplitude >= 0.0) || !isfinite(amplitude)) return HM_EDOMAIN;
  const double v = hm_mps_from_kmh(speed_kmh);
  if (!(v > 0.0) || !isfinite(v)) return HM_EDOMAIN;
  /* a geometric grid in frequency over the wavelengths: the trapezoid rule in ln f (df = f d ln f) */
  double f[MOTION_GRID], shape[MOTION_GRID], mot[HM_SYSTEM_MAX_WHEELSETS * MOTION_GRID];
  const double f_lo = v / MOTION_WL_MAX_M, f_hi = v / MOTION_WL_MIN_M, dl = log(f_hi / f_lo) / (MOTION_GRID - 1);
  for (size_t k = 0; k < MOTION_GRID; ++k) f[k] = f_lo * exp(dl * (double)k);
  const hm_sensor_point any = {1, {m->sys.wheelset_y_state[0] + 1}, {1.0}}; /* (sensor_spectrum sets the conicity) */
  const hm_status st = sensor_spectrum(m, conicity, speed_kmh, &any, f, MOTION_GRID, 0.0, run->motion_rms_m, shape, mot);
  if (st != HM_OK) return st;
  for (size_t i = 0; i < m->sys.n_wheelsets; ++i) {
    double var = 0.0;
    for (size_t k = 0; k < MOTION_GRID; ++k)
      var += (k == 0 || k == MOTION_GRID - 1 ? 0.5 : 1.0) * mot[i * MOTION_GRID + k] * f[k] * dl;
    motion_rms_m[i] = sqrt(2.0 * amplitude * var); /* (the density two-sided: both signs of f) */
  }
  return HM_OK;
}

/* State s of the complex eigenvector whose real and imaginary parts are dgeev's columns k and k + 1 (d x d). */
static double _Complex eigvec_at(const double *vr, size_t d, size_t s, size_t k) {
  return vr[s + d * k] + I * vr[s + d * (k + 1)];
}

hm_status hm_mode_model_displacement_per_accel(hm_mode_model m, double conicity, double speed_kmh,
                                               const hm_sensor_point *point, double f_hz, double *out) {
  if (!m || !point || !out) return HM_EINVAL;
  if (!(speed_kmh > 0.0) || !isfinite(speed_kmh) || !(f_hz > 0.0) || !isfinite(f_hz) || !(conicity >= 0.0) ||
      !isfinite(conicity))
    return HM_EDOMAIN;
  hm_status st = set_conicity(m, conicity);
  if (st != HM_OK) return st;
  const hm_system *sys = &m->sys;
  if (!hm_sensor_point_valid(sys, point)) return HM_EINVAL;
  const size_t d = sys->dim;
  double re[NMAX], im[NMAX], vr[NMAX * NMAX];
  if ((st = hm_system_eig(sys, hm_mps_from_kmh(speed_kmh), re, im, vr)) != HM_OK) return st;
  int k = -1; /* the least-damped oscillatory root within HM_MODE_MODEL_SHAPE_BAND of f */
  for (size_t j = 0; j < d; ++j)
    if (im[j] > 0.0 && fabs(im[j] / (2.0 * HM_PI) / f_hz - 1.0) <= HM_MODE_MODEL_SHAPE_BAND && (k < 0 || re[j] > re[k]))
      k = (int)j;
  if (k < 0) return HM_ENOCRIT; /* (no mode there) */
  const double _Complex lam = re[k] + I * im[k];
  double _Complex acc = 0.0; /* the point's acceleration: lambda times its velocity states */
  for (size_t j = 0; j < point->n_terms; ++j)
    acc += point->weight[j] * lam * eigvec_at(vr, d, (size_t)point->state[j], (size_t)k);
  double most = 0.0;
  for (size_t i = 0; i < sys->n_wheelsets; ++i)
    most = fmax(most, cabs(eigvec_at(vr, d, (size_t)sys->wheelset_y_state[i], (size_t)k)));
  const double r = most / cabs(acc);
  if (!(r > 0.0) || !isfinite(r)) return HM_ENONFINITE;
  *out = r;
  return HM_OK;
}

/* Gaussian equivalent linearisation (Roberts and Spanos, Random Vibration and Statistical Linearization, ch. 5): a
 * wheelset moving about the track as a Gaussian process of rms s sees the wheel-rail terms' mean derivative E[d f /
 * d r] over r ~ N(0, s^2), not the derivative at rest (the flange force F_T(r) = alpha1 r^3 + alpha2 r^5 of MODEL.md
 * has none there: its mean slope is 3 alpha1 s^2 + 15 alpha2 s^4). Each wheelset's terms depend on its own r alone, so
 * the mean of the Jacobian and of the track's input matrix over the 5-point Gauss-Hermite rule, every wheelset at its
 * own sqrt(2) s_i x_q, is exact for each (F_T' is a polynomial of degree 4; the rule holds to degree 9). */
static const double GH_X[5] = {-2.020182870456086, -0.958572464613819, 0.0, 0.958572464613819, 2.020182870456086};
static const double GH_W[5] = {0.019953242059046, 0.393619323152241, 0.945308720482942, 0.393619323152241,
                               0.019953242059046}; /* (their sum sqrt(pi)) */

/* The Jacobian jac (dim x dim, row-major) and the track's input columns B[i] (d f / d y_track_i) at speed v [m/s],
 * at rest (motion NULL) or in the mean over the wheelsets' motion (above). */
static hm_status linearised(const hm_system *sys, double v, const double *motion_rms_m, double *jac,
                            double (*B)[NMAX]) {
  const size_t d = sys->dim, nw = sys->n_wheelsets;
  int moving = 0;
  for (size_t i = 0; motion_rms_m && i < nw; ++i) moving = moving || motion_rms_m[i] > 0.0;
  const int nq = moving ? 5 : 1;
  const double h = 1e-7;
  memset(jac, 0, d * d * sizeof jac[0]);
  for (size_t i = 0; i < nw; ++i) memset(B[i], 0, d * sizeof B[i][0]);
  for (int q = 0; q < nq; ++q) {
    double x[NMAX] = {0.0}, jq[NMAX * NMAX], f0[NMAX], f1[NMAX], yt[HM_SYSTEM_MAX_WHEELSETS] = {0.0};
    const double wq = moving ? GH_W[q] / sqrt(HM_PI) : 1.0;
    if (moving)
      for (size_t i = 0; i < nw; ++i) x[sys->wheelset_y_state[i]] = sqrt(2.0) * motion_rms_m[i] * GH_X[q];
    hm_status st = sys->jacobian(sys->model, v, x, jq);
    if (st == HM_OK) st = sys->rhs_track(sys->model, v, x, yt, f0);
    if (st != HM_OK) return st;
    for (size_t k = 0; k < d * d; ++k) jac[k] += wq * jq[k];
    for (size_t i = 0; i < nw; ++i) { /* d f / d y_track_i by a one-sided difference */
      yt[i] = h;
      st = sys->rhs_track(sys->model, v, x, yt, f1);
      yt[i] = 0.0;
      if (st != HM_OK) return st;
      for (size_t r = 0; r < d; ++r) B[i][r] += wq * (f1[r] - f0[r]) / h;
    }
  }
  return HM_OK;
}

static hm_status sensor_spectrum(hm_mode_model m, double conicity, double speed_kmh, const hm_sensor_point *point,
                                 const double *f_hz, size_t n, double shift, const double *motion_rms_m,
                                 double *shape, double *motion_out) {
  if (!m || !point || !f_hz || !shape || n == 0 || n > HM_MODE_MODEL_SPECTRUM_MAX_BINS || !(speed_kmh > 0.0) ||
      !isfinite(speed_kmh) || !isfinite(conicity) || conicity < 0.0)
    return HM_EDOMAIN;
  for (size_t k = 0; k < n; ++k)
    if (!(f_hz[k] > 0.0) || !isfinite(f_hz[k])) return HM_EDOMAIN;
  hm_status st = set_conicity(m, conicity);
  if (st != HM_OK) return st;
  const hm_system *sys = &m->sys;
  if (!hm_sensor_point_valid(sys, point)) return HM_EINVAL;
  const size_t d = sys->dim, nw = sys->n_wheelsets;
  const double v = hm_mps_from_kmh(speed_kmh);
  double jac[NMAX * NMAX], B[HM_SYSTEM_MAX_WHEELSETS][NMAX];
  if ((st = linearised(sys, v, motion_rms_m, jac, B)) != HM_OK) return st;
  double out[HM_MODE_MODEL_SPECTRUM_MAX_BINS]; /* (shape untouched on a failure) */
  for (size_t k = 0; k < n; ++k) {
    const double w = 2.0 * HM_PI * f_hz[k];
    double _Complex a[NMAX * NMAX], u[NMAX];
    for (size_t r = 0; r < d; ++r) {
      u[r] = 0.0;
      for (size_t c = 0; c < d; ++c) a[r + d * c] = (r == c ? I * w + shift : 0.0) - jac[d * r + c]; /* column-major */
    }
    double _Complex ua[HM_SYSTEM_MAX_WHEELSETS];
    for (size_t i = 0; i < nw; ++i) {
      ua[i] = cexp(-(I * w + shift) * (sys->wheelset_x_m[0] - sys->wheelset_x_m[i]) / v);
      for (size_t r = 0; r < d; ++r) u[r] += B[i][r] * ua[i];
    }
    double _Complex x[NMAX];
    memcpy(x, u, d * sizeof x[0]);
    int ipiv[NMAX], info = 0;
    const int nn = (int)d, one = 1;
    zgesv_(&nn, &one, a, &nn, ipiv, x, &nn, &info);
    if (info != 0) return HM_ELAPACK;
    double _Complex acc = 0.0; /* the point's sum of accelerations: rows of i w X (= A X + B u) */
    for (size_t j = 0; j < point->n_terms; ++j) acc += point->weight[j] * (I * w + shift) * x[point->state[j]];
    const double S = hm_track_alignment_psd(w / v) / v;
    out[k] = creal(acc * conj(acc)) * S;
    if (!isfinite(out[k])) return HM_ENONFINITE;
    for (size_t i = 0; motion_out && i < nw; ++i) { /* wheelset i's displacement from the track under it */
      const double _Complex r = x[sys->wheelset_y_state[i]] - ua[i];
      motion_out[i * n + k] = creal(r * conj(r)) * S;
    }
  }
  memcpy(shape, out, n * sizeof shape[0]);
  return HM_OK;
}

/* ---- the monitor's reading on the model ---- */

hm_status hm_mode_model_set_sensor(hm_mode_model m, const char *where) {
  if (!m) return HM_EINVAL;
  if (!where) {
    m->have_sensor = 0;
    return HM_OK;
  }
  hm_sensor_point p;
  hm_status st = hm_mode_model_sensor(m, where, &p);
  if (st != HM_OK) return st;
  m->sensor = p;
  m->have_sensor = 1;
  return HM_OK;
}

int hm_mode_model_has_sensor(const hm_mode_model m) { return m && m->have_sensor; }

void hm_mode_model_set_reading_gain(hm_mode_model m, hm_mode_model_gain_fn gain, const void *ctx) {
  if (!m) return;
  m->gain = gain;
  m->gain_ctx = ctx;
}

/* A fit's pair (0 or 1) as a mode: its decay rate -|sigma| and angular frequency |w0|. */
static void pair_of(const double *th, int second, double *sigma, double *w) {
  *sigma = -fabs(th[second ? HM_W_SIGMA2 : HM_W_SIGMA]);
  *w = fabs(th[second ? HM_W_W02 : HM_W_W0]);
}

/* A candidate's distance from the reference (0 without one: then the best objective chooses). */
static double ref_distance(const ref_mode *ref, double sigma, double w) {
  if (!ref) return 0.0;
  const double a = (sigma - ref->sigma) / ref->e_sigma, b = (w - ref->w) / ref->e_w;
  return a * a + b * b;
}

/* The candidate fits of `poles` pairs from starts[0..n): the one nearest ref (in_band), else of least objective. */
static int choose_fit(const hm_whittle_data *d, unsigned poles, double (*starts)[NPM], int n, const ref_mode *ref,
                      double w_lo, double w_hi, double w_ref, double *th) {
  double best = INFINITY, fi[NPM][NPM], obj;
  unsigned it;
  int found = 0;
  for (int k = 0; k < n; ++k) {
    if (!hm_whittle_score(d, poles, starts[k], HM_MODE_MODEL_READING_TOL, HM_MODE_MODEL_READING_ITER, &obj, fi, &it))
      continue;
    const int second = poles == 2 && fabs(starts[k][HM_W_SIGMA2]) < fabs(starts[k][HM_W_SIGMA]);
    double sg, w;
    pair_of(starts[k], second, &sg, &w);
    if (!(w > w_lo && w < w_hi)) continue;
    /* a mode as the monitor's validity has it (modal.h): lightly damped, and a peak above the band's mean level (its
     * numerator taken at its frequency: w_ref is the bins' reference, u = ln(w / w_ref)) */
    if (!(-sg < HM_MODE_MODEL_READING_MAX_ZETA * hypot(sg, w)) ||
        !(hm_whittle_peak(starts[k], (unsigned)second, d->window_s, w_ref) >= HM_MODE_MODEL_READING_MIN_PEAK))
      continue;
    const double score = ref ? ref_distance(ref, sg, w) : obj;
    if (score < best) {
      best = score;
      memcpy(th, starts[k], sizeof(double) * NPM);
      found = 1;
    }
  }
  return found;
}

static hm_status reading_fit(hm_mode_model m, double conicity, double v_kmh, unsigned poles, const ref_mode *ref,
                             const double *warm1, const double *warm2, double *th1_out, double *th2_out, double *sigma,
                             double *w) {
  if (!m->have_sensor) return HM_EINVAL;
  /* HM_MODE_MODEL_READING_DF_HZ, or wider where the band needs more than NREAD bins */
  const double df = fmax(HM_MODE_MODEL_READING_DF_HZ, (m->band_hi_hz - m->band_lo_hz) / (double)(NREAD - 1));
  size_t n = (size_t)floor((m->band_hi_hz - m->band_lo_hz) / df) + 1;
  if (n > NREAD) n = NREAD;
  if (n < 16) return HM_EDOMAIN;
  const double w_ref = 2.0 * HM_PI * sqrt(fmax(m->band_lo_hz, df) * m->band_hi_hz);
  for (size_t k = 0; k < n; ++k) {
    m->rd_f[k] = fmax(m->band_lo_hz, 0.5 * df) + df * (double)k;
    m->rd_w[k] = 2.0 * HM_PI * m->rd_f[k];
    m->rd_u[k] = log(m->rd_w[k] / w_ref);
  }
  /* the leakage of a window of HM_MODE_MODEL_READING_WINDOW_S on both sides: the spectrum's poles moved left by
   * HM_WHITTLE_LEAKAGE / T and the fit told T (a peak far narrower than the bins is then a few bins wide) */
  const double T = HM_MODE_MODEL_READING_WINDOW_S;
  hm_status st = sensor_spectrum(m, conicity, v_kmh, &m->sensor, m->rd_f, n, HM_WHITTLE_LEAKAGE / T, NULL, m->rd_p, NULL);
  if (st != HM_OK) return st;
  double mean = 0.0;
  for (size_t k = 0; k < n; ++k) {
    if (m->gain) m->rd_p[k] *= m->gain(m->gain_ctx, m->rd_f[k]);
    mean += m->rd_p[k];
  }
  mean /= (double)n;
  if (!(mean > 0.0) || !isfinite(mean)) return HM_ENONFINITE;
  for (size_t k = 0; k < n; ++k) m->rd_p[k] = m->rd_p[k] / mean + HM_MODE_MODEL_READING_FLOOR;
  /* the roots at this conicity and speed: starts for a fit, and the read pair's own root */
  double re[NMAX], im[NMAX];
  if ((st = hm_system_eig(&m->sys, hm_mps_from_kmh(v_kmh), re, im, NULL)) != HM_OK) return st;
  const hm_whittle_data d = {m->rd_w, m->rd_u, m->rd_p, n, T};
  const double w_lo = 2.0 * HM_PI * m->band_lo_hz, w_hi = 2.0 * HM_PI * m->band_hi_hz;
  enum { MAX_STARTS = 4 + NMAX / 2 };
  double starts[MAX_STARTS][NPM], th1[NPM], th2[NPM];
  memset(starts, 0, sizeof starts);
  memset(th2, 0, sizeof th2);
  int found = 0, ns = 0;
  if (warm1) {
    memcpy(starts[0], warm1, sizeof starts[0]);
    found = choose_fit(&d, 1, starts, 1, NULL, w_lo, w_hi, w_ref, th1);
  }
  if (!found) {
    /* without a reference: three widths at the spectrum's peak (a smooth peak's fit may settle off it from a narrow
     * start) and every oscillatory root in the band; with one: the reference and the peak */
    hm_whittle_cold_start(&d, 2, -0.7, starts[ns++]);
    hm_whittle_cold_start(&d, 2, -4.0, starts[ns++]);
    hm_whittle_cold_start(&d, 2, -10.0, starts[ns++]);
    if (ref) { /* at the reference (its level the spectrum's there) and at the peak: the one nearest it is kept */
      memcpy(starts[0], starts[1], sizeof starts[0]);
      starts[0][HM_W_SIGMA] = fmin(ref->sigma, -0.1);
      starts[0][HM_W_W0] = ref->w;
      size_t kr = 0;
      for (size_t k = 1; k < n; ++k)
        if (fabs(m->rd_w[k] - ref->w) < fabs(m->rd_w[kr] - ref->w)) kr = k;
      const double at = hm_whittle_peak(starts[0], 0, T, w_ref);
      if (at > 0.0 && isfinite(at)) starts[0][HM_W_C0] += log(m->rd_p[kr] / at);
      ns = 2; /* and starts[1], the cold one at the peak */
    }
    if (!ref)
      for (size_t i = 0; i < m->sys.dim && ns < MAX_STARTS; ++i) {
        if (!(im[i] > w_lo && im[i] < w_hi)) continue;
        memcpy(starts[ns], starts[1], sizeof starts[0]);
        starts[ns][HM_W_SIGMA] = fmin(re[i], -0.1);
        starts[ns++][HM_W_W0] = im[i];
      }
    found = choose_fit(&d, 1, starts, ns, poles == 1 ? ref : NULL, w_lo, w_hi, w_ref, th1);
  }
  if (!found) return HM_ENOCRIT;
  const double *th = th1;
  if (poles == 2) {
    ns = 0;
    if (warm2) memcpy(starts[ns++], warm2, sizeof starts[0]);
    if (!warm2 || !choose_fit(&d, 2, starts, 1, NULL, w_lo, w_hi, w_ref, th2)) {
      ns = 0;
      hm_whittle_split_start(th1, T, 0.4, starts[ns++]);
      hm_whittle_split_start(th1, T, 0.15, starts[ns++]);
      /* the split of least objective, as modal.c keeps the best likelihood: the one nearest ref made the reading
       * jump with the conicity between the two splits' decompositions, and the inversion settle on an island where
       * one happened to sit on the measured mode (the default bogie, 410 km/h, -3.64 1/s at 14.25 Hz: 0.1953 +-
       * 0.0073 from the 0.1875-0.19 island, 0.150 +- 0.026 from the smooth reading; truth 0.15) */
      if (!choose_fit(&d, 2, starts, ns, NULL, w_lo, w_hi, w_ref, th2)) return HM_ENOCRIT;
    }
    th = th2;
  }
  const int second = poles == 2 && fabs(th2[HM_W_SIGMA2]) < fabs(th2[HM_W_SIGMA]); /* the less damped (modal.c) */
  double s, ww;
  pair_of(th, second, &s, &ww);
  /* a stationary spectrum tells |sigma| alone; where the root the read pair follows is unstable there is none to
   * read: the reading is given growing (+|sigma|), so that no measured (decaying) reading is explained there by the
   * mirror image of the stable side (a stable root's peak beside an unstable one is still read as decaying: the
   * inversion below refuses such conicities) */
  size_t kf = m->sys.dim; /* the oscillatory root the read pair follows: nearest it in frequency */
  for (size_t i = 0; i < m->sys.dim; ++i)
    if (im[i] > 0.0 && (kf == m->sys.dim || fabs(im[i] - ww) < fabs(im[kf] - ww))) kf = i;
  if (kf < m->sys.dim && re[kf] >= 0.0) s = fabs(s);
  memcpy(th1_out, th1, sizeof th1);
  memcpy(th2_out, th2, sizeof th2);
  *sigma = s;
  *w = ww;
  return HM_OK;
}

hm_status hm_mode_model_reading(hm_mode_model m, double conicity, double speed_kmh, unsigned poles, double *sigma_1_s,
                                double *f_hz) {
  if (!m || !sigma_1_s || !f_hz) return HM_EINVAL;
  if (!m->have_sensor || (poles != 1 && poles != 2) || !(speed_kmh > 0.0) || !(speed_kmh < 1e4) ||
      !isfinite(conicity) || conicity < 0.0)
    return HM_EDOMAIN;
  double t1[NPM], t2[NPM], s, w;
  hm_status st = reading_fit(m, conicity, speed_kmh, poles, NULL, NULL, NULL, t1, t2, &s, &w);
  if (st != HM_OK) return st;
  *sigma_1_s = s;
  *f_hz = w / (2.0 * HM_PI);
  return HM_OK;
}
