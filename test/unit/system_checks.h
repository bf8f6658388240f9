/* The tests' own checks of any model (system.h), used by test_bogie_model.c, test_car.c and test_system_cycles.c:
 * classic RK4 of the right-hand side (nothing of the core's integrators or shooting), the growth rate of the linear
 * motion it gives (and the critical speed against it), and the analytic Jacobian against central differences. Include after hm_test.h. */
#ifndef HM_TEST_SYSTEM_CHECKS_H
#define HM_TEST_SYSTEM_CHECKS_H

#include <string.h>

#include "hunting_monitor/linear.h"
#include "hunting_monitor/system.h"

/* One RK4 step of h from x (dim states) at speed v [m/s]. */
static inline void system_rk4_step(const hm_system *sys, double v, double *x, double h) {
  enum { N = HM_SYSTEM_MAX_DIM };
  const size_t n = sys->dim;
  double k1[N], k2[N], k3[N], k4[N], t[N];
  sys->rhs(sys->model, v, x, k1);
  for (size_t i = 0; i < n; ++i) t[i] = x[i] + 0.5 * h * k1[i];
  sys->rhs(sys->model, v, t, k2);
  for (size_t i = 0; i < n; ++i) t[i] = x[i] + 0.5 * h * k2[i];
  sys->rhs(sys->model, v, t, k3);
  for (size_t i = 0; i < n; ++i) t[i] = x[i] + h * k3[i];
  sys->rhs(sys->model, v, t, k4);
  for (size_t i = 0; i < n; ++i) x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
}

/* The growth rate [1/s] of the linearised motion at v: RK4 at 1 ms from a 1e-8 disturbance of every displacement
 * (far inside the linear range), settle_s for the other modes to die out, then the least-squares slope of ln of the
 * displacements' squares (1 s means) over span_s, renormalised as it goes (the log keeps the total). */
static inline double system_growth_rate(const hm_system *sys, double v, double settle_s, double span_s) {
  enum { N = HM_SYSTEM_MAX_DIM };
  const size_t n = sys->dim;
  int disp[N];
  double x[N];
  for (size_t i = 0; i < n; ++i) {
    disp[i] = sys->state_body[i] >= 0 && sys->state_inertia[i] == 0.0; /* a body's displacement */
    x[i] = disp[i] ? 1e-8 * (1.0 + 0.3 * (double)(i % 5)) * (i % 3 ? 1.0 : -1.0) : 0.0;
  }
  const double h = 1e-3;
  const long steps = (long)((settle_s + span_s) / h), per_block = 1000;
  double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0, acc = 0.0, scale = 0.0;
  int nb = 0;
  for (long s = 1; s <= steps; ++s) {
    system_rk4_step(sys, v, x, h);
    double nx = 0.0;
    for (size_t i = 0; i < n; ++i) nx += disp[i] ? fabs(x[i]) : 0.0;
    if (nx > 1e-6 || (nx < 1e-12 && nx > 0.0)) {
      for (size_t i = 0; i < n; ++i) x[i] /= nx / 1e-8;
      scale += log(nx / 1e-8);
    }
    if (s * h > settle_s) {
      for (size_t i = 0; i < n; ++i) acc += disp[i] ? x[i] * x[i] : 0.0;
      if (s % per_block == 0) {
        const double tc = (double)(s - per_block / 2) * h, y = log(acc / per_block) + 2.0 * scale;
        sx += tc, sy += y, sxx += tc * tc, sxy += tc * y;
        ++nb;
        acc = 0.0;
      }
    }
  }
  return 0.5 * (nb * sxy - sx * sy) / (nb * sxx - sx * sx); /* |x|^2 grows at twice the rate */
}

/* The critical speed by eigenvalues (hm_system_critical_speed's defaults) against the simulation's growth rate 0.1 km/h
 * either side (stable below, unstable above); the speed [m/s] and the spectrum there into *vc and *s. */
static inline void check_critical_against_simulation(const hm_system *sys, double *vc, hm_system_spectrum *s) {
  hm_system_critical_options opt;
  hm_system_critical_options_default(&opt);
  *vc = 0.0;
  const hm_status st = hm_system_critical_speed(sys, &opt, vc, s);
  HM_CHECK(st == HM_OK, "critical");
  if (st != HM_OK) return;
  printf("  critical %.4f km/h at %.4f Hz, the mode's energy %.3f / %.3f / %.3f in wheelsets / frames / carbody\n",
         hm_kmh_from_mps(*vc), s->frequency_hz, s->body_share[0], sys->n_bodies > 1 ? s->body_share[1] : 0.0,
         sys->n_bodies > 2 ? s->body_share[2] : 0.0);
  const double below = system_growth_rate(sys, *vc - hm_mps_from_kmh(0.1), 60.0, 240.0);
  const double above = system_growth_rate(sys, *vc + hm_mps_from_kmh(0.1), 60.0, 240.0);
  printf("  simulated growth rates 0.1 km/h below and above: %.6f, %.6f 1/s\n", below, above);
  HM_CHECK(below < 0.0 && above > 0.0, "the simulation's stability changes within 0.1 km/h of the critical speed");
}

/* The analytic Jacobian at (v, x) against central differences of the right-hand side (relative 1e-6, absolute 1e-3
 * where the entry is tiny). */
static inline void check_jacobian(const hm_system *sys, double v, const double *x_in, const char *what) {
  enum { N = HM_SYSTEM_MAX_DIM };
  const size_t n = sys->dim;
  double x[N], jac[N * N], fp[N], fm[N];
  memcpy(x, x_in, n * sizeof(double));
  HM_CHECK(sys->jacobian(sys->model, v, x, jac) == HM_OK, "%s: jacobian", what);
  for (size_t j = 0; j < n; ++j) {
    const double h = 1e-7 * fmax(1e-3, fabs(x[j])), xj = x[j];
    x[j] = xj + h;
    sys->rhs(sys->model, v, x, fp);
    x[j] = xj - h;
    sys->rhs(sys->model, v, x, fm);
    x[j] = xj;
    for (size_t i = 0; i < n; ++i) {
      const double fd = (fp[i] - fm[i]) / (2.0 * h);
      HM_CHECK(fabs(jac[n * i + j] - fd) <= 1e-6 * fabs(fd) + 1e-3, "%s: d f%zu / d x%zu = %.9g, differences %.9g",
               what, i, j, jac[n * i + j], fd);
    }
  }
}

#endif
