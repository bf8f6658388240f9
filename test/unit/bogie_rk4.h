/* Tests' own integrator of the bogie (test_bogie_model.c, test_system_cycles.c): one classic RK4 step of
 * hm_bogie_rhs without track input, nothing of the core's integrators or shooting. */
#ifndef HM_TEST_BOGIE_RK4_H
#define HM_TEST_BOGIE_RK4_H

#include "hunting_monitor/bogie.h"

static inline void bogie_rk4_step(const hm_bogie_model *m, double v_mps, double *x, double h) {
  enum { N = HM_BOGIE_DIM };
  double k1[N], k2[N], k3[N], k4[N], t[N];
  hm_bogie_rhs(m, v_mps, x, NULL, k1);
  for (int i = 0; i < N; ++i) t[i] = x[i] + 0.5 * h * k1[i];
  hm_bogie_rhs(m, v_mps, t, NULL, k2);
  for (int i = 0; i < N; ++i) t[i] = x[i] + 0.5 * h * k2[i];
  hm_bogie_rhs(m, v_mps, t, NULL, k3);
  for (int i = 0; i < N; ++i) t[i] = x[i] + h * k3[i];
  hm_bogie_rhs(m, v_mps, t, NULL, k4);
  for (int i = 0; i < N; ++i) x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
}

#endif
