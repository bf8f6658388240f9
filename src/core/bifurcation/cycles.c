/* Limit cycles by shooting; pseudo-arclength continuation from a Hopf point; LPC, BPC, PD and NS points. */
#include "hunting_monitor/cycles.h"

#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "hunting_monitor/integrate.h"
#include "hunting_monitor/linear.h"
#include "continuation.h"
#include "floquet.h"
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
  opt->shoot.rtol = 1e-9;
  opt->shoot.atol = 1e-12;
  opt->shoot.use_symmetry = 1;
  hm_cont_options_default(&opt->cont);
}

/* ---- multipliers and test functions ---- */

typedef struct {
  hm_cont_point head;    /* unknowns and unit tangent (scaled) */
  hm_cycle_point pub;
  hm_cycle_tests tests;  /* the event test functions (floquet.h) */
} node;

/* The continuation problem: the shooting equations in the unknowns u = (y0, psi0, dpsi0, T, p). */
typedef struct {
  hm_sh sh;
  hm_shot last;          /* the latest evaluation */
  hm_cont_problem prob;
  const hm_cycle_options *opt;
  hm_cycle_point *points;
  size_t max_points, np;
  hm_cycle_event *events;
  size_t max_events, ne;
} cyc;

static hm_status fill_node(const hm_sh *c, const hm_shot *s, const double *u, const double *t, node *nd) {
  node out;
  memset(&out, 0, sizeof out);
  hm_status st = hm_floquet(NX, s->phi, c->symmetric, out.pub.mult_re, out.pub.mult_im, &out.pub.trivial_index,
                            &out.pub.n_unstable, &out.tests);
  if (st != HM_OK) return st;
  out.pub.param = u[4];
  out.pub.period_s = u[3];
  out.pub.amp_y_m = s->amp_y;
  out.pub.amp_psi_rad = s->amp_psi;
  out.pub.x0[0] = u[0];
  out.pub.x0[1] = 0.0;
  out.pub.x0[2] = u[1];
  out.pub.x0[3] = u[2];
  out.pub.stable = out.pub.n_unstable == 0;
  out.pub.dparam_ds = t[4];
  out.tests.dparam_ds = t[4];
  out.tests.amp_m = s->amp_y;
  memcpy(out.head.t, t, NU * sizeof(double));
  memcpy(out.head.u, u, NU * sizeof(double));
  *nd = out;
  return HM_OK;
}

static hm_status cyc_eval(void *ctx, const double *u, int iter, double *res, double *jac) {
  (void)iter;
  cyc *y = (cyc *)ctx;
  hm_status st = hm_sh_shoot(&y->sh, u, &y->last);
  if (st != HM_OK) return st;
  for (int i = 0; i < NX; ++i) {
    res[i] = y->last.res[i] / hm_sh_res_scale[i];
    for (int j = 0; j < NU; ++j) jac[NU * i + j] = y->last.jac[NW * i + j] * y->sh.sc[j] / hm_sh_res_scale[i];
  }
  return HM_OK;
}

static hm_status cyc_finish(void *ctx, const double *u, const double *t, void *nd) {
  cyc *y = (cyc *)ctx;
  return fill_node(&y->sh, &y->last, u, t, (node *)nd);
}

/* ---- event location ---- */

static void emit_event(void *ctx, hm_cycle_event_kind kind, const void *located, int stable_side) {
  cyc *y = (cyc *)ctx;
  const hm_cycle_event ev = {kind, y->np, ((const node *)located)->pub, stable_side};
  if (y->ne < y->max_events) y->events[y->ne] = ev;
  ++y->ne;
}

/* Detect and locate the events between consecutive nodes a and b (b reached from a with step ds). */
static void detect_events(cyc *y, const node *a, const node *b, double ds) {
  node located;
  hm_cycle_events_between(&y->prob, &y->opt->cont, a, b, ds, offsetof(node, tests), y->sh.symmetric, &located,
                          emit_event, y);
}

static void store(cyc *y, const node *nd) {
  if (y->np < y->max_points) y->points[y->np] = nd->pub;
  ++y->np;
}

static void cyc_accepted(void *ctx, const void *a, const void *b, double ds) {
  cyc *y = (cyc *)ctx;
  detect_events(y, (const node *)a, (const node *)b, ds);
  store(y, (const node *)b);
}

static int cyc_stop(void *ctx, const void *nd) {
  const cyc *y = (const cyc *)ctx;
  const hm_cycle_point *c = &((const node *)nd)->pub;
  if (c->param < y->opt->p_min || c->param > y->opt->p_max) return HM_CONT_PARAM_RANGE;
  if (c->amp_y_m > y->opt->amp_max_m) return HM_CONT_AMP_MAX;
  return HM_CONT_RUNNING;
}

static hm_status cyc_init(cyc *y, const hm_vehicle *veh, double speed_kmh, const hm_cycle_options *opt) {
  memset(y, 0, sizeof *y);
  y->opt = opt;
  y->prob.n = NU;
  y->prob.scale = y->sh.sc;
  y->prob.node_size = sizeof(node);
  y->prob.ctx = y;
  y->prob.eval = cyc_eval;
  y->prob.finish = cyc_finish;
  y->prob.stop = cyc_stop;
  y->prob.accepted = cyc_accepted;
  return hm_sh_init(&y->sh, veh, speed_kmh, opt->param, &opt->shoot, 0, HM_PARAM_SPEED);
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

double hm_cycles_lowest(const hm_cycle_point *points, size_t n_points, const hm_cycle_event *events, size_t n_events) {
  double lowest = INFINITY;
  for (size_t i = 0; points && i < n_points; ++i) lowest = fmin(lowest, points[i].param);
  for (size_t i = 0; events && i < n_events; ++i)
    if (events[i].kind == HM_CYCLE_LPC) lowest = fmin(lowest, events[i].point.param);
  return lowest;
}

static int options_valid(const hm_cycle_options *o) {
  return o->p_max > o->p_min && o->amp_max_m > 0.0 && o->amp_start_m > 0.0 && o->amp_start_m < o->amp_max_m &&
         o->shoot.rtol > 0.0 && o->shoot.atol >= 0.0 && hm_cont_options_valid(&o->cont);
}

/* Solve with unknown `which` fixed at value (the start of the branch, or a cycle at a given parameter). */
static hm_status solve_fixed(cyc *y, double *u, int which, double value, node *nd) {
  double row[NU] = {0, 0, 0, 0, 0};
  row[which] = 1.0;
  const double tref[NU] = {1, 0, 0, 0, 0}; /* orient the tangent towards growing amplitude */
  return hm_cont_correct(&y->prob, &y->opt->cont, u, row, value / y->sh.sc[which], tref, nd, NULL);
}

hm_status hm_cycle_solve(const hm_vehicle *veh, double speed_kmh, const hm_cycle_options *opt, double p,
                         const double x0_guess[4], double period_guess_s, hm_cycle_point *cycle) {
  if (!veh || !opt || !x0_guess || !cycle || !options_valid(opt)) return HM_EINVAL;
  cyc y;
  hm_status st = cyc_init(&y, veh, speed_kmh, opt);
  if (st == HM_OK) {
    double u[NU] = {x0_guess[0], x0_guess[2], x0_guess[3], period_guess_s, p};
    node nd;
    st = solve_fixed(&y, u, 4, p, &nd);
    if (st == HM_OK) *cycle = nd.pub;
  }
  hm_sh_free(&y.sh);
  return st;
}

static hm_status start_branch(cyc *y, const hm_hopf_point *hopf, node *n0, node *n1) {
  hm_sh *c = &y->sh;
  double u[NU];
  const double amp = y->opt->amp_start_m;
  hm_status st = start_guess(c, hopf, amp, u);
  if (st != HM_OK) return st;
  if ((st = solve_fixed(y, u, 0, amp, n0)) != HM_OK) return st;
  /* second cycle at twice the amplitude: the state scales with it, the parameter shift with its square */
  double u1[NU];
  memcpy(u1, n0->head.u, sizeof u1);
  for (int j = 0; j < 3; ++j) u1[j] *= 2.0;
  const double ph = hopf_param(c, hopf);
  u1[4] = ph + 4.0 * (n0->head.u[4] - ph);
  return solve_fixed(y, u1, 0, 2.0 * amp, n1);
}

hm_status hm_cycles_continue(const hm_vehicle *veh, double speed_kmh, const hm_hopf_point *hopf,
                             const hm_cycle_options *opt, hm_cycle_point *points, size_t max_points,
                             size_t *n_points, hm_cycle_event *events, size_t max_events, size_t *n_events,
                             hm_cont_stats *stats) {
  if (!veh || !hopf || !opt || !n_points || !n_events || (max_points && !points) || (max_events && !events) ||
      !options_valid(opt))
    return HM_EINVAL;
  cyc y;
  hm_status st = cyc_init(&y, veh, speed_kmh, opt);
  y.points = points;
  y.max_points = max_points;
  y.events = events;
  y.max_events = max_events;
  node prev, cur;
  if (st == HM_OK) st = start_branch(&y, hopf, &prev, &cur);
  if (st != HM_OK) {
    hm_sh_free(&y.sh);
    return st;
  }
  store(&y, &prev);
  store(&y, &cur);
  hm_cont_stats s;
  hm_cont_run(&y.prob, &opt->cont, &cur, &prev, &s);
  hm_sh_free(&y.sh);
  *n_points = y.np < max_points ? y.np : max_points;
  *n_events = y.ne < max_events ? y.ne : max_events;
  s.newton_iterations = y.prob.newton_iterations; /* the start's corrections included */
  s.shots = y.sh.n_shots;
  s.integration_steps = y.sh.n_steps;
  if (stats) *stats = s;
  return HM_OK;
}
