/* Conicity fit: exact recovery, statistics against their definitions, noise consistency, bad input. */
#include <stdlib.h>
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/conicity_fit.h"
#include "hunting_monitor/linear.h"

static void sample(const hm_conicity *truth, double *y, double *l, size_t n, double sigma) {
  for (size_t i = 0; i < n; ++i) {
    y[i] = (-12.0 + 24.0 * (double)i / (double)(n - 1)) * 1e-3;
    hm_conicity_eval(truth, y[i], &l[i], NULL);
    if (sigma > 0.0) l[i] += sigma * hm_test_gauss();
  }
}

static hm_conicity simplified(void) {
  hm_conicity c = {0.1358, 2, {{0.7, 0.01, 0.00145}, {0.7, -0.01, 0.00145}}};
  return c;
}

/* The term of the fit closest in centre to b. */
static const hm_gaussian *term_near(const hm_conicity *c, double b) {
  const hm_gaussian *best = &c->terms[0];
  for (size_t k = 1; k < c->n_terms; ++k)
    if (fabs(c->terms[k].center_m - b) < fabs(best->center_m - b)) best = &c->terms[k];
  return best;
}

static void check_recovered(const hm_conicity *fit, const hm_conicity *truth, double rel) {
  HM_CHECK_DELTA(fit->constant, truth->constant, rel * fabs(truth->constant) + 1e-12, "constant");
  HM_CHECK(fit->n_terms == truth->n_terms, "%zu terms", fit->n_terms);
  for (size_t k = 0; k < truth->n_terms; ++k) {
    const hm_gaussian *t = &truth->terms[k], *f = term_near(fit, t->center_m);
    HM_CHECK_REL(f->amplitude, t->amplitude, rel, "amplitude");
    HM_CHECK_REL(f->center_m, t->center_m, rel, "centre");
    HM_CHECK_REL(f->width_m, t->width_m, rel, "width");
  }
}

/* Noise-free data: parameters recovered to 1e-6 (simplified symmetric form, both parametrisations, and an
 * asymmetric 3-term curve), and the Hopf speed of the reference vehicle (517.618 km/h) reproduced. */
static void noise_free_recovery(void) {
  double y[241], l[241];
  const hm_conicity s = simplified();
  sample(&s, y, l, 241, 0.0);
  hm_fit_options o;
  hm_fit_options_default(&o);
  hm_fit_result r;
  for (int sym = 0; sym < 2; ++sym) {
    o.symmetric = sym;
    HM_CHECK(hm_conicity_fit(y, l, 241, &o, &r, NULL, 0) == HM_OK, "fit");
    check_recovered(&r.conicity, &s, 1e-6);
    hm_vehicle v;
    hm_vehicle_default(&v);
    double l0, vc;
    hm_conicity_eval(&r.conicity, 0.0, &l0, NULL);
    HM_CHECK(hm_linear_critical_speed(&v, l0, &vc) == HM_OK, "Hopf speed");
    HM_CHECK_DELTA(hm_kmh_from_mps(vc), 517.618, 6e-4, "Hopf speed of the fitted vehicle [km/h]");
  }
  const hm_conicity three = {0.12, 3, {{0.5, -0.008, 0.0015}, {0.3, 0.001, 0.003}, {0.6, 0.009, 0.0012}}};
  sample(&three, y, l, 241, 0.0);
  o.symmetric = 0;
  o.n_terms = 3;
  HM_CHECK(hm_conicity_fit(y, l, 241, &o, &r, NULL, 0) == HM_OK, "fit");
  check_recovered(&r.conicity, &three, 1e-6);
}

/* SSE, R^2, adjusted R^2 and RMSE recomputed here from their definitions and the returned curve. */
static void statistics_follow_their_definitions(void) {
  double y[121], l[121];
  const hm_conicity s = simplified();
  sample(&s, y, l, 121, 0.0157);
  hm_fit_options o;
  hm_fit_options_default(&o);
  o.symmetric = 1;
  hm_fit_result r;
  HM_CHECK(hm_conicity_fit(y, l, 121, &o, &r, NULL, 0) == HM_OK, "fit");
  double sse = 0.0, mean = 0.0, sst = 0.0;
  for (int i = 0; i < 121; ++i) mean += l[i] / 121.0;
  for (int i = 0; i < 121; ++i) {
    double f;
    hm_conicity_eval(&r.conicity, y[i], &f, NULL);
    sse += (l[i] - f) * (l[i] - f);
    sst += (l[i] - mean) * (l[i] - mean);
  }
  const double m = 4.0, dof = 121.0 - m; /* constant + (a, b, c) of the pair */
  HM_CHECK(r.n_params == 4 && r.dof == 117, "parameters %zu, dof %zu", r.n_params, r.dof);
  HM_CHECK_REL(r.sse, sse, 1e-10, "SSE");
  HM_CHECK_REL(r.r2, 1.0 - sse / sst, 1e-12, "R^2");
  HM_CHECK_REL(r.adj_r2, 1.0 - (sse / dof) / (sst / 120.0), 1e-12, "adjusted R^2");
  HM_CHECK_REL(r.rmse, sqrt(sse / dof), 1e-10, "RMSE");
}

/* Noisy data over 40 seeds (400 points, sigma 0.0157): every RMSE within 10% of sigma, their mean within 2%,
 * and the true parameters inside +-2 standard errors in about 95% of the cases (at least 85% here). */
static void noise_consistency(void) {
  const double sigma = 0.0157;
  const hm_conicity s = simplified();
  double y[400], l[400], mean_rmse = 0.0;
  int inside = 0, total = 0;
  hm_fit_options o;
  hm_fit_options_default(&o);
  o.symmetric = 1;
  for (int seed = 0; seed < 40; ++seed) {
    sample(&s, y, l, 400, sigma);
    hm_fit_result r;
    HM_CHECK(hm_conicity_fit(y, l, 400, &o, &r, NULL, 0) == HM_OK, "fit");
    HM_CHECK_REL(r.rmse, sigma, 0.10, "RMSE vs noise sigma");
    mean_rmse += r.rmse / 40.0;
    const hm_gaussian *f = term_near(&r.conicity, 0.01);
    const size_t k = (size_t)(f - r.conicity.terms);
    const double est[4] = {r.conicity.constant, f->amplitude, f->center_m, f->width_m};
    const double se[4] = {r.constant_se, r.amplitude_se[k], r.center_se[k], r.width_se[k]};
    const double tru[4] = {0.1358, 0.7, 0.01, 0.00145};
    for (int j = 0; j < 4; ++j, ++total) inside += fabs(est[j] - tru[j]) <= 2.0 * se[j];
  }
  printf("  mean RMSE %.5f (sigma %.5f); truth within 2 se in %d of %d\n", mean_rmse, sigma, inside, total);
  HM_CHECK_REL(mean_rmse, sigma, 0.02, "mean RMSE");
  HM_CHECK(inside >= 0.85 * total, "coverage of the standard errors %d/%d", inside, total);
}

static void bad_input_is_refused(void) {
  double y[10], l[10];
  const hm_conicity s = simplified();
  sample(&s, y, l, 10, 0.0);
  hm_fit_options o;
  hm_fit_options_default(&o);
  hm_fit_result r;
  memset(&r, 0x5a, sizeof r);
  const hm_fit_result before = r;
  char why[160];
  o.n_terms = 3; /* 10 parameters, 10 points */
  HM_CHECK(hm_conicity_fit(y, l, 10, &o, &r, why, sizeof why) == HM_EDOMAIN, "too few points");
  HM_CHECK(strstr(why, "10 points cannot determine 10 parameters") != NULL, "'%s'", why);
  o.n_terms = 1;
  l[3] = NAN;
  HM_CHECK(hm_conicity_fit(y, l, 10, &o, &r, why, sizeof why) == HM_EDOMAIN, "NaN");
  HM_CHECK(strstr(why, "point 4 is not a finite number") != NULL, "'%s'", why);
  sample(&s, y, l, 10, 0.0);
  for (int i = 0; i < 10; ++i) y[i] = 0.001;
  HM_CHECK(hm_conicity_fit(y, l, 10, &o, &r, why, sizeof why) == HM_EDOMAIN, "all y equal");
  HM_CHECK(strstr(why, "all displacements are equal") != NULL, "'%s'", why);
  sample(&s, y, l, 10, 0.0);
  for (int i = 0; i < 10; ++i) l[i] = 0.2;
  HM_CHECK(hm_conicity_fit(y, l, 10, &o, &r, why, sizeof why) == HM_EDOMAIN, "constant conicity");
  o.n_terms = 9;
  HM_CHECK(hm_conicity_fit(y, l, 10, &o, &r, why, sizeof why) == HM_EINVAL, "9 terms");
  o.n_terms = 0;
  HM_CHECK(hm_conicity_fit(y, l, 10, &o, &r, why, sizeof why) == HM_EINVAL, "0 terms");
  HM_CHECK(memcmp(&r, &before, sizeof r) == 0, "result changed on failure");
}

int main(void) {
  HM_RUN(noise_free_recovery);
  HM_RUN(statistics_follow_their_definitions);
  HM_RUN(noise_consistency);
  HM_RUN(bad_input_is_refused);
  HM_TEST_EXIT();
}
