/* Hopf points and Lyapunov coefficients against MODEL.md section 6 and against the cycles they predict. */
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/cycles.h"
#include "hunting_monitor/hopf.h"
#include "hunting_monitor/linear.h"

static hm_vehicle study_vehicle(double kx) {
  hm_vehicle v;
  hm_vehicle_default(&v);
  v.stiffness_long_n_m = kx * 1e6;
  v.stiffness_lat_n_m = 10.96e6;
  return v;
}

static hm_hopf_point hopf_in_speed(const hm_vehicle *v) {
  hm_hopf_point h;
  memset(&h, 0, sizeof h);
  size_t n = 0;
  HM_CHECK(hm_hopf_find(v, 500.0, HM_PARAM_SPEED, 100.0, 900.0, 1e-10, &h, 1, &n) == HM_OK && n == 1, "Hopf");
  return h;
}

/* MODEL.md section 6: Ky = 10.96; Hopf V to 1e-3 km/h, l1 to 4 significant digits. */
static void published_first_lyapunov_coefficients(void) {
  const double kx[] = {9.1, 9.7, 9.9}, v_ref[] = {527.4349, 544.3795, 550.3513}, l1_ref[] = {7.4072, 3.8482, 2.7316};
  for (int i = 0; i < 3; ++i) {
    const hm_vehicle v = study_vehicle(kx[i]);
    const hm_hopf_point h = hopf_in_speed(&v);
    printf("  Kx %.1f: V %.6f km/h, l1 %.6f\n", kx[i], h.speed_kmh, h.l1);
    HM_CHECK_DELTA(h.speed_kmh, v_ref[i], 1e-3, "Hopf V [km/h]");
    HM_CHECK_REL(h.l1, l1_ref[i], 1e-4, "l1");
  }
}

/* GH on the (Kx, V) Hopf curve at Kx = 10.413634, V = 566.5220, l2 = -37.5146. */
static void published_generalised_hopf(void) {
  const hm_vehicle v = study_vehicle(9.0);
  const hm_hopf_curve_options o = {HM_PLANE_KX_V, 9.0, 10.7, 18, 0.0, 0.0, 0.0, 1e-9};
  hm_hopf_curve_point pts[18];
  hm_hopf_point gh[4];
  size_t np = 0, ng = 0;
  HM_CHECK(hm_hopf_curve(&v, &o, pts, 18, &np, gh, 4, &ng) == HM_OK, "curve");
  HM_CHECK(np == 18 && ng == 1, "%zu points, %zu GH points", np, ng);
  if (ng != 1) return;
  printf("  GH: Kx %.7f, V %.5f, l2 %.5f\n", gh[0].kx_mn_m, gh[0].speed_kmh, gh[0].l2);
  HM_CHECK_DELTA(gh[0].kx_mn_m, 10.413634, 1e-5, "GH Kx [MN/m]");
  HM_CHECK_DELTA(gh[0].speed_kmh, 566.5220, 1e-3, "GH V [km/h]");
  HM_CHECK_REL(gh[0].l2, -37.5146, 1e-4, "l2");
  HM_CHECK(fabs(gh[0].l1) < 1e-6, "l1 at GH = %g", gh[0].l1);
  /* every curve point is on the stability boundary by a second method: there the Jacobian (dgeev) has a purely
   * imaginary pair (its real part below 1e-7 of the imaginary one) and it is the least stable pair */
  for (size_t i = 0; i < np; ++i) {
    hm_vehicle w = study_vehicle(pts[i].point.kx_mn_m);
    double re[4], im[4];
    HM_CHECK(hm_linear_eigenvalues(&w, 0.1358, hm_mps_from_kmh(pts[i].point.speed_kmh), re, im) == HM_OK, "dgeev");
    HM_CHECK(fabs(re[0]) <= 1e-7 * fabs(im[0]), "point %zu: eigenvalue %g%+gi is not on the boundary", i, re[0], im[0]);
  }
}

/* Second method for l1: the normal form predicts small cycles at p - p_h = -l1 |z|^2 / alpha', with
 * max|y| = 2 |z| |q0| (x = z q + c.c., <q, q> = 1) and alpha' = d Re(lambda)/dV (here by differences of
 * dgeev eigenvalues). The cycles come from the shooting solver; Richardson extrapolation in amplitude^2
 * removes the O(amplitude^4) term. */
static void l1_predicts_the_small_cycles(void) {
  const double kx[] = {9.1, 10.7};
  for (int i = 0; i < 2; ++i) {
    const hm_vehicle v = study_vehicle(kx[i]);
    const hm_hopf_point h = hopf_in_speed(&v);
    double qr[4], qi[4], w, sp, sm;
    HM_CHECK(hm_hopf_eigenvector(&v, h.speed_kmh, qr, qi, &w) == HM_OK, "eigenvector");
    const double q0 = hypot(qr[0], qi[0]), dv = 1e-3;
    hm_linear_spectral_abscissa(&v, 0.1358, hm_mps_from_kmh(h.speed_kmh + dv), &sp);
    hm_linear_spectral_abscissa(&v, 0.1358, hm_mps_from_kmh(h.speed_kmh - dv), &sm);
    const double alpha = (sp - sm) / (2.0 * dv);
    hm_cycle_options o;
    hm_cycle_options_default(&o, HM_PARAM_SPEED);
    o.amp_start_m = 2e-4;
    o.amp_max_m = 3e-4;
    hm_cycle_point pts[64];
    hm_cycle_event ev[4];
    size_t np = 0, ne = 0;
    HM_CHECK(hm_cycles_continue(&v, 500.0, &h, &o, pts, 64, &np, ev, 4, &ne, NULL) == HM_OK && np >= 2, "cycles");
    double est[2];
    for (int k = 0; k < 2; ++k) {
      const double z = pts[k].amp_y_m / (2.0 * q0);
      est[k] = -alpha * (pts[k].param - h.speed_kmh) / (z * z);
    }
    const double l1_cycles = (4.0 * est[0] - est[1]) / 3.0;
    printf("  Kx %.1f: l1 from cycles %.5f (at 0.2 mm %.5f), formula %.5f\n", kx[i], l1_cycles, est[0], h.l1);
    HM_CHECK_DELTA(l1_cycles, h.l1, 2e-3 * fabs(h.l1) + 1e-3, "l1 from the cycle family");
  }
}

/* Hopf points in Kx, Ky and conicity at fixed speed: on each, the linear critical speed is that speed. */
static void hopf_along_other_parameters(void) {
  const hm_param ps[] = {HM_PARAM_KX, HM_PARAM_KY, HM_PARAM_CONICITY};
  const double lo[] = {1.0, 0.5, 0.01}, hi[] = {30.0, 40.0, 1.0};
  for (int i = 0; i < 3; ++i) {
    const hm_vehicle v = study_vehicle(9.7);
    hm_hopf_point pts[4];
    size_t n = 0;
    HM_CHECK(hm_hopf_find(&v, 550.0, ps[i], lo[i], hi[i], 1e-12, pts, 4, &n) == HM_OK && n >= 1, "find %s",
             hm_param_name(ps[i]));
    for (size_t k = 0; k < n && k < 4; ++k) {
      hm_vehicle w = v;
      double vc;
      w.stiffness_long_n_m = pts[k].kx_mn_m * 1e6;
      w.stiffness_lat_n_m = pts[k].ky_mn_m * 1e6;
      hm_vehicle_set_conicity_at_zero(&w, pts[k].conicity);
      HM_CHECK(hm_linear_critical_speed(&w, pts[k].conicity, &vc) == HM_OK, "critical speed");
      HM_CHECK_DELTA(hm_kmh_from_mps(vc), 550.0, 1e-6, "critical speed at the Hopf point [km/h]");
    }
  }
}

static void bad_inputs(void) {
  const hm_vehicle v = study_vehicle(9.7);
  hm_hopf_point h;
  size_t n = 99;
  HM_CHECK(hm_hopf_find(&v, 500.0, HM_PARAM_SPEED, 900.0, 100.0, 1e-9, &h, 1, &n) == HM_EINVAL, "reversed range");
  HM_CHECK(hm_hopf_find(&v, 500.0, HM_PARAM_KX, 1.0, 30.0, 0.0, &h, 1, &n) == HM_EINVAL, "zero tolerance");
  HM_CHECK(n == 99, "count changed on failure");
  HM_CHECK(hm_hopf_find(&v, 500.0, HM_PARAM_SPEED, 100.0, 200.0, 1e-9, &h, 1, &n) == HM_OK && n == 0,
           "no Hopf point below 200 km/h");
  hm_vehicle bad = v;
  bad.mass_kg = NAN;
  HM_CHECK(hm_hopf_find(&bad, 500.0, HM_PARAM_SPEED, 100.0, 900.0, 1e-9, &h, 1, &n) == HM_EDOMAIN, "NaN mass");
}

int main(void) {
  HM_RUN(published_first_lyapunov_coefficients);
  HM_RUN(published_generalised_hopf);
  HM_RUN(l1_predicts_the_small_cycles);
  HM_RUN(hopf_along_other_parameters);
  HM_RUN(bad_inputs);
  HM_TEST_EXIT();
}
