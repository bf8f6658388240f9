/* The two-axle bogie: its equations, analytic Jacobian and its place as a system (see bogie.h). */
#include "hunting_monitor/bogie.h"

#include <math.h>
#include <string.h>

#include "validate.h"

void hm_bogie_default(hm_bogie *b) {
  memset(b, 0, sizeof *b);
  hm_vehicle_default(&b->wheelset);
  b->frame_mass_kg = 2600.0;
  b->frame_yaw_inertia_kg_m2 = 1800.0;
  b->half_wheelbase_m = 1.25;
  b->secondary_lat_stiffness_n_m = 0.25e6;
  b->secondary_lat_damping_n_s_m = 30e3;
  b->airspring_long_stiffness_n_m = 0.15e6;
  b->airspring_half_distance_m = 1.0;
  b->yaw_damper_damping_n_s_m = 1e6;
  b->yaw_damper_stiffness_n_m = 50e6;
  b->yaw_damper_half_distance_m = 1.3;
}

hm_status hm_bogie_validate(const hm_bogie *b, char *why, size_t why_len) {
  if (!b) {
    (void)hm_reject(why, why_len, "bogie", "NULL pointer", 0.0);
    return HM_EINVAL;
  }
  hm_status st = hm_vehicle_validate(&b->wheelset, why, why_len);
  if (st != HM_OK) return st;
  const hm_field_check checks[] = {
      {"bogie.frame_mass_kg", b->frame_mass_kg, HM_RULE_POSITIVE, 0.0, 0.0},
      {"bogie.frame_yaw_inertia_kg_m2", b->frame_yaw_inertia_kg_m2, HM_RULE_POSITIVE, 0.0, 0.0},
      {"bogie.half_wheelbase_m", b->half_wheelbase_m, HM_RULE_POSITIVE, 0.0, 0.0},
      {"bogie.secondary_lat_stiffness_n_m", b->secondary_lat_stiffness_n_m, HM_RULE_NONNEG, 0.0, 0.0},
      {"bogie.secondary_lat_damping_n_s_m", b->secondary_lat_damping_n_s_m, HM_RULE_NONNEG, 0.0, 0.0},
      {"bogie.airspring_long_stiffness_n_m", b->airspring_long_stiffness_n_m, HM_RULE_NONNEG, 0.0, 0.0},
      {"bogie.airspring_half_distance_m", b->airspring_half_distance_m, HM_RULE_POSITIVE, 0.0, 0.0},
      {"bogie.yaw_damper_damping_n_s_m", b->yaw_damper_damping_n_s_m, HM_RULE_POSITIVE, 0.0, 0.0},
      {"bogie.yaw_damper_stiffness_n_m", b->yaw_damper_stiffness_n_m, HM_RULE_POSITIVE, 0.0, 0.0},
      {"bogie.yaw_damper_half_distance_m", b->yaw_damper_half_distance_m, HM_RULE_POSITIVE, 0.0, 0.0},
  };
  return hm_check_fields(checks, sizeof checks / sizeof checks[0], why, why_len);
}

static const char *const BOGIE_BODIES[] = {"wheelsets", "bogie frame"};

static hm_status sys_rhs(const void *model, double v, const double *x, double *dx) {
  return hm_bogie_rhs((const hm_bogie_model *)model, v, x, NULL, dx);
}

static hm_status sys_jac(const void *model, double v, const double *x, double *jac) {
  return hm_bogie_jacobian((const hm_bogie_model *)model, v, x, jac);
}

static hm_status sys_dfdv(const void *model, double v, const double *x, double *dfdv) {
  return hm_bogie_dfdv((const hm_bogie_model *)model, v, x, dfdv);
}

static hm_status sys_rhs_track(const void *model, double v, const double *x, const double *yt, double *dx) {
  return hm_bogie_rhs((const hm_bogie_model *)model, v, x, yt, dx);
}

hm_status hm_bogie_sensor(const hm_bogie_model *m, const char *where, hm_sensor_point *out) {
  if (!m || !where || !out) return HM_EINVAL;
  if (strcmp(where, "axlebox") == 0) {
    *out = (hm_sensor_point){1, {1, 0, 0, 0}, {1.0, 0.0, 0.0, 0.0}};
    return HM_OK;
  }
  if (strcmp(where, "frame") == 0 && !m->frame_held) {
    *out = (hm_sensor_point){2, {9, 11, 0, 0}, {1.0, m->bogie.half_wheelbase_m, 0.0, 0.0}};
    return HM_OK;
  }
  return HM_EINVAL;
}

hm_status hm_bogie_dfdv(const hm_bogie_model *m, double v, const double *x, double *dfdv) {
  const size_t n = m->frame_held ? HM_BOGIE_HELD_DIM : HM_BOGIE_DIM;
  const double iv2 = 1.0 / (v * v);
  for (size_t i = 0; i < n; ++i) dfdv[i] = 0.0;
  for (int i = 0; i < 2; ++i) {
    dfdv[4 * i + 1] = m->coef.c_lat_m_s2 * iv2 * x[4 * i + 1];
    dfdv[4 * i + 3] = m->coef.c_yaw_m_s2 * iv2 * x[4 * i + 3];
  }
  for (size_t i = 0; i < n; ++i)
    if (!isfinite(dfdv[i])) return HM_ENONFINITE;
  return HM_OK;
}

hm_status hm_bogie_model_init(hm_bogie_model *m, const hm_bogie *bogie, int frame_held, hm_system *sys) {
  if (!m || !bogie || !sys) return HM_EINVAL;
  hm_status st = hm_bogie_validate(bogie, NULL, 0);
  if (st != HM_OK) return st;
  hm_bogie_model w;
  memset(&w, 0, sizeof w);
  w.bogie = *bogie;
  hm_linear_coef_from_vehicle(&bogie->wheelset, &w.coef);
  w.frame_held = frame_held != 0;
  const double mw = bogie->wheelset.mass_kg, iw = bogie->wheelset.yaw_inertia_kg_m2;
  const double inertia[HM_BOGIE_DIM] = {0, mw, 0, iw, 0, mw, 0, iw, 0, bogie->frame_mass_kg, 0,
                                        bogie->frame_yaw_inertia_kg_m2, 0};
  const int body[HM_BOGIE_DIM] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, -1};
  const double scale[HM_BOGIE_DIM] = {1e-3, 0.1, 1e-3, 0.1, 1e-3, 0.1, 1e-3, 0.1, 1e-3, 0.1, 1e-3, 0.1, 1e-3};
  memcpy(w.inertia, inertia, sizeof inertia);
  memcpy(w.scale, scale, sizeof scale);
  memcpy(w.body, body, sizeof body);
  w.x_m[0] = bogie->half_wheelbase_m;
  w.x_m[1] = -bogie->half_wheelbase_m;
  w.y_state[0] = 0;
  w.y_state[1] = 4;
  *m = w;
  *sys = (hm_system){m->frame_held ? HM_BOGIE_HELD_DIM : HM_BOGIE_DIM, sys_rhs, sys_jac, sys_dfdv, m, 2,
                     BOGIE_BODIES, m->body, m->inertia, m->scale, 0, 1,
                     hm_conicity_is_even(&bogie->wheelset.conicity, 1e-12), sys_rhs_track, 2, m->x_m, m->y_state};
  return HM_OK;
}

hm_status hm_bogie_rhs(const hm_bogie_model *m, double v, const double *x, const double *y_track_m, double *dxdt) {
  static const double at_rest[4] = {0.0, 0.0, 0.0, 0.0};
  double f, mz;
  return hm_bogie_rhs_under(m, v, x, y_track_m, at_rest, dxdt, &f, &mz);
}

hm_status hm_bogie_rhs_under(const hm_bogie_model *m, double v, const double *x, const double *y_track_m,
                             const double att[4], double *dxdt, double *force_on_car_n, double *moment_on_car_nm) {
  const hm_bogie *b = &m->bogie;
  const hm_linear_coef *c = &m->coef;
  const double mw = b->wheelset.mass_kg, ky_s2 = b->wheelset.stiffness_lat_n_m / mw;
  const double kg_s2 = c->k_lat_s2 - ky_s2, inv_v = 1.0 / v;
  const double ky = b->wheelset.stiffness_lat_n_m, kyaw = b->wheelset.stiffness_long_n_m *
                                                          b->wheelset.spring_half_distance_m *
                                                          b->wheelset.spring_half_distance_m;
  const double yf = m->frame_held ? 0.0 : x[8], psif = m->frame_held ? 0.0 : x[10];
  const double xs[2] = {b->half_wheelbase_m, -b->half_wheelbase_m};
  double dx[HM_BOGIE_DIM], fy = 0.0, mz = 0.0;
  for (int i = 0; i < 2; ++i) {
    const double *w = x + 4 * i;
    double *d = dx + 4 * i;
    const double r = w[0] - (y_track_m ? y_track_m[i] : 0.0), r2 = r * r;
    const double q = w[0] - yf - xs[i] * psif;
    double lambda;
    hm_conicity_eval(&b->wheelset.conicity, r, &lambda, NULL);
    const double flange = r * r2 * (c->f1_m2_s2 + c->f2_m4_s2 * r2); /* F_T(r)/m */
    d[0] = w[1];
    d[1] = -c->c_lat_m_s2 * inv_v * w[1] + c->c_lat_m_s2 * w[2] - kg_s2 * w[0] - ky_s2 * q - flange;
    d[2] = w[3];
    d[3] = -c->e_yaw_m_s2 * lambda * r - c->c_yaw_m_s2 * inv_v * w[3] - c->k_yaw_s2 * (w[2] - psif);
    fy += ky * q;
    mz += xs[i] * ky * q + kyaw * (w[2] - psif);
  }
  size_t n = HM_BOGIE_HELD_DIM;
  double f_car = 0.0, m_car = 0.0;
  if (!m->frame_held) {
    const double dd = b->yaw_damper_half_distance_m, kd = b->yaw_damper_stiffness_n_m;
    const double rel_psi = psif - att[2];
    const double damper = kd * (dd * rel_psi - x[12]); /* the force in each yaw damper */
    const double ka_yaw = 2.0 * b->airspring_long_stiffness_n_m * b->airspring_half_distance_m *
                          b->airspring_half_distance_m;
    f_car = b->secondary_lat_stiffness_n_m * (yf - att[0]) + b->secondary_lat_damping_n_s_m * (x[9] - att[1]);
    m_car = ka_yaw * rel_psi + 2.0 * dd * damper;
    dx[8] = x[9];
    dx[9] = (fy - f_car) / b->frame_mass_kg;
    dx[10] = x[11];
    dx[11] = (mz - m_car) / b->frame_yaw_inertia_kg_m2;
    dx[12] = damper / b->yaw_damper_damping_n_s_m;
    n = HM_BOGIE_DIM;
  }
  for (size_t i = 0; i < n; ++i)
    if (!isfinite(dx[i])) return HM_ENONFINITE;
  memcpy(dxdt, dx, n * sizeof(double));
  *force_on_car_n = f_car;
  *moment_on_car_nm = m_car;
  return HM_OK;
}

hm_status hm_bogie_jacobian(const hm_bogie_model *m, double v, const double *x, double *jac) {
  const hm_bogie *b = &m->bogie;
  const hm_linear_coef *c = &m->coef;
  const size_t n = m->frame_held ? HM_BOGIE_HELD_DIM : HM_BOGIE_DIM;
  const double mw = b->wheelset.mass_kg, ky = b->wheelset.stiffness_lat_n_m, ky_s2 = ky / mw;
  const double kg_s2 = c->k_lat_s2 - ky_s2, inv_v = 1.0 / v;
  const double kyaw = b->wheelset.stiffness_long_n_m * b->wheelset.spring_half_distance_m *
                      b->wheelset.spring_half_distance_m;
  const double xs[2] = {b->half_wheelbase_m, -b->half_wheelbase_m};
  double J[HM_BOGIE_DIM * HM_BOGIE_DIM];
  memset(J, 0, sizeof J);
#define AT(i, j) J[n * (size_t)(i) + (size_t)(j)]
  for (int i = 0; i < 2; ++i) {
    const int o = 4 * i;
    const double r = x[o], r2 = r * r;
    double lambda, dlambda;
    hm_conicity_eval(&b->wheelset.conicity, r, &lambda, &dlambda);
    const double dflange = r2 * (3.0 * c->f1_m2_s2 + 5.0 * c->f2_m4_s2 * r2);
    AT(o, o + 1) = 1.0;
    AT(o + 1, o) = -kg_s2 - ky_s2 - dflange;
    AT(o + 1, o + 1) = -c->c_lat_m_s2 * inv_v;
    AT(o + 1, o + 2) = c->c_lat_m_s2;
    AT(o + 2, o + 3) = 1.0;
    AT(o + 3, o) = -c->e_yaw_m_s2 * (lambda + dlambda * r);
    AT(o + 3, o + 2) = -c->k_yaw_s2;
    AT(o + 3, o + 3) = -c->c_yaw_m_s2 * inv_v;
    if (!m->frame_held) {
      AT(o + 1, 8) = ky_s2;
      AT(o + 1, 10) = ky_s2 * xs[i];
      AT(o + 3, 10) = c->k_yaw_s2;
    }
  }
  if (!m->frame_held) {
    const double mf = b->frame_mass_kg, jf = b->frame_yaw_inertia_kg_m2;
    const double dd = b->yaw_damper_half_distance_m, kd = b->yaw_damper_stiffness_n_m, cd = b->yaw_damper_damping_n_s_m;
    const double ka_yaw = 2.0 * b->airspring_long_stiffness_n_m * b->airspring_half_distance_m *
                          b->airspring_half_distance_m;
    AT(8, 9) = 1.0;
    AT(10, 11) = 1.0;
    double dyf = -b->secondary_lat_stiffness_n_m, dpsif_lat = 0.0, dyf_yaw = 0.0;
    double dpsif_yaw = -ka_yaw - 2.0 * dd * dd * kd;
    for (int i = 0; i < 2; ++i) {
      const int o = 4 * i;
      AT(9, o) = ky / mf;
      AT(11, o) = xs[i] * ky / jf;
      AT(11, o + 2) = kyaw / jf;
      dyf -= ky;
      dpsif_lat -= ky * xs[i];
      dyf_yaw -= xs[i] * ky;
      dpsif_yaw -= xs[i] * xs[i] * ky + kyaw;
    }
    AT(9, 8) = dyf / mf;
    AT(9, 9) = -b->secondary_lat_damping_n_s_m / mf;
    AT(9, 10) = dpsif_lat / mf;
    AT(11, 8) = dyf_yaw / jf;
    AT(11, 10) = dpsif_yaw / jf;
    AT(11, 12) = 2.0 * dd * kd / jf;
    AT(12, 10) = kd * dd / cd;
    AT(12, 12) = -kd / cd;
  }
#undef AT
  for (size_t i = 0; i < n * n; ++i)
    if (!isfinite(J[i])) return HM_ENONFINITE;
  memcpy(jac, J, n * n * sizeof(double));
  return HM_OK;
}
