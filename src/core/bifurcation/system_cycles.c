/* Limit cycles of any model in the running speed: shooting, Floquet multipliers, continuation from the Hopf point
 * and its events (see system_cycles.h). */
#include "hunting_monitor/system_cycles.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

#include "hunting_monitor/integrate.h"
#include "hunting_monitor/linear.h"
#include "continuation.h"
#include "floquet.h"
#include "shooting.h"

enum { NMAX = HM_SYSTEM_MAX_DIM, UMAX = HM_SYSTEM_MAX_DIM + 1, ZMAX = NMAX + NMAX * NMAX + NMAX };

static const double PERIOD_SCALE_S = 1e-2, SPEED_SCALE_KMH = 1.0;

void hm_system_cycle_options_default(hm_system_cycle_options *opt) {
  opt->v_min_kmh = 100.0;
  opt->v_max_kmh = 1500.0;
  opt->amp_max_m = 0.020;
  opt->amp_start_m = 2e-4;
  opt->shoot.rtol = 1e-9;
  opt->shoot.atol = 1e-12;
  opt->shoot.use_symmetry = 1;
  hm_cont_options_default(&opt->cont);
}

/* ---- the shooting map ---- */

typedef struct {
  hm_system sys;
  size_t n, nu;          /* states; unknowns n + 1: the n - 1 free states of x0, T, V */
  size_t amp_unknown;    /* the unknown holding x0[amp_state] */
  int symmetric;
  hm_shooting_options shoot;
  hm_dop853 integ;
  double sc[UMAX];       /* scale of each unknown */
  double v_mps;          /* the speed of the integration under way */
  double amp;            /* its running max |x[amp_state]| */
  hm_status rhs_status;  /* a callback's failure inside the integration */
  size_t n_shots, n_steps;
} shooter;

typedef struct {
  double u[UMAX];
  double res[NMAX];      /* x(tau) - sigma x0 */
  double jac[NMAX * UMAX]; /* d res / d u, row-major n x nu */
  double phi[NMAX * NMAX]; /* Phi(tau), column-major */
  double amp;
} shot;

/* z = [x, Phi (n columns), s]: x' = f, Phi' = J Phi, s' = J s + df/dV (per km/h); J's zeros skipped. */
static hm_status aug_rhs(double t, const double *z, double *dz, void *ctx) {
  (void)t;
  shooter *c = (shooter *)ctx;
  const size_t n = c->n;
  double jac[NMAX * NMAX], dfdv[NMAX], val[NMAX * NMAX];
  int col_of[NMAX * NMAX], row_end[NMAX];
  hm_status st = c->sys.rhs(c->sys.model, c->v_mps, z, dz);
  if (st == HM_OK) st = c->sys.jacobian(c->sys.model, c->v_mps, z, jac);
  if (st == HM_OK) st = c->sys.dfdv(c->sys.model, c->v_mps, z, dfdv);
  if (st != HM_OK) return st;
  int nnz = 0;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = 0; j < n; ++j)
      if (jac[n * i + j] != 0.0) val[nnz] = jac[n * i + j], col_of[nnz++] = (int)j;
    row_end[i] = nnz;
  }
  for (size_t col = 0; col <= n; ++col) {
    const double *v = z + n + n * col;
    double *dv = dz + n + n * col;
    int k = 0;
    for (size_t i = 0; i < n; ++i) {
      double acc = col == n ? dfdv[i] / 3.6 : 0.0;
      for (; k < row_end[i]; ++k) acc += val[k] * v[col_of[k]];
      dv[i] = acc;
    }
  }
  return HM_OK;
}

/* The cycle's amplitude: the largest |y| of every wheelset over each step (a car's trailing bogie may hunt alone). */
static int amp_observer(double t_old, const double *x_old, const double *f_old, double t_new, const double *x_new,
                        const double *f_new, void *ctx) {
  shooter *c = (shooter *)ctx;
  for (size_t i = 0; i < c->sys.n_wheelsets; ++i) {
    const size_t a = c->sys.wheelset_y_state[i], p = a + 1;
    c->amp = fmax(c->amp, hm_sh_extreme(t_new - t_old, x_old[a], x_old[p], f_old[p], x_new[a], x_new[p], f_new[p]));
  }
  return 0;
}

static double start_amplitude(const shooter *c, const double *x0) {
  double amp = 0.0;
  for (size_t i = 0; i < c->sys.n_wheelsets; ++i) amp = fmax(amp, fabs(x0[c->sys.wheelset_y_state[i]]));
  return amp;
}

static void state_of(const shooter *c, const double *u, double *x0) {
  for (size_t i = 0, k = 0; i < c->n; ++i) x0[i] = i == c->sys.phase_state ? 0.0 : u[k++];
}

static hm_status shoot_at(shooter *c, const double *u, shot *s) {
  const size_t n = c->n, nu = c->nu;
  const double T = u[n - 1], v_kmh = u[n];
  if (!(T > 0.0) || !isfinite(T) || !(v_kmh > 0.0) || !isfinite(v_kmh)) return HM_EDOMAIN;
  c->v_mps = hm_mps_from_kmh(v_kmh);
  double x0[NMAX], z[ZMAX], f[NMAX];
  state_of(c, u, x0);
  memset(z, 0, (n + n * n + n) * sizeof(double));
  memcpy(z, x0, n * sizeof(double));
  for (size_t i = 0; i < n; ++i) z[n + n * i + i] = 1.0;
  const double tau = c->symmetric ? 0.5 * T : T, sigma = c->symmetric ? -1.0 : 1.0;
  c->amp = start_amplitude(c, x0);
  const hm_ode_system ode = {n + n * n + n, aug_rhs, NULL, c};
  const hm_dopri_options dopt = {c->shoot.rtol, c->shoot.atol, 0.0, 0.0, 0, n};
  hm_dopri_stats ds;
  ++c->n_shots;
  hm_status st = hm_dop853_integrate(c->integ, &ode, &dopt, 0.0, tau, z, amp_observer, c, &ds);
  c->n_steps += ds.n_accepted + ds.n_rejected;
  if (st != HM_OK) return st;
  if ((st = c->sys.rhs(c->sys.model, c->v_mps, z, f)) != HM_OK) return st;
  memcpy(s->u, u, nu * sizeof(double));
  for (size_t i = 0; i < n; ++i) {
    s->res[i] = z[i] - sigma * x0[i];
    for (size_t j = 0, k = 0; j < n; ++j) {
      if (j == c->sys.phase_state) continue;
      s->jac[nu * i + k++] = z[n + n * j + i] - (i == j ? sigma : 0.0);
    }
    s->jac[nu * i + n - 1] = f[i] * (tau / T);
    s->jac[nu * i + n] = z[n + n * n + i];
  }
  memcpy(s->phi, z + n, n * n * sizeof(double));
  s->amp = c->amp;
  return HM_OK;
}

static hm_status shooter_init(shooter *c, const hm_system *sys, const hm_shooting_options *opt) {
  memset(c, 0, sizeof *c);
  hm_status st = hm_system_validate(sys);
  if (st != HM_OK) return st;
  if (!(opt->rtol > 0.0) || !(opt->atol >= 0.0)) return HM_EINVAL;
  c->sys = *sys;
  c->n = sys->dim;
  c->nu = sys->dim + 1;
  c->amp_unknown = sys->amp_state - (sys->amp_state > sys->phase_state ? 1 : 0);
  c->symmetric = opt->use_symmetry && sys->odd;
  c->shoot = *opt;
  for (size_t i = 0, k = 0; i < c->n; ++i)
    if (i != sys->phase_state) c->sc[k++] = sys->state_scale[i];
  c->sc[c->n - 1] = PERIOD_SCALE_S;
  c->sc[c->n] = SPEED_SCALE_KMH;
  c->integ = hm_dop853_create(c->n + c->n * c->n + c->n);
  return c->integ ? HM_OK : HM_ENOMEM;
}

/* ---- nodes: a cycle, its multipliers and test functions ---- */

typedef struct {
  hm_cont_point head;
  hm_system_cycle_point pub;
  hm_cycle_tests tests;
} node;

typedef struct {
  shooter sh;
  shot last;
  hm_cont_problem prob;
  const hm_system_cycle_options *opt;
  hm_system_cycle_point *points;
  size_t max_points, np;
  hm_system_cycle_event *events;
  size_t max_events, ne;
} family;

static hm_status fill_node(const shooter *c, const shot *s, const double *u, const double *t, node *nd) {
  const size_t n = c->n;
  node out;
  memset(&out, 0, sizeof out);
  hm_status st = hm_floquet(n, s->phi, c->symmetric, out.pub.mult_re, out.pub.mult_im, &out.pub.trivial_index,
                            &out.pub.n_unstable, &out.tests);
  if (st != HM_OK) return st;
  out.pub.dim = n;
  out.pub.speed_kmh = u[n];
  out.pub.period_s = u[n - 1];
  out.pub.amp_m = s->amp;
  state_of(c, u, out.pub.x0);
  out.pub.stable = out.pub.n_unstable == 0;
  out.pub.dspeed_ds = t[n];
  out.tests.dparam_ds = t[n];
  out.tests.amp_m = s->amp;
  memcpy(out.head.t, t, c->nu * sizeof(double));
  memcpy(out.head.u, u, c->nu * sizeof(double));
  *nd = out;
  return HM_OK;
}

static hm_status fam_eval(void *ctx, const double *u, int iter, double *res, double *jac) {
  (void)iter;
  family *y = (family *)ctx;
  const shooter *c = &y->sh;
  hm_status st = shoot_at(&y->sh, u, &y->last);
  if (st != HM_OK) return st;
  for (size_t i = 0; i < c->n; ++i) {
    const double rs = c->sys.state_scale[i];
    res[i] = y->last.res[i] / rs;
    for (size_t j = 0; j < c->nu; ++j) jac[c->nu * i + j] = y->last.jac[c->nu * i + j] * c->sc[j] / rs;
  }
  return HM_OK;
}

static hm_status fam_finish(void *ctx, const double *u, const double *t, void *nd) {
  family *y = (family *)ctx;
  return fill_node(&y->sh, &y->last, u, t, (node *)nd);
}

/* ---- events ---- */

static void emit_event(void *ctx, hm_cycle_event_kind kind, const void *located, int stable_side) {
  family *y = (family *)ctx;
  const hm_system_cycle_event ev = {kind, y->np, ((const node *)located)->pub, stable_side};
  if (y->ne < y->max_events) y->events[y->ne] = ev;
  ++y->ne;
}

static void detect_events(family *y, const node *a, const node *b, double ds) {
  node located;
  hm_cycle_events_between(&y->prob, &y->opt->cont, a, b, ds, offsetof(node, tests), y->sh.symmetric, &located,
                          emit_event, y);
}

static void store(family *y, const node *nd) {
  if (y->np < y->max_points) y->points[y->np] = nd->pub;
  ++y->np;
}

static void fam_accepted(void *ctx, const void *a, const void *b, double ds) {
  family *y = (family *)ctx;
  detect_events(y, (const node *)a, (const node *)b, ds);
  store(y, (const node *)b);
}

static int fam_stop(void *ctx, const void *nd) {
  const family *y = (const family *)ctx;
  const hm_system_cycle_point *c = &((const node *)nd)->pub;
  if (c->speed_kmh < y->opt->v_min_kmh || c->speed_kmh > y->opt->v_max_kmh) return HM_CONT_PARAM_RANGE;
  if (c->amp_m > y->opt->amp_max_m) return HM_CONT_AMP_MAX;
  return HM_CONT_RUNNING;
}

static int options_valid(const hm_system_cycle_options *o) {
  return o && isfinite(o->v_min_kmh) && o->v_min_kmh > 0.0 && isfinite(o->v_max_kmh) && o->v_max_kmh > o->v_min_kmh &&
         isfinite(o->amp_max_m) && o->amp_start_m > 0.0 && o->amp_start_m < o->amp_max_m && o->shoot.rtol > 0.0 &&
         o->shoot.atol >= 0.0 && hm_cont_options_valid(&o->cont);
}

static hm_status family_init(family *y, const hm_system *sys, const hm_system_cycle_options *opt) {
  memset(y, 0, sizeof *y);
  y->opt = opt;
  hm_status st = shooter_init(&y->sh, sys, &opt->shoot);
  y->prob.n = y->sh.nu;
  y->prob.scale = y->sh.sc;
  y->prob.node_size = sizeof(node);
  y->prob.ctx = y;
  y->prob.eval = fam_eval;
  y->prob.finish = fam_finish;
  y->prob.stop = fam_stop;
  y->prob.accepted = fam_accepted;
  return st;
}

/* Newton with unknown `which` fixed at value; the tangent oriented towards growing amplitude. */
static hm_status solve_fixed(family *y, double *u, size_t which, double value, node *nd) {
  double row[UMAX] = {0}, tref[UMAX] = {0};
  row[which] = 1.0;
  tref[y->sh.amp_unknown] = 1.0;
  return hm_cont_correct(&y->prob, &y->opt->cont, u, row, value / y->sh.sc[which], tref, nd, NULL);
}

/* The Hopf point and the first guess of its cycle of amplitude amp: the critical eigenvector q (dgeev), turned so
 * that q[amp_state] is real and positive, x0 = amp Re(q) / q[amp_state], T = 2 pi / omega, V = the Hopf speed. */
static hm_status start_guess(const shooter *c, const hm_system_cycle_options *opt, double amp, double *u,
                             double *v_hopf_kmh) {
  const size_t n = c->n;
  hm_system_critical_options copt = {hm_mps_from_kmh(opt->v_min_kmh), hm_mps_from_kmh(opt->v_max_kmh),
                                     hm_mps_from_kmh(5.0), hm_mps_from_kmh(1e-9)};
  double v_mps;
  hm_status st = hm_system_critical_speed(&c->sys, &copt, &v_mps, NULL);
  if (st != HM_OK) return st;
  double vr[NMAX * NMAX], re[NMAX], im[NMAX], x0[NMAX];
  if ((st = hm_system_eig(&c->sys, v_mps, re, im, vr)) != HM_OK) return st;
  size_t k = n;
  for (size_t i = 0; i < n; ++i)
    if (im[i] > 0.0 && (k == n || re[i] > re[k])) k = i;
  if (k == n) return HM_ENOCRIT; /* the crossing is a real eigenvalue: no Hopf point, no cycles born there */
  const size_t ia = c->sys.amp_state;
  const double qr = vr[ia + n * k], qi = vr[ia + n * (k + 1)], q0 = hypot(qr, qi);
  if (!(q0 > 0.0)) return HM_ENOCONV; /* the mode does not move the amplitude coordinate */
  for (size_t i = 0; i < n; ++i) /* Re(q conj(q_a) / |q_a|) / |q_a| */
    x0[i] = amp * (vr[i + n * k] * qr + vr[i + n * (k + 1)] * qi) / (q0 * q0);
  for (size_t i = 0, m = 0; i < n; ++i)
    if (i != c->sys.phase_state) u[m++] = x0[i];
  u[n - 1] = 2.0 * HM_PI / im[k];
  u[n] = hm_kmh_from_mps(v_mps);
  *v_hopf_kmh = u[n];
  return HM_OK;
}

static hm_status start_branch(family *y, node *n0, node *n1) {
  double u[UMAX], vh;
  const double amp = y->opt->amp_start_m;
  const size_t n = y->sh.n;
  hm_status st = start_guess(&y->sh, y->opt, amp, u, &vh);
  if (st != HM_OK) return st;
  if ((st = solve_fixed(y, u, y->sh.amp_unknown, amp, n0)) != HM_OK) return st;
  double u1[UMAX]; /* twice the amplitude: the state scales with it, the speed's shift with its square */
  memcpy(u1, n0->head.u, sizeof u1);
  for (size_t j = 0; j + 1 < n; ++j) u1[j] *= 2.0;
  u1[n] = vh + 4.0 * (n0->head.u[n] - vh);
  return solve_fixed(y, u1, y->sh.amp_unknown, 2.0 * amp, n1);
}

hm_status hm_system_cycles_continue(const hm_system *sys, const hm_system_cycle_options *opt,
                                    hm_system_cycle_point *points, size_t max_points, size_t *n_points,
                                    hm_system_cycle_event *events, size_t max_events, size_t *n_events,
                                    hm_cont_stats *stats) {
  if (!sys || !n_points || !n_events || (max_points && !points) || (max_events && !events) || !options_valid(opt))
    return HM_EINVAL;
  family y;
  hm_status st = family_init(&y, sys, opt);
  y.points = points;
  y.max_points = max_points;
  y.events = events;
  y.max_events = max_events;
  node prev, cur;
  if (st == HM_OK) st = start_branch(&y, &prev, &cur);
  if (st != HM_OK) {
    hm_dop853_destroy(y.sh.integ);
    return st;
  }
  store(&y, &prev);
  store(&y, &cur);
  hm_cont_stats s;
  hm_cont_run(&y.prob, &opt->cont, &cur, &prev, &s);
  hm_dop853_destroy(y.sh.integ);
  *n_points = y.np < max_points ? y.np : max_points;
  *n_events = y.ne < max_events ? y.ne : max_events;
  s.newton_iterations = y.prob.newton_iterations;
  s.shots = y.sh.n_shots;
  s.integration_steps = y.sh.n_steps;
  if (stats) *stats = s;
  return HM_OK;
}

hm_status hm_system_cycle_solve(const hm_system *sys, const hm_system_cycle_options *opt, double v_kmh,
                                const double *x0_guess, double period_guess_s, hm_system_cycle_point *cycle) {
  if (!sys || !x0_guess || !cycle || !options_valid(opt) || !isfinite(v_kmh) || !(v_kmh > 0.0)) return HM_EINVAL;
  family y;
  hm_status st = family_init(&y, sys, opt);
  if (st == HM_OK) {
    double u[UMAX];
    const size_t n = y.sh.n;
    for (size_t i = 0, m = 0; i < n; ++i)
      if (i != sys->phase_state) u[m++] = x0_guess[i];
    u[n - 1] = period_guess_s;
    u[n] = v_kmh;
    node nd;
    st = solve_fixed(&y, u, n, v_kmh, &nd);
    if (st == HM_OK) *cycle = nd.pub;
  }
  hm_dop853_destroy(y.sh.integ);
  return st;
}

double hm_system_cycles_lowest(const hm_system_cycle_point *points, size_t n_points,
                               const hm_system_cycle_event *events, size_t n_events) {
  double lowest = INFINITY;
  for (size_t i = 0; points && i < n_points; ++i) lowest = fmin(lowest, points[i].speed_kmh);
  for (size_t i = 0; events && i < n_events; ++i)
    if (events[i].kind == HM_CYCLE_LPC) lowest = fmin(lowest, events[i].point.speed_kmh);
  return lowest;
}
