/* Pseudo-arclength continuation engine (see continuation.h). */
#include "continuation.h"

#include <math.h>
#include <string.h>

#include "hunting_monitor/roots.h"
#include "lapack.h"

enum { MAXN = HM_CONT_MAX_N };

const char *hm_cont_stop_name(hm_cont_stop stop) {
  switch (stop) {
    case HM_CONT_STEP_LIMIT: return "step limit reached";
    case HM_CONT_PARAM_RANGE: return "parameter left its range";
    case HM_CONT_PARAM2_RANGE: return "second parameter left its range";
    case HM_CONT_AMP_MAX: return "amplitude limit reached";
    case HM_CONT_AMP_MIN: return "fold cycle shrank to the minimum amplitude (towards a GH point)";
    case HM_CONT_MIN_STEP: return "no convergence at the smallest step";
  }
  return "?";
}

void hm_cont_options_default(hm_cont_options *o) {
  o->ds_init = 0.2;
  o->ds_min = 1e-4;
  o->ds_max = 20.0;
  o->max_steps = 2000;
  o->min_tangent_cos = 0.95;
  o->fast_newton_iters = 2;
  o->slow_newton_iters = 5;
  o->grow_factor = 1.5;
  o->shrink_factor = 0.7;
  o->jump_floor = 0.05;
  o->predictor_tol = 0.03;
  o->curvature_predictor = 1;
  o->newton_tol = 1e-9;
  o->newton_max_iter = 8;
  o->locate_tol = 1e-9;
}

int hm_cont_options_valid(const hm_cont_options *o) {
  return o && o->ds_min > 0.0 && o->ds_init >= o->ds_min && o->ds_max >= o->ds_init && isfinite(o->ds_max) &&
         o->max_steps > 0 && o->min_tangent_cos > 0.0 && o->min_tangent_cos < 1.0 && o->fast_newton_iters >= 1 &&
         o->slow_newton_iters > o->fast_newton_iters && o->grow_factor >= 1.0 && isfinite(o->grow_factor) &&
         o->shrink_factor > 0.0 && o->shrink_factor <= 1.0 && o->jump_floor >= 0.0 && o->predictor_tol >= 0.0 && isfinite(o->predictor_tol) &&
         (o->curvature_predictor == 0 || o->curvature_predictor == 1) && o->newton_tol > 0.0 &&
         o->newton_max_iter > 0 && o->locate_tol > 0.0;
}

/* Solve [jac; row] x = b in place (n x n, jac row-major (n - 1) x n). */
static hm_status solve_bordered(size_t n, const double *jac, const double *row, double *b) {
  double A[MAXN * MAXN];
  for (size_t i = 0; i + 1 < n; ++i)
    for (size_t j = 0; j < n; ++j) A[i + n * j] = jac[n * i + j];
  for (size_t j = 0; j < n; ++j) A[(n - 1) + n * j] = row[j];
  int ipiv[MAXN], info = 0;
  const int nn = (int)n, one = 1;
  dgesv_(&nn, &one, A, &nn, ipiv, b, &nn, &info);
  return info == 0 ? HM_OK : HM_ELAPACK;
}

hm_status hm_cont_correct(hm_cont_problem *p, const hm_cont_options *o, double *u, const double *row, double target,
                          const double *tref, void *node, int *iters) {
  const size_t n = p->n;
  double w[MAXN], res[MAXN], jac[MAXN * MAXN];
  memcpy(w, u, n * sizeof(double));
  memset(jac, 0, sizeof jac);
  size_t it = 0;
  int converged = 0;
  double dprev = INFINITY;
  for (; it < o->newton_max_iter && !converged; ++it) {
    hm_status st = p->eval(p->ctx, w, (int)it, res, jac);
    ++p->newton_iterations;
    if (st != HM_OK) return st;
    double b[MAXN], rowdot = 0.0;
    for (size_t j = 0; j < n; ++j) rowdot += row[j] * w[j] / p->scale[j];
    for (size_t i = 0; i + 1 < n; ++i) b[i] = -res[i];
    b[n - 1] = -(rowdot - target);
    if ((st = solve_bordered(n, jac, row, b)) != HM_OK) return st;
    double dmax = 0.0;
    for (size_t j = 0; j < n; ++j) {
      w[j] += b[j] * p->scale[j];
      dmax = fmax(dmax, fabs(b[j]));
    }
    if (!isfinite(dmax) || dmax > 50.0) return HM_ENOCONV; /* diverging */
    /* converged when the update, or the error left after it, is below the tolerance: at a contraction rate
     * dmax / dprev (linear at worst: the LPC system's chord row) the remaining error is about dmax^2 / dprev */
    converged = dmax <= o->newton_tol || (isfinite(dprev) && dmax < 0.5 * dprev && dmax * dmax <= o->newton_tol * dprev);
    dprev = dmax;
  }
  if (!converged) return HM_ENOCONV;
  /* tangent: the null vector of the Jacobian (last evaluation), normalised and oriented along tref */
  double t[MAXN] = {0}, norm = 0.0, dot = 0.0;
  t[n - 1] = 1.0;
  hm_status st = solve_bordered(n, jac, tref, t);
  if (st != HM_OK) return st;
  for (size_t j = 0; j < n; ++j) norm += t[j] * t[j];
  norm = sqrt(norm);
  if (!(norm > 0.0) || !isfinite(norm)) return HM_ENONFINITE;
  for (size_t j = 0; j < n; ++j) {
    t[j] /= norm;
    dot += t[j] * tref[j];
  }
  if (dot < 0.0)
    for (size_t j = 0; j < n; ++j) t[j] = -t[j];
  if ((st = p->finish(p->ctx, w, t, node)) != HM_OK) return st;
  memcpy(u, w, n * sizeof(double));
  if (iters) *iters = (int)it;
  return HM_OK;
}

/* The step from a of length sigma; Newton starts from the predictor, or, given a point `near` on the branch that
 * satisfies the arclength condition at near_sigma, from near moved along a's tangent to sigma (event location). */
static hm_status cont_step(hm_cont_problem *p, const hm_cont_options *o, const void *a, double sigma, void *out,
                           int *iters, double *pred_err, const double *near, double near_sigma, const double *kappa) {
  const hm_cont_point *pa = (const hm_cont_point *)a;
  const size_t n = p->n;
  double w[MAXN], pred[MAXN], target = 0.0;
  for (size_t j = 0; j < n; ++j) {
    target += pa->t[j] * (pa->u[j] / p->scale[j] + sigma * pa->t[j]);
    pred[j] = pa->u[j] + (sigma * pa->t[j] + (kappa ? 0.5 * sigma * sigma * kappa[j] : 0.0)) * p->scale[j];
    w[j] = near ? near[j] + (sigma - near_sigma) * pa->t[j] * p->scale[j] : pred[j];
  }
  hm_status st = hm_cont_correct(p, o, w, pa->t, target, pa->t, out, iters);
  if (st != HM_OK) return st;
  /* A corrector that lands farther from the predictor than the step itself has jumped to another branch
   * (for cycles typically the trivial one, x0 = 0, which solves the shooting equations for every T and p). */
  double dist = 0.0;
  for (size_t j = 0; j < n; ++j) dist += (w[j] - pred[j]) * (w[j] - pred[j]) / (p->scale[j] * p->scale[j]);
  if (pred_err) *pred_err = sqrt(dist);
  return sqrt(dist) > fmax(fabs(sigma), o->jump_floor) ? HM_ENOCONV : HM_OK;
}

hm_status hm_cont_step(hm_cont_problem *p, const hm_cont_options *o, const void *a, double sigma, void *out,
                       int *iters) {
  return cont_step(p, o, a, sigma, out, iters, NULL, NULL, 0.0, NULL);
}

hm_cont_stop hm_cont_run(hm_cont_problem *p, const hm_cont_options *o, void *cur, void *scratch,
                         hm_cont_stats *stats) {
  hm_cont_stats s = {HM_CONT_STEP_LIMIT, 0, 0, 0, 0, 0};
  const size_t newton0 = p->newton_iterations;
  double ds = o->ds_init, kappa[MAXN] = {0};
  int have_kappa = 0;
  for (size_t attempt = 0; attempt < o->max_steps; ++attempt) {
    const int reason = p->stop(p->ctx, cur);
    if (reason != HM_CONT_RUNNING) {
      s.stop = (hm_cont_stop)reason;
      break;
    }
    int iters = 0;
    double pred_err = 0.0;
    hm_status st = cont_step(p, o, cur, ds, scratch, &iters, &pred_err, NULL, 0.0, have_kappa ? kappa : NULL);
    double dot = 0.0;
    if (st == HM_OK)
      for (size_t j = 0; j < p->n; ++j) dot += ((hm_cont_point *)scratch)->t[j] * ((hm_cont_point *)cur)->t[j];
    if (st != HM_OK || dot < o->min_tangent_cos) {
      ++s.rejected;
      if (ds <= o->ds_min) {
        s.stop = HM_CONT_MIN_STEP;
        break;
      }
      ds = fmax(0.5 * ds, o->ds_min);
      continue;
    }
    if (p->accepted) p->accepted(p->ctx, cur, scratch, ds);
    /* the branch's curvature (scaled) from the tangents at both ends: the next predictor's second-order term */
    have_kappa = o->curvature_predictor;
    for (size_t j = 0; j < p->n; ++j)
      kappa[j] = (((hm_cont_point *)scratch)->t[j] - ((hm_cont_point *)cur)->t[j]) / ds;
    memcpy(cur, scratch, p->node_size);
    ++s.steps;
    if (o->predictor_tol > 0.0) {
      /* the predictor's error grows as ds^2 (tangent) or ds^3 (with the curvature) */
      const double r = pred_err > 0.0 ? o->predictor_tol / pred_err : INFINITY;
      const double f = have_kappa ? cbrt(r) : sqrt(r);
      ds = fmin(fmax(ds * fmin(fmax(f, o->shrink_factor), o->grow_factor), o->ds_min), o->ds_max);
    } else if (iters <= o->fast_newton_iters) ds = fmin(o->grow_factor * ds, o->ds_max);
    else if (iters >= o->slow_newton_iters) ds = fmax(o->shrink_factor * ds, o->ds_min);
  }
  s.newton_iterations = p->newton_iterations - newton0;
  if (stats) *stats = s;
  return s.stop;
}

typedef struct {
  hm_cont_problem *p;
  const hm_cont_options *o;
  const void *a;
  void *node;
  double (*test)(const void *node, void *arg);
  void *arg;
  double near[MAXN], near_sigma; /* the latest point found, the start of the next correction */
} locate_ctx;

static hm_status locate_fn(double sigma, double *value, void *ctx) {
  locate_ctx *l = (locate_ctx *)ctx;
  hm_status st = cont_step(l->p, l->o, l->a, sigma, l->node, NULL, NULL, l->near, l->near_sigma, NULL);
  if (st == HM_OK) {
    *value = l->test(l->node, l->arg);
    memcpy(l->near, ((const hm_cont_point *)l->node)->u, sizeof l->near);
    l->near_sigma = sigma;
  }
  return st;
}

hm_status hm_cont_locate(hm_cont_problem *p, const hm_cont_options *o, const void *a, const void *b, double ds,
                         double fa, double fb, double (*test)(const void *node, void *arg), void *arg, void *out) {
  locate_ctx l = {p, o, a, out, test, arg, {0}, ds};
  memcpy(l.near, ((const hm_cont_point *)b)->u, sizeof l.near);
  double root;
  hm_status st = hm_brent_root(locate_fn, &l, 0.0, ds, fa, fb, o->locate_tol, 100, &root);
  if (st == HM_OK && root != l.near_sigma) /* else out holds the point found last, at the root */
    st = cont_step(p, o, a, root, out, NULL, NULL, l.near, l.near_sigma, NULL);
  return st;
}
