/* Levenberg-Marquardt fit of lambda(y) = constant + Gaussians (see conicity_fit.h). */
#include "hunting_monitor/conicity_fit.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lapack.h"


#define MAXP (1 + 3 * HM_CONICITY_MAX_TERMS)

typedef enum { UNIT_SINGLE, UNIT_PAIR, UNIT_CENTRED } unit_kind;

typedef struct {
  const double *y, *l;
  size_t n;
  int fit_constant;
  size_t n_units;
  unit_kind kind[HM_CONICITY_MAX_TERMS];
  size_t np;        /* parameters */
  double *J;        /* n x np, row-major */
  double *r;        /* residuals */
} problem;

void hm_fit_options_default(hm_fit_options *opt) {
  opt->n_terms = 2;
  opt->symmetric = 0;
  opt->fit_constant = 1;
  opt->max_iter = 400;
  opt->tol = 1e-12;
}

/* Parameter layout: [constant], then per unit (a, b, log c), or (a, log c) for a centred term. */
static size_t unit_params(unit_kind k) { return k == UNIT_CENTRED ? 2 : 3; }

/* Model value at y and (if grad) its gradient with respect to p. */
static double model(const problem *pr, const double *p, double y, double *grad) {
  size_t k = 0;
  double v = 0.0;
  if (pr->fit_constant) {
    v = p[0];
    if (grad) grad[0] = 1.0;
    k = 1;
  }
  for (size_t u = 0; u < pr->n_units; ++u) {
    const unit_kind kind = pr->kind[u];
    const double a = p[k], b = kind == UNIT_CENTRED ? 0.0 : p[k + 1];
    const double c = exp(p[k + unit_params(kind) - 1]);
    const double u1 = (y - b) / c, g1 = exp(-u1 * u1);
    double ga = g1, gb = a * g1 * 2.0 * u1 / c, gt = a * g1 * 2.0 * u1 * u1;
    if (kind == UNIT_PAIR) {
      const double u2 = (y + b) / c, g2 = exp(-u2 * u2);
      ga += g2;
      gb -= a * g2 * 2.0 * u2 / c;
      gt += a * g2 * 2.0 * u2 * u2;
    }
    v += a * ga;
    if (grad) {
      grad[k] = ga;
      if (kind != UNIT_CENTRED) grad[k + 1] = gb;
      grad[k + unit_params(kind) - 1] = gt;
    }
    k += unit_params(kind);
  }
  return v;
}

/* Residuals (and Jacobian if with_jac); returns SSE (inf if not finite). */
static double evaluate(problem *pr, const double *p, int with_jac) {
  double sse = 0.0;
  for (size_t i = 0; i < pr->n; ++i) {
    const double m = model(pr, p, pr->y[i], with_jac ? pr->J + i * pr->np : NULL);
    pr->r[i] = m - pr->l[i];
    sse += pr->r[i] * pr->r[i];
  }
  return isfinite(sse) ? sse : INFINITY;
}

/* J^T J (column-major, full) and g = J^T r. */
static void normal_equations(const problem *pr, double *A, double *g) {
  const size_t np = pr->np;
  memset(A, 0, np * np * sizeof(double));
  memset(g, 0, np * sizeof(double));
  for (size_t i = 0; i < pr->n; ++i) {
    const double *Ji = pr->J + i * np;
    for (size_t a = 0; a < np; ++a) {
      g[a] += Ji[a] * pr->r[i];
      for (size_t b = 0; b <= a; ++b) A[a + b * np] += Ji[a] * Ji[b];
    }
  }
  for (size_t a = 0; a < np; ++a)
    for (size_t b = 0; b < a; ++b) A[b + a * np] = A[a + b * np];
}

/* Levenberg-Marquardt from p (in/out); returns the final SSE and the iteration count. */
static double levenberg_marquardt(problem *pr, double *p, const hm_fit_options *opt, size_t *iters) {
  const size_t np = pr->np;
  const int n = (int)np, one = 1;
  double A[MAXP * MAXP], M[MAXP * MAXP], g[MAXP], d[MAXP], trial[MAXP];
  double sse = evaluate(pr, p, 1);
  if (!isfinite(sse)) return INFINITY;
  normal_equations(pr, A, g);
  double mu = 0.0, nu = 2.0;
  for (size_t a = 0; a < np; ++a) mu = fmax(mu, A[a + a * np]);
  mu *= 1e-3;
  size_t it;
  for (it = 0; it < opt->max_iter; ++it) {
    memcpy(M, A, np * np * sizeof(double));
    for (size_t a = 0; a < np; ++a) {
      M[a + a * np] += mu * fmax(A[a + a * np], 1e-30);
      d[a] = -g[a];
    }
    int info = 0;
    dposv_("L", &n, &one, M, &n, d, &n, &info, 1);
    if (info != 0) {
      mu *= nu;
      nu *= 2.0;
      continue;
    }
    double dn = 0.0, pn = 0.0, predicted = 0.0;
    for (size_t a = 0; a < np; ++a) {
      trial[a] = p[a] + d[a];
      dn += d[a] * d[a];
      pn += p[a] * p[a];
      predicted += d[a] * (mu * fmax(A[a + a * np], 1e-30) * d[a] - g[a]);
    }
    if (sqrt(dn) <= opt->tol * (sqrt(pn) + opt->tol)) break;
    /* the trial is evaluated with its Jacobian: if it is accepted that is the next step's Jacobian; if not,
     * A and g (built from the last accepted point) stay valid */
    const double sse_trial = evaluate(pr, trial, 1);
    const double rho = predicted > 0.0 ? (sse - sse_trial) / predicted : -1.0;
    if (sse_trial < sse) {
      const double rel = (sse - sse_trial) / fmax(sse, 1e-300);
      memcpy(p, trial, np * sizeof(double));
      sse = sse_trial;
      normal_equations(pr, A, g);
      const double f = 2.0 * rho - 1.0;
      mu *= fmax(1.0 / 3.0, 1.0 - f * f * f);
      nu = 2.0;
      if (rel <= opt->tol) break;
    } else {
      mu *= nu;
      nu *= 2.0;
      if (mu > 1e30) break;
    }
  }
  *iters = it;
  return sse;
}

/* ---- starting points ---- */

typedef struct {
  double y, h; /* position and height above the baseline */
  double hw;   /* half width at half maximum */
} peak;

/* Local maxima of the (3-point smoothed) data above the baseline, by decreasing height; data sorted by y. */
static size_t find_peaks(const double *y, const double *l, size_t n, double base, peak *pk, size_t max) {
  size_t m = 0;
  for (size_t i = 1; i + 1 < n; ++i) {
    const double s = (l[i - 1] + l[i] + l[i + 1]) / 3.0;
    const double sl = i >= 2 ? (l[i - 2] + l[i - 1] + l[i]) / 3.0 : l[i - 1];
    const double sr = i + 2 < n ? (l[i] + l[i + 1] + l[i + 2]) / 3.0 : l[i + 1];
    if (!(s >= sl && s > sr) || s - base <= 0.0) continue;
    const double h = s - base;
    size_t a = i, b = i;
    while (a > 0 && l[a] - base > 0.5 * h) --a;
    while (b + 1 < n && l[b] - base > 0.5 * h) ++b;
    peak p = {y[i], h, fmax(0.5 * (y[b] - y[a]), 1e-9)};
    /* insert by height */
    size_t j = m < max ? m++ : max - 1;
    if (j == max - 1 && m == max && pk[j].h >= h) continue;
    while (j > 0 && pk[j - 1].h < h) {
      pk[j] = pk[j - 1];
      --j;
    }
    pk[j] = p;
  }
  return m;
}

/* Parameters of start number s (0..n_starts-1); 0 if there is no such start. */
static int make_start(const problem *pr, const peak *pk, size_t npk, double base, double ymin, double ymax, int s,
                      double *p) {
  const double width_scale[3] = {1.0, 0.5, 2.0};
  if (s > 3) return 0;
  size_t k = 0;
  if (pr->fit_constant) p[k++] = base;
  size_t used = 0;
  const double span = ymax - ymin, top = npk ? pk[0].h : 0.1;
  for (size_t u = 0; u < pr->n_units; ++u) {
    const unit_kind kind = pr->kind[u];
    double a = top, b = ymin + span * ((double)u + 0.5) / (double)pr->n_units, c = span / (4.0 * pr->n_units);
    if (s < 3 && kind != UNIT_CENTRED) {
      /* the next unused peak (for pairs: on the positive side, mirrored) */
      while (used < npk && kind == UNIT_PAIR && pk[used].y <= 0.0) ++used;
      if (used < npk) {
        a = pk[used].h;
        b = kind == UNIT_PAIR ? fabs(pk[used].y) : pk[used].y;
        c = pk[used].hw / sqrt(log(2.0)) * width_scale[s];
        ++used;
      }
    } else if (kind == UNIT_PAIR) {
      b = fabs(b) + 0.25 * span / (double)pr->n_units;
    }
    if (kind == UNIT_CENTRED) b = 0.0;
    p[k++] = a;
    if (kind != UNIT_CENTRED) p[k++] = b;
    p[k++] = log(fmax(c, 1e-9));
  }
  return 1;
}

/* ---- statistics ---- */

static void standard_errors(problem *pr, const double *p, double rmse, hm_fit_result *res) {
  const size_t np = pr->np;
  double A[MAXP * MAXP], g[MAXP];
  evaluate(pr, p, 1);
  /* Jacobian columns of log c -> c: divide by c */
  size_t k = pr->fit_constant;
  for (size_t u = 0; u < pr->n_units; ++u) {
    const size_t col = k + unit_params(pr->kind[u]) - 1;
    const double c = exp(p[col]);
    for (size_t i = 0; i < pr->n; ++i) pr->J[i * np + col] /= c;
    k += unit_params(pr->kind[u]);
  }
  normal_equations(pr, A, g);
  const int n = (int)np;
  int info = 0;
  dpotrf_("L", &n, A, &n, &info, 1);
  if (info == 0) dpotri_("L", &n, A, &n, &info, 1);
  res->se_available = info == 0;
  double se[MAXP];
  for (size_t a = 0; a < np; ++a) se[a] = info == 0 ? rmse * sqrt(fmax(A[a + a * np], 0.0)) : NAN;
  k = 0;
  res->constant_se = 0.0;
  if (pr->fit_constant) res->constant_se = se[k++];
  size_t term = 0;
  for (size_t u = 0; u < pr->n_units; ++u) {
    const unit_kind kind = pr->kind[u];
    const double sa = se[k], sb = kind == UNIT_CENTRED ? 0.0 : se[k + 1], sc = se[k + unit_params(kind) - 1];
    for (int copy = 0; copy < (kind == UNIT_PAIR ? 2 : 1); ++copy, ++term) {
      res->amplitude_se[term] = sa;
      res->center_se[term] = sb;
      res->width_se[term] = sc;
    }
    k += unit_params(kind);
  }
}

static void conicity_of(const problem *pr, const double *p, hm_conicity *con) {
  memset(con, 0, sizeof *con);
  size_t k = 0;
  if (pr->fit_constant) con->constant = p[k++];
  for (size_t u = 0; u < pr->n_units; ++u) {
    const unit_kind kind = pr->kind[u];
    const double a = p[k], b = kind == UNIT_CENTRED ? 0.0 : p[k + 1], c = exp(p[k + unit_params(kind) - 1]);
    con->terms[con->n_terms++] = (hm_gaussian){a, b, c};
    if (kind == UNIT_PAIR) con->terms[con->n_terms++] = (hm_gaussian){a, -b, c};
    k += unit_params(kind);
  }
}

static hm_status reject(char *why, size_t len, hm_status st, const char *msg) {
  if (why && len) snprintf(why, len, "%s", msg);
  return st;
}

static int compare_by_y(const void *a, const void *b) {
  const double ya = ((const double *)a)[0], yb = ((const double *)b)[0];
  return (ya > yb) - (ya < yb);
}

hm_status hm_conicity_fit(const double *y_m, const double *conicity, size_t n, const hm_fit_options *opt,
                          hm_fit_result *out, char *why, size_t why_len) {
  if (!y_m || !conicity || !opt || !out) return reject(why, why_len, HM_EINVAL, "NULL argument");
  if (opt->n_terms < 1 || opt->n_terms > HM_CONICITY_MAX_TERMS || opt->max_iter == 0 || !(opt->tol > 0.0))
    return reject(why, why_len, HM_EINVAL, "terms must be 1..8, max_iter > 0 and tol > 0");
  problem pr;
  memset(&pr, 0, sizeof pr);
  pr.fit_constant = opt->fit_constant != 0;
  pr.n_units = 0;
  if (opt->symmetric) {
    for (size_t i = 0; i < opt->n_terms / 2; ++i) pr.kind[pr.n_units++] = UNIT_PAIR;
    if (opt->n_terms % 2) pr.kind[pr.n_units++] = UNIT_CENTRED;
  } else {
    for (size_t i = 0; i < opt->n_terms; ++i) pr.kind[pr.n_units++] = UNIT_SINGLE;
  }
  pr.np = (size_t)pr.fit_constant;
  for (size_t u = 0; u < pr.n_units; ++u) pr.np += unit_params(pr.kind[u]);
  char msg[160];
  if (n < pr.np + 1) {
    snprintf(msg, sizeof msg, "%zu points cannot determine %zu parameters (need at least %zu points)", n, pr.np,
             pr.np + 1);
    return reject(why, why_len, HM_EDOMAIN, msg);
  }
  double ymin = INFINITY, ymax = -INFINITY, mean = 0.0, lmin = INFINITY, lmax = -INFINITY;
  for (size_t i = 0; i < n; ++i) {
    if (!isfinite(y_m[i]) || !isfinite(conicity[i])) {
      snprintf(msg, sizeof msg, "point %zu is not a finite number (y %g, conicity %g)", i + 1, y_m[i], conicity[i]);
      return reject(why, why_len, HM_EDOMAIN, msg);
    }
    ymin = fmin(ymin, y_m[i]);
    ymax = fmax(ymax, y_m[i]);
    lmin = fmin(lmin, conicity[i]);
    lmax = fmax(lmax, conicity[i]);
    mean += conicity[i];
  }
  mean /= (double)n;
  if (ymax == ymin) return reject(why, why_len, HM_EDOMAIN, "all displacements are equal: no curve can be fitted");
  if (lmax == lmin) return reject(why, why_len, HM_EDOMAIN, "the conicity is constant: use conicity.constant alone");
  /* sorted copy for the peak search; problem arrays */
  double *pairs = malloc(2 * n * sizeof(double)), *ys = malloc(2 * n * sizeof(double));
  pr.J = malloc(n * pr.np * sizeof(double));
  pr.r = malloc(n * sizeof(double));
  peak *pk = malloc(n * sizeof(peak));
  hm_status st = HM_OK;
  if (!pairs || !ys || !pr.J || !pr.r || !pk) st = HM_ENOMEM;
  double best[MAXP], best_sse = INFINITY;
  size_t best_iters = 0, tried = 0;
  if (st == HM_OK) {
    for (size_t i = 0; i < n; ++i) {
      pairs[2 * i] = y_m[i];
      pairs[2 * i + 1] = conicity[i];
    }
    qsort(pairs, n, 2 * sizeof(double), compare_by_y);
    for (size_t i = 0; i < n; ++i) {
      ys[i] = pairs[2 * i];
      ys[n + i] = pairs[2 * i + 1];
    }
    const double base = pr.fit_constant ? lmin : 0.0;
    const size_t npk = find_peaks(ys, ys + n, n, base, pk, n);
    pr.y = y_m;
    pr.l = conicity;
    pr.n = n;
    double p[MAXP];
    for (int s = 0; make_start(&pr, pk, npk, base, ymin, ymax, s, p); ++s) {
      size_t iters = 0;
      const double sse = levenberg_marquardt(&pr, p, opt, &iters);
      ++tried;
      if (sse < best_sse) {
        best_sse = sse;
        memcpy(best, p, pr.np * sizeof(double));
        best_iters = iters;
      }
    }
    if (!isfinite(best_sse)) st = HM_ENOCONV;
  }
  if (st == HM_OK) {
    hm_fit_result res;
    memset(&res, 0, sizeof res);
    conicity_of(&pr, best, &res.conicity);
    double sst = 0.0;
    for (size_t i = 0; i < n; ++i) sst += (conicity[i] - mean) * (conicity[i] - mean);
    res.n_points = n;
    res.n_params = pr.np;
    res.dof = n - pr.np;
    res.sse = best_sse;
    res.r2 = 1.0 - best_sse / sst;
    res.adj_r2 = 1.0 - (best_sse / (double)res.dof) / (sst / (double)(n - 1));
    res.rmse = sqrt(best_sse / (double)res.dof);
    res.iterations = best_iters;
    res.starts_tried = tried;
    standard_errors(&pr, best, res.rmse, &res);
    *out = res;
  } else if (why && why_len) {
    snprintf(why, why_len, "%s", st == HM_ENOMEM ? "out of memory" : "no starting point converged to a finite fit");
  }
  free(pairs);
  free(ys);
  free(pr.J);
  free(pr.r);
  free(pk);
  return st;
}
