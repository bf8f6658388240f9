/* system.h: a model of any dimension, its spectrum and linear critical speed, checked on MODEL.md's wheelset against
 * the closed forms of linear.h (the Hurwitz criterion) and MODEL.md's published 517.618 km/h. */
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/system.h"

/* The wheelset through the generic path: the same eigenvalues as linear.h's (its own 4x4 matrix) to 1e-9. */
static void wheelset_eigenvalues_as_linear_h(void) {
  hm_vehicle veh;
  hm_vehicle_default(&veh);
  hm_wheelset_system ws;
  hm_system sys;
  HM_CHECK(hm_wheelset_system_init(&ws, &veh, &sys) == HM_OK, "init");
  const double speeds_kmh[] = {150.0, 400.0, 517.618, 700.0};
  for (int k = 0; k < 4; ++k) {
    const double v = hm_mps_from_kmh(speeds_kmh[k]);
    hm_system_spectrum s;
    double re[4], im[4];
    HM_CHECK(hm_system_spectrum_at(&sys, v, &s) == HM_OK, "spectrum");
    HM_CHECK(hm_linear_eigenvalues(&veh, 0.1358, v, re, im) == HM_OK, "linear.h");
    HM_CHECK(s.dim == 4, "dim %zu", s.dim);
    for (int i = 0; i < 4; ++i) {
      const double scale = hypot(re[i], im[i]);
      HM_CHECK_DELTA(s.re[i], re[i], 1e-9 * scale, "re");
      HM_CHECK_DELTA(s.im[i], im[i], 1e-9 * scale, "im");
    }
    HM_CHECK_DELTA(s.body_share[0], 1.0, 1e-12, "one body holds all the energy");
  }
}

/* The critical speed by eigenvalue bisection against the closed form of the Hurwitz determinant (linear.h) and the
 * published 517.618 km/h at 14.28 Hz (MODEL.md section 6), over conicities. */
static void wheelset_critical_speed_as_closed_form(void) {
  hm_system_critical_options opt;
  hm_system_critical_options_default(&opt);
  const double lambdas[] = {0.08, 0.12, 0.1358, 0.2, 0.3};
  for (int k = 0; k < 5; ++k) {
    hm_vehicle veh;
    hm_vehicle_default(&veh);
    HM_CHECK(hm_vehicle_set_conicity_at_zero(&veh, lambdas[k]) == HM_OK, "conicity");
    hm_wheelset_system ws;
    hm_system sys;
    HM_CHECK(hm_wheelset_system_init(&ws, &veh, &sys) == HM_OK, "init");
    double v = 0.0, v_closed = 0.0, omega = 0.0;
    hm_system_spectrum s;
    HM_CHECK(hm_system_critical_speed(&sys, &opt, &v, &s) == HM_OK, "critical at %g", lambdas[k]);
    HM_CHECK(hm_linear_critical_speed(&veh, lambdas[k], &v_closed) == HM_OK, "closed form");
    HM_CHECK(hm_linear_hopf_omega(&veh, &omega) == HM_OK, "omega");
    HM_CHECK_REL(v, v_closed, 1e-9, "critical speed against the closed form");
    HM_CHECK_REL(s.frequency_hz, omega / (2.0 * HM_PI), 1e-6, "frequency at the crossing");
    HM_CHECK_DELTA(s.abscissa_1_s, 0.0, 1e-6, "real part at the crossing");
    if (lambdas[k] == 0.1358) {
      HM_CHECK_DELTA(hm_kmh_from_mps(v), 517.618, 0.0005, "MODEL.md's published critical speed");
      HM_CHECK_DELTA(s.frequency_hz, 14.28, 0.005, "MODEL.md's published frequency");
    }
  }
}

/* Where there is no crossing in the range, and bad input: a status, outputs untouched. */
static void no_crossing_and_bad_input(void) {
  hm_vehicle veh;
  hm_vehicle_default(&veh);
  hm_wheelset_system ws;
  hm_system sys;
  HM_CHECK(hm_wheelset_system_init(&ws, &veh, &sys) == HM_OK, "init");
  hm_system_critical_options opt;
  hm_system_critical_options_default(&opt);
  double v = -1.0;
  opt.v_max_mps = hm_mps_from_kmh(500.0); /* below 517.6: stable throughout */
  HM_CHECK(hm_system_critical_speed(&sys, &opt, &v, NULL) == HM_ENOCRIT && v == -1.0, "stable throughout");
  opt.v_min_mps = hm_mps_from_kmh(530.0), opt.v_max_mps = hm_mps_from_kmh(900.0); /* unstable from the start */
  HM_CHECK(hm_system_critical_speed(&sys, &opt, &v, NULL) == HM_ENOCRIT && v == -1.0, "unstable throughout");
  opt.tol_mps = NAN;
  HM_CHECK(hm_system_critical_speed(&sys, &opt, &v, NULL) == HM_EINVAL && v == -1.0, "NaN tolerance");
  hm_system_spectrum s;
  memset(&s, 0x5a, sizeof s);
  const unsigned char before = ((unsigned char *)&s)[0];
  HM_CHECK(hm_system_spectrum_at(&sys, -3.0, &s) == HM_EDOMAIN && ((unsigned char *)&s)[0] == before, "v < 0");
  HM_CHECK(hm_system_spectrum_at(&sys, NAN, &s) == HM_EDOMAIN, "v NaN");
  hm_system bad = sys;
  bad.dim = HM_SYSTEM_MAX_DIM + 1;
  HM_CHECK(hm_system_validate(&bad) == HM_EINVAL, "dimension beyond the maximum");
  bad = sys;
  bad.jacobian = NULL;
  HM_CHECK(hm_system_spectrum_at(&bad, 100.0, &s) == HM_EINVAL, "no Jacobian");
  veh.mass_kg = -1.0;
  HM_CHECK(hm_wheelset_system_init(&ws, &veh, &sys) == HM_EDOMAIN, "negative mass");
}

int main(void) {
  HM_RUN(wheelset_eigenvalues_as_linear_h);
  HM_RUN(wheelset_critical_speed_as_closed_form);
  HM_RUN(no_crossing_and_bad_input);
  HM_TEST_EXIT();
}
