/* Equivalent conicity from delta-r (eqcon.h) against closed forms: a cone, unequal radii, Duffing's period (the
 * complete elliptic integral by the arithmetic-geometric mean), the harmonic linearisation of a cubic, and an
 * asymmetric function's kinematic oscillation integrated here by RK4. */
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/eqcon.h"

static const double PI = 3.14159265358979323846, E0R0 = 0.75 * 0.46;

enum { NMAX = 4001 };
static double ys[NMAX], drs[NMAX];

/* delta-r tabulated over [-half, half] mm every step mm. */
static size_t tabulate(double half_mm, double step_mm, double (*f)(double y, const double *p), const double *p) {
  const size_t n = (size_t)lround(2.0 * half_mm / step_mm) + 1;
  for (size_t k = 0; k < n; ++k) {
    ys[k] = 1e-3 * (-half_mm + step_mm * (double)k);
    drs[k] = f(ys[k], p);
  }
  return n;
}

static double cone(double y, const double *p) { return 2.0 * y * p[0] + p[1]; }
static double cubic(double y, const double *p) { return 2.0 * (p[0] * y + p[1] * y * y * y); }
static double quadratic(double y, const double *p) { return 2.0 * p[0] * y + p[1] * y * y; }
static double dead_zone(double y, const double *p) { return fabs(y) <= p[1] ? 0.0 : 2.0 * p[0] * (y - copysign(p[1], y)); }

static hm_eqcon make(size_t n) {
  hm_eqcon_config c;
  hm_eqcon_config_default(&c);
  hm_eqcon e = NULL;
  char why[128] = "";
  HM_CHECK(hm_eqcon_create(&c, ys, drs, n, &e, why, sizeof why) == HM_OK, "create: %s", why);
  return e;
}

/* A cone, delta-r = 2 y tan(gamma), tan(gamma) = 0.05 and 1/40: both methods give tan(gamma) at every amplitude
 * from 1 to 7.5 mm (to 1e-8), the wavelength Klingel's 2 pi sqrt(e0 r0 / tan gamma). */
static void cone_is_its_own_conicity(void) {
  const double tans[] = {0.05, 0.025};
  for (int i = 0; i < 2; ++i) {
    const double p[2] = {tans[i], 0.0};
    hm_eqcon e = make(tabulate(10.0, 0.1, cone, p));
    double worst = 0.0;
    for (double a = 1.0; a <= 7.5 + 1e-9; a += 0.5)
      for (int m = 0; m < 2; ++m) {
        hm_eqcon_result r;
        HM_CHECK(hm_eqcon_at(e, (hm_eqcon_method)m, 1e-3 * a, &r) == HM_OK, "amplitude %g mm", a);
        worst = fmax(worst, fabs(r.tan_gamma_e / tans[i] - 1.0));
        HM_CHECK_REL(r.wavelength_m, 2.0 * PI * sqrt(E0R0 / tans[i]), 1e-8, "Klingel's wavelength");
      }
    HM_CHECK(worst < 1e-8, "tan gamma %g: off by %.2g relative", tans[i], worst);
    printf("  cone %.3f: tan gamma_e within %.1e at 1-7.5 mm (both methods), wavelength %.3f m\n", tans[i], worst,
           2.0 * PI * sqrt(E0R0 / tans[i]));
    hm_eqcon_destroy(e);
  }
}

/* Unequal wheel radii, delta-r = 2 y 0.15 + 0.4 mm: the equilibrium at -0.4 / 0.3 = -1.3333 mm, the oscillation
 * about it (turning points y_eq -+ a), tan gamma_e 0.15 at every amplitude. */
static void unequal_radii_shift_the_equilibrium(void) {
  const double p[2] = {0.15, 0.4e-3};
  hm_eqcon e = make(tabulate(12.0, 0.1, cone, p));
  HM_CHECK_DELTA(hm_eqcon_equilibrium_m(e), -0.4e-3 / 0.3, 1e-12, "equilibrium");
  for (double a = 1.0; a <= 7.5 + 1e-9; a += 1.0)
    for (int m = 0; m < 2; ++m) {
      hm_eqcon_result r;
      HM_CHECK(hm_eqcon_at(e, (hm_eqcon_method)m, 1e-3 * a, &r) == HM_OK, "amplitude %g mm", a);
      HM_CHECK_REL(r.tan_gamma_e, 0.15, 1e-8, "tan gamma_e");
      HM_CHECK_DELTA(r.y_low_m, -0.4e-3 / 0.3 - 1e-3 * a, 1e-9, "lower turning point");
      HM_CHECK_DELTA(r.y_high_m, -0.4e-3 / 0.3 + 1e-3 * a, 1e-9, "upper turning point");
    }
  hm_eqcon_destroy(e);
}

static double agm(double a, double b) {
  for (int i = 0; i < 60 && fabs(a - b) > 1e-16 * a; ++i) {
    const double m = 0.5 * (a + b);
    b = sqrt(a * b);
    a = m;
  }
  return a;
}

/* delta-r = 2 (t y + k y^3), t = 0.05, k = 2000 / m^2 (the conicity doubles by 5 mm), tabulated every 0.01 mm: the
 * integration gives Duffing's wavelength, y'' + A y + B y^3 = 0 (A = t / e0 r0, B = k / e0 r0) with amplitude a:
 * L = 4 K(m) / sqrt(A + B a^2), m = B a^2 / (2 (A + B a^2)), K by the AGM; the regression t + 3/4 k a^2. To 5e-6
 * (the table's linear interpolation of the cubic: h^2 / 8 |delta-r''| is 1e-5 of delta-r at 7.5 mm). */
static void cubic_against_duffing_and_harmonic_balance(void) {
  const double t = 0.05, k = 2000.0, p[2] = {t, k};
  hm_eqcon e = make(tabulate(10.0, 0.01, cubic, p));
  double worst_i = 0.0, worst_r = 0.0;
  for (double a_mm = 1.0; a_mm <= 7.5 + 1e-9; a_mm += 0.5) {
    const double a = 1e-3 * a_mm, A = t / E0R0, B = k / E0R0;
    const double m = B * a * a / (2.0 * (A + B * a * a));
    const double K = PI / (2.0 * agm(1.0, sqrt(1.0 - m)));
    const double L = 4.0 * K / sqrt(A + B * a * a);
    const double tan_i = E0R0 * pow(2.0 * PI / L, 2.0), tan_r = t + 0.75 * k * a * a;
    hm_eqcon_result ri, rr;
    HM_CHECK(hm_eqcon_at(e, HM_EQCON_INTEGRATION, a, &ri) == HM_OK && hm_eqcon_at(e, HM_EQCON_REGRESSION, a, &rr) == HM_OK,
             "amplitude %g mm", a_mm);
    worst_i = fmax(worst_i, fabs(ri.tan_gamma_e / tan_i - 1.0));
    worst_r = fmax(worst_r, fabs(rr.tan_gamma_e / tan_r - 1.0));
    HM_CHECK_REL(ri.wavelength_m, L, 1e-6, "Duffing's wavelength");
  }
  HM_CHECK(worst_i < 5e-6 && worst_r < 5e-6, "integration off by %.2g, regression by %.2g", worst_i, worst_r);
  printf("  cubic: integration within %.1e of Duffing's, regression within %.1e of t + 3/4 k a^2\n", worst_i, worst_r);
  hm_eqcon_destroy(e);
}

/* The kinematic oscillation y'' = -delta-r(y) / (2 e0 r0) integrated by RK4 (step 1 mm of track) from the upper
 * turning point until y' is zero again, twice: the wavelength. */
static double rk4_wavelength(const double *p, double y_top) {
  double y = y_top, v = 0.0, x = 0.0, h = 1e-3;
  int crossings = 0;
  double last_x = 0.0;
  while (crossings < 2 && x < 1e3) {
    const double k1y = v, k1v = -quadratic(y, p) / (2.0 * E0R0);
    const double k2y = v + 0.5 * h * k1v, k2v = -quadratic(y + 0.5 * h * k1y, p) / (2.0 * E0R0);
    const double k3y = v + 0.5 * h * k2v, k3v = -quadratic(y + 0.5 * h * k2y, p) / (2.0 * E0R0);
    const double k4y = v + h * k3v, k4v = -quadratic(y + h * k3y, p) / (2.0 * E0R0);
    const double v_new = v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
    const double y_new = y + h / 6.0 * (k1y + 2 * k2y + 2 * k3y + k4y);
    if ((v < 0.0) != (v_new < 0.0) && v != 0.0) { /* a turning point inside the step: linear in v */
      ++crossings;
      last_x = x + h * v / (v - v_new);
    }
    v = v_new;
    y = y_new;
    x += h;
  }
  return last_x;
}

/* An asymmetric function, delta-r = 2 t y + c y^2 (t = 0.05, c = 10 / m: one side steeper), every 0.01 mm: the
 * turning points of the integration have equal potential t y^2 + c y^3 / 3 (to 2e-5 of it: the table's
 * interpolation) and lie 2 a apart, the wavelength is that of an RK4 integration of the oscillation from the upper
 * turning point (to 2e-6), and the conicity falls with the amplitude as the quadratic oscillator's frequency does
 * (Lindstedt: w = w0 (1 - 5/12 alpha^2 a^2 / w0^4), w0^2 = t / e0 r0, alpha = c / 2 e0 r0; at 1 mm to 3e-4, the
 * next order). */
static void asymmetric_function_against_rk4(void) {
  const double p[2] = {0.05, 10.0};
  hm_eqcon e = make(tabulate(10.0, 0.01, quadratic, p));
  double worst = 0.0, prev = 0.0;
  for (double a_mm = 1.0; a_mm <= 6.0 + 1e-9; a_mm += 1.0) {
    hm_eqcon_result r;
    HM_CHECK(hm_eqcon_at(e, HM_EQCON_INTEGRATION, 1e-3 * a_mm, &r) == HM_OK, "amplitude %g mm", a_mm);
    const double i_hi = p[0] * r.y_high_m * r.y_high_m + p[1] * pow(r.y_high_m, 3) / 3.0;
    const double i_lo = p[0] * r.y_low_m * r.y_low_m + p[1] * pow(r.y_low_m, 3) / 3.0;
    HM_CHECK(fabs(i_hi - i_lo) <= 2e-5 * i_hi, "equal potential: %.6g vs %.6g", i_hi, i_lo);
    HM_CHECK_REL(r.y_high_m - r.y_low_m, 2e-3 * a_mm, 2e-7, "peak to peak (to the default tol, 1e-7)");
    const double L = rk4_wavelength(p, r.y_high_m);
    worst = fmax(worst, fabs(r.wavelength_m / L - 1.0));
    HM_CHECK(prev == 0.0 || r.tan_gamma_e < prev, "tan gamma_e falls with the amplitude");
    prev = r.tan_gamma_e;
    if (a_mm == 1.0) {
      const double w0sq = p[0] / E0R0, alpha = p[1] / (2.0 * E0R0), a = 1e-3;
      const double w = sqrt(w0sq) * (1.0 - 5.0 / 12.0 * alpha * alpha * a * a / (w0sq * w0sq));
      HM_CHECK_REL(r.tan_gamma_e, E0R0 * w * w, 3e-4, "Lindstedt at 1 mm");
    }
  }
  HM_CHECK(worst < 2e-6, "wavelength off the RK4 integration by %.2g", worst);
  printf("  asymmetric: wavelength within %.1e of an RK4 integration, tan gamma_e at 6 mm %.4f\n", worst, prev);
  hm_eqcon_destroy(e);
}

/* A dead zone (worn profiles, EN 15302's case E4): delta-r = 0 for |y| <= d = 1 mm, a cone of 0.1 outside. Within
 * the zone nothing restores: tan gamma_e = 0 up to a = d; beyond, the motion is the cone's harmonic arcs joined by a
 * straight drift across 2 d at the slope w (a - d): L = (2 pi / w) (1 + 2 d / (pi (a - d))), so tan gamma_e =
 * 0.1 / (1 + 2 d / (pi (a - d)))^2 (to 1e-6). */
static void dead_zone_against_closed_form(void) {
  const double t = 0.1, d = 1e-3, p[2] = {t, d};
  hm_eqcon e = make(tabulate(10.0, 0.1, dead_zone, p));
  double worst = 0.0;
  for (double a_mm = 0.5; a_mm <= 7.5 + 1e-9; a_mm += 0.5) {
    hm_eqcon_result r;
    HM_CHECK(hm_eqcon_at(e, HM_EQCON_INTEGRATION, 1e-3 * a_mm, &r) == HM_OK, "amplitude %g mm", a_mm);
    const double a = 1e-3 * a_mm, ref = a <= d ? 0.0 : t / pow(1.0 + 2.0 * d / (PI * (a - d)), 2.0);
    if (a <= d)
      HM_CHECK(r.tan_gamma_e == 0.0 && isinf(r.wavelength_m), "inside the zone: %g", r.tan_gamma_e);
    else
      worst = fmax(worst, fabs(r.tan_gamma_e / ref - 1.0));
  }
  HM_CHECK(worst < 1e-6, "off the closed form by %.2g", worst);
  printf("  dead zone of +-1 mm on a 0.1 cone: 0 within it, the closed form to %.1e beyond\n", worst);
  hm_eqcon_destroy(e);
}

/* Bad input: named errors, outputs untouched; amplitudes beyond the table undefined. */
static void bad_input(void) {
  hm_eqcon_config c;
  hm_eqcon_config_default(&c);
  char why[160] = "";
  hm_eqcon e = (hm_eqcon)(&c); /* a sentinel: must stay */
  const double y3[3] = {-1e-3, 0.0, 1e-3}, falling[3] = {1e-4, 0.0, -1e-4}, rising[3] = {-1e-4, 0.0, 1e-4};
  const double back[3] = {-1e-3, 1e-3, 0.0}, nan3[3] = {-1e-4, NAN, 1e-4};
  HM_CHECK(hm_eqcon_create(&c, y3, falling, 3, &e, why, sizeof why) == HM_EDOMAIN && strstr(why, "no restoring"),
           "%s", why);
  HM_CHECK(hm_eqcon_create(&c, back, rising, 3, &e, why, sizeof why) == HM_EDOMAIN && strstr(why, "increase strictly"),
           "%s", why);
  HM_CHECK(hm_eqcon_create(&c, y3, nan3, 3, &e, why, sizeof why) == HM_EDOMAIN && strstr(why, "point 2"), "%s", why);
  HM_CHECK(hm_eqcon_create(&c, y3, rising, 2, &e, why, sizeof why) == HM_EDOMAIN && strstr(why, "at least 3"), "%s",
           why);
  c.r0_m = -0.46;
  HM_CHECK(hm_eqcon_create(&c, y3, rising, 3, &e, why, sizeof why) == HM_EDOMAIN && strstr(why, "r0_m"), "%s", why);
  HM_CHECK(e == (hm_eqcon)(&c), "output touched on failure");
  const double p[2] = {0.05, 0.0};
  e = make(tabulate(5.0, 0.1, cone, p));
  hm_eqcon_result r = {.tan_gamma_e = -1.0};
  HM_CHECK(hm_eqcon_at(e, HM_EQCON_INTEGRATION, 5.5e-3, &r) == HM_EDOMAIN &&
               hm_eqcon_at(e, HM_EQCON_REGRESSION, 5.5e-3, &r) == HM_EDOMAIN &&
               hm_eqcon_at(e, HM_EQCON_INTEGRATION, 0.0, &r) == HM_EDOMAIN &&
               hm_eqcon_at(e, HM_EQCON_INTEGRATION, NAN, &r) == HM_EDOMAIN &&
               hm_eqcon_at(e, (hm_eqcon_method)7, 1e-3, &r) == HM_EDOMAIN && r.tan_gamma_e == -1.0,
           "beyond the table or bad amplitude: refused, untouched");
  HM_CHECK(hm_eqcon_at(e, HM_EQCON_INTEGRATION, 4.9e-3, &r) == HM_OK, "inside the table");
  hm_eqcon_destroy(e);
}

int main(void) {
  HM_RUN(cone_is_its_own_conicity);
  HM_RUN(unequal_radii_shift_the_equilibrium);
  HM_RUN(cubic_against_duffing_and_harmonic_balance);
  HM_RUN(asymmetric_function_against_rk4);
  HM_RUN(dead_zone_against_closed_form);
  HM_RUN(bad_input);
  HM_TEST_EXIT();
}
