/* Integrators: measured convergence order on problems with known solutions, dense output, tangent maps. */
#include <stdlib.h>
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/integrate.h"
#include "hunting_monitor/model.h"

/* x' = [x1, -x0]: x(t) = [cos t, -sin t] from [1, 0]. */
static hm_status osc_rhs(double t, const double *x, double *f, void *p) {
  (void)t;
  (void)p;
  f[0] = x[1];
  f[1] = -x[0];
  return HM_OK;
}
static hm_status osc_jac(double t, const double *x, double *J, void *p) {
  (void)t;
  (void)x;
  (void)p;
  J[0] = 0;
  J[1] = 1;
  J[2] = -1;
  J[3] = 0;
  return HM_OK;
}

/* Non-autonomous, nonlinear: y' = y cos t, y(t) = exp(sin t) from y(0) = 1. */
static hm_status expsin_rhs(double t, const double *x, double *f, void *p) {
  (void)p;
  f[0] = x[0] * cos(t);
  return HM_OK;
}
static hm_status expsin_jac(double t, const double *x, double *J, void *p) {
  (void)x;
  (void)p;
  J[0] = cos(t);
  return HM_OK;
}

/* Global error at T of Dormand-Prince with a fixed step h (tolerances so loose every step is accepted). */
static double dopri_fixed_step_error(const hm_ode_system *sys, double T, double h, const double *x0,
                                     double (*exact)(double, int)) {
  hm_dopri d = hm_dopri_create(sys->dim);
  double x[2];
  memcpy(x, x0, sys->dim * sizeof(double));
  const hm_dopri_options opt = {1e10, 1e10, h, h, 0, 0};
  hm_dopri_stats st;
  HM_CHECK(hm_dopri_integrate(d, sys, &opt, 0.0, T, x, NULL, NULL, NULL, &st) == HM_OK, "integrate");
  HM_CHECK(st.n_rejected == 0, "fixed-step run rejected %zu steps", st.n_rejected);
  hm_dopri_destroy(d);
  double err = 0.0;
  for (size_t i = 0; i < sys->dim; ++i) err = fmax(err, fabs(x[i] - exact(T, (int)i)));
  return err;
}

static double osc_exact(double t, int i) { return i == 0 ? cos(t) : -sin(t); }
static double expsin_exact(double t, int i) {
  (void)i;
  return exp(sin(t));
}

/* Order p from errors at h and h/2: log2(e(h)/e(h/2)). Dormand-Prince 5(4) propagates the 5th-order solution. */
static void dopri_convergence_order_is_five(void) {
  const hm_ode_system osc = {2, osc_rhs, osc_jac, NULL}, es = {1, expsin_rhs, expsin_jac, NULL};
  const double x_osc[2] = {1.0, 0.0}, x_es[1] = {1.0};
  const double hs[] = {0.2, 0.1, 0.05};
  double e_osc[3], e_es[3];
  for (int i = 0; i < 3; ++i) {
    e_osc[i] = dopri_fixed_step_error(&osc, 10.0, hs[i], x_osc, osc_exact);
    e_es[i] = dopri_fixed_step_error(&es, 10.0, hs[i], x_es, expsin_exact);
  }
  for (int i = 0; i < 2; ++i) {
    const double p_osc = log2(e_osc[i] / e_osc[i + 1]), p_es = log2(e_es[i] / e_es[i + 1]);
    printf("  dopri order: oscillator %.3f, exp(sin t) %.3f\n", p_osc, p_es);
    HM_CHECK(p_osc > 4.7 && p_osc < 5.5, "oscillator order %g", p_osc);
    HM_CHECK(p_es > 4.7 && p_es < 5.5, "exp(sin t) order %g", p_es);
  }
}

/* Adaptive run: 100 periods of the oscillator at rtol 1e-10 stays accurate; the error shrinks with tol. */
static void dopri_error_control_tracks_tolerance(void) {
  const hm_ode_system osc = {2, osc_rhs, NULL, NULL};
  hm_dopri d = hm_dopri_create(2);
  const double T = 200.0 * HM_PI;
  double errs[3];
  const double tols[] = {1e-6, 1e-8, 1e-10};
  for (int i = 0; i < 3; ++i) {
    double x[2] = {1.0, 0.0};
    const hm_dopri_options opt = {tols[i], tols[i], 0.0, 0.0, 0, 0};
    HM_CHECK(hm_dopri_integrate(d, &osc, &opt, 0.0, T, x, NULL, NULL, NULL, NULL) == HM_OK, "integrate");
    errs[i] = fmax(fabs(x[0] - cos(T)), fabs(x[1] + sin(T)));
  }
  printf("  adaptive errors over 100 periods: %.2e %.2e %.2e\n", errs[0], errs[1], errs[2]);
  HM_CHECK(errs[2] < 1e-7, "rtol 1e-10 error %g", errs[2]);
  HM_CHECK(errs[0] > errs[1] && errs[1] > errs[2], "error does not decrease with tolerance");
  hm_dopri_destroy(d);
}

typedef struct {
  double worst;
  int calls;
} dense_ctx;

static int dense_observer(hm_dopri integ, double t_old, double t_new, const double *x_new, void *ctx) {
  dense_ctx *c = (dense_ctx *)ctx;
  (void)x_new;
  for (int k = 1; k < 4; ++k) {
    const double t = t_old + (t_new - t_old) * k / 4.0;
    double x[2];
    if (hm_dopri_dense(integ, t, x) != HM_OK) c->worst = INFINITY;
    c->worst = fmax(c->worst, fmax(fabs(x[0] - cos(t)), fabs(x[1] + sin(t))));
  }
  c->calls++;
  return 0;
}

static int stop_after_three(hm_dopri integ, double t_old, double t_new, const double *x_new, void *ctx) {
  (void)integ;
  (void)t_old;
  (void)t_new;
  (void)x_new;
  return ++*(int *)ctx >= 3;
}

/* Dense output inside steps is accurate (4th-order interpolant) and an observer can stop the run. */
static void dopri_dense_output_and_observer(void) {
  const hm_ode_system osc = {2, osc_rhs, NULL, NULL};
  hm_dopri d = hm_dopri_create(2);
  double x[2] = {1.0, 0.0}, t_end;
  const hm_dopri_options opt = {1e-9, 1e-9, 0.0, 0.0, 0, 0};
  dense_ctx c = {0.0, 0};
  HM_CHECK(hm_dopri_integrate(d, &osc, &opt, 0.0, 20.0, x, &t_end, dense_observer, &c, NULL) == HM_OK, "run");
  printf("  dense output worst error %.2e over %d steps\n", c.worst, c.calls);
  HM_CHECK(c.worst < 1e-7, "dense output error %g", c.worst);
  HM_CHECK(t_end == 20.0, "t_end %g", t_end);
  int count = 0;
  double y[2] = {1.0, 0.0};
  HM_CHECK(hm_dopri_integrate(d, &osc, &opt, 0.0, 20.0, y, &t_end, stop_after_three, &count, NULL) == HM_OK, "stop");
  HM_CHECK(count == 3 && t_end < 20.0, "observer stop: %d calls, t_end %g", count, t_end);
  HM_CHECK_DELTA(y[0], cos(t_end), 1e-8, "state at early stop");
  hm_dopri_destroy(d);
}

/* ---- DOP853 ---- */

static double dop853_fixed_step_error(const hm_ode_system *sys, double T, double h, const double *x0,
                                      double (*exact)(double, int)) {
  hm_dop853 d = hm_dop853_create(sys->dim);
  double x[2];
  memcpy(x, x0, sys->dim * sizeof(double));
  const hm_dopri_options opt = {1e10, 1e10, h, h, 0, 0};
  hm_dopri_stats st;
  HM_CHECK(hm_dop853_integrate(d, sys, &opt, 0.0, T, x, NULL, NULL, &st) == HM_OK, "integrate");
  HM_CHECK(st.n_rejected == 0 && st.n_rhs == 12 * st.n_accepted + 1, "fixed-step run: %zu rejected, %zu rhs",
           st.n_rejected, st.n_rhs);
  hm_dop853_destroy(d);
  double err = 0.0;
  for (size_t i = 0; i < sys->dim; ++i) err = fmax(err, fabs(x[i] - exact(T, (int)i)));
  return err;
}

/* Order 8 from errors at h and h/2 on the oscillator and on x' = x cos t (x = exp(sin t)); a wrong coefficient in
 * the tableau drops the order. */
static void dop853_convergence_order_is_eight(void) {
  const hm_ode_system osc = {2, osc_rhs, osc_jac, NULL}, es = {1, expsin_rhs, expsin_jac, NULL};
  const double x_osc[2] = {1.0, 0.0}, x_es[1] = {1.0};
  const double hs[] = {0.5, 0.25, 0.125};
  double e_osc[3], e_es[3];
  for (int i = 0; i < 3; ++i) {
    e_osc[i] = dop853_fixed_step_error(&osc, 10.0, hs[i], x_osc, osc_exact);
    e_es[i] = dop853_fixed_step_error(&es, 10.0, hs[i], x_es, expsin_exact);
  }
  for (int i = 0; i < 2; ++i) {
    const double p_osc = log2(e_osc[i] / e_osc[i + 1]), p_es = log2(e_es[i] / e_es[i + 1]);
    printf("  dop853 order: oscillator %.3f, exp(sin t) %.3f (errors %.1e, %.1e)\n", p_osc, p_es, e_osc[i + 1],
           e_es[i + 1]);
    HM_CHECK(p_osc > 7.5 && p_osc < 8.6, "oscillator order %g", p_osc);
    HM_CHECK(p_es > 7.5 && p_es < 8.8, "exp(sin t) order %g", p_es);
  }
}

typedef struct {
  int calls;
  double worst; /* largest |x - exact| at the step ends */
} step_ctx;

static int step_check(double t_old, const double *x_old, const double *f_old, double t_new, const double *x_new,
                      const double *f_new, void *ctx) {
  step_ctx *c = (step_ctx *)ctx;
  (void)f_old;
  (void)f_new;
  c->worst = fmax(c->worst, fmax(fabs(x_old[0] - cos(t_old)), fabs(x_new[0] - cos(t_new))));
  return ++c->calls == 1000000;
}

/* Adaptive: 100 periods of the oscillator with a global error below 2e-8 at a step tolerance of 1e-10, in far fewer steps than Dormand-Prince 5(4)
 * at the same tolerance; the observer sees the exact solution at every step end; an observer can stop the run. */
static void dop853_adaptive_and_observer(void) {
  const hm_ode_system osc = {2, osc_rhs, NULL, NULL};
  hm_dop853 d = hm_dop853_create(2);
  hm_dopri p = hm_dopri_create(2);
  const double T = 200.0 * HM_PI;
  const hm_dopri_options opt = {1e-10, 1e-10, 0.0, 0.0, 0, 0};
  double x[2] = {1.0, 0.0}, y[2] = {1.0, 0.0};
  hm_dopri_stats s8, s5;
  step_ctx c = {0, 0.0};
  HM_CHECK(hm_dop853_integrate(d, &osc, &opt, 0.0, T, x, step_check, &c, &s8) == HM_OK, "dop853");
  HM_CHECK(hm_dopri_integrate(p, &osc, &opt, 0.0, T, y, NULL, NULL, NULL, &s5) == HM_OK, "dopri");
  printf("  100 periods at 1e-10: dop853 %zu steps (%zu rhs), error %.1e; dopri5 %zu steps (%zu rhs)\n",
         s8.n_accepted, s8.n_rhs, fabs(x[0] - 1.0), s5.n_accepted, s5.n_rhs);
  HM_CHECK_DELTA(x[0], 1.0, 2e-8, "x(100 periods)");
  HM_CHECK(c.worst < 2e-8 && c.calls == (int)s8.n_accepted, "observer: %d calls, worst %g", c.calls, c.worst);
  HM_CHECK(s8.n_rhs < s5.n_rhs, "no fewer right-hand sides than dopri5");
  step_ctx stop = {999997, 0.0};
  double z[2] = {1.0, 0.0};
  HM_CHECK(hm_dop853_integrate(d, &osc, &opt, 0.0, T, z, step_check, &stop, &s8) == HM_OK && s8.n_accepted == 3,
           "observer stop after %zu steps", s8.n_accepted);
  const hm_dopri_options neg = {-1.0, 1e-9, 0.0, 0.0, 0, 0};
  double w[2] = {NAN, 0.0};
  HM_CHECK(hm_dop853_integrate(d, &osc, &neg, 0.0, 1.0, x, NULL, NULL, NULL) == HM_EINVAL, "rtol < 0");
  HM_CHECK(hm_dop853_integrate(d, &osc, &opt, 0.0, 1.0, w, NULL, NULL, NULL) == HM_ENONFINITE, "NaN start");
  HM_CHECK(hm_dop853_create(0) == NULL, "dim 0");
  hm_dop853_destroy(d);
  hm_dopri_destroy(p);
}

/* The oscillator plus a rapidly decaying, uncontrolled passenger z' = -30 z (components 2, 3 = two copies): with
 * err_dim 2 the steps are those of the oscillator integrated alone (the reference run), with all components under
 * control the stiff-ish passenger takes more; the oscillator's solution stays within its tolerance. */
static hm_status osc_passenger_rhs(double t, const double *x, double *dx, void *p) {
  osc_rhs(t, x, dx, p);
  dx[2] = -30.0 * x[2];
  dx[3] = -30.0 * x[3];
  return HM_OK;
}

static void dopri_error_control_on_leading_components(void) {
  const hm_ode_system osc = {2, osc_rhs, NULL, NULL}, both = {4, osc_passenger_rhs, NULL, NULL};
  hm_dopri d2 = hm_dopri_create(2), d4 = hm_dopri_create(4);
  const hm_dopri_options all = {1e-10, 1e-10, 0.0, 0.0, 0, 0}, lead = {1e-10, 1e-10, 0.0, 0.0, 0, 2};
  double x[2] = {1.0, 0.0}, y[4] = {1.0, 0.0, 1.0, 1.0}, w[4] = {1.0, 0.0, 1.0, 1.0};
  hm_dopri_stats s2, s4, sa;
  HM_CHECK(hm_dopri_integrate(d2, &osc, &all, 0.0, 10.0, x, NULL, NULL, NULL, &s2) == HM_OK, "alone");
  HM_CHECK(hm_dopri_integrate(d4, &both, &lead, 0.0, 10.0, y, NULL, NULL, NULL, &s4) == HM_OK, "leading");
  HM_CHECK(hm_dopri_integrate(d4, &both, &all, 0.0, 10.0, w, NULL, NULL, NULL, &sa) == HM_OK, "all");
  printf("  steps: oscillator alone %zu, leading components %zu, all components %zu\n", s2.n_accepted,
         s4.n_accepted, sa.n_accepted);
  HM_CHECK(s4.n_accepted == s2.n_accepted && s4.n_rejected == s2.n_rejected, "not the oscillator's steps");
  HM_CHECK(sa.n_accepted > s2.n_accepted, "the passenger under control took no more steps");
  HM_CHECK_DELTA(y[0], cos(10.0), 1e-8, "oscillator");
  hm_dopri_destroy(d2);
  hm_dopri_destroy(d4);
}

/* Variational equations of the oscillator: Phi(t) = [[cos t, sin t], [-sin t, cos t]]. */
static void variational_matrix_is_the_rotation(void) {
  const hm_ode_system osc = {2, osc_rhs, osc_jac, NULL};
  double jac[4];
  hm_variational var = {&osc, 2, jac};
  const hm_ode_system vsys = {6, hm_variational_rhs, NULL, &var};
  hm_dopri d = hm_dopri_create(6);
  double z[6] = {1.0, 0.0, 1.0, 0.0, 0.0, 1.0}; /* x, then columns of Phi = I */
  const hm_dopri_options opt = {1e-11, 1e-12, 0.0, 0.0, 0, 0};
  const double T = 2.5;
  HM_CHECK(hm_dopri_integrate(d, &vsys, &opt, 0.0, T, z, NULL, NULL, NULL, NULL) == HM_OK, "run");
  HM_CHECK_DELTA(z[2], cos(T), 1e-9, "Phi00");
  HM_CHECK_DELTA(z[3], -sin(T), 1e-9, "Phi10");
  HM_CHECK_DELTA(z[4], sin(T), 1e-9, "Phi01");
  HM_CHECK_DELTA(z[5], cos(T), 1e-9, "Phi11");
  hm_dopri_destroy(d);
}

/* Implicit midpoint: order 2 on exp(sin t), exact energy conservation on the oscillator (a quadratic
 * invariant, preserved by the midpoint rule up to the Newton tolerance), tangent map = step map (linear). */
static void midpoint_order_two_and_invariant(void) {
  const hm_ode_system es = {1, expsin_rhs, expsin_jac, NULL}, osc = {2, osc_rhs, osc_jac, NULL};
  hm_midpoint mp1 = hm_midpoint_create(1), mp2 = hm_midpoint_create(2);
  double errs[3];
  const double hs[] = {0.02, 0.01, 0.005};
  for (int i = 0; i < 3; ++i) {
    double x[1] = {1.0};
    const int n = (int)lround(5.0 / hs[i]);
    for (int s = 0; s < n; ++s)
      HM_CHECK(hm_midpoint_step(mp1, &es, s * hs[i], hs[i], 1e-14, 20, x, NULL, 0) == HM_OK, "step");
    errs[i] = fabs(x[0] - exp(sin(5.0)));
  }
  for (int i = 0; i < 2; ++i) {
    const double p = log2(errs[i] / errs[i + 1]);
    printf("  midpoint order %.3f\n", p);
    HM_CHECK(p > 1.9 && p < 2.1, "midpoint order %g", p);
  }
  double x[2] = {1.0, 0.0}, T[4] = {1, 0, 0, 1};
  for (int s = 0; s < 10000; ++s) HM_CHECK(hm_midpoint_step(mp2, &osc, 0.0, 0.05, 1e-14, 20, x, T, 2) == HM_OK, "step");
  HM_CHECK_DELTA(x[0] * x[0] + x[1] * x[1], 1.0, 1e-11, "energy after 10000 midpoint steps");
  /* Linear system: the tangent matrix maps x0 to x exactly. */
  HM_CHECK_DELTA(T[0] * 1.0 + T[2] * 0.0, x[0], 1e-10, "tangent map x0");
  HM_CHECK_DELTA(T[1] * 1.0 + T[3] * 0.0, x[1], 1e-10, "tangent map x1");
  hm_midpoint_destroy(mp1);
  hm_midpoint_destroy(mp2);
}

static hm_status nan_after_one(double t, const double *x, double *f, void *p) {
  (void)p;
  f[0] = t > 1.0 ? NAN : -x[0];
  return HM_OK;
}

/* Bad input: errors, state untouched. */
static void integrator_bad_inputs(void) {
  const hm_ode_system osc = {2, osc_rhs, osc_jac, NULL}, bad = {1, nan_after_one, NULL, NULL};
  hm_dopri d = hm_dopri_create(2), d1 = hm_dopri_create(1);
  double x[2] = {1.0, 0.0};
  const hm_dopri_options opt = {1e-9, 1e-9, 0.0, 0.0, 0, 0};
  HM_CHECK(hm_dopri_create(0) == NULL, "zero dimension");
  HM_CHECK(hm_dopri_integrate(d, &osc, &opt, 1.0, 0.0, x, NULL, NULL, NULL, NULL) == HM_EINVAL, "t1 < t0");
  const hm_dopri_options neg = {-1.0, 1e-9, 0.0, 0.0, 0, 0};
  HM_CHECK(hm_dopri_integrate(d, &osc, &neg, 0.0, 1.0, x, NULL, NULL, NULL, NULL) == HM_EINVAL, "rtol < 0");
  double xn[2] = {NAN, 0.0};
  HM_CHECK(hm_dopri_integrate(d, &osc, &opt, 0.0, 1.0, xn, NULL, NULL, NULL, NULL) == HM_ENONFINITE, "NaN state");
  double y[1] = {1.0};
  const hm_status st = hm_dopri_integrate(d1, &bad, &opt, 0.0, 2.0, y, NULL, NULL, NULL, NULL);
  HM_CHECK(st == HM_ENONFINITE, "NaN right-hand side: %s", hm_status_str(st));
  HM_CHECK(y[0] == 1.0, "state changed on failure");
  const hm_dopri_options few = {1e-12, 1e-12, 0.0, 0.0, 5, 0};
  HM_CHECK(hm_dopri_integrate(d, &osc, &few, 0.0, 100.0, x, NULL, NULL, NULL, NULL) == HM_ESTEP, "step limit");
  HM_CHECK(x[0] == 1.0 && x[1] == 0.0, "state changed on failure");
  HM_CHECK(hm_dopri_integrate(d1, &osc, &opt, 0.0, 1.0, x, NULL, NULL, NULL, NULL) == HM_EINVAL, "dim mismatch");
  hm_midpoint mp = hm_midpoint_create(2);
  HM_CHECK(hm_midpoint_step(mp, &osc, 0.0, -0.1, 1e-12, 10, x, NULL, 0) == HM_EINVAL, "negative step");
  HM_CHECK(hm_midpoint_step(mp, &osc, 0.0, 0.1, 1e-30, 1, x, NULL, 0) == HM_ENOCONV, "Newton limit");
  HM_CHECK(x[0] == 1.0 && x[1] == 0.0, "state changed on failure");
  hm_midpoint_destroy(mp);
  hm_dopri_destroy(d);
  hm_dopri_destroy(d1);
}

int main(void) {
  HM_RUN(dopri_convergence_order_is_five);
  HM_RUN(dopri_error_control_tracks_tolerance);
  HM_RUN(dopri_dense_output_and_observer);
  HM_RUN(dopri_error_control_on_leading_components);
  HM_RUN(dop853_convergence_order_is_eight);
  HM_RUN(dop853_adaptive_and_observer);
  HM_RUN(variational_matrix_is_the_rotation);
  HM_RUN(midpoint_order_two_and_invariant);
  HM_RUN(integrator_bad_inputs);
  HM_TEST_EXIT();
}
