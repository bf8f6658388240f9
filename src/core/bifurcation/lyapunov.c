/* Benettin's algorithm for Lyapunov exponents with QR re-orthonormalisation. */
#include "hunting_monitor/lyapunov.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lapack.h"

void hm_lyap_options_default(hm_lyap_options *opt) {
  opt->method = HM_LYAP_MIDPOINT;
  opt->step_s = 1e-4;
  opt->rtol = 1e-9;
  opt->atol = 1e-12;
  opt->newton_tol = 1e-12;
  opt->newton_max_iter = 20;
  opt->renorm_interval_s = 0.01;
  opt->transient_s = 0.0;
  opt->duration_s = 100.0;
}

typedef struct {
  size_t n, k;
  double *z;        /* [x, tangent (n x k column-major)] */
  double *jac;      /* n x n scratch for the variational system */
  double *tau, *work;
  int lwork;
  hm_dopri dopri;
  hm_midpoint midpoint;
  hm_variational var;
  hm_ode_system var_sys;
} lyap_work;

static void work_free(lyap_work *w) {
  free(w->z);
  free(w->jac);
  free(w->tau);
  free(w->work);
  hm_dopri_destroy(w->dopri);
  hm_midpoint_destroy(w->midpoint);
}

static hm_status work_alloc(lyap_work *w, const hm_ode_system *sys, size_t k, hm_lyap_method method) {
  const size_t n = sys->dim;
  memset(w, 0, sizeof *w);
  w->n = n;
  w->k = k;
  w->z = calloc(n + n * k, sizeof(double));
  w->jac = calloc(n * n, sizeof(double));
  w->tau = calloc(k, sizeof(double));
  if (!w->z || !w->jac || !w->tau) return HM_ENOMEM;
  /* dgeqrf and dorgqr workspace: query once, keep the larger. */
  const int m = (int)n, kk = (int)k, query = -1;
  int info = 0;
  double opt_qr = 0.0, opt_q = 0.0;
  dgeqrf_(&m, &kk, w->z + n, &m, w->tau, &opt_qr, &query, &info);
  if (info != 0) return HM_ELAPACK;
  dorgqr_(&m, &kk, &kk, w->z + n, &m, w->tau, &opt_q, &query, &info);
  if (info != 0) return HM_ELAPACK;
  w->lwork = (int)fmax(fmax(opt_qr, opt_q), (double)kk);
  w->work = calloc((size_t)w->lwork, sizeof(double));
  if (!w->work) return HM_ENOMEM;
  if (method == HM_LYAP_DOPRI) {
    w->var = (hm_variational){sys, k, w->jac};
    w->var_sys = (hm_ode_system){n + n * k, hm_variational_rhs, NULL, &w->var};
    w->dopri = hm_dopri_create(n + n * k);
    if (!w->dopri) return HM_ENOMEM;
  } else {
    w->midpoint = hm_midpoint_create(n);
    if (!w->midpoint) return HM_ENOMEM;
  }
  return HM_OK;
}

/* Advance state and tangents by one renormalisation interval. */
static hm_status advance(lyap_work *w, const hm_ode_system *sys, const hm_lyap_options *opt, double t,
                         double interval, size_t midpoint_steps) {
  if (opt->method == HM_LYAP_DOPRI) {
    const hm_dopri_options dopt = {opt->rtol, opt->atol, 0.0, 0.0, 0, 0};
    return hm_dopri_integrate(w->dopri, &w->var_sys, &dopt, t, t + interval, w->z, NULL, NULL, NULL, NULL);
  }
  for (size_t s = 0; s < midpoint_steps; ++s) {
    hm_status st = hm_midpoint_step(w->midpoint, sys, t + (double)s * opt->step_s, opt->step_s, opt->newton_tol,
                                    opt->newton_max_iter, w->z, w->z + w->n, w->k);
    if (st != HM_OK) return st;
  }
  return HM_OK;
}

/* QR of the tangent matrix: add log|R_ii| to sums (if given), replace the tangents by Q. */
static hm_status reorthonormalise(lyap_work *w, double *sums) {
  const int m = (int)w->n, k = (int)w->k;
  int info = 0;
  double *T = w->z + w->n;
  dgeqrf_(&m, &k, T, &m, w->tau, w->work, &w->lwork, &info);
  if (info != 0) return HM_ELAPACK;
  for (size_t i = 0; i < w->k; ++i) {
    const double r = fabs(T[i + i * w->n]);
    if (!(r > 0.0) || !isfinite(r)) return HM_ENONFINITE;
    if (sums) sums[i] += log(r);
  }
  dorgqr_(&m, &k, &k, T, &m, w->tau, w->work, &w->lwork, &info);
  return info == 0 ? HM_OK : HM_ELAPACK;
}

static int options_valid(const hm_lyap_options *o) {
  const int common = o->renorm_interval_s > 0.0 && isfinite(o->renorm_interval_s) && o->transient_s >= 0.0 &&
                     isfinite(o->transient_s) && o->duration_s > 0.0 && isfinite(o->duration_s);
  /* bounded work: at most HM_LYAP_MAX_STEPS renormalisations or midpoint steps (a step of 1e-300 s is refused,
   * not run for ever), and an interval no longer than the averaging time */
  const double span = o->duration_s + o->transient_s;
  if (!common || o->renorm_interval_s > o->duration_s || span / o->renorm_interval_s > HM_LYAP_MAX_STEPS) return 0;
  if (o->method == HM_LYAP_DOPRI) return o->rtol > 0.0 && o->atol >= 0.0;
  if (o->method == HM_LYAP_MIDPOINT)
    return o->step_s > 0.0 && o->step_s <= o->renorm_interval_s && span / o->step_s <= HM_LYAP_MAX_STEPS &&
           o->newton_tol > 0.0 && o->newton_max_iter > 0;
  return 0;
}

hm_status hm_lyapunov_spectrum(const hm_ode_system *sys, double t0, const double *x0, size_t n_exp,
                               const hm_lyap_options *opt, double *exponents, double *x_end) {
  if (!sys || !x0 || !opt || !exponents || !sys->rhs || !sys->jac) return HM_EINVAL;
  if (sys->dim == 0 || n_exp == 0 || n_exp > sys->dim || !options_valid(opt)) return HM_EINVAL;
  const size_t n = sys->dim;
  lyap_work w;
  hm_status st = work_alloc(&w, sys, n_exp, opt->method);
  double *sums = calloc(n_exp, sizeof(double));
  if (st == HM_OK && !sums) st = HM_ENOMEM;
  if (st != HM_OK) {
    free(sums);
    work_free(&w);
    return st;
  }
  memcpy(w.z, x0, n * sizeof(double));
  for (size_t j = 0; j < n_exp; ++j) w.z[n + j + j * n] = 1.0;
  size_t steps = 1;
  double interval = opt->renorm_interval_s;
  if (opt->method == HM_LYAP_MIDPOINT) {
    steps = (size_t)fmax(1.0, round(opt->renorm_interval_s / opt->step_s));
    interval = (double)steps * opt->step_s;
  }
  const size_t n_transient = (size_t)ceil(opt->transient_s / interval - 1e-9);
  const size_t n_average = (size_t)fmax(1.0, round(opt->duration_s / interval));
  double t = t0;
  for (size_t i = 0; i < n_transient + n_average && st == HM_OK; ++i) {
    st = advance(&w, sys, opt, t, interval, steps);
    t = t0 + (double)(i + 1) * interval;
    if (st == HM_OK) st = reorthonormalise(&w, i < n_transient ? NULL : sums);
  }
  if (st == HM_OK) {
    const double T = (double)n_average * interval;
    for (size_t i = 0; i < n_exp; ++i) sums[i] /= T;
    /* Benettin's order is already nearly decreasing; sort to make it exact. */
    for (size_t i = 1; i < n_exp; ++i)
      for (size_t j = i; j > 0 && sums[j - 1] < sums[j]; --j) {
        const double tmp = sums[j];
        sums[j] = sums[j - 1];
        sums[j - 1] = tmp;
      }
    memcpy(exponents, sums, n_exp * sizeof(double));
    if (x_end) memcpy(x_end, w.z, n * sizeof(double));
  }
  free(sums);
  work_free(&w);
  return st;
}
