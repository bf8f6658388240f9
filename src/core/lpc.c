/* Two-parameter continuation of folds of cycles (LPC curves) and location of their cusps (CPC). */
#include <math.h>
#include <string.h>

#include "hunting_monitor/cycles.h"
#include "hunting_monitor/roots.h"
#include "lapack.h"
#include "shooting.h"

void hm_lpc_options_default(hm_lpc_options *opt, hm_param param2) {
  opt->param2 = param2;
  opt->p2_min = param2 == HM_PARAM_CONICITY ? 1e-3 : param2 == HM_PARAM_SPEED ? 10.0 : 0.1;
  opt->p2_max = param2 == HM_PARAM_CONICITY ? 2.0 : param2 == HM_PARAM_SPEED ? 2000.0 : 100.0;
  opt->amp_min_m = 5e-4;
  opt->ds_init = 0.1;
  opt->ds_min = 1e-4;
  opt->ds_max = 5.0;
  opt->max_steps = 400;
  opt->fd_step = 1e-6;
}

/* A point of the LPC system with its tangent (scaled). */
typedef struct {
  double w[NW];
  double t[NW];
  double amp;
} lnode;

typedef struct {
  hm_sh sh;
  const hm_lpc_options *lopt;
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

/* Rows of the extended Jacobian: the scaled residual Jacobian (4 x 6) and, if with_gradient, the fold test's
 * gradient by forward differences (6 more shots; otherwise row 4 of J5 is kept from an earlier call). */
static hm_status extended_rows(lctx *l, const double *w, hm_shot *s, double *res, double *J5, double *g,
                               int with_gradient) {
  hm_sh *c = &l->sh;
  hm_status st = hm_sh_shoot(c, w, s);
  if (st != HM_OK) return st;
  if ((st = fold_test(c, s, g)) != HM_OK) return st;
  for (int i = 0; i < NX; ++i) {
    res[i] = s->res[i] / hm_sh_res_scale[i];
    for (int j = 0; j < NW; ++j) J5[NW * i + j] = s->jac[NW * i + j] * c->sc[j] / hm_sh_res_scale[i];
  }
  for (int j = 0; j < NW && with_gradient; ++j) {
    double wp[NW], gp;
    hm_shot sp;
    memcpy(wp, w, sizeof wp);
    wp[j] += l->lopt->fd_step * c->sc[j];
    if ((st = hm_sh_shoot(c, wp, &sp)) != HM_OK) return st;
    if ((st = fold_test(c, &sp, &gp)) != HM_OK) return st;
    J5[NW * NX + j] = (gp - *g) / l->lopt->fd_step;
  }
  return HM_OK;
}

/* Solve the 6x6 system [J5; row] x = b (column-major assembly). */
static hm_status solve6(const double *J5, const double *row, double *b) {
  double A[NW * NW];
  for (int i = 0; i < NW - 1; ++i)
    for (int j = 0; j < NW; ++j) A[i + NW * j] = J5[NW * i + j];
  for (int j = 0; j < NW; ++j) A[(NW - 1) + NW * j] = row[j];
  int ipiv[NW], info = 0;
  const int n = NW, one = 1;
  dgesv_(&n, &one, A, &n, ipiv, b, &n, &info);
  return info == 0 ? HM_OK : HM_ELAPACK;
}

/* Newton on (residual, fold test, row . w/sc = target); then the unit tangent oriented along tref. */
static hm_status lpc_correct(lctx *l, double *w, const double *row, double target, const double *tref,
                             lnode *out, int *iters) {
  hm_sh *c = &l->sh;
  double v[NW], J5[(NW - 1) * NW], res[NX], g;
  memcpy(v, w, sizeof v);
  hm_shot s;
  int converged = 0, it;
  for (it = 0; it < (int)c->opt->newton_max_iter && !converged; ++it) {
    /* the fold test's gradient is computed once per correction (a chord step for that row) */
    hm_status st = extended_rows(l, v, &s, res, J5, &g, it == 0);
    if (st != HM_OK) return st;
    double b[NW], rowdot = 0.0;
    for (int i = 0; i < NX; ++i) b[i] = -res[i];
    b[NX] = -g;
    for (int j = 0; j < NW; ++j) rowdot += row[j] * v[j] / c->sc[j];
    b[NW - 1] = -(rowdot - target);
    if ((st = solve6(J5, row, b)) != HM_OK) return st;
    double dmax = 0.0;
    for (int j = 0; j < NW; ++j) {
      v[j] += b[j] * c->sc[j];
      dmax = fmax(dmax, fabs(b[j]));
    }
    if (!isfinite(dmax) || dmax > 50.0) return HM_ENOCONV;
    converged = dmax <= c->opt->newton_tol;
  }
  if (!converged) return HM_ENOCONV;
  /* tangent: null vector of [J5] from the last evaluation */
  double t[NW] = {0, 0, 0, 0, 0, 1.0}, norm = 0.0, dot = 0.0;
  hm_status st = solve6(J5, tref, t);
  if (st != HM_OK) return st;
  for (int j = 0; j < NW; ++j) norm += t[j] * t[j];
  norm = sqrt(norm);
  if (!(norm > 0.0) || !isfinite(norm)) return HM_ENONFINITE;
  for (int j = 0; j < NW; ++j) {
    t[j] /= norm;
    dot += t[j] * tref[j];
  }
  for (int j = 0; j < NW; ++j) out->t[j] = dot < 0.0 ? -t[j] : t[j];
  memcpy(out->w, v, sizeof v);
  memcpy(w, v, sizeof v);
  out->amp = s.amp_y;
  if (iters) *iters = it;
  return HM_OK;
}

static hm_status lpc_step(lctx *l, const lnode *a, double sigma, lnode *out, int *iters) {
  double w[NW], target = 0.0;
  for (int j = 0; j < NW; ++j) {
    w[j] = a->w[j] + sigma * a->t[j] * l->sh.sc[j];
    target += a->t[j] * w[j] / l->sh.sc[j];
  }
  hm_status st = lpc_correct(l, w, a->t, target, a->t, out, iters);
  if (st != HM_OK) return st;
  /* reject a corrector that left the neighbourhood of the predictor (a jump to another branch) */
  double dist = 0.0;
  for (int j = 0; j < NW; ++j) {
    const double d = (out->w[j] - a->w[j]) / l->sh.sc[j] - sigma * a->t[j];
    dist += d * d;
  }
  return sqrt(dist) > fmax(fabs(sigma), 0.05) ? HM_ENOCONV : HM_OK;
}

static hm_lpc_point to_point(const lnode *n) {
  hm_lpc_point p;
  p.p1 = n->w[4];
  p.p2 = n->w[5];
  p.amp_y_m = n->amp;
  p.period_s = n->w[3];
  p.x0[0] = n->w[0];
  p.x0[1] = 0.0;
  p.x0[2] = n->w[1];
  p.x0[3] = n->w[2];
  p.dp1_ds = n->t[4];
  p.dp2_ds = n->t[5];
  return p;
}

typedef struct {
  lctx *l;
  const lnode *a;
  lnode last;
} cusp_ctx;

static hm_status cusp_fn(double sigma, double *value, void *ctx) {
  cusp_ctx *c = (cusp_ctx *)ctx;
  hm_status st = lpc_step(c->l, c->a, sigma, &c->last, NULL);
  if (st == HM_OK) *value = c->last.t[5];
  return st;
}

/* Trace one direction from start; appends points to buf (room cap), cusps likewise. */
static const char *trace(lctx *l, const lnode *start, hm_lpc_point *buf, size_t cap, size_t *n, hm_lpc_point *cusps,
                         size_t max_cusps, size_t *n_cusps) {
  const hm_lpc_options *o = l->lopt;
  lnode cur = *start;
  double ds = o->ds_init;
  for (size_t step = 0; step < o->max_steps; ++step) {
    if (cur.w[5] < o->p2_min || cur.w[5] > o->p2_max) return "second parameter left its range";
    if (cur.w[4] < l->sh.opt->p_min || cur.w[4] > l->sh.opt->p_max) return "first parameter left its range";
    if (cur.amp < o->amp_min_m) return "fold cycle shrank to the minimum amplitude (towards a GH point)";
    if (cur.amp > l->sh.opt->amp_max_m) return "amplitude limit reached";
    lnode next;
    int iters = 0;
    hm_status st = lpc_step(l, &cur, ds, &next, &iters);
    double dot = 0.0;
    if (st == HM_OK)
      for (int j = 0; j < NW; ++j) dot += next.t[j] * cur.t[j];
    if (st != HM_OK || dot < 0.9) {
      if (ds <= o->ds_min) return "no convergence at the smallest step";
      ds = fmax(0.5 * ds, o->ds_min);
      continue;
    }
    if ((cur.t[5] > 0.0) != (next.t[5] > 0.0)) {
      cusp_ctx cc = {l, &cur, next};
      double root;
      if (hm_brent_root(cusp_fn, &cc, 0.0, ds, cur.t[5], next.t[5], l->sh.opt->locate_tol, 100, &root) == HM_OK &&
          lpc_step(l, &cur, root, &cc.last, NULL) == HM_OK) {
        if (*n_cusps < max_cusps) cusps[*n_cusps] = to_point(&cc.last);
        ++*n_cusps;
      }
    }
    if (*n < cap) buf[*n] = to_point(&next);
    ++*n;
    cur = next;
    /* the fold row's gradient is a chord, so 3 iterations is fast convergence here */
    if (iters <= 3) ds = fmin(1.5 * ds, o->ds_max);
    else if (iters >= 6) ds = fmax(0.7 * ds, o->ds_min);
  }
  return "step limit reached";
}

hm_status hm_lpc_curve(const hm_vehicle *veh, double speed_kmh, const hm_cycle_options *copt,
                       const hm_lpc_options *lopt, const hm_cycle_event *fold, hm_lpc_point *points,
                       size_t max_points, size_t *n_points, hm_lpc_point *cusps, size_t max_cusps,
                       size_t *n_cusps, const char *stop_reasons[2]) {
  if (!veh || !copt || !lopt || !fold || !n_points || !n_cusps || (max_points && !points) ||
      (max_cusps && !cusps) || fold->kind != HM_CYCLE_LPC || lopt->param2 == copt->param ||
      !(lopt->p2_max > lopt->p2_min) || !(lopt->ds_min > 0.0) || !(lopt->ds_max >= lopt->ds_init) ||
      !(lopt->fd_step > 0.0))
    return HM_EINVAL;
  lctx l;
  l.lopt = lopt;
  hm_status st = hm_sh_init(&l.sh, veh, speed_kmh, copt, 1, lopt->param2);
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
  st = lpc_correct(&l, w, fix_p2, p2 / l.sh.sc[5], fix_p2, &start, NULL);
  if (st != HM_OK) {
    hm_sh_free(&l.sh);
    return st;
  }
  /* backward half first (reversed into the output), then the start point and the forward half */
  hm_lpc_point back[512], fwd[512];
  size_t nb = 0, nf = 0, nc = 0;
  lnode rev = start;
  for (int j = 0; j < NW; ++j) rev.t[j] = -start.t[j];
  const char *r0 = trace(&l, &rev, back, 512, &nb, cusps, max_cusps, &nc);
  const char *r1 = trace(&l, &start, fwd, 512, &nf, cusps, max_cusps, &nc);
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
  *n_cusps = nc < max_cusps ? nc : max_cusps;
  if (stop_reasons) {
    stop_reasons[0] = r0;
    stop_reasons[1] = r1;
  }
  return HM_OK;
}
