/* Limit cycles by shooting; pseudo-arclength continuation from a Hopf point; LPC, BPC, PD and NS points. */
#include "hunting_monitor/cycles.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hunting_monitor/integrate.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/roots.h"
#include "lapack.h"
#include "shooting.h"

const char *hm_cycle_event_name(hm_cycle_event_kind kind) {
  switch (kind) {
    case HM_CYCLE_LPC: return "LPC";
    case HM_CYCLE_BPC: return "BPC";
    case HM_CYCLE_PD: return "PD";
    case HM_CYCLE_NS: return "NS";
  }
  return "?";
}

void hm_cycle_options_default(hm_cycle_options *opt, hm_param p) {
  opt->param = p;
  opt->p_min = p == HM_PARAM_SPEED ? 10.0 : 1e-3;
  opt->p_max = p == HM_PARAM_SPEED ? 2000.0 : p == HM_PARAM_CONICITY ? 2.0 : 100.0;
  opt->amp_max_m = 0.020;
  opt->amp_start_m = 2e-4;
  opt->ds_init = 0.2;
  opt->ds_min = 1e-4;
  opt->ds_max = 5.0;
  opt->max_steps = 2000;
  opt->rtol = 1e-9;
  opt->atol = 1e-12;
  opt->newton_tol = 1e-9;
  opt->newton_max_iter = 8;
  opt->locate_tol = 1e-9;
  opt->use_symmetry = 1;
}

/* The 5x5 Newton matrix [scaled Jacobian; row] in column-major order. */
static void newton_matrix(const hm_sh *c, const hm_shot *s, const double *row, double *A) {
  for (int i = 0; i < NX; ++i)
    for (int j = 0; j < NU; ++j) A[i + NU * j] = s->jac[NW * i + j] * c->sc[j] / hm_sh_res_scale[i];
  for (int j = 0; j < NU; ++j) A[NX + NU * j] = row[j];
}

/*
 * Newton on the shooting equations plus one scalar equation row . (u / sc) = target. u in/out (unscaled).
 * Converged when the scaled update is below newton_tol; *iters gets the iteration count; s receives the
 * last evaluation (at the iterate before the final, converged update).
 */
static hm_status newton(hm_sh *c, double *u, const double *row, double target, hm_shot *s, int *iters) {
  double w[NW] = {0, 0, 0, 0, 0, 0};
  memcpy(w, u, NU * sizeof(double));
  for (size_t it = 0; it < c->opt->newton_max_iter; ++it) {
    hm_status st = hm_sh_shoot(c, w, s);
    if (st != HM_OK) return st;
    double A[NU * NU], b[NU];
    newton_matrix(c, s, row, A);
    double rowdot = 0.0;
    for (int j = 0; j < NU; ++j) rowdot += row[j] * w[j] / c->sc[j];
    for (int i = 0; i < NX; ++i) b[i] = -s->res[i] / hm_sh_res_scale[i];
    b[NX] = -(rowdot - target);
    int ipiv[NU], info = 0;
    const int n = NU, one = 1;
    dgesv_(&n, &one, A, &n, ipiv, b, &n, &info);
    if (info != 0) return HM_ELAPACK;
    double dmax = 0.0;
    for (int j = 0; j < NU; ++j) {
      w[j] += b[j] * c->sc[j];
      dmax = fmax(dmax, fabs(b[j]));
    }
    if (!isfinite(dmax) || dmax > 50.0) return HM_ENOCONV; /* diverging */
    if (dmax <= c->opt->newton_tol) {
      memcpy(u, w, NU * sizeof(double));
      if (iters) *iters = (int)it + 1;
      return HM_OK;
    }
  }
  return HM_ENOCONV;
}

/* Unit tangent (scaled) of the branch: the null vector of the scaled Jacobian, oriented along ref. */
static hm_status tangent_of(const hm_sh *c, const hm_shot *s, const double *ref, double *t) {
  double A[NU * NU], b[NU] = {0, 0, 0, 0, 1.0};
  newton_matrix(c, s, ref, A);
  int ipiv[NU], info = 0;
  const int n = NU, one = 1;
  dgesv_(&n, &one, A, &n, ipiv, b, &n, &info);
  if (info != 0) return HM_ELAPACK;
  double norm = 0.0, dot = 0.0;
  for (int j = 0; j < NU; ++j) norm += b[j] * b[j];
  norm = sqrt(norm);
  if (!(norm > 0.0) || !isfinite(norm)) return HM_ENONFINITE;
  for (int j = 0; j < NU; ++j) {
    t[j] = b[j] / norm;
    dot += t[j] * ref[j];
  }
  if (dot < 0.0)
    for (int j = 0; j < NU; ++j) t[j] = -t[j];
  return HM_OK;
}

/* ---- multipliers and test functions ---- */

typedef struct {
  hm_cycle_point pub;
  double t[NU];          /* unit tangent (scaled) */
  double u[NU];
  double bpc, pd;        /* test functions */
  int ns_count;          /* complex non-trivial multipliers outside the unit circle */
} node;

static hm_status fill_node(const hm_sh *c, const hm_shot *s, const double *u, const double *t, node *nd) {
  double re[NX], im[NX];
  hm_status st = hm_sh_eig4(s->phi, re, im);
  if (st != HM_OK) return st;
  /* Symmetric cycles: R = -Phi(T/2) has eigenvalues mu = -eig(Phi), the multipliers are mu^2, and
   * det(R + I) = prod(mu + 1) changes sign where a real mu crosses -1 (symmetry-breaking branch point).
   * Otherwise the multipliers are eig(Phi(T)) and the branch-point test is prod(m - 1) over the non-trivial
   * real ones. The trivial multiplier (eigenvalue of R at +1 along the flow) is the one closest to +1. */
  double bpc = 1.0;
  int trivial = 0;
  double dmin = INFINITY;
  for (int i = 0; i < NX; ++i) {
    const double mr = c->symmetric ? -re[i] : re[i], mi = c->symmetric ? -im[i] : im[i];
    const double d = hypot(mr - 1.0, mi);
    if (d < dmin) {
      dmin = d;
      trivial = i;
    }
    if (c->symmetric) {
      if (mi == 0.0) bpc *= mr + 1.0;
      re[i] = mr * mr - mi * mi;
      im[i] = 2.0 * mr * mi;
    }
  }
  if (!c->symmetric)
    for (int i = 0; i < NX; ++i)
      if (i != trivial && im[i] == 0.0) bpc *= re[i] - 1.0;
  /* sort by decreasing modulus, following the trivial multiplier */
  int order[NX] = {0, 1, 2, 3};
  for (int i = 1; i < NX; ++i)
    for (int j = i; j > 0 && hypot(re[order[j - 1]], im[order[j - 1]]) < hypot(re[order[j]], im[order[j]]); --j) {
      const int tmp = order[j];
      order[j] = order[j - 1];
      order[j - 1] = tmp;
    }
  node out;
  memset(&out, 0, sizeof out);
  double pd = 1.0;
  int n_unstable = 0, ns_count = 0;
  for (int k = 0; k < NX; ++k) {
    const int i = order[k];
    out.pub.mult_re[k] = re[i];
    out.pub.mult_im[k] = im[i];
    if (i == trivial) {
      out.pub.trivial_index = k;
      continue;
    }
    const double mod = hypot(re[i], im[i]);
    if (mod > 1.0) ++n_unstable;
    if (fabs(im[i]) > 1e-12 * (1.0 + mod) && mod > 1.0) ++ns_count;
    if (im[i] == 0.0) pd *= re[i] + 1.0;
    else if (im[i] > 0.0) pd *= (re[i] + 1.0) * (re[i] + 1.0) + im[i] * im[i];
  }
  out.pub.param = u[4];
  out.pub.period_s = u[3];
  out.pub.amp_y_m = s->amp_y;
  out.pub.amp_psi_rad = s->amp_psi;
  out.pub.x0[0] = u[0];
  out.pub.x0[1] = 0.0;
  out.pub.x0[2] = u[1];
  out.pub.x0[3] = u[2];
  out.pub.n_unstable = n_unstable;
  out.pub.stable = n_unstable == 0;
  out.pub.dparam_ds = t[4];
  memcpy(out.t, t, sizeof out.t);
  memcpy(out.u, u, sizeof out.u);
  out.bpc = bpc;
  out.pd = pd;
  out.ns_count = ns_count;
  *nd = out;
  return HM_OK;
}

/* Corrector from node a along its tangent at arclength sigma; fills nd. */
static hm_status step_from(hm_sh *c, const node *a, double sigma, node *nd, int *iters) {
  double u[NU], row[NU], target = 0.0;
  for (int j = 0; j < NU; ++j) {
    u[j] = a->u[j] + sigma * a->t[j] * c->sc[j];
    row[j] = a->t[j];
    target += a->t[j] * u[j] / c->sc[j];
  }
  double pred[NU];
  memcpy(pred, u, sizeof pred);
  hm_shot s;
  hm_status st = newton(c, u, row, target, &s, iters);
  if (st != HM_OK) return st;
  /* A corrector that lands farther from the predictor than the step itself has jumped to another branch
   * (typically the trivial one, x0 = 0, which solves the shooting equations for every T and p). */
  double dist = 0.0;
  for (int j = 0; j < NU; ++j) dist += (u[j] - pred[j]) * (u[j] - pred[j]) / (c->sc[j] * c->sc[j]);
  if (sqrt(dist) > fmax(fabs(sigma), 0.05)) return HM_ENOCONV;
  double t[NU];
  if ((st = tangent_of(c, &s, a->t, t)) != HM_OK) return st;
  return fill_node(c, &s, u, t, nd);
}

/* ---- event location ---- */

typedef struct {
  hm_sh *c;
  const node *a;
  hm_cycle_event_kind kind;
  node last;
} locate_ctx;

static double test_value(const node *nd, hm_cycle_event_kind kind) {
  switch (kind) {
    case HM_CYCLE_LPC: return nd->pub.dparam_ds;
    case HM_CYCLE_BPC: return nd->bpc;
    case HM_CYCLE_PD: return nd->pd;
    case HM_CYCLE_NS: {
      double worst = -INFINITY; /* largest modulus of a complex non-trivial multiplier, minus 1 */
      for (int k = 0; k < NX; ++k)
        if (k != nd->pub.trivial_index && nd->pub.mult_im[k] != 0.0)
          worst = fmax(worst, hypot(nd->pub.mult_re[k], nd->pub.mult_im[k]) - 1.0);
      return worst;
    }
  }
  return NAN;
}

static hm_status locate_fn(double sigma, double *value, void *ctx) {
  locate_ctx *l = (locate_ctx *)ctx;
  hm_status st = step_from(l->c, l->a, sigma, &l->last, NULL);
  if (st != HM_OK) return st;
  *value = test_value(&l->last, l->kind);
  return HM_OK;
}

static hm_status locate(hm_sh *c, const node *a, const node *b, double ds, hm_cycle_event_kind kind, node *out) {
  locate_ctx l = {c, a, kind, *b};
  double root;
  hm_status st = hm_brent_root(locate_fn, &l, 0.0, ds, test_value(a, kind), test_value(b, kind),
                               c->opt->locate_tol, 100, &root);
  if (st != HM_OK) return st;
  if ((st = step_from(c, a, root, out, NULL)) != HM_OK) return st;
  return HM_OK;
}

static int sign_change(double x, double y) { return (x > 0.0) != (y > 0.0); }

/* Detect and locate the events between consecutive nodes a and b (b reached from a with step ds). */
static void detect_events(hm_sh *c, const node *a, const node *b, double ds, size_t index, hm_cycle_event *events,
                          size_t max_events, size_t *n_events) {
  int flags[4] = {0, 0, 0, 0};
  flags[HM_CYCLE_LPC] = sign_change(a->pub.dparam_ds, b->pub.dparam_ds);
  flags[HM_CYCLE_BPC] = sign_change(a->bpc, b->bpc) && (c->symmetric || !flags[HM_CYCLE_LPC]);
  flags[HM_CYCLE_PD] = sign_change(a->pd, b->pd);
  flags[HM_CYCLE_NS] = a->ns_count != b->ns_count && test_value(a, HM_CYCLE_NS) > -INFINITY &&
                       test_value(b, HM_CYCLE_NS) > -INFINITY;
  for (int k = 0; k < 4; ++k) {
    if (!flags[k]) continue;
    node located;
    if (locate(c, a, b, ds, (hm_cycle_event_kind)k, &located) != HM_OK) continue;
    if (k == HM_CYCLE_NS && fabs(test_value(&located, HM_CYCLE_NS)) > 1e-4) continue; /* not a crossing */
    hm_cycle_event ev;
    ev.kind = (hm_cycle_event_kind)k;
    ev.index = index;
    ev.point = located.pub;
    ev.stable_side = 0;
    if (k == HM_CYCLE_LPC) {
      const node *upper = a->pub.amp_y_m > b->pub.amp_y_m ? a : b, *lower = upper == a ? b : a;
      ev.stable_side = upper->pub.stable ? 1 : lower->pub.stable ? -1 : 0;
    }
    if (*n_events < max_events) events[*n_events] = ev;
    ++*n_events;
  }
}

/* ---- start at the Hopf point ---- */

/* The Hopf point's value of the continuation parameter. */
static double hopf_param(const hm_sh *c, const hm_hopf_point *hopf) {
  switch (c->param) {
    case HM_PARAM_SPEED: return hopf->speed_kmh;
    case HM_PARAM_KX: return hopf->kx_mn_m;
    case HM_PARAM_KY: return hopf->ky_mn_m;
    case HM_PARAM_CONICITY: return hopf->conicity;
  }
  return NAN;
}

/* First guess of the cycle of max|y| = amp from the critical eigenvector and the normal form. */
static hm_status start_guess(hm_sh *c, const hm_hopf_point *hopf, double amp, double *u) {
  hm_vehicle v = c->base;
  double speed = c->base_speed_kmh;
  const double ph = hopf_param(c, hopf);
  hm_status st = hm_param_set(&v, &speed, c->param, ph);
  if (st != HM_OK) return st;
  double qr[4], qi[4], w;
  if ((st = hm_hopf_eigenvector(&v, speed, qr, qi, &w)) != HM_OK) return st;
  /* rotate q so that q0 is real and positive: x(t) = 2 |z| Re(q e^{iwt}), max y = 2 |z| q0 */
  const double q0 = hypot(qr[0], qi[0]), cr = qr[0] / q0, ci = -qi[0] / q0;
  double x0[4];
  for (int i = 0; i < 4; ++i) x0[i] = (qr[i] * cr - qi[i] * ci) / q0 * amp; /* 2|z| q0 = amp */
  /* parameter shift from the normal form: alpha'(p - ph) + l1 |z|^2 = 0, alpha' = d Re(lambda) / dp */
  const double dp = 1e-4 * c->sc[4];
  double s_plus, s_minus, lambda0;
  hm_vehicle vp = v, vm = v;
  double sp = speed, sm = speed;
  hm_param_set(&vp, &sp, c->param, ph + dp);
  hm_param_set(&vm, &sm, c->param, ph - dp);
  hm_conicity_eval(&vp.conicity, 0.0, &lambda0, NULL);
  if ((st = hm_linear_spectral_abscissa(&vp, lambda0, hm_mps_from_kmh(sp), &s_plus)) != HM_OK) return st;
  hm_conicity_eval(&vm.conicity, 0.0, &lambda0, NULL);
  if ((st = hm_linear_spectral_abscissa(&vm, lambda0, hm_mps_from_kmh(sm), &s_minus)) != HM_OK) return st;
  const double alpha_p = (s_plus - s_minus) / (2.0 * dp), z = amp / (2.0 * q0);
  u[0] = x0[0];
  u[1] = x0[2];
  u[2] = x0[3];
  u[3] = 2.0 * HM_PI / w;
  u[4] = alpha_p != 0.0 ? ph - hopf->l1 * z * z / alpha_p : ph;
  return HM_OK;
}

static int options_valid(const hm_cycle_options *o) {
  return o->p_max > o->p_min && o->amp_max_m > 0.0 && o->amp_start_m > 0.0 && o->amp_start_m < o->amp_max_m &&
         o->ds_min > 0.0 && o->ds_init >= o->ds_min && o->ds_max >= o->ds_init && o->rtol > 0.0 &&
         o->atol >= 0.0 && o->newton_tol > 0.0 && o->newton_max_iter > 0 && o->locate_tol > 0.0;
}

/* Solve at fixed amplitude u[0] = amp (the start of the branch). */
static hm_status solve_fixed(hm_sh *c, double *u, int which, double value, const double *tref, node *nd) {
  double row[NU] = {0, 0, 0, 0, 0};
  row[which] = 1.0;
  hm_shot s;
  hm_status st = newton(c, u, row, value / c->sc[which], &s, NULL);
  if (st != HM_OK) return st;
  double t[NU];
  if ((st = tangent_of(c, &s, tref, t)) != HM_OK) return st;
  return fill_node(c, &s, u, t, nd);
}

hm_status hm_cycle_solve(const hm_vehicle *veh, double speed_kmh, const hm_cycle_options *opt, double p,
                         const double x0_guess[4], double period_guess_s, hm_cycle_point *cycle) {
  if (!veh || !opt || !x0_guess || !cycle || !options_valid(opt)) return HM_EINVAL;
  hm_sh c;
  hm_status st = hm_sh_init(&c, veh, speed_kmh, opt, 0, HM_PARAM_SPEED);
  if (st == HM_OK) {
    double u[NU] = {x0_guess[0], x0_guess[2], x0_guess[3], period_guess_s, p};
    const double tref[NU] = {1, 0, 0, 0, 0};
    node nd;
    st = solve_fixed(&c, u, 4, p, tref, &nd);
    if (st == HM_OK) *cycle = nd.pub;
  }
  hm_sh_free(&c);
  return st;
}

static hm_status start_branch(hm_sh *c, const hm_hopf_point *hopf, node *n0, node *n1) {
  double u[NU];
  const double amp = c->opt->amp_start_m;
  hm_status st = start_guess(c, hopf, amp, u);
  if (st != HM_OK) return st;
  const double tref[NU] = {1, 0, 0, 0, 0}; /* orient the tangent towards growing amplitude */
  if ((st = solve_fixed(c, u, 0, amp, tref, n0)) != HM_OK) return st;
  /* second cycle at twice the amplitude: the state scales with it, the parameter shift with its square */
  double u1[NU];
  memcpy(u1, n0->u, sizeof u1);
  for (int j = 0; j < 3; ++j) u1[j] *= 2.0;
  const double ph = hopf_param(c, hopf);
  u1[4] = ph + 4.0 * (n0->u[4] - ph);
  return solve_fixed(c, u1, 0, 2.0 * amp, tref, n1);
}

hm_status hm_cycles_continue(const hm_vehicle *veh, double speed_kmh, const hm_hopf_point *hopf,
                             const hm_cycle_options *opt, hm_cycle_point *points, size_t max_points,
                             size_t *n_points, hm_cycle_event *events, size_t max_events, size_t *n_events,
                             const char **stop_reason) {
  if (!veh || !hopf || !opt || !n_points || !n_events || (max_points && !points) || (max_events && !events) ||
      !options_valid(opt))
    return HM_EINVAL;
  hm_sh c;
  hm_status st = hm_sh_init(&c, veh, speed_kmh, opt, 0, HM_PARAM_SPEED);
  const char *reason = "step limit reached";
  size_t np = 0, ne = 0;
  node prev, cur;
  if (st == HM_OK) st = start_branch(&c, hopf, &prev, &cur);
  if (st != HM_OK) {
    hm_sh_free(&c);
    return st;
  }
  if (np < max_points) points[np] = prev.pub;
  ++np;
  if (np < max_points) points[np] = cur.pub;
  ++np;
  double ds = opt->ds_init;
  for (size_t step = 0; step < opt->max_steps; ++step) {
    if (cur.pub.param < opt->p_min || cur.pub.param > opt->p_max) {
      reason = "parameter left its range";
      break;
    }
    if (cur.pub.amp_y_m > opt->amp_max_m) {
      reason = "amplitude limit reached";
      break;
    }
    node next;
    int iters = 0;
    st = step_from(&c, &cur, ds, &next, &iters);
    double dot = 0.0;
    if (st == HM_OK)
      for (int j = 0; j < NU; ++j) dot += next.t[j] * cur.t[j];
    if (st != HM_OK || dot < 0.95) {
      if (ds <= opt->ds_min) {
        reason = "no convergence at the smallest step";
        break;
      }
      ds = fmax(0.5 * ds, opt->ds_min);
      continue;
    }
    detect_events(&c, &cur, &next, ds, np, events, max_events, &ne);
    if (np < max_points) points[np] = next.pub;
    ++np;
    prev = cur;
    cur = next;
    if (iters <= 2) ds = fmin(1.5 * ds, opt->ds_max);
    else if (iters >= 5) ds = fmax(0.7 * ds, opt->ds_min);
  }
  hm_sh_free(&c);
  *n_points = np < max_points ? np : max_points;
  *n_events = ne < max_events ? ne : max_events;
  if (stop_reason) *stop_reason = reason;
  return HM_OK;
}
