/* car.h: the whole vehicle of issue #28. Checked against the bogie (the carbody held: its eigenvalues each twice and
 * its critical speed), its analytic Jacobian against central differences of its right-hand side, and its critical
 * speed by eigenvalues against the growth rate of a time simulation (the tests' own RK4 of the right-hand side) on
 * both sides of it (the wheelsets' mode of the default car). And a carbody mode: without secondary lateral damping
 * at conicity 0.03 the carbody's sway on its air springs (the closed form sqrt(2 Ksy / mc) / 2 pi) is the mode that
 * crosses, if only just (its real part moves by about 1e-5 1/s per km/h there: no carbody hunting of practical
 * growth without the carbody's roll, which this model leaves out). */
#include <string.h>

#include "hm_test.h"
#include "system_checks.h"
#include "hunting_monitor/car.h"
#include "hunting_monitor/linear.h"

static void car_at(double lambda0, double csy, int held, hm_car_model *m, hm_system *sys) {
  hm_car c;
  hm_car_default(&c);
  c.bogie.secondary_lat_damping_n_s_m = csy;
  HM_CHECK(hm_vehicle_set_conicity_at_zero(&c.bogie.wheelset, lambda0) == HM_OK, "conicity");
  HM_CHECK(hm_car_model_init(m, &c, held, sys) == HM_OK, "init");
}

static void held_carbody_is_two_bogies(void) {
  hm_car_model m;
  hm_system sys, bsys;
  car_at(0.1358, 30e3, 1, &m, &sys);
  hm_bogie_model bm;
  HM_CHECK(hm_bogie_model_init(&bm, &m.car.bogie, 0, &bsys) == HM_OK, "bogie");
  HM_CHECK(sys.dim == HM_CAR_HELD_DIM, "dimension");
  const double speeds[] = {300.0, 540.0};
  for (int k = 0; k < 2; ++k) {
    hm_system_spectrum s, b;
    const double v = hm_mps_from_kmh(speeds[k]);
    HM_CHECK(hm_system_spectrum_at(&sys, v, &s) == HM_OK && hm_system_spectrum_at(&bsys, v, &b) == HM_OK, "spectra");
    int used[HM_BOGIE_DIM] = {0};
    for (size_t i = 0; i < s.dim; ++i) {
      size_t best = 0;
      double d_best = INFINITY;
      for (size_t q = 0; q < b.dim; ++q) {
        const double d = hypot(s.re[i] - b.re[q], s.im[i] - b.im[q]);
        if (d < d_best) d_best = d, best = q;
      }
      used[best]++;
      HM_CHECK(d_best <= 1e-8 * hypot(b.re[best], b.im[best]), "eigenvalue %zu off by %.3g", i, d_best);
    }
    for (size_t q = 0; q < b.dim; ++q) HM_CHECK(used[q] == 2, "bogie eigenvalue %zu found %d times", q, used[q]);
  }
  hm_system_critical_options opt;
  hm_system_critical_options_default(&opt);
  double vc = 0.0, vb = 0.0;
  HM_CHECK(hm_system_critical_speed(&sys, &opt, &vc, NULL) == HM_OK, "car held");
  HM_CHECK(hm_system_critical_speed(&bsys, &opt, &vb, NULL) == HM_OK, "bogie");
  HM_CHECK_REL(vc, vb, 1e-9, "the held carbody's critical speed is the bogie's");
}

static void jacobian_against_differences(void) {
  for (int held = 0; held <= 1; ++held) {
    hm_car_model m;
    hm_system sys;
    car_at(0.1358, 30e3, held, &m, &sys);
    double x[HM_CAR_DIM];
    for (size_t i = 0; i < HM_CAR_DIM; ++i) { /* in the nonlinear range: 2-6 mm, 0.02-0.06 m/s, the dampers 0.2 mm */
      const size_t k = i < 26 ? i % 13 : i - 26;
      x[i] = (k == 12 ? 2e-4 : k % 2 ? 0.02 : 0.002) * (i % 3 ? 1.0 : -0.7) * (1.0 + 0.07 * (double)i);
    }
    check_jacobian(&sys, hm_mps_from_kmh(380.0), x, held ? "carbody held" : "carbody free");
  }
}

static void critical_speed_against_simulation(void) {
  hm_car_model m;
  hm_system sys;
  car_at(0.1358, 30e3, 0, &m, &sys);
  hm_system_critical_options opt;
  hm_system_critical_options_default(&opt);
  double vc = 0.0;
  hm_system_spectrum s;
  HM_CHECK(hm_system_critical_speed(&sys, &opt, &vc, &s) == HM_OK, "critical");
  printf("  critical %.4f km/h at %.3f Hz, the mode's energy %.2f / %.2f / %.2f in wheelsets / frames / carbody\n",
         hm_kmh_from_mps(vc), s.frequency_hz, s.body_share[0], s.body_share[1], s.body_share[2]);
  HM_CHECK(s.dominant_body == 0, "the wheelsets' mode");
  const double below = system_growth_rate(&sys, vc - hm_mps_from_kmh(0.1), 60.0, 240.0);
  const double above = system_growth_rate(&sys, vc + hm_mps_from_kmh(0.1), 60.0, 240.0);
  printf("  simulated growth rates 0.1 km/h below and above: %.6f, %.6f 1/s\n", below, above);
  HM_CHECK(below < 0.0 && above > 0.0, "the simulation's stability changes within 0.1 km/h of the critical speed");
}

static void carbody_mode(void) {
  hm_car_model m;
  hm_system sys;
  car_at(0.03, 0.0, 0, &m, &sys);
  hm_system_critical_options opt;
  hm_system_critical_options_default(&opt);
  double vc = 0.0;
  hm_system_spectrum s;
  HM_CHECK(hm_system_critical_speed(&sys, &opt, &vc, &s) == HM_OK, "critical");
  printf("  conicity 0.03, no lateral damper: critical %.2f km/h at %.3f Hz, the mode's energy %.3f in the carbody\n",
         hm_kmh_from_mps(vc), s.frequency_hz, s.body_share[2]);
  HM_CHECK(s.dominant_body == 2 && s.body_share[2] > 0.99, "the carbody's mode");
  const double f_sway = sqrt(2.0 * m.car.bogie.secondary_lat_stiffness_n_m / m.car.carbody_mass_kg) / (2.0 * HM_PI);
  HM_CHECK_DELTA(s.frequency_hz, f_sway, 0.03 * f_sway, "at the carbody's sway frequency on the air springs");
}

static void bad_parameters(void) {
  hm_car c;
  hm_car_default(&c);
  char why[160] = "";
  HM_CHECK(hm_car_validate(&c, why, sizeof why) == HM_OK, "defaults: %s", why);
  c.carbody_mass_kg = -1.0;
  HM_CHECK(hm_car_validate(&c, why, sizeof why) == HM_EDOMAIN &&
               strcmp(why, "car.carbody_mass_kg: must be > 0 (got -1)") == 0, "message: %s", why);
  hm_car_default(&c);
  c.bogie.frame_mass_kg = NAN;
  HM_CHECK(hm_car_validate(&c, why, sizeof why) == HM_EDOMAIN && strstr(why, "bogie.frame_mass_kg"), "%s", why);
}

int main(void) {
  HM_RUN(held_carbody_is_two_bogies);
  HM_RUN(jacobian_against_differences);
  HM_RUN(critical_speed_against_simulation);
  HM_RUN(carbody_mode);
  HM_RUN(bad_parameters);
  HM_TEST_EXIT();
}
