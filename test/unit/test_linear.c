/* Linear stability: published numbers of MODEL.md section 6, and the closed forms against LAPACK. */
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/model.h"

static hm_vehicle vehicle_kx_ky(double kx_mn, double ky_mn) {
  hm_vehicle v;
  hm_vehicle_default(&v);
  v.stiffness_long_n_m = kx_mn * 1e6;
  v.stiffness_lat_n_m = ky_mn * 1e6;
  return v;
}

static double crit_kmh(double kx, double ky, double lambda) {
  hm_vehicle v = vehicle_kx_ky(kx, ky);
  double s = NAN;
  HM_CHECK(hm_linear_critical_speed(&v, lambda, &s) == HM_OK, "critical speed kx %g ky %g", kx, ky);
  return hm_kmh_from_mps(s);
}

/* MODEL.md section 6: lambda = 0.1271, Ky = 8.96, Kx swept; and Kx = 8.96, Ky swept. Tolerance 1e-3 km/h. */
static void published_critical_speeds_kx(void) {
  const double kx[] = {8.96, 6.96, 4.96, 2.96}, ref[] = {536.634923, 476.872437, 428.155705, 384.701298};
  for (int i = 0; i < 4; ++i) HM_CHECK_DELTA(crit_kmh(kx[i], 8.96, 0.1271), ref[i], 1e-3, "V0(Kx) [km/h]");
}

static void published_critical_speeds_ky(void) {
  const double ky[] = {2.96, 8.96, 14.96, 20.96}, ref[] = {554.296633, 536.634923, 565.303816, 635.487135};
  for (int i = 0; i < 4; ++i) HM_CHECK_DELTA(crit_kmh(8.96, ky[i], 0.1271), ref[i], 1e-3, "V0(Ky) [km/h]");
}

/* Hopf points of the nonlinear model (lambda(0) = 0.1358, Ky = 10.96) are the linear critical speeds. */
static void published_nonlinear_hopf_speeds(void) {
  const double kx[] = {9.1, 9.7, 9.9, 10.413634}, ref[] = {527.4349, 544.3795, 550.3513, 566.5220};
  for (int i = 0; i < 4; ++i) HM_CHECK_DELTA(crit_kmh(kx[i], 10.96, 0.1358), ref[i], 1e-3, "Hopf V [km/h]");
  /* MODEL.md section 7: default vehicle, Hopf at 517.618 km/h (3 decimals published). */
  HM_CHECK_DELTA(crit_kmh(8.96, 8.96, 0.1358), 517.618, 6e-4, "default Hopf V [km/h]");
}

/* Eigenvalues at Kx = Ky = 8.96, lambda = 0.1271, V0 = 536.634923: -61.5026 +- 90.8747i, 0 +- 89.7127i. */
static void published_eigenvalues(void) {
  hm_vehicle v = vehicle_kx_ky(8.96, 8.96);
  double re[4], im[4], omega;
  HM_CHECK(hm_linear_eigenvalues(&v, 0.1271, hm_mps_from_kmh(536.634923), re, im) == HM_OK, "dgeev");
  HM_CHECK_DELTA(re[0], 0.0, 1e-3, "Re of critical pair");
  HM_CHECK_DELTA(re[1], 0.0, 1e-3, "Re of critical pair");
  HM_CHECK_DELTA(im[0], 89.7127, 1e-3, "Im of critical pair");
  HM_CHECK_DELTA(im[1], -89.7127, 1e-3, "Im of critical pair");
  HM_CHECK_DELTA(re[2], -61.5026, 1e-3, "Re of damped pair");
  HM_CHECK_DELTA(re[3], -61.5026, 1e-3, "Re of damped pair");
  HM_CHECK_DELTA(im[2], 90.8747, 1e-3, "Im of damped pair");
  HM_CHECK_DELTA(im[3], -90.8747, 1e-3, "Im of damped pair");
  /* The closed-form Hopf frequency sqrt(A3/A1) against the published imaginary part. */
  HM_CHECK(hm_linear_hopf_omega(&v, &omega) == HM_OK, "omega");
  HM_CHECK_DELTA(omega, 89.7127, 1e-3, "Hopf omega [rad/s]");
}

/* A random valid vehicle: every parameter within a factor of about 2 of the defaults. */
static void random_vehicle(hm_vehicle *v, double *lambda) {
  hm_vehicle_default(v);
  v->mass_kg *= hm_test_uniform(0.5, 2.0);
  v->yaw_inertia_kg_m2 *= hm_test_uniform(0.5, 2.0);
  v->contact_half_distance_m *= hm_test_uniform(0.8, 1.2);
  v->spring_half_distance_m *= hm_test_uniform(0.7, 1.3);
  v->rolling_radius_m *= hm_test_uniform(0.8, 1.2);
  v->creep_long_n *= hm_test_uniform(0.3, 2.0);
  v->creep_lat_n *= hm_test_uniform(0.3, 2.0);
  v->spring_ratio = hm_test_uniform(1.0, 1.8);
  v->stiffness_long_n_m = hm_test_uniform(0.5e6, 25e6);
  v->stiffness_lat_n_m = hm_test_uniform(0.5e6, 25e6);
  *lambda = hm_test_uniform(0.02, 0.5);
}

/* Closed-form critical speed against eigenvalue bisection (dgeev only) on 1000 random parameter sets that
 * have one; the sets without one must be recognised as such by both methods. */
static void closed_form_matches_eigenvalue_bisection(void) {
  int compared = 0, no_crit = 0, i;
  double worst = 0.0;
  for (i = 0; compared < 1000 && i < 3000; ++i) {
    hm_vehicle v;
    double lambda, vc = NAN, ve = NAN;
    random_vehicle(&v, &lambda);
    const hm_status sc = hm_linear_critical_speed(&v, lambda, &vc);
    const hm_status se = hm_linear_critical_speed_eig(&v, lambda, 0.5, 1e5, 1e-9, &ve);
    HM_CHECK(sc == se, "set %d: closed form says %s, eigenvalues say %s", i, hm_status_str(sc), hm_status_str(se));
    if (sc == HM_OK && se == HM_OK) {
      const double rel = fabs(vc - ve) / ve;
      if (rel > worst) worst = rel;
      HM_CHECK(rel < 1e-8, "set %d: closed form %.12g m/s, bisection %.12g m/s", i, vc, ve);
      ++compared;
    } else {
      ++no_crit;
    }
  }
  printf("  %d random sets: %d critical speeds compared, %d without one (both methods agree), worst relative "
         "difference %.2e\n", i, compared, no_crit, worst);
  HM_CHECK(compared == 1000, "only %d sets with a critical speed", compared);
}

/* Critical conicity: the spectral abscissa (dgeev) is zero there and changes sign across it. */
static void critical_conicity_is_on_the_boundary(void) {
  int checked = 0;
  for (int i = 0; i < 200; ++i) {
    hm_vehicle v;
    double lambda, lc, s0, s_lo, s_hi;
    random_vehicle(&v, &lambda);
    const double speed = hm_test_uniform(50.0, 250.0);
    if (hm_linear_critical_conicity(&v, speed, &lc) != HM_OK) continue;
    ++checked;
    HM_CHECK(hm_linear_spectral_abscissa(&v, lc, speed, &s0) == HM_OK, "abscissa");
    HM_CHECK(hm_linear_spectral_abscissa(&v, lc * (1 - 1e-6), speed, &s_lo) == HM_OK, "abscissa");
    HM_CHECK(hm_linear_spectral_abscissa(&v, lc * (1 + 1e-6), speed, &s_hi) == HM_OK, "abscissa");
    HM_CHECK(fabs(s0) < 1e-7 * 100.0, "abscissa %g at critical conicity", s0);
    HM_CHECK(s_lo < 0.0 && s_hi > 0.0, "no sign change across lambda_c = %g: %g, %g", lc, s_lo, s_hi);
  }
  HM_CHECK(checked >= 100, "only %d of 200 random vehicles had a critical conicity to check", checked);
  /* and the published pair: at V0 = 536.634923 km/h (Kx = Ky = 8.96) the critical conicity is 0.1271. */
  hm_vehicle v = vehicle_kx_ky(8.96, 8.96);
  double lc;
  HM_CHECK(hm_linear_critical_conicity(&v, hm_mps_from_kmh(536.634923), &lc) == HM_OK, "lambda_c");
  HM_CHECK_DELTA(lc, 0.1271, 1e-8, "critical conicity at 536.634923 km/h");
}

/* Hurwitz Delta3 sign against eigenvalue stability at random points away from the boundary. */
static void hurwitz_sign_matches_eigenvalues(void) {
  for (int i = 0; i < 500; ++i) {
    hm_vehicle v;
    double lambda, d3, s;
    random_vehicle(&v, &lambda);
    const double speed = hm_test_uniform(20.0, 300.0);
    HM_CHECK(hm_linear_hurwitz_delta3(&v, lambda, speed, &d3) == HM_OK, "delta3");
    HM_CHECK(hm_linear_spectral_abscissa(&v, lambda, speed, &s) == HM_OK, "abscissa");
    if (fabs(s) > 1e-6) HM_CHECK((d3 > 0.0) == (s < 0.0), "Delta3 %g but abscissa %g", d3, s);
  }
}

/* At the closed-form critical speed the critical pair's frequency is the closed-form Hopf frequency. */
static void hopf_frequency_matches_eigenvalues(void) {
  int checked = 0;
  for (int i = 0; i < 100; ++i) {
    hm_vehicle v;
    double lambda, vc, omega, re[4], im[4];
    random_vehicle(&v, &lambda);
    if (hm_linear_critical_speed(&v, lambda, &vc) != HM_OK) continue;
    ++checked;
    HM_CHECK(hm_linear_hopf_omega(&v, &omega) == HM_OK, "omega");
    HM_CHECK(hm_linear_eigenvalues(&v, lambda, vc, re, im) == HM_OK, "dgeev");
    HM_CHECK_REL(fabs(im[0]), omega, 1e-7, "Im of the critical pair vs sqrt(A3/A1)");
  }
  HM_CHECK(checked >= 50, "only %d of 100 random vehicles had a critical speed to check", checked);
}

/* Bad input: clear status, outputs untouched. */
static void bad_inputs_are_rejected(void) {
  hm_vehicle v;
  hm_vehicle_default(&v);
  double out = 42.0, re[4] = {1, 2, 3, 4}, im[4] = {5, 6, 7, 8};
  HM_CHECK(hm_linear_critical_speed(&v, -0.1, &out) == HM_EDOMAIN, "negative conicity");
  HM_CHECK(hm_linear_critical_speed(&v, NAN, &out) == HM_EDOMAIN, "NaN conicity");
  HM_CHECK(hm_linear_critical_conicity(&v, 0.0, &out) == HM_EDOMAIN, "zero speed");
  HM_CHECK(hm_linear_critical_conicity(&v, NAN, &out) == HM_EDOMAIN, "NaN speed");
  HM_CHECK(hm_linear_eigenvalues(&v, 0.1, -5.0, re, im) == HM_EDOMAIN, "negative speed");
  HM_CHECK(hm_linear_critical_speed(NULL, 0.1, &out) == HM_EINVAL, "NULL vehicle");
  v.mass_kg = -1.0;
  HM_CHECK(hm_linear_critical_speed(&v, 0.1, &out) == HM_EDOMAIN, "negative mass");
  HM_CHECK(out == 42.0, "output changed on failure");
  HM_CHECK(re[0] == 1 && im[3] == 8, "eigenvalues changed on failure");
  hm_vehicle_default(&v);
  HM_CHECK(hm_linear_critical_speed(&v, 0.0, &out) == HM_ENOCRIT, "zero conicity has no critical speed");
}

int main(void) {
  HM_RUN(published_critical_speeds_kx);
  HM_RUN(published_critical_speeds_ky);
  HM_RUN(published_nonlinear_hopf_speeds);
  HM_RUN(published_eigenvalues);
  HM_RUN(closed_form_matches_eigenvalue_bisection);
  HM_RUN(critical_conicity_is_on_the_boundary);
  HM_RUN(hurwitz_sign_matches_eigenvalues);
  HM_RUN(hopf_frequency_matches_eigenvalues);
  HM_RUN(bad_inputs_are_rejected);
  HM_TEST_EXIT();
}
