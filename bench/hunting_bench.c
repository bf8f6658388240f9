/* hunting_bench: throughput and wall-time figures of the C core, printed as JSON (not a test). */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <time.h>

#include "hunting_monitor/integrate.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/model.h"

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

int main(void) {
  hm_vehicle veh;
  hm_vehicle_default(&veh);
  volatile double sink = 0.0;

  /* Closed-form critical speeds over a sweep of conicities. */
  const long n_closed = 20000000;
  double t0 = now_s();
  for (long i = 0; i < n_closed; ++i) {
    double v;
    if (hm_linear_critical_speed(&veh, 0.05 + 1e-8 * (double)(i & 0xffff), &v) == HM_OK) sink += v;
  }
  const double closed_per_s = (double)n_closed / (now_s() - t0);

  /* Eigenvalue-based critical speeds: bisection on dgeev's spectral abscissa to 1e-6 m/s. */
  const long n_eig = 300;
  t0 = now_s();
  for (long i = 0; i < n_eig; ++i) {
    double v;
    if (hm_linear_critical_speed_eig(&veh, 0.05 + 1e-4 * (double)i, 1.0, 1e4, 1e-6, &v) == HM_OK) sink += v;
  }
  const double eig_per_s = (double)n_eig / (now_s() - t0);

  /* Right-hand-side evaluations of the nonlinear model. */
  hm_model model;
  hm_model_init(&model, &veh, hm_mps_from_kmh(543.0));
  const long n_rhs = 20000000;
  double x[4] = {0.004, 0.01, 0.001, 0.02}, f[4];
  t0 = now_s();
  for (long i = 0; i < n_rhs; ++i) {
    x[0] = 0.004 + 1e-12 * (double)(i & 0xff);
    hm_model_rhs(0.0, x, f, &model);
    sink += f[1];
  }
  const double rhs_per_s = (double)n_rhs / (now_s() - t0);

  /* 100 s of model time at 543 km/h, rtol 1e-9 (atol 1e-12), from MODEL.md's x0 (0.001, 0.001, 0.006, 0.06). */
  hm_dopri integ = hm_dopri_create(4);
  const hm_ode_system sys = {4, hm_model_rhs, hm_model_jacobian, &model};
  const hm_dopri_options opt = {1e-9, 1e-12, 0.0, 0.0, 0};
  double xs[4] = {0.001, 0.001, 0.006, 0.06};
  hm_dopri_stats stats = {0, 0, 0};
  t0 = now_s();
  const hm_status st = hm_dopri_integrate(integ, &sys, &opt, 0.0, 100.0, xs, NULL, NULL, NULL, &stats);
  const double sim_s = now_s() - t0;
  hm_dopri_destroy(integ);

  printf("{\n");
  printf("  \"closed_form_critical_speeds_per_s\": %.4g,\n", closed_per_s);
  printf("  \"eigenvalue_bisection_critical_speeds_per_s\": %.4g,\n", eig_per_s);
  printf("  \"closed_form_speedup_over_eigenvalues\": %.4g,\n", closed_per_s / eig_per_s);
  printf("  \"rhs_evaluations_per_s\": %.4g,\n", rhs_per_s);
  printf("  \"simulate_100s_at_543kmh_rtol1e-9_wall_s\": %.4g,\n", sim_s);
  printf("  \"simulate_status\": \"%s\",\n", hm_status_str(st));
  printf("  \"simulate_steps\": %zu,\n", stats.n_accepted + stats.n_rejected);
  printf("  \"simulate_rhs_evaluations\": %zu\n", stats.n_rhs);
  printf("}\n");
  return sink == 12345.678 ? 1 : 0;
}
