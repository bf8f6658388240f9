/* Two-parameter continuation of folds of cycles (LPC curves) and location of their cusps (CPC). */
#include <math.h>
#include <string.h>

#include "continuation.h"
#include "hunting_monitor/cycles.h"
#include "lapack.h"
#include "shooting.h"

void hm_lpc_options_default(hm_lpc_options *opt, hm_param param2) {
  opt->param2 = param2;
  opt->p2_min = param2 == HM_PARAM_CONICITY ? 1e-3 : param2 == HM_PARAM_SPEED ? 10.0 : 0.1;
  opt->p2_max = param2 == HM_PARAM_CONICITY ? 2.0 : param2 == HM_PARAM_SPEED ? 2000.0 : 100.0;
  opt->amp_min_m = 5e-4;
  opt->fd_step = 1e-6;
  hm_cont_options_default(&opt->cont);
  opt->cont.ds_init = 0.1;
  opt->cont.max_steps = 400;
  opt->cont.min_tangent_cos = 0.9;
  /* the fold row's gradient is a chord, so 3 iterations is fast convergence here */
  opt->cont.fast_newton_iters = 3;
  opt->cont.slow_newton_iters = 6;
}

/* A point of the LPC system with its tangent (scaled), u = (y0, psi0, dpsi0, T, p1, p2). */
typedef struct {
  hm_cont_point head;
  double amp;
} lnode;

typedef struct {
  hm_sh sh;
  hm_shot last;
  hm_cont_problem prob;
  const hm_cycle_options *copt;
  const hm_lpc_options *lopt;
  hm_lpc_point *buf;      /* the current direction's points */
  size_t cap, n;
  hm_lpc_point *cusps;
  size_t max_cusps, n_cusps;
} lctx;

/* Fold test: det of the scaled Jacobian of the residual with respect to (y0, psi0, dpsi0, T). */
static hm_status fold_test(const hm_sh *c, const hm_shot *s, double *g) {
  double A[NX * NX];
  for (int i = 0; i < NX; ++i)
    for (int j = 0; j < NX; ++j) A[i + NX * j] = s->jac[NW * i + j] * c->sc[j] / hm_sh_res_scale[i];
  int ipiv[NX], info = 0;
  const int n = NX;
  dgetrf_(&n, &n, A, &n, ipiv, &info);
  if (info < 0) return HM_ELAPACK;
  double det = 1.0;
  for (int i = 0; i < NX; ++i) det *= (ipiv[i] != i + 1 ? -1.0 : 1.0) * A[i + NX * i];
  *g = det;
  return HM_OK;
}

/* Equations: the scaled shooting residual (4 rows) and the fold test (row 5). The fold test's gradient is taken
 * by forward differences (6 more shots) at the first iteration of a correction only (a chord for that row). */
static hm_status lpc_eval(void *ctx, const double *w, int iter, double *res, double *J5) {
  lctx *l = (lctx *)ctx;
  hm_sh *c = &l->sh;
  hm_status st = hm_sh_shoot(c, w, &l->last);
  if (st != HM_OK) return st;
  double g;
  if ((st = fold_test(c, &l->last, &g)) != HM_OK) return st;
  for (int i = 0; i < NX; ++i) {
    res[i] = l->last.res[i] / hm_sh_res_scale[i];
    for (int j = 0; j < NW; ++j) J5[NW * i + j] = l->last.jac[NW * i + j] * c->sc[j] / hm_sh_res_scale[i];
  }
  res[NX] = g;
  for (int j = 0; j < NW && iter == 0; ++j) {
    double wp[NW], gp;
    hm_shot sp;
    memcpy(wp, w, sizeof wp);
    wp[j] += l->lopt->fd_step * c->sc[j];
    if ((st = hm_sh_shoot(c, wp, &sp)) != HM_OK) return st;
    if ((st = fold_test(c, &sp, &gp)) != HM_OK) return st;
    J5[NW * NX + j] = (gp - g) / l->lopt->fd_step;
  }
  return HM_OK;
}

static hm_status lpc_finish(void *ctx, const double *w, const double *t, void *node) {
  lctx *l = (lctx *)ctx;
  lnode *out = (lnode *)node;
  memcpy(out->head.u, w, NW * sizeof(double));
  memcpy(out->head.t, t, NW * sizeof(double));
  out->amp = l->last.amp_y;
  return HM_OK;
}

static hm_lpc_point to_point(const lnode *n) {
  hm_lpc_point p;
  p.p1 = n->head.u[4];
  p.p2 = n->head.u[5];
  p.amp_y_m = n->amp;
  p.period_s = n->head.u[3];
  p.x0[0] = n->head.u[0];
  p.x0[1] = 0.0;
  p.x0[2] = n->head.u[1];
  p.x0[3] = n->head.u[2];
  p.dp1_ds = n->head.t[4];
  p.dp2_ds = n->head.t[5];
  return p;
}

static int lpc_stop(void *ctx, const void *node) {
  const lctx *l = (const lctx *)ctx;
  const lnode *cur = (const lnode *)node;
  if (cur->head.u[5] < l->lopt->p2_min || cur->head.u[5] > l->lopt->p2_max) return HM_CONT_PARAM2_RANGE;
  if (cur->head.u[4] < l->copt->p_min || cur->head.u[4] > l->copt->p_max) return HM_CONT_PARAM_RANGE;
  if (cur->amp < l->lopt->amp_min_m) return HM_CONT_AMP_MIN;
  if (cur->amp > l->copt->amp_max_m) return HM_CONT_AMP_MAX;
  return HM_CONT_RUNNING;
}

static double dp2_ds(const void *node, void *arg) {
  (void)arg;
  return ((const lnode *)node)->head.t[5];
}

/* Cusps where dp2/ds changes sign; then store the point. */
static void lpc_accepted(void *ctx, const void *a, const void *b, double ds) {
  lctx *l = (lctx *)ctx;
  const lnode *cur = (const lnode *)a, *next = (const lnode *)b;
  if ((cur->head.t[5] > 0.0) != (next->head.t[5] > 0.0)) {
    lnode cusp;
    if (hm_cont_locate(&l->prob, &l->lopt->cont, cur, next, ds, cur->head.t[5], next->head.t[5], dp2_ds, NULL, &cusp) ==
        HM_OK) {
      if (l->n_cusps < l->max_cusps) l->cusps[l->n_cusps] = to_point(&cusp);
      ++l->n_cusps;
    }
  }
  if (l->n < l->cap) l->buf[l->n] = to_point(next);
  ++l->n;
}

/* Trace one direction from start into buf (room cap); *n counts the points. */
static void trace(lctx *l, const lnode *start, hm_lpc_point *buf, size_t cap, size_t *n, hm_cont_stats *stats) {
  l->buf = buf;
  l->cap = cap;
  l->n = 0;
  const size_t shots0 = l->sh.n_shots, steps0 = l->sh.n_steps;
  lnode cur = *start, scratch;
  hm_cont_run(&l->prob, &l->lopt->cont, &cur, &scratch, stats);
  stats->shots = l->sh.n_shots - shots0;
  stats->integration_steps = l->sh.n_steps - steps0;
  *n = l->n;
}

hm_status hm_lpc_curve(const hm_vehicle *veh, double speed_kmh, const hm_cycle_options *copt,
                       const hm_lpc_options *lopt, const hm_cycle_event *fold, hm_lpc_point *points,
                       size_t max_points, size_t *n_points, hm_lpc_point *cusps, size_t max_cusps,
                       size_t *n_cusps, hm_cont_stats stats[2]) {
  if (!veh || !copt || !lopt || !fold || !n_points || !n_cusps || (max_points && !points) ||
      (max_cusps && !cusps) || fold->kind != HM_CYCLE_LPC || lopt->param2 == copt->param ||
      !(lopt->p2_max > lopt->p2_min) || !hm_cont_options_valid(&lopt->cont) || !(lopt->fd_step > 0.0))
    return HM_EINVAL;
  lctx l;
  memset(&l, 0, sizeof l);
  l.copt = copt;
  l.lopt = lopt;
  l.cusps = cusps;
  l.max_cusps = max_cusps;
  l.prob.n = NW;
  l.prob.scale = l.sh.sc;
  l.prob.node_size = sizeof(lnode);
  l.prob.ctx = &l;
  l.prob.eval = lpc_eval;
  l.prob.finish = lpc_finish;
  l.prob.stop = lpc_stop;
  l.prob.accepted = lpc_accepted;
  hm_status st = hm_sh_init(&l.sh, veh, speed_kmh, copt->param, &copt->shoot, 1, lopt->param2);
  if (st != HM_OK) {
    hm_sh_free(&l.sh);
    return st;
  }
  const double p2 = hm_param_get(veh, speed_kmh, lopt->param2);
  double w[NW] = {fold->point.x0[0], fold->point.x0[2], fold->point.x0[3], fold->point.period_s,
                  fold->point.param, p2};
  /* correct onto the fold at fixed p2, with the tangent oriented towards increasing p2 */
  const double fix_p2[NW] = {0, 0, 0, 0, 0, 1.0};
  lnode start;
  st = hm_cont_correct(&l.prob, &lopt->cont, w, fix_p2, p2 / l.sh.sc[5], fix_p2, &start, NULL);
  if (st != HM_OK) {
    hm_sh_free(&l.sh);
    return st;
  }
  const size_t start_newton = l.prob.newton_iterations, start_shots = l.sh.n_shots, start_steps = l.sh.n_steps;
  /* backward half first (reversed into the output), then the start point and the forward half */
  hm_lpc_point back[512], fwd[512];
  size_t nb = 0, nf = 0;
  hm_cont_stats s[2];
  lnode rev = start;
  for (int j = 0; j < NW; ++j) rev.head.t[j] = -start.head.t[j];
  trace(&l, &rev, back, 512, &nb, &s[0]);
  trace(&l, &start, fwd, 512, &nf, &s[1]);
  s[0].newton_iterations += start_newton;
  s[0].shots += start_shots;
  s[0].integration_steps += start_steps;
  hm_sh_free(&l.sh);
  if (nb > 512) nb = 512;
  if (nf > 512) nf = 512;
  size_t np = 0;
  for (size_t i = nb; i > 0; --i)
    if (np < max_points) points[np++] = back[i - 1];
  if (np < max_points) points[np++] = to_point(&start);
  for (size_t i = 0; i < nf; ++i)
    if (np < max_points) points[np++] = fwd[i];
  *n_points = np;
  *n_cusps = l.n_cusps < max_cusps ? l.n_cusps : max_cusps;
  if (stats) {
    stats[0] = s[0];
    stats[1] = s[1];
  }
  return HM_OK;
}
