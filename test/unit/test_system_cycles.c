/* system_cycles.h: cycles of any model. MODEL.md's wheelset run through it against the published folds (section 6,
 * an independent shooting computation: 542.478651 and 543.209002 km/h) and against its own 4-state engine
 * (cycles.h); the two-axle bogie's cycles against simulations started around them (classic RK4 of the right-hand
 * side, nothing of the shooting), and its folds against a computation at tolerances 100 times tighter. */
#include <stdlib.h>
#include <string.h>

#include "hm_test.h"
#include "system_checks.h"
#include "hunting_monitor/bogie.h"
#include "hunting_monitor/car.h"
#include "hunting_monitor/hopf.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/system_cycles.h"

enum { MAX_POINTS = 1000, MAX_EVENTS = 40 };

static hm_system_cycle_point points[MAX_POINTS];
static hm_system_cycle_event events[MAX_EVENTS];

/* The default bogie (config/bogie_default.yaml) as a system. */
static void default_bogie(hm_bogie_model *m, hm_system *sys) {
  hm_bogie b;
  hm_bogie_default(&b);
  HM_CHECK(hm_bogie_model_init(m, &b, 0, sys) == HM_OK, "init");
}

/* The default car (config/car_default.yaml) as a system. */
static void default_car(hm_car_model *m, hm_system *sys) {
  hm_car c;
  hm_car_default(&c);
  HM_CHECK(hm_car_model_init(m, &c, 0, sys) == HM_OK, "init");
}

static void wheelset_folds_as_published(void) {
  hm_vehicle veh;
  hm_vehicle_default(&veh);
  veh.stiffness_long_n_m = 9.7e6;
  veh.stiffness_lat_n_m = 10.96e6;
  hm_wheelset_system ws;
  hm_system sys;
  HM_CHECK(hm_wheelset_system_init(&ws, &veh, &sys) == HM_OK, "init");
  hm_system_cycle_options opt;
  hm_system_cycle_options_default(&opt);
  opt.amp_max_m = 0.0075;
  size_t np = 0, ne = 0;
  HM_CHECK(hm_system_cycles_continue(&sys, &opt, points, MAX_POINTS, &np, events, MAX_EVENTS, &ne, NULL) == HM_OK,
           "continue");
  /* the wheelset's own engine on the same family */
  hm_hopf_point hopf;
  size_t nh = 0;
  HM_CHECK(hm_hopf_find(&veh, 500.0, HM_PARAM_SPEED, 100.0, 1500.0, 1e-9, &hopf, 1, &nh) == HM_OK && nh == 1, "hopf");
  hm_cycle_options copt;
  hm_cycle_options_default(&copt, HM_PARAM_SPEED);
  copt.amp_max_m = 0.0075;
  static hm_cycle_point cp[MAX_POINTS];
  hm_cycle_event ce[MAX_EVENTS];
  size_t cn = 0, cne = 0;
  HM_CHECK(hm_cycles_continue(&veh, 500.0, &hopf, &copt, cp, MAX_POINTS, &cn, ce, MAX_EVENTS, &cne, NULL) == HM_OK,
           "cycles.h");
  const double published[2] = {542.478651, 543.209002};
  HM_CHECK(ne == 2 && cne == 2, "two folds each (%zu, %zu)", ne, cne);
  for (size_t i = 0; i < 2 && i < ne && i < cne; ++i) {
    HM_CHECK(events[i].kind == HM_CYCLE_LPC, "fold");
    HM_CHECK_DELTA(events[i].point.speed_kmh, published[i], 1e-6, "LPC against MODEL.md's independent shooting");
    HM_CHECK_DELTA(events[i].point.speed_kmh, ce[i].point.param, 1e-6, "LPC against cycles.h");
    HM_CHECK_DELTA(events[i].point.amp_m, ce[i].point.amp_y_m, 1e-9, "fold amplitude against cycles.h");
    HM_CHECK_DELTA(events[i].point.period_s, ce[i].point.period_s, 1e-9, "fold period against cycles.h");
  }
  HM_CHECK(ne == 2 && events[0].stable_side == 1 && events[1].stable_side == -1, "stable between the folds");
}

/* The largest |y| of every wheelset over the last second of t_s seconds of the nonlinear system at v from x0
 * (classic RK4 at 0.1 ms of its right-hand side); a run that passes 40 mm stops there and returns that. */
static double simulate_amplitude(const hm_system *sys, double v_kmh, const double *x0, double t_s) {
  double x[HM_SYSTEM_MAX_DIM];
  memcpy(x, x0, sys->dim * sizeof(double));
  const double h = 1e-4, v = hm_mps_from_kmh(v_kmh);
  const long steps = (long)(t_s / h);
  double amp = 0.0;
  for (long s = 1; s <= steps; ++s) {
    system_rk4_step(sys, v, x, h);
    double y = 0.0; /* every wheelset's |y|, as the family's amplitude */
    for (size_t w = 0; w < sys->n_wheelsets; ++w) y = fmax(y, fabs(x[sys->wheelset_y_state[w]]));
    if (y > 0.04) return y;
    if (s * h > t_s - 1.0) amp = fmax(amp, y);
  }
  return amp;
}

/* Simulations from 20% inside and outside the family's first stable cycle above 3 mm end on it (to 1%). */
static void settles_on_stable_cycle(const hm_system *sys, const hm_system_cycle_point *c) {
  double x[HM_SYSTEM_MAX_DIM];
  for (int side = -1; side <= 1; side += 2) {
    for (size_t i = 0; i < sys->dim; ++i) x[i] = (1.0 + 0.2 * side) * c->x0[i];
    const double a = simulate_amplitude(sys, c->speed_kmh, x, 25.0);
    printf("  stable cycle %.3f km/h, %.4f mm: from %+.0f%% the simulation ends at %.4f mm\n", c->speed_kmh,
           1e3 * c->amp_m, 20.0 * side, 1e3 * a);
    HM_CHECK_DELTA(a, c->amp_m, 0.01 * c->amp_m, "settles on the stable cycle");
  }
}

/* The default bogie's family at 0.1358: simulations from 20% inside and outside a stable cycle settle on it (within
 * 1% of its amplitude), from 2% inside an unstable one decay towards the origin and from 2% outside leave it. */
static void bogie_cycles_where_simulations_settle(void) {
  hm_bogie_model m;
  hm_system sys;
  default_bogie(&m, &sys);
  hm_system_cycle_options opt;
  hm_system_cycle_options_default(&opt);
  opt.v_min_kmh = 150.0, opt.v_max_kmh = 700.0, opt.amp_max_m = 0.016;
  size_t np = 0, ne = 0;
  hm_cont_stats st;
  HM_CHECK(hm_system_cycles_continue(&sys, &opt, points, MAX_POINTS, &np, events, MAX_EVENTS, &ne, &st) == HM_OK,
           "continue");
  HM_CHECK(np > 20 && ne >= 1 && events[0].kind == HM_CYCLE_LPC, "a family with a fold (%zu points)", np);
  printf("  %zu cycles, %zu events (%s); the first fold %.6f km/h at %.3f mm\n", np, ne, hm_cont_stop_name(st.stop),
         events[0].point.speed_kmh, 1e3 * events[0].point.amp_m);
  const hm_system_cycle_point *stable = NULL, *unstable = NULL;
  for (size_t i = 0; i < np; ++i) {
    if (!stable && points[i].stable && points[i].amp_m > 3e-3) stable = &points[i];
    if (stable && !unstable && !points[i].stable && points[i].amp_m > 6.5e-3 && points[i].speed_kmh < 520.0)
      unstable = &points[i];
  }
  HM_CHECK(stable && unstable, "a stable cycle above 3 mm and an unstable one above 6.5 mm below 520 km/h");
  if (!stable || !unstable) return;
  settles_on_stable_cycle(&sys, stable);
  double x[HM_BOGIE_DIM];
  for (int side = -1; side <= 1; side += 2) {
    for (size_t i = 0; i < HM_BOGIE_DIM; ++i) x[i] = (1.0 + 0.02 * side) * unstable->x0[i];
    const double a = simulate_amplitude(&sys, unstable->speed_kmh, x, 3.0);
    printf("  unstable cycle %.3f km/h, %.4f mm: from %+.0f%% the simulation ends at %.4f mm\n", unstable->speed_kmh,
           1e3 * unstable->amp_m, 2.0 * side, 1e3 * a);
    HM_CHECK(side < 0 ? a < 0.5 * unstable->amp_m : a > 1.1 * unstable->amp_m, "leaves the unstable cycle");
  }
}

/* The whole vehicle (30 states): its family's stable cycles are where simulations settle too. */
static void car_cycles_where_simulations_settle(void) {
  hm_car_model m;
  hm_system sys;
  default_car(&m, &sys);
  hm_system_cycle_options opt;
  hm_system_cycle_options_default(&opt);
  opt.amp_max_m = 0.0065;
  size_t np = 0, ne = 0;
  HM_CHECK(hm_system_cycles_continue(&sys, &opt, points, MAX_POINTS, &np, events, MAX_EVENTS, &ne, NULL) == HM_OK,
           "continue");
  const hm_system_cycle_point *stable = NULL;
  for (size_t i = 0; i < np && !stable; ++i)
    if (points[i].stable && points[i].amp_m > 3e-3) stable = &points[i];
  HM_CHECK(stable != NULL, "a stable cycle above 3 mm");
  if (stable) settles_on_stable_cycle(&sys, stable);
}

/* A cycle's amplitude is the largest |y| of every wheelset (review of issue #28: after its first fold the car's family
 * is its trailing bogie hunting alone, which the leading wheelset's |y| had called 0.06 mm): checked against the
 * tests' own RK4 over one period from each tested cycle's start. */
static void car_amplitude_over_every_wheelset(void) {
  hm_car_model m;
  hm_system sys;
  default_car(&m, &sys);
  hm_system_cycle_options opt;
  hm_system_cycle_options_default(&opt);
  opt.v_min_kmh = 300.0, opt.v_max_kmh = 700.0, opt.amp_max_m = 0.012;
  size_t np = 0, ne = 0;
  HM_CHECK(hm_system_cycles_continue(&sys, &opt, points, MAX_POINTS, &np, events, MAX_EVENTS, &ne, NULL) == HM_OK,
           "continue");
  double worst = 0.0, trailing_share = 0.0;
  for (size_t i = 0; i < np; i += np / 8 + 1) {
    double x[HM_SYSTEM_MAX_DIM], amp = 0.0, lead = 0.0;
    memcpy(x, points[i].x0, sys.dim * sizeof(double));
    const double v = hm_mps_from_kmh(points[i].speed_kmh), T = points[i].period_s;
    const int steps = 20000;
    for (int k = 0; k < steps; ++k) {
      system_rk4_step(&sys, v, x, T / steps);
      for (size_t w = 0; w < sys.n_wheelsets; ++w) amp = fmax(amp, fabs(x[sys.wheelset_y_state[w]]));
      lead = fmax(lead, fabs(x[0]));
    }
    worst = fmax(worst, fabs(amp - points[i].amp_m) / amp);
    trailing_share = fmax(trailing_share, amp / fmax(lead, 1e-12));
  }
  printf("  car family: %zu cycles, amplitudes against one period's RK4 to %.2g relative; a trailing wheelset's |y| up "
         "to %.3g times the leading one's\n", np, worst, trailing_share);
  HM_CHECK(np > 10 && worst < 1e-3, "every wheelset's |y| counted");
}

/* The bogie's first fold at rtol 1e-9 (the default) and at 1e-11 with atol 1e-14: the same to 1e-6 km/h. */
static void bogie_fold_refined(void) {
  hm_bogie_model m;
  hm_system sys;
  default_bogie(&m, &sys);
  double fold[2] = {0.0, 0.0};
  for (int k = 0; k < 2; ++k) {
    hm_system_cycle_options opt;
    hm_system_cycle_options_default(&opt);
    opt.amp_max_m = 0.0065;
    if (k == 1) opt.shoot.rtol = 1e-11, opt.shoot.atol = 1e-14;
    size_t np = 0, ne = 0;
    HM_CHECK(hm_system_cycles_continue(&sys, &opt, points, MAX_POINTS, &np, events, MAX_EVENTS, &ne, NULL) == HM_OK &&
                 ne >= 1 && events[0].kind == HM_CYCLE_LPC,
             "fold found at tolerance %d", k);
    fold[k] = ne >= 1 ? events[0].point.speed_kmh : NAN;
    HM_CHECK(ne >= 1 && fabs(events[0].point.dspeed_ds) < 1e-6, "located where dV/ds = 0");
  }
  HM_CHECK_DELTA(fold[0], fold[1], 1e-6, "fold speed at 1e-9 against 1e-11");
}

static void bad_input(void) {
  hm_bogie_model m;
  hm_system sys;
  default_bogie(&m, &sys);
  hm_system_cycle_options opt;
  hm_system_cycle_options_default(&opt);
  size_t np = 7, ne = 7;
  opt.v_max_kmh = 400.0; /* no critical speed below 400 km/h */
  HM_CHECK(hm_system_cycles_continue(&sys, &opt, points, MAX_POINTS, &np, events, MAX_EVENTS, &ne, NULL) ==
                   HM_ENOCRIT && np == 7 && ne == 7,
           "no Hopf point in range");
  hm_system_cycle_options_default(&opt);
  opt.amp_start_m = opt.amp_max_m * 2.0;
  HM_CHECK(hm_system_cycles_continue(&sys, &opt, points, MAX_POINTS, &np, events, MAX_EVENTS, &ne, NULL) == HM_EINVAL,
           "start above the limit");
  hm_system_cycle_options_default(&opt);
  opt.v_min_kmh = NAN;
  HM_CHECK(hm_system_cycles_continue(&sys, &opt, points, MAX_POINTS, &np, events, MAX_EVENTS, &ne, NULL) == HM_EINVAL,
           "NaN speed");
  hm_system_cycle_options_default(&opt);
  hm_system_cycle_point c;
  double x0[HM_BOGIE_DIM] = {0};
  HM_CHECK(hm_system_cycle_solve(&sys, &opt, -5.0, x0, 0.07, &c) == HM_EINVAL, "negative speed");
}

int main(void) {
  HM_RUN(wheelset_folds_as_published);
  HM_RUN(bogie_cycles_where_simulations_settle);
  HM_RUN(car_cycles_where_simulations_settle);
  HM_RUN(car_amplitude_over_every_wheelset);
  HM_RUN(bogie_fold_refined);
  HM_RUN(bad_input);
  HM_TEST_EXIT();
}
