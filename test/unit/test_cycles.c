/* Limit cycles and their folds against MODEL.md sections 6-7, direct simulation and a second shooting method. */
#include <stdlib.h>
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/cycles.h"
#include "hunting_monitor/integrate.h"
#include "hunting_monitor/linear.h"

enum { CAP = 20000 };

typedef struct {
  hm_vehicle veh;
  hm_hopf_point hopf;
  hm_cycle_point *pts;
  size_t np;
  hm_cycle_event ev[32];
  size_t ne;
} family;

static void run(family *f, double kx, double ky, double amp_max, double rtol, double ds_scale) {
  hm_vehicle_default(&f->veh);
  f->veh.stiffness_long_n_m = kx * 1e6;
  f->veh.stiffness_lat_n_m = ky * 1e6;
  size_t n = 0;
  HM_CHECK(hm_hopf_find(&f->veh, 500.0, HM_PARAM_SPEED, 100.0, 900.0, 1e-10, &f->hopf, 1, &n) == HM_OK && n == 1,
           "Hopf");
  hm_cycle_options o;
  hm_cycle_options_default(&o, HM_PARAM_SPEED);
  o.p_min = 150.0;
  o.p_max = 700.0;
  o.amp_max_m = amp_max;
  o.shoot.rtol = rtol;
  o.shoot.atol = rtol * 1e-3;
  o.cont.ds_max *= ds_scale;
  o.cont.ds_init *= ds_scale;
  o.cont.max_steps = (size_t)(o.cont.max_steps / ds_scale);
  f->pts = malloc(CAP * sizeof *f->pts);
  HM_CHECK(hm_cycles_continue(&f->veh, 500.0, &f->hopf, &o, f->pts, CAP, &f->np, f->ev, 32, &f->ne, NULL) == HM_OK,
           "continuation");
}

static const hm_cycle_event *event(const family *f, hm_cycle_event_kind kind, int which) {
  for (size_t i = 0; i < f->ne; ++i)
    if (f->ev[i].kind == kind && which-- == 0) return &f->ev[i];
  return NULL;
}

/* Cycles of the branch at parameter value p (linear interpolation between branch points), by amplitude. */
static size_t cycles_at(const family *f, double p, double *amp, int *stable, size_t max) {
  size_t n = 0;
  for (size_t i = 1; i < f->np && n < max; ++i) {
    const hm_cycle_point *a = &f->pts[i - 1], *b = &f->pts[i];
    if ((a->param - p) * (b->param - p) > 0.0 || a->param == b->param) continue;
    /* the cycle at exactly p by Newton from the chord between the bracketing branch points */
    const double t = (p - a->param) / (b->param - a->param);
    double x0[4];
    for (int k = 0; k < 4; ++k) x0[k] = a->x0[k] + t * (b->x0[k] - a->x0[k]);
    hm_cycle_options o;
    hm_cycle_options_default(&o, HM_PARAM_SPEED);
    o.shoot.rtol = 1e-10;
    o.shoot.atol = 1e-13;
    hm_cycle_point c;
    HM_CHECK(hm_cycle_solve(&f->veh, 500.0, &o, p, x0, a->period_s + t * (b->period_s - a->period_s), &c) == HM_OK,
             "cycle at %g between branch points %zu and %zu", p, i - 1, i);
    amp[n] = c.amp_y_m;
    stable[n] = c.stable;
    ++n;
  }
  for (size_t i = 1; i < n; ++i) /* sort by amplitude */
    for (size_t j = i; j > 0 && amp[j - 1] > amp[j]; --j) {
      const double ta = amp[j];
      const int ts = stable[j];
      amp[j] = amp[j - 1];
      stable[j] = stable[j - 1];
      amp[j - 1] = ta;
      stable[j - 1] = ts;
    }
  return n;
}

static family study97; /* Kx 9.7, Ky 10.96, up to 16 mm: shared by several tests */

/* MODEL.md section 6: independent shooting values; hold LPC speeds to 0.01 km/h (we ask 1e-4). */
static void published_folds_kx_9_7_and_9_9(void) {
  const hm_cycle_event *l1 = event(&study97, HM_CYCLE_LPC, 0), *l2 = event(&study97, HM_CYCLE_LPC, 1);
  HM_CHECK(l1 && l2, "two folds near the Hopf point");
  if (!l1 || !l2) return;
  printf("  Kx 9.7: LPC1 %.6f km/h %.3f mm, LPC2 %.6f km/h %.3f mm\n", l1->point.param, l1->point.amp_y_m * 1e3,
         l2->point.param, l2->point.amp_y_m * 1e3);
  HM_CHECK_DELTA(l1->point.param, 542.478651, 1e-4, "LPC1 V");
  HM_CHECK_DELTA(l2->point.param, 543.209002, 1e-4, "LPC2 V");
  HM_CHECK_DELTA(l1->point.amp_y_m, 4.17e-3, 0.01e-3, "LPC1 amplitude");
  HM_CHECK_DELTA(l2->point.amp_y_m, 5.98e-3, 0.01e-3, "LPC2 amplitude");
  HM_CHECK(l1->stable_side == 1 && l2->stable_side == -1, "stable cycles between the folds");
  family f99;
  run(&f99, 9.9, 10.96, 0.0065, 1e-10, 1.0);
  const hm_cycle_event *m1 = event(&f99, HM_CYCLE_LPC, 0), *m2 = event(&f99, HM_CYCLE_LPC, 1);
  HM_CHECK(m1 && m2, "two folds at Kx 9.9");
  if (m1 && m2) {
    HM_CHECK_DELTA(m1->point.param, 549.363387, 1e-4, "LPC1 V (Kx 9.9)");
    HM_CHECK_DELTA(m2->point.param, 551.158654, 1e-4, "LPC2 V (Kx 9.9)");
    HM_CHECK_DELTA(m1->point.amp_y_m, 3.43e-3, 0.01e-3, "LPC1 amplitude (Kx 9.9)");
    HM_CHECK_DELTA(m2->point.amp_y_m, 6.08e-3, 0.01e-3, "LPC2 amplitude (Kx 9.9)");
  }
  free(f99.pts);
}

/* At V = 543 four cycles coexist: unstable 2.77 mm, stable 5.502 mm, unstable 6.28 mm, stable 14.87 mm. */
static void four_cycles_at_543(void) {
  double amp[8];
  int stable[8];
  const size_t n = cycles_at(&study97, 543.0, amp, stable, 8);
  printf("  V 543: %zu cycles:", n);
  for (size_t i = 0; i < n; ++i) printf(" %.3f mm (%s)", amp[i] * 1e3, stable[i] ? "stable" : "unstable");
  printf("\n");
  HM_CHECK(n == 4, "%zu cycles", n);
  if (n != 4) return;
  const double ref[4] = {2.77e-3, 5.502e-3, 6.28e-3, 14.87e-3};
  const int ref_stable[4] = {0, 1, 0, 1};
  for (int i = 0; i < 4; ++i) {
    HM_CHECK_DELTA(amp[i], ref[i], 0.01e-3, "cycle amplitude at 543 km/h");
    HM_CHECK(stable[i] == ref_stable[i], "cycle %d stability", i);
  }
}

/* Integrating from initial conditions around the cycles at V = 543 reaches what the cycles predict: inside the
 * small unstable cycle the origin, between it and the next unstable cycle the 5.502 mm cycle, beyond that the
 * 14.87 mm cycle (amplitude within 1%). Initial conditions: the unstable cycles' points scaled by 0.95 / 1.05. */
static double simulate_amplitude(const hm_vehicle *veh, const double *x0, double t_end) {
  hm_model m;
  hm_model_init(&m, veh, hm_mps_from_kmh(543.0));
  const hm_ode_system sys = {4, hm_model_rhs, hm_model_jacobian, &m};
  hm_dopri d = hm_dopri_create(4);
  double x[4];
  memcpy(x, x0, sizeof x);
  const hm_dopri_options o = {1e-10, 1e-13, 0.0, 0.0, 0, 0};
  HM_CHECK(hm_dopri_integrate(d, &sys, &o, 0.0, t_end, x, NULL, NULL, NULL, NULL) == HM_OK, "settle");
  /* then the largest |y| over one more second */
  double amp = 0.0;
  for (int k = 0; k < 2000; ++k) {
    HM_CHECK(hm_dopri_integrate(d, &sys, &o, 0.0, 5e-4, x, NULL, NULL, NULL, NULL) == HM_OK, "sample");
    amp = fmax(amp, fabs(x[0]));
  }
  hm_dopri_destroy(d);
  return amp;
}

static const hm_cycle_point *nearest_cycle(const family *f, double p, double amp) {
  const hm_cycle_point *best = NULL;
  double bd = INFINITY;
  for (size_t i = 0; i < f->np; ++i) {
    const double d = fabs(f->pts[i].param - p) + 1e3 * fabs(f->pts[i].amp_y_m - amp);
    if (d < bd) {
      bd = d;
      best = &f->pts[i];
    }
  }
  return best;
}

static void simulation_reaches_predicted_cycles(void) {
  hm_cycle_options o;
  hm_cycle_options_default(&o, HM_PARAM_SPEED);
  hm_cycle_point small, mid;
  const hm_cycle_point *g1 = nearest_cycle(&study97, 543.0, 2.77e-3), *g2 = nearest_cycle(&study97, 543.0, 6.28e-3);
  HM_CHECK(hm_cycle_solve(&study97.veh, 500.0, &o, 543.0, g1->x0, g1->period_s, &small) == HM_OK, "2.77 mm cycle");
  HM_CHECK(hm_cycle_solve(&study97.veh, 500.0, &o, 543.0, g2->x0, g2->period_s, &mid) == HM_OK, "6.28 mm cycle");
  double ic[4][4];
  const double scale[4] = {0.95, 1.05, 0.95, 1.05};
  const hm_cycle_point *base[4] = {&small, &small, &mid, &mid};
  for (int k = 0; k < 4; ++k)
    for (int i = 0; i < 4; ++i) ic[k][i] = scale[k] * base[k]->x0[i];
  const double expected[4] = {0.0, 5.502e-3, 5.502e-3, 14.87e-3};
  for (int k = 0; k < 4; ++k) {
    /* the origin attracts slowly (Re lambda = -0.069 1/s) and the escape from the unstable cycle is slow too
     * (multiplier 1.006 per period), hence the long runs */
    const double amp = simulate_amplitude(&study97.veh, ic[k], expected[k] == 0.0 ? 200.0 : 150.0);
    printf("  start %.2f x (%.3f mm cycle): settles at %.4f mm, expected %.3f mm\n", scale[k],
           base[k]->amp_y_m * 1e3, amp * 1e3, expected[k] * 1e3);
    if (expected[k] == 0.0)
      HM_CHECK(amp < 0.1 * small.amp_y_m, "decay towards the origin: %g m after 200 s", amp);
    else
      HM_CHECK_REL(amp, expected[k], 0.01, "settled amplitude");
  }
}

/* The stable cycle of the branch at speed v (between the folds), by interpolation. */
static int stable_cycle_at(const family *f, double v, double *x0, double *amp) {
  for (size_t i = 1; i < f->np; ++i) {
    const hm_cycle_point *a = &f->pts[i - 1], *b = &f->pts[i];
    if (!a->stable || !b->stable || (a->param - v) * (b->param - v) > 0.0 || a->param == b->param) continue;
    const double t = (v - a->param) / (b->param - a->param);
    for (int k = 0; k < 4; ++k) x0[k] = a->x0[k] + t * (b->x0[k] - a->x0[k]);
    *amp = a->amp_y_m + t * (b->amp_y_m - a->amp_y_m);
    return 1;
  }
  return 0;
}

/* Brute force around LPC1: 0.1 km/h above it a trajectory started on the stable cycle stays there; 0.1 km/h
 * below it, where no cycle exists between the folds' amplitudes, the same start decays towards the origin. */
static void fold_brute_force(void) {
  const hm_cycle_event *l1 = event(&study97, HM_CYCLE_LPC, 0);
  HM_CHECK(l1 != NULL, "no fold on the Kx 9.7 family");
  if (!l1) return;
  double x0[4] = {0, 0, 0, 0}, amp_cycle = 0.0;
  HM_CHECK(stable_cycle_at(&study97, l1->point.param + 0.1, x0, &amp_cycle), "stable cycle above the fold");
  for (int side = 0; side < 2; ++side) {
    const double v = l1->point.param + (side ? -0.1 : 0.1);
    hm_model m;
    hm_model_init(&m, &study97.veh, hm_mps_from_kmh(v));
    const hm_ode_system sys = {4, hm_model_rhs, NULL, &m};
    hm_dopri d = hm_dopri_create(4);
    double x[4];
    memcpy(x, x0, sizeof x);
    const hm_dopri_options dop = {1e-10, 1e-13, 0.0, 0.0, 0, 0};
    HM_CHECK(hm_dopri_integrate(d, &sys, &dop, 0.0, 150.0, x, NULL, NULL, NULL, NULL) == HM_OK, "simulate");
    double amp = 0.0;
    for (int k = 0; k < 200; ++k) {
      hm_dopri_integrate(d, &sys, &dop, 0.0, 5e-4, x, NULL, NULL, NULL, NULL);
      amp = fmax(amp, fabs(x[0]));
    }
    hm_dopri_destroy(d);
    printf("  V = LPC1 %s 0.1 km/h: amplitude after 150 s %.4f mm (stable cycle above: %.4f mm)\n",
           side ? "-" : "+", amp * 1e3, amp_cycle * 1e3);
    if (side)
      HM_CHECK(amp < 0.5 * l1->point.amp_y_m, "below the fold the trajectory should decay (%g m)", amp);
    else
      HM_CHECK_REL(amp, amp_cycle, 0.01, "above the fold the trajectory stays on the stable cycle");
  }
}

/* Mesh refinement (integration tolerance 1e-9 -> 1e-12 and steps / 4) moves the folds by less than 1e-4 km/h. */
static void folds_are_converged(void) {
  family fine;
  run(&fine, 9.7, 10.96, 0.0065, 1e-12, 0.25);
  for (int k = 0; k < 2; ++k) {
    const hm_cycle_event *a = event(&study97, HM_CYCLE_LPC, k), *b = event(&fine, HM_CYCLE_LPC, k);
    HM_CHECK(a && b, "fold %d in both runs", k);
    if (a && b) {
      printf("  LPC%d: %.8f vs refined %.8f km/h\n", k + 1, a->point.param, b->point.param);
      HM_CHECK_DELTA(a->point.param, b->point.param, 1e-4, "fold speed change under refinement");
    }
  }
  free(fine.pts);
}

/* Symmetric half-period shooting against full-period shooting (no symmetry used): same cycle, same multipliers. */
static void symmetric_and_full_shooting_agree(void) {
  hm_cycle_options sym, full;
  hm_cycle_options_default(&sym, HM_PARAM_SPEED);
  full = sym;
  full.shoot.use_symmetry = 0;
  const hm_cycle_point *g = nearest_cycle(&study97, 543.0, 5.5e-3);
  hm_cycle_point a, b;
  HM_CHECK(hm_cycle_solve(&study97.veh, 500.0, &sym, 543.0, g->x0, g->period_s, &a) == HM_OK, "symmetric");
  HM_CHECK(hm_cycle_solve(&study97.veh, 500.0, &full, 543.0, g->x0, g->period_s, &b) == HM_OK, "full period");
  HM_CHECK_DELTA(a.period_s, b.period_s, 1e-10, "period");
  HM_CHECK_DELTA(a.amp_y_m, b.amp_y_m, 1e-9, "amplitude");
  for (int k = 0; k < 4; ++k) {
    HM_CHECK_DELTA(a.mult_re[k], b.mult_re[k], 1e-6, "multiplier (real part)");
    HM_CHECK_DELTA(fabs(a.mult_im[k]), fabs(b.mult_im[k]), 1e-6, "multiplier (imaginary part)");
  }
  HM_CHECK(a.stable && b.stable, "the 5.5 mm cycle is stable");
}

/* MODEL.md section 7, default vehicle: Hopf 517.618, LPC1 515.691 (4.2 mm), LPC2 516.353 (6.0 mm), third fold
 * near 239.5 km/h (10.4 mm), symmetry-breaking branch points near 261 and 304 km/h. */
static void default_vehicle_whole_family(void) {
  family f;
  run(&f, 8.96, 8.96, 0.016, 1e-10, 1.0);
  const hm_cycle_event *a = event(&f, HM_CYCLE_LPC, 0), *b = event(&f, HM_CYCLE_LPC, 1),
                       *c = event(&f, HM_CYCLE_LPC, 2), *p = event(&f, HM_CYCLE_BPC, 0),
                       *q = event(&f, HM_CYCLE_BPC, 1);
  HM_CHECK(a && b && c && p && q, "three folds and two branch points");
  if (a && b && c && p && q) {
    printf("  folds %.4f (%.2f mm), %.4f (%.2f mm), %.3f (%.2f mm); BPC %.2f, %.2f km/h\n", a->point.param,
           a->point.amp_y_m * 1e3, b->point.param, b->point.amp_y_m * 1e3, c->point.param, c->point.amp_y_m * 1e3,
           p->point.param, q->point.param);
    HM_CHECK_DELTA(a->point.param, 515.691, 0.01, "LPC1");
    HM_CHECK_DELTA(b->point.param, 516.353, 0.01, "LPC2");
    HM_CHECK_DELTA(c->point.param, 239.5, 0.1, "third fold");
    HM_CHECK_DELTA(a->point.amp_y_m, 4.2e-3, 0.05e-3, "LPC1 amplitude");
    HM_CHECK_DELTA(b->point.amp_y_m, 6.0e-3, 0.05e-3, "LPC2 amplitude");
    HM_CHECK_DELTA(c->point.amp_y_m, 10.4e-3, 0.05e-3, "third fold amplitude");
    HM_CHECK_DELTA(p->point.param, 261.0, 1.0, "first branch point");
    HM_CHECK_DELTA(q->point.param, 304.0, 2.0, "second branch point");
    /* the lowest speed with a cycle is the third fold itself (MODEL.md: 239.5), not the nearest branch point */
    HM_CHECK(hm_cycles_lowest(f.pts, f.np, f.ev, f.ne) == c->point.param, "lowest %.6f is not the fold %.6f",
             hm_cycles_lowest(f.pts, f.np, f.ev, f.ne), c->point.param);
  }
  /* the unstable cycle beyond LPC2 at lower speeds: about 7.2 mm at 504.5, 8.2 at 420, 9.2 mm at 293 km/h */
  const double v[3] = {504.5, 420.0, 293.0}, ref[3] = {7.2e-3, 8.2e-3, 9.2e-3};
  for (int i = 0; i < 3; ++i) {
    double amp[8];
    int st[8];
    const size_t n = cycles_at(&f, v[i], amp, st, 8);
    HM_CHECK(n >= 1 && !st[0], "an unstable cycle at %g km/h", v[i]);
    if (n >= 1) HM_CHECK_DELTA(amp[0], ref[i], 0.05e-3, "basin edge amplitude");
  }
  free(f.pts);
}

/* The fixture the next cases share, built inside HM_RUN so that its checks count. */
static void study_family_kx_9_7(void) { run(&study97, 9.7, 10.96, 0.016, 1e-9, 1.0); /* the default tolerance */ }

int main(void) {
  HM_RUN(study_family_kx_9_7);
  HM_RUN(published_folds_kx_9_7_and_9_9);
  HM_RUN(four_cycles_at_543);
  HM_RUN(simulation_reaches_predicted_cycles);
  HM_RUN(fold_brute_force);
  HM_RUN(folds_are_converged);
  HM_RUN(symmetric_and_full_shooting_agree);
  HM_RUN(default_vehicle_whole_family);
  free(study97.pts);
  HM_TEST_EXIT();
}
