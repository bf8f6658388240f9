/* bogie.h: the two-axle bogie of issue #28. Checked against the lone wheelset of MODEL.md (the frame held: the same
 * eigenvalues, each twice, and the closed-form 517.618 km/h), its analytic Jacobian against central differences of
 * its right-hand side, and its critical speed by eigenvalue bisection against a second method: the growth rate of a
 * time simulation (classic RK4 of the right-hand side itself, no Jacobian, no LAPACK) on both sides of it. */
#include <string.h>

#include "hm_test.h"
#include "system_checks.h"
#include "hunting_monitor/bogie.h"
#include "hunting_monitor/linear.h"

/* The default bogie at conicity lambda0, frame free or held: *b, *m and *sys filled. */
static void default_bogie(double lambda0, int held, hm_bogie *b, hm_bogie_model *m, hm_system *sys) {
  hm_bogie_default(b);
  HM_CHECK(hm_vehicle_set_conicity_at_zero(&b->wheelset, lambda0) == HM_OK, "conicity");
  HM_CHECK(hm_bogie_model_init(m, b, held, sys) == HM_OK, "init");
  HM_CHECK(sys->dim == (held ? HM_BOGIE_HELD_DIM : HM_BOGIE_DIM), "dimension %zu", sys->dim);
}

static void held_frame_is_the_lone_wheelset(void) {
  const double lambdas[] = {0.12, 0.1358, 0.2};
  for (int k = 0; k < 3; ++k) {
    hm_bogie b;
    hm_bogie_model m;
    hm_system sys;
    default_bogie(lambdas[k], 1, &b, &m, &sys);
    const double speeds[] = {200.0, 450.0, 650.0};
    for (int j = 0; j < 3; ++j) {
      const double v = hm_mps_from_kmh(speeds[j]);
      hm_system_spectrum s;
      double re[4], im[4];
      HM_CHECK(hm_system_spectrum_at(&sys, v, &s) == HM_OK, "spectrum");
      HM_CHECK(hm_linear_eigenvalues(&b.wheelset, lambdas[k], v, re, im) == HM_OK, "wheelset");
      /* each of the wheelset's eigenvalues appears twice */
      int used[4] = {0, 0, 0, 0};
      for (int i = 0; i < 8; ++i) {
        int best = -1;
        double d_best = INFINITY;
        for (int q = 0; q < 4; ++q) {
          const double d = hypot(s.re[i] - re[q], s.im[i] - im[q]);
          if (d < d_best) d_best = d, best = q;
        }
        used[best]++;
        HM_CHECK(d_best <= 1e-9 * hypot(re[best], im[best]), "eigenvalue %d off by %.3g", i, d_best);
      }
      for (int q = 0; q < 4; ++q) HM_CHECK(used[q] == 2, "wheelset eigenvalue %d found %d times", q, used[q]);
    }
    hm_system_critical_options opt;
    hm_system_critical_options_default(&opt);
    double v = 0.0, v_closed = 0.0;
    hm_system_spectrum s;
    HM_CHECK(hm_system_critical_speed(&sys, &opt, &v, &s) == HM_OK, "critical");
    HM_CHECK(hm_linear_critical_speed(&b.wheelset, lambdas[k], &v_closed) == HM_OK, "closed form");
    HM_CHECK_REL(v, v_closed, 1e-9, "held frame's critical speed against the closed form");
    HM_CHECK_DELTA(s.body_share[0], 1.0, 1e-12, "the held frame has no energy");
    if (lambdas[k] == 0.1358) HM_CHECK_DELTA(hm_kmh_from_mps(v), 517.618, 0.0005, "MODEL.md's 517.618 km/h");
  }
}

/* The analytic Jacobian against central differences of the right-hand side, at a state in the nonlinear range
 * (the conicity's Gaussians and the flange force active). */
static void jacobian_against_differences(void) {
  hm_bogie b;
  hm_bogie_default(&b);
  const double x[HM_BOGIE_DIM] = {0.0062, 0.05, 0.0011, -0.02, -0.0048, 0.03, -0.0007, 0.01,
                                  0.0015, -0.004, 0.0003, 0.002, 0.0002};
  for (int held = 0; held <= 1; ++held) {
    hm_bogie_model m;
    hm_system sys;
    HM_CHECK(hm_bogie_model_init(&m, &b, held, &sys) == HM_OK, "init");
    check_jacobian(&sys, hm_mps_from_kmh(380.0), x, held ? "frame held" : "frame free");
  }
}

/* The critical speed by eigenvalues against the simulation: stable 0.1 km/h below it, unstable 0.1 km/h above it,
 * for a critical mode of the wheelsets (14 Hz at 0.1358) and one of the frame (at 0.30); and the rates 15 km/h off
 * it within 3% of the eigenvalue's real part. */
static void critical_speed_against_simulation(void) {
  const double lambdas[] = {0.1358, 0.30};
  for (int k = 0; k < 2; ++k) {
    hm_bogie b;
    hm_bogie_model m;
    hm_system sys;
    default_bogie(lambdas[k], 0, &b, &m, &sys);
    double vc = 0.0;
    hm_system_spectrum s;
    printf("  conicity %.4f:\n", lambdas[k]);
    check_critical_against_simulation(&sys, &vc, &s);
    for (int side = -1; side <= 1; side += 2) {
      const double v = vc + side * hm_mps_from_kmh(15.0);
      hm_system_spectrum e;
      HM_CHECK(hm_system_spectrum_at(&sys, v, &e) == HM_OK, "spectrum");
      const double g = system_growth_rate(&sys, v, 60.0, 60.0);
      HM_CHECK_DELTA(g, e.abscissa_1_s, 0.03 * fabs(e.abscissa_1_s), "growth rate 15 km/h off the critical speed");
    }
  }
}

static void bad_parameters(void) {
  hm_bogie b;
  hm_bogie_default(&b);
  char why[160] = "";
  HM_CHECK(hm_bogie_validate(&b, why, sizeof why) == HM_OK, "defaults valid: %s", why);
  b.frame_mass_kg = -2600.0;
  HM_CHECK(hm_bogie_validate(&b, why, sizeof why) == HM_EDOMAIN, "negative frame mass");
  HM_CHECK(strcmp(why, "bogie.frame_mass_kg: must be > 0 (got -2600)") == 0, "message: %s", why);
  hm_bogie_default(&b);
  b.yaw_damper_stiffness_n_m = NAN;
  HM_CHECK(hm_bogie_validate(&b, why, sizeof why) == HM_EDOMAIN && strstr(why, "yaw_damper_stiffness_n_m"), "NaN");
  hm_bogie_default(&b);
  b.secondary_lat_damping_n_s_m = 0.0; /* allowed: no lateral damper */
  HM_CHECK(hm_bogie_validate(&b, why, sizeof why) == HM_OK, "zero lateral damping allowed");
  b.wheelset.mass_kg = 0.0;
  HM_CHECK(hm_bogie_validate(&b, why, sizeof why) == HM_EDOMAIN && strstr(why, "vehicle.mass_kg"), "wheelset: %s", why);
  hm_bogie_model m;
  hm_system sys;
  memset(&m, 0x33, sizeof m);
  HM_CHECK(hm_bogie_model_init(&m, &b, 0, &sys) == HM_EDOMAIN && ((unsigned char *)&m)[0] == 0x33, "untouched");
}

int main(void) {
  HM_RUN(held_frame_is_the_lone_wheelset);
  HM_RUN(jacobian_against_differences);
  HM_RUN(critical_speed_against_simulation);
  HM_RUN(bad_parameters);
  HM_TEST_EXIT();
}
