/* Lyapunov spectra against closed forms: the linear model's eigenvalues and its trace, and Lorenz. */
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/lyapunov.h"
#include "hunting_monitor/model.h"

/* The linear model's Lyapunov spectrum equals the real parts of its eigenvalues (dgeev); the sum equals the
 * trace of the Jacobian -(c_lat + c_yaw)/v (Liouville) - both methods. */
static void linear_spectrum_is_eigenvalue_real_parts(void) {
  const double speeds_kmh[] = {400.0, 540.0};
  const double conicities[] = {0.22, 0.1271};
  for (int c = 0; c < 2; ++c) {
    for (int method = 0; method < 2; ++method) {
      hm_vehicle v, lin;
      hm_vehicle_default(&v);
      hm_vehicle_set_conicity_at_zero(&v, conicities[c]);
      hm_vehicle_linearized(&v, &lin);
      hm_model m;
      HM_CHECK(hm_model_init(&m, &lin, hm_mps_from_kmh(speeds_kmh[c])) == HM_OK, "init");
      const hm_ode_system sys = {4, hm_model_rhs, hm_model_jacobian, &m};
      hm_lyap_options opt;
      hm_lyap_options_default(&opt);
      opt.method = method ? HM_LYAP_DOPRI : HM_LYAP_MIDPOINT;
      opt.duration_s = 400.0;
      opt.step_s = 2e-4;
      const double x0[4] = {0.0, 0.0, 0.0, 0.0};
      double ex[4], re[4], im[4];
      HM_CHECK(hm_lyapunov_spectrum(&sys, 0.0, x0, 4, &opt, ex, NULL) == HM_OK, "spectrum");
      HM_CHECK(hm_linear_eigenvalues(&v, conicities[c], m.speed_mps, re, im) == HM_OK, "eig");
      printf("  %s V=%g lambda=%g: exponents %.4f %.4f %.4f %.4f, Re(eig) %.4f %.4f %.4f %.4f\n",
             method ? "dopri" : "midpoint", speeds_kmh[c], conicities[c], ex[0], ex[1], ex[2], ex[3], re[0], re[1],
             re[2], re[3]);
      for (int i = 0; i < 4; ++i) HM_CHECK_DELTA(ex[i], re[i], 0.02, "exponent vs Re(eigenvalue)");
      const double trace = -(m.coef.c_lat_m_s2 + m.coef.c_yaw_m_s2) / m.speed_mps;
      HM_CHECK_DELTA(ex[0] + ex[1] + ex[2] + ex[3], trace, 1e-3 * fabs(trace), "sum of exponents vs trace");
    }
  }
}

/* Lorenz (sigma 10, rho 28, beta 8/3): published exponents about 0.9056, 0, -14.5723 (Sprott, Chaos and
 * Time-Series Analysis, 2003); their sum is exactly -(sigma + 1 + beta) = -13.6667. */
static hm_status lorenz_rhs(double t, const double *x, double *f, void *p) {
  (void)t;
  (void)p;
  f[0] = 10.0 * (x[1] - x[0]);
  f[1] = x[0] * (28.0 - x[2]) - x[1];
  f[2] = x[0] * x[1] - 8.0 / 3.0 * x[2];
  return HM_OK;
}
static hm_status lorenz_jac(double t, const double *x, double *J, void *p) {
  (void)t;
  (void)p;
  const double j[9] = {-10.0, 10.0, 0.0, 28.0 - x[2], -1.0, -x[0], x[1], x[0], -8.0 / 3.0};
  memcpy(J, j, sizeof j);
  return HM_OK;
}

static void lorenz_spectrum(void) {
  const hm_ode_system sys = {3, lorenz_rhs, lorenz_jac, NULL};
  hm_lyap_options opt;
  hm_lyap_options_default(&opt);
  opt.method = HM_LYAP_DOPRI;
  opt.rtol = 1e-8;
  opt.atol = 1e-10;
  opt.renorm_interval_s = 0.5;
  opt.transient_s = 20.0;
  opt.duration_s = 1000.0;
  const double x0[3] = {1.0, 1.0, 20.0};
  double ex[3];
  HM_CHECK(hm_lyapunov_spectrum(&sys, 0.0, x0, 3, &opt, ex, NULL) == HM_OK, "spectrum");
  printf("  Lorenz exponents %.4f %.4f %.4f\n", ex[0], ex[1], ex[2]);
  HM_CHECK_DELTA(ex[0], 0.9056, 0.03, "largest Lorenz exponent");
  HM_CHECK_DELTA(ex[1], 0.0, 0.01, "zero Lorenz exponent");
  HM_CHECK_DELTA(ex[2], -14.5723, 0.03, "smallest Lorenz exponent");
  HM_CHECK_DELTA(ex[0] + ex[1] + ex[2], -(10.0 + 1.0 + 8.0 / 3.0), 1e-3, "sum = trace");
  /* The largest exponent alone (one tangent vector; the step sequence and so the chaotic trajectory differ). */
  double ex1;
  HM_CHECK(hm_lyapunov_spectrum(&sys, 0.0, x0, 1, &opt, &ex1, NULL) == HM_OK, "largest");
  printf("  Lorenz largest exponent alone %.4f\n", ex1);
  HM_CHECK_DELTA(ex1, 0.9056, 0.03, "largest Lorenz exponent, one tangent vector");
}

static void bad_options_are_rejected(void) {
  const hm_ode_system sys = {3, lorenz_rhs, lorenz_jac, NULL};
  hm_lyap_options opt;
  hm_lyap_options_default(&opt);
  const double x0[3] = {1.0, 1.0, 20.0};
  double ex[3] = {7, 7, 7};
  opt.duration_s = -1.0;
  HM_CHECK(hm_lyapunov_spectrum(&sys, 0.0, x0, 3, &opt, ex, NULL) == HM_EINVAL, "negative duration");
  hm_lyap_options_default(&opt);
  opt.step_s = 0.1; /* longer than the renormalisation interval */
  HM_CHECK(hm_lyapunov_spectrum(&sys, 0.0, x0, 3, &opt, ex, NULL) == HM_EINVAL, "step > interval");
  hm_lyap_options_default(&opt);
  HM_CHECK(hm_lyapunov_spectrum(&sys, 0.0, x0, 4, &opt, ex, NULL) == HM_EINVAL, "more exponents than states");
  const hm_ode_system nojac = {3, lorenz_rhs, NULL, NULL};
  HM_CHECK(hm_lyapunov_spectrum(&nojac, 0.0, x0, 3, &opt, ex, NULL) == HM_EINVAL, "no Jacobian");
  HM_CHECK(ex[0] == 7 && ex[2] == 7, "outputs changed on failure");
}

int main(void) {
  HM_RUN(linear_spectrum_is_eigenvalue_real_parts);
  HM_RUN(lorenz_spectrum);
  HM_RUN(bad_options_are_rejected);
  HM_TEST_EXIT();
}
