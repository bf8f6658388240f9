/* Dormand-Prince 5(4) with dense output, the implicit midpoint rule, and variational systems. */
#include "hunting_monitor/integrate.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "lapack.h"
#include "rk.h"

hm_status hm_variational_rhs(double t, const double *z, double *dzdt, void *variational) {
  const hm_variational *var = (const hm_variational *)variational;
  const hm_ode_system *base = var->base;
  const size_t n = base->dim;
  hm_status st = base->rhs(t, z, dzdt, base->params);
  if (st != HM_OK) return st;
  st = base->jac(t, z, var->jac_work, base->params);
  if (st != HM_OK) return st;
  const double *J = var->jac_work;
  for (size_t c = 0; c < var->k; ++c) {
    const double *phi = z + n + c * n;
    double *dphi = dzdt + n + c * n;
    for (size_t i = 0; i < n; ++i) {
      double s = 0.0;
      for (size_t l = 0; l < n; ++l) s += J[i * n + l] * phi[l];
      dphi[i] = s;
    }
  }
  return HM_OK;
}

hm_status hm_rk_check(const hm_ode_system *sys, size_t dim, const hm_dopri_options *opt, double t0, double t1,
                      const double *x) {
  if (!sys || !opt || !x || !sys->rhs || sys->dim != dim) return HM_EINVAL;
  if (!isfinite(t0) || !isfinite(t1) || t1 < t0) return HM_EINVAL;
  if (!(opt->rtol > 0.0) || !(opt->atol >= 0.0) || !isfinite(opt->rtol) || !isfinite(opt->atol)) return HM_EINVAL;
  for (size_t i = 0; i < dim; ++i)
    if (!isfinite(x[i])) return HM_ENONFINITE;
  return HM_OK;
}

hm_status hm_rk_drive(const hm_rk_method *m, const hm_dopri_options *opt, double t0, double t1, double h,
                      double *t_reached, hm_dopri_stats *s) {
  const double h_max = opt->h_max > 0.0 ? fmin(opt->h_max, t1 - t0) : t1 - t0;
  const size_t max_steps = opt->max_steps ? opt->max_steps : 100000000u;
  double t = t0;
  h = fmin(h, h_max);
  int last_rejected = 0, last_nonfinite = 0;
  hm_status st = HM_OK;
  while (t < t1 && st == HM_OK) {
    if (s->n_accepted + s->n_rejected >= max_steps) {
      st = HM_ESTEP;
      break;
    }
    if (h < 1e-14 * fmax(1.0, fabs(t))) {
      st = last_nonfinite ? HM_ENONFINITE : HM_ESTEP;
      break;
    }
    int final_step = 0;
    if (t + 1.01 * h >= t1) {
      h = t1 - t;
      final_step = 1;
    }
    double err;
    st = m->attempt(m->ctx, t, h, &err);
    s->n_rhs += m->rhs_per_attempt;
    if (st == HM_ENONFINITE) {
      err = INFINITY; /* a failed step: retry smaller */
      st = HM_OK;
    }
    if (st != HM_OK) break;
    last_nonfinite = !isfinite(err);
    if (err <= 1.0) {
      const double t_new = final_step ? t1 : t + h;
      int stop = 0;
      st = m->accept(m->ctx, t, t_new, h, &stop);
      s->n_rhs += m->rhs_per_accept;
      s->n_accepted++;
      t = t_new;
      if (stop) break;
      double fac = err > 0.0 ? 0.9 * pow(err, -m->expo) : m->fac_max;
      fac = fmin(m->fac_max, fmax(m->fac_min, fac));
      if (last_rejected) fac = fmin(fac, 1.0);
      h = fmin(h * fac, h_max);
      last_rejected = 0;
    } else {
      s->n_rejected++;
      h *= isfinite(err) ? fmax(m->fac_min, 0.9 * pow(err, -m->expo)) : 0.2;
      last_rejected = 1;
    }
  }
  *t_reached = t;
  return st;
}

/* ---- Dormand-Prince 5(4): tableau and Shampine's dense output (Hairer's DOPRI5) ---- */

static const double C2 = 1.0 / 5.0, C3 = 3.0 / 10.0, C4 = 4.0 / 5.0, C5 = 8.0 / 9.0;
static const double A21 = 1.0 / 5.0;
static const double A31 = 3.0 / 40.0, A32 = 9.0 / 40.0;
static const double A41 = 44.0 / 45.0, A42 = -56.0 / 15.0, A43 = 32.0 / 9.0;
static const double A51 = 19372.0 / 6561.0, A52 = -25360.0 / 2187.0, A53 = 64448.0 / 6561.0, A54 = -212.0 / 729.0;
static const double A61 = 9017.0 / 3168.0, A62 = -355.0 / 33.0, A63 = 46732.0 / 5247.0, A64 = 49.0 / 176.0,
                    A65 = -5103.0 / 18656.0;
static const double A71 = 35.0 / 384.0, A73 = 500.0 / 1113.0, A74 = 125.0 / 192.0, A75 = -2187.0 / 6784.0,
                    A76 = 11.0 / 84.0;
static const double E1 = 71.0 / 57600.0, E3 = -71.0 / 16695.0, E4 = 71.0 / 1920.0, E5 = -17253.0 / 339200.0,
                    E6 = 22.0 / 525.0, E7 = -1.0 / 40.0;
static const double D1 = -12715105075.0 / 11282082432.0, D3 = 87487479700.0 / 32700410799.0,
                    D4 = -10690763975.0 / 1880347072.0, D5 = 701980252875.0 / 199316789632.0,
                    D6 = -1453857185.0 / 822651844.0, D7 = 69997945.0 / 29380423.0;

struct hm_dopri_s {
  size_t dim;
  double *x, *xnew, *xs, *k1, *k2, *k3, *k4, *k5, *k6, *k7, *err;
  double *r1, *r2, *r3, *r4, *r5; /* dense-output coefficients of the last accepted step */
  double t_old, h_last;
  int have_dense;
};

hm_dopri hm_dopri_create(size_t dim) {
  if (dim == 0 || dim > (size_t)1 << 24) return NULL;
  hm_dopri d = calloc(1, sizeof *d);
  if (!d) return NULL;
  double *mem = calloc(16 * dim, sizeof(double));
  if (!mem) {
    free(d);
    return NULL;
  }
  d->dim = dim;
  double **slots[] = {&d->x,  &d->xnew, &d->xs, &d->k1, &d->k2, &d->k3, &d->k4, &d->k5,
                      &d->k6, &d->k7,   &d->err, &d->r1, &d->r2, &d->r3, &d->r4, &d->r5};
  for (size_t i = 0; i < 16; ++i) *slots[i] = mem + i * dim;
  return d;
}

void hm_dopri_destroy(hm_dopri d) {
  if (!d) return;
  free(d->x); /* the first slot owns the block */
  free(d);
}

/* xs = x + h * sum_j a_j k_j over the given stages. */
static void stage_state(size_t n, double *xs, const double *x, double h, int m, const double *a,
                        const double *const *k) {
  for (size_t i = 0; i < n; ++i) {
    double s = 0.0;
    for (int j = 0; j < m; ++j) s += a[j] * k[j][i];
    xs[i] = x[i] + h * s;
  }
}

/* One Dormand-Prince step from (t, d->x) with k1 = f(t, x) already in d->k1: fills xnew, k2..k7, err. */
static hm_status dopri_try(hm_dopri d, const hm_ode_system *sys, double t, double h) {
  const size_t n = d->dim;
  hm_status st;
  const double a2[] = {A21}, a3[] = {A31, A32}, a4[] = {A41, A42, A43}, a5[] = {A51, A52, A53, A54},
               a6[] = {A61, A62, A63, A64, A65}, a7[] = {A71, 0.0, A73, A74, A75, A76};
  const double *k[] = {d->k1, d->k2, d->k3, d->k4, d->k5, d->k6};
  stage_state(n, d->xs, d->x, h, 1, a2, k);
  if ((st = sys->rhs(t + C2 * h, d->xs, d->k2, sys->params)) != HM_OK) return st;
  stage_state(n, d->xs, d->x, h, 2, a3, k);
  if ((st = sys->rhs(t + C3 * h, d->xs, d->k3, sys->params)) != HM_OK) return st;
  stage_state(n, d->xs, d->x, h, 3, a4, k);
  if ((st = sys->rhs(t + C4 * h, d->xs, d->k4, sys->params)) != HM_OK) return st;
  stage_state(n, d->xs, d->x, h, 4, a5, k);
  if ((st = sys->rhs(t + C5 * h, d->xs, d->k5, sys->params)) != HM_OK) return st;
  stage_state(n, d->xs, d->x, h, 5, a6, k);
  if ((st = sys->rhs(t + h, d->xs, d->k6, sys->params)) != HM_OK) return st;
  stage_state(n, d->xnew, d->x, h, 6, a7, k);
  if ((st = sys->rhs(t + h, d->xnew, d->k7, sys->params)) != HM_OK) return st;
  for (size_t i = 0; i < n; ++i)
    d->err[i] = h * (E1 * d->k1[i] + E3 * d->k3[i] + E4 * d->k4[i] + E5 * d->k5[i] + E6 * d->k6[i] +
                     E7 * d->k7[i]);
  return HM_OK;
}

/* Weighted RMS norm of the error estimate; +inf if anything is not finite. */
static double dopri_error_norm(const hm_dopri d, const hm_dopri_options *opt) {
  double s = 0.0;
  const size_t m = hm_rk_err_dim(opt, d->dim);
  for (size_t i = 0; i < m; ++i) {
    const double sc = opt->atol + opt->rtol * fmax(fabs(d->x[i]), fabs(d->xnew[i]));
    const double e = d->err[i] / sc;
    s += e * e;
  }
  for (size_t i = m; i < d->dim; ++i) /* an uncontrolled component that is not finite still fails the step */
    if (!isfinite(d->err[i])) return INFINITY;
  s = sqrt(s / (double)m);
  return isfinite(s) ? s : INFINITY;
}

static void dopri_store_dense(hm_dopri d, double t, double h) {
  for (size_t i = 0; i < d->dim; ++i) {
    const double ydiff = d->xnew[i] - d->x[i];
    const double bspl = h * d->k1[i] - ydiff;
    d->r1[i] = d->x[i];
    d->r2[i] = ydiff;
    d->r3[i] = bspl;
    d->r4[i] = ydiff - h * d->k7[i] - bspl;
    d->r5[i] = h * (D1 * d->k1[i] + D3 * d->k3[i] + D4 * d->k4[i] + D5 * d->k5[i] + D6 * d->k6[i] +
                    D7 * d->k7[i]);
  }
  d->t_old = t;
  d->h_last = h;
  d->have_dense = 1;
}

hm_status hm_dopri_dense_partial(const hm_dopri d, double t, size_t first, size_t count, double *x_out) {
  if (!d || !x_out || !d->have_dense || first + count > d->dim || first + count < first) return HM_EINVAL;
  const double theta = (t - d->t_old) / d->h_last;
  if (!(theta >= -1e-12 && theta <= 1.0 + 1e-12)) return HM_EINVAL;
  const double theta1 = 1.0 - theta;
  for (size_t k = 0; k < count; ++k) {
    const size_t i = first + k;
    x_out[k] = d->r1[i] + theta * (d->r2[i] + theta1 * (d->r3[i] + theta * (d->r4[i] + theta1 * d->r5[i])));
  }
  return HM_OK;
}

hm_status hm_dopri_dense(const hm_dopri d, double t, double *x_out) {
  if (!d) return HM_EINVAL;
  return hm_dopri_dense_partial(d, t, 0, d->dim, x_out);
}

/* Hairer's starting-step heuristic (Solving ODEs I, II.4) with one explicit Euler probe. */
static hm_status dopri_initial_step(hm_dopri d, const hm_ode_system *sys, const hm_dopri_options *opt, double t,
                                    double h_max, double *h_out) {
  const size_t n = hm_rk_err_dim(opt, d->dim); /* the controlled components */
  double d0 = 0.0, d1 = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double sc = opt->atol + opt->rtol * fabs(d->x[i]);
    d0 += (d->x[i] / sc) * (d->x[i] / sc);
    d1 += (d->k1[i] / sc) * (d->k1[i] / sc);
  }
  d0 = sqrt(d0 / (double)n);
  d1 = sqrt(d1 / (double)n);
  double h0 = (d0 < 1e-5 || d1 < 1e-5) ? 1e-6 : 0.01 * d0 / d1;
  h0 = fmin(h0, h_max);
  for (size_t i = 0; i < d->dim; ++i) d->xs[i] = d->x[i] + h0 * d->k1[i];
  hm_status st = sys->rhs(t + h0, d->xs, d->k2, sys->params);
  if (st != HM_OK) return st;
  double d2 = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double sc = opt->atol + opt->rtol * fabs(d->x[i]);
    const double e = (d->k2[i] - d->k1[i]) / sc;
    d2 += e * e;
  }
  d2 = sqrt(d2 / (double)n) / h0;
  const double dm = fmax(d1, d2);
  const double h1 = dm <= 1e-15 ? fmax(1e-6, h0 * 1e-3) : pow(0.01 / dm, 0.2);
  *h_out = fmin(fmin(100.0 * h0, h1), h_max);
  return HM_OK;
}

typedef struct {
  hm_dopri d;
  const hm_ode_system *sys;
  const hm_dopri_options *opt;
  hm_dopri_observer observer;
  void *ctx;
} dopri_run;

static hm_status dopri_attempt(void *ctx, double t, double h, double *err) {
  dopri_run *r = (dopri_run *)ctx;
  hm_status st = dopri_try(r->d, r->sys, t, h);
  if (st == HM_OK) *err = dopri_error_norm(r->d, r->opt);
  return st;
}

static hm_status dopri_accept(void *ctx, double t_old, double t_new, double h, int *stop) {
  dopri_run *r = (dopri_run *)ctx;
  hm_dopri d = r->d;
  dopri_store_dense(d, t_old, h);
  memcpy(d->x, d->xnew, d->dim * sizeof(double));
  memcpy(d->k1, d->k7, d->dim * sizeof(double)); /* first same as last */
  *stop = r->observer && r->observer(d, t_old, t_new, d->x, r->ctx);
  return HM_OK;
}

hm_status hm_dopri_integrate(hm_dopri d, const hm_ode_system *sys, const hm_dopri_options *opt, double t0,
                             double t1, double *x, double *t_end, hm_dopri_observer observer, void *ctx,
                             hm_dopri_stats *stats) {
  if (!d) return HM_EINVAL;
  hm_status st = hm_rk_check(sys, d->dim, opt, t0, t1, x);
  if (st != HM_OK) return st;
  hm_dopri_stats s = {0, 0, 0};
  memcpy(d->x, x, d->dim * sizeof(double));
  d->have_dense = 0;
  double t = t0;
  if (t1 > t0) {
    const double h_max = opt->h_max > 0.0 ? fmin(opt->h_max, t1 - t0) : t1 - t0;
    if ((st = sys->rhs(t, d->x, d->k1, sys->params)) != HM_OK) return st;
    s.n_rhs = 1;
    double h = opt->h_init > 0.0 ? fmin(opt->h_init, h_max) : 0.0;
    if (h == 0.0) {
      if ((st = dopri_initial_step(d, sys, opt, t, h_max, &h)) != HM_OK) return st;
      s.n_rhs++;
    }
    dopri_run r = {d, sys, opt, observer, ctx};
    const hm_rk_method m = {dopri_attempt, dopri_accept, &r, 0.2, 0.2, 5.0, 6, 0};
    if ((st = hm_rk_drive(&m, opt, t0, t1, h, &t, &s)) != HM_OK) return st;
  }
  memcpy(x, d->x, d->dim * sizeof(double));
  if (t_end) *t_end = t;
  if (stats) *stats = s;
  return HM_OK;
}

/* ---- implicit midpoint rule ---- */

struct hm_midpoint_s {
  size_t dim;
  double *z, *mid, *f, *jac, *a, *b, *rhs;
  int *ipiv;
};

hm_midpoint hm_midpoint_create(size_t dim) {
  if (dim == 0 || dim > 4096) return NULL;
  hm_midpoint mp = calloc(1, sizeof *mp);
  if (!mp) return NULL;
  double *mem = calloc(4 * dim + 3 * dim * dim, sizeof(double));
  int *ipiv = calloc(dim, sizeof(int));
  if (!mem || !ipiv) {
    free(mem);
    free(ipiv);
    free(mp);
    return NULL;
  }
  mp->dim = dim;
  mp->z = mem;
  mp->mid = mem + dim;
  mp->f = mem + 2 * dim;
  mp->rhs = mem + 3 * dim;
  mp->jac = mem + 4 * dim;
  mp->a = mp->jac + dim * dim;
  mp->b = mp->a + dim * dim;
  mp->ipiv = ipiv;
  return mp;
}

void hm_midpoint_destroy(hm_midpoint mp) {
  if (!mp) return;
  free(mp->z);
  free(mp->ipiv);
  free(mp);
}

/* mp->a = I + s J (column-major), J row-major at mp->jac. */
static void identity_plus(hm_midpoint mp, double s) {
  const size_t n = mp->dim;
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) mp->a[i + j * n] = (i == j ? 1.0 : 0.0) + s * mp->jac[i * n + j];
}

static hm_status midpoint_eval(hm_midpoint mp, const hm_ode_system *sys, double t, const double *x) {
  const size_t n = mp->dim;
  for (size_t i = 0; i < n; ++i) mp->mid[i] = 0.5 * (x[i] + mp->z[i]);
  hm_status st = sys->rhs(t, mp->mid, mp->f, sys->params);
  if (st != HM_OK) return st;
  return sys->jac(t, mp->mid, mp->jac, sys->params);
}

hm_status hm_midpoint_step(hm_midpoint mp, const hm_ode_system *sys, double t, double h, double newton_tol,
                           size_t max_iter, double *x, double *tangent, size_t k) {
  if (!mp || !sys || !x || !sys->rhs || !sys->jac || sys->dim != mp->dim) return HM_EINVAL;
  if (!(h > 0.0) || !isfinite(h) || !(newton_tol > 0.0) || max_iter == 0 || k > mp->dim) return HM_EINVAL;
  const size_t n = mp->dim;
  const int ni = (int)n, one = 1;
  int info = 0;
  const double tm = t + 0.5 * h;
  hm_status st = sys->rhs(t, x, mp->f, sys->params);
  if (st != HM_OK) return st;
  for (size_t i = 0; i < n; ++i) mp->z[i] = x[i] + h * mp->f[i];
  int converged = 0;
  for (size_t it = 0; it < max_iter && !converged; ++it) {
    if ((st = midpoint_eval(mp, sys, tm, x)) != HM_OK) return st;
    for (size_t i = 0; i < n; ++i) mp->rhs[i] = -(mp->z[i] - x[i] - h * mp->f[i]);
    identity_plus(mp, -0.5 * h); /* d/dz of the residual: I - h/2 J(mid) */
    dgesv_(&ni, &one, mp->a, &ni, mp->ipiv, mp->rhs, &ni, &info);
    if (info != 0) return HM_ELAPACK;
    double dmax = 0.0, zmax = 0.0;
    for (size_t i = 0; i < n; ++i) {
      mp->z[i] += mp->rhs[i];
      dmax = fmax(dmax, fabs(mp->rhs[i]));
      zmax = fmax(zmax, fabs(mp->z[i]));
    }
    if (!isfinite(dmax) || !isfinite(zmax)) return HM_ENONFINITE;
    converged = dmax <= newton_tol * (1.0 + zmax);
  }
  if (!converged) return HM_ENOCONV;
  if (tangent && k > 0) {
    if ((st = midpoint_eval(mp, sys, tm, x)) != HM_OK) return st;
    identity_plus(mp, 0.5 * h);
    /* b = (I + h/2 J) tangent, column-major dim x k */
    for (size_t c = 0; c < k; ++c)
      for (size_t i = 0; i < n; ++i) {
        double s = 0.0;
        for (size_t l = 0; l < n; ++l) s += mp->a[i + l * n] * tangent[l + c * n];
        mp->b[i + c * n] = s;
      }
    identity_plus(mp, -0.5 * h);
    const int ki = (int)k;
    dgesv_(&ni, &ki, mp->a, &ni, mp->ipiv, mp->b, &ni, &info);
    if (info != 0) return HM_ELAPACK;
    memcpy(tangent, mp->b, n * k * sizeof(double));
  }
  memcpy(x, mp->z, n * sizeof(double));
  return HM_OK;
}
