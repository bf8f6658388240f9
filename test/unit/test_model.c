/* The model: validation, right-hand side and analytic Jacobian (against finite differences). */
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/model.h"

/* MODEL.md section 2 and 3 values, written out here independently of hm_vehicle_default. */
static void defaults_are_the_published_parameters(void) {
  hm_vehicle v;
  hm_vehicle_default(&v);
  HM_CHECK(v.mass_kg == 1869.0 && v.yaw_inertia_kg_m2 == 910.0, "m, I");
  HM_CHECK(v.contact_half_distance_m == 0.7465 && v.spring_half_distance_m == 1.0, "d0, d1");
  HM_CHECK(v.rolling_radius_m == 0.43 && v.creep_long_n == 7.99e6 && v.creep_lat_n == 7.99e6, "r0, kx, ky");
  HM_CHECK(v.spring_ratio == 1.351186 && v.stiffness_long_n_m == 8.96e6 && v.stiffness_lat_n_m == 8.96e6, "l0/l1, Kx, Ky");
  HM_CHECK(v.flange_alpha1_n_m3 == -1.6e11 && v.flange_alpha2_n_m5 == 1.6e15, "alpha1, alpha2");
  HM_CHECK(hm_vehicle_validate(&v, NULL, 0) == HM_OK, "defaults validate");
  double l0;
  hm_conicity_eval(&v.conicity, 0.0, &l0, NULL);
  HM_CHECK_DELTA(l0, 0.1358, 1e-15, "lambda(0) of the simplified fit");
  /* lambda(0.01) = 0.7 + 0.7 exp(-(0.02/0.00145)^2) + 0.1358 */
  double l1;
  hm_conicity_eval(&v.conicity, 0.01, &l1, NULL);
  HM_CHECK_DELTA(l1, 0.7 + 0.7 * exp(-pow(0.02 / 0.00145, 2)) + 0.1358, 1e-15, "lambda(0.01)");
}

/* F_T(y) = 1.6e11 y^3 (1e4 y^2 - 1): zero at 0 and at +-10 mm, outward inside, restoring outside. */
static void flange_force_closed_form(void) {
  hm_vehicle v;
  hm_vehicle_default(&v);
  const double ys[] = {-0.015, -0.01, -0.004, 0.0, 0.002, 0.008, 0.01, 0.012};
  for (size_t i = 0; i < sizeof ys / sizeof ys[0]; ++i) {
    const double y = ys[i], ref = 1.6e11 * y * y * y * (1e4 * y * y - 1.0);
    double f, df;
    hm_flange_force(&v, y, &f, &df);
    HM_CHECK_DELTA(f, ref, 1e-9 * (1.0 + fabs(ref)), "F_T(y)");
    const double dref = 1.6e11 * (5e4 * y * y * y * y - 3.0 * y * y);
    HM_CHECK_DELTA(df, dref, 1e-9 * (1.0 + fabs(dref)), "dF_T/dy");
  }
}

/* Analytic Jacobian against central differences at random states up to 15 mm and 2e-2 rad. */
static void jacobian_matches_finite_differences(void) {
  hm_vehicle v;
  hm_vehicle_default(&v);
  hm_model m;
  HM_CHECK(hm_model_init(&m, &v, 150.0) == HM_OK, "init");
  double worst = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    const double x[4] = {hm_test_uniform(-0.015, 0.015), hm_test_uniform(-0.5, 0.5), hm_test_uniform(-0.02, 0.02),
                         hm_test_uniform(-1.0, 1.0)};
    double J[16];
    HM_CHECK(hm_model_jacobian(0.0, x, J, &m) == HM_OK, "jacobian");
    for (int j = 0; j < 4; ++j) {
      const double scale[4] = {1e-7, 1e-5, 1e-7, 1e-5};
      double xp[4], xm[4], fp[4], fm[4];
      memcpy(xp, x, sizeof xp);
      memcpy(xm, x, sizeof xm);
      xp[j] += scale[j];
      xm[j] -= scale[j];
      hm_model_rhs(0.0, xp, fp, &m);
      hm_model_rhs(0.0, xm, fm, &m);
      for (int i = 0; i < 4; ++i) {
        const double fd = (fp[i] - fm[i]) / (2 * scale[j]);
        const double err = fabs(fd - J[4 * i + j]) / (1.0 + fabs(J[4 * i + j]));
        if (err > worst) worst = err;
      }
    }
  }
  HM_CHECK(worst < 1e-6, "worst relative Jacobian error %g", worst);
}

/* For the linear model f(x) = J x exactly, with J from MODEL.md section 2 written out here. */
static void linear_rhs_is_the_published_matrix(void) {
  hm_vehicle v, lin;
  hm_vehicle_default(&v);
  hm_vehicle_linearized(&v, &lin);
  const double speed = 140.0, lambda = 0.1358, m = 1869, I = 910, d0 = 0.7465, r0 = 0.43, k = 7.99e6, K = 8.96e6;
  const double A[16] = {0, 1, 0, 0,
                        -(K / m) * (1.351186 - 1) - K / m, -2 * k / (m * speed), 2 * k / m, 0,
                        0, 0, 0, 1,
                        -2 * d0 * k * lambda / (I * r0), 0, -K * 1.0 / I, -2 * d0 * d0 * k / (I * speed)};
  hm_model mdl;
  HM_CHECK(hm_model_init(&mdl, &lin, speed) == HM_OK, "init");
  const double x[4] = {0.003, -0.02, 0.001, 0.05};
  double f[4];
  HM_CHECK(hm_model_rhs(0.0, x, f, &mdl) == HM_OK, "rhs");
  for (int i = 0; i < 4; ++i) {
    double ref = 0.0;
    for (int j = 0; j < 4; ++j) ref += A[4 * i + j] * x[j];
    HM_CHECK_DELTA(f[i], ref, 1e-12 * (1.0 + fabs(ref)), "f_i(x)");
  }
  double f0[4];
  const double origin[4] = {0, 0, 0, 0};
  hm_model_init(&mdl, &v, speed);
  HM_CHECK(hm_model_rhs(0.0, origin, f0, &mdl) == HM_OK, "rhs");
  HM_CHECK(f0[0] == 0 && f0[1] == 0 && f0[2] == 0 && f0[3] == 0, "the origin is an equilibrium");
}

/* Each invalid field is rejected with its name in the message. */
static void validation_names_the_bad_field(void) {
  hm_vehicle v;
  char why[160];
#define EXPECT_REJECT(assign, field_name)                                                         \
  do {                                                                                            \
    hm_vehicle_default(&v);                                                                       \
    assign;                                                                                       \
    why[0] = '\0';                                                                                \
    HM_CHECK(hm_vehicle_validate(&v, why, sizeof why) == HM_EDOMAIN, "%s not rejected", #assign); \
    HM_CHECK(strstr(why, field_name) != NULL, "message '%s' does not name %s", why, field_name);  \
  } while (0)
  EXPECT_REJECT(v.mass_kg = -1869.0, "vehicle.mass_kg");
  EXPECT_REJECT(v.mass_kg = NAN, "vehicle.mass_kg");
  EXPECT_REJECT(v.yaw_inertia_kg_m2 = 0.0, "vehicle.yaw_inertia_kg_m2");
  EXPECT_REJECT(v.contact_half_distance_m = INFINITY, "vehicle.contact_half_distance_m");
  EXPECT_REJECT(v.spring_half_distance_m = -1.0, "vehicle.spring_half_distance_m");
  EXPECT_REJECT(v.rolling_radius_m = 0.0, "vehicle.rolling_radius_m");
  EXPECT_REJECT(v.creep_long_n = -7.99e6, "vehicle.creep_long_n");
  EXPECT_REJECT(v.creep_lat_n = NAN, "vehicle.creep_lat_n");
  EXPECT_REJECT(v.spring_ratio = 0.0, "vehicle.spring_ratio");
  EXPECT_REJECT(v.stiffness_long_n_m = 0.0, "vehicle.kx_mn_m");
  EXPECT_REJECT(v.stiffness_lat_n_m = -1.0, "vehicle.ky_mn_m");
  EXPECT_REJECT(v.conicity.constant = -0.1, "conicity.constant");
  EXPECT_REJECT(v.conicity.n_terms = 9, "conicity.gaussians");
  EXPECT_REJECT(v.conicity.terms[1].width_m = 0.0, "conicity.gaussians[1].width_m");
  EXPECT_REJECT(v.conicity.terms[0].amplitude = NAN, "conicity.gaussians[0].amplitude");
  EXPECT_REJECT(v.conicity.terms[0].center_m = INFINITY, "conicity.gaussians[0].center_m");
  EXPECT_REJECT(v.flange_alpha1_n_m3 = NAN, "flange.alpha1_n_m3");
  EXPECT_REJECT(v.flange_alpha2_n_m5 = -INFINITY, "flange.alpha2_n_m5");
#undef EXPECT_REJECT
  hm_vehicle_default(&v);
  v.stiffness_lat_n_m = 0.0;
  HM_CHECK(hm_vehicle_validate(&v, why, sizeof why) == HM_OK, "Ky = 0 is allowed (no lateral spring)");
  HM_CHECK(hm_vehicle_validate(NULL, why, sizeof why) == HM_EINVAL, "NULL vehicle");
}

/* Speed and state errors: status code, outputs untouched. */
static void model_rejects_bad_speed_and_state(void) {
  hm_vehicle v;
  hm_vehicle_default(&v);
  hm_model m;
  memset(&m, 0x5a, sizeof m);
  const hm_model before = m;
  HM_CHECK(hm_model_init(&m, &v, 0.0) == HM_EDOMAIN, "zero speed");
  HM_CHECK(hm_model_init(&m, &v, -3.0) == HM_EDOMAIN, "negative speed");
  HM_CHECK(hm_model_init(&m, &v, NAN) == HM_EDOMAIN, "NaN speed");
  HM_CHECK(memcmp(&m, &before, sizeof m) == 0, "model changed on failure");
  HM_CHECK(hm_model_init(&m, &v, 150.0) == HM_OK, "init");
  const double x[4] = {1e80, 0.0, 0.0, 0.0};
  double f[4] = {1, 2, 3, 4};
  HM_CHECK(hm_model_rhs(0.0, x, f, &m) == HM_ENONFINITE, "overflowing state gives HM_ENONFINITE");
  HM_CHECK(f[0] == 1 && f[1] == 2 && f[2] == 3 && f[3] == 4, "rhs output changed on failure");
  const double xn[4] = {NAN, 0.0, 0.0, 0.0};
  HM_CHECK(hm_model_rhs(0.0, xn, f, &m) == HM_ENONFINITE, "NaN state gives HM_ENONFINITE");
}

static void set_conicity_at_zero(void) {
  hm_vehicle v;
  hm_vehicle_default(&v);
  HM_CHECK(hm_vehicle_set_conicity_at_zero(&v, 0.2) == HM_OK, "set");
  double l0;
  hm_conicity_eval(&v.conicity, 0.0, &l0, NULL);
  HM_CHECK_DELTA(l0, 0.2, 1e-15, "lambda(0) after set");
  HM_CHECK(hm_vehicle_set_conicity_at_zero(&v, -0.1) == HM_EDOMAIN, "negative conicity");
  HM_CHECK(hm_vehicle_set_conicity_at_zero(&v, NAN) == HM_EDOMAIN, "NaN conicity");
}

/* Evenness of lambda(y) (the model's odd symmetry, which shooting uses to integrate half a period): the default
 * and the raw three-Gaussian fit of MODEL.md section 3 against lambda evaluated at +-y (the definition), and a
 * term moved off its mirror. */
static void conicity_evenness_matches_the_definition(void) {
  hm_vehicle v;
  hm_vehicle_default(&v);
  double worst = 0.0;
  for (int i = 1; i <= 200; ++i) {
    double lp, lm;
    hm_conicity_eval(&v.conicity, 1e-4 * i, &lp, NULL);
    hm_conicity_eval(&v.conicity, -1e-4 * i, &lm, NULL);
    worst = fmax(worst, fabs(lp - lm));
  }
  HM_CHECK(worst < 1e-15 && hm_conicity_is_even(&v.conicity, 1e-12), "default: even %d, worst |l(y) - l(-y)| %g",
           hm_conicity_is_even(&v.conicity, 1e-12), worst);
  hm_conicity raw = {0.0, 3, {{0.7099, 0.009884, 0.001472}, {0.6979, -0.009873, 0.001444}, {2.319e14, -18.3, 3.095}}};
  double lp, lm;
  hm_conicity_eval(&raw, 0.01, &lp, NULL);
  hm_conicity_eval(&raw, -0.01, &lm, NULL);
  HM_CHECK(fabs(lp - lm) > 1e-3 && !hm_conicity_is_even(&raw, 1e-12), "raw fit: l(0.01) %g, l(-0.01) %g", lp, lm);
  v.conicity.terms[1].center_m *= 1.01;
  HM_CHECK(!hm_conicity_is_even(&v.conicity, 1e-12), "a moved term");
}

int main(void) {
  HM_RUN(defaults_are_the_published_parameters);
  HM_RUN(flange_force_closed_form);
  HM_RUN(jacobian_matches_finite_differences);
  HM_RUN(linear_rhs_is_the_published_matrix);
  HM_RUN(validation_names_the_bad_field);
  HM_RUN(model_rejects_bad_speed_and_state);
  HM_RUN(set_conicity_at_zero);
  HM_RUN(conicity_evenness_matches_the_definition);
  HM_TEST_EXIT();
}
