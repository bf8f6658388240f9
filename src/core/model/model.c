/* The wheelset model: docs/MODEL.md sections 2 and 3. */
#include "hunting_monitor/model.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "validate.h"

void hm_vehicle_default(hm_vehicle *veh) {
  memset(veh, 0, sizeof *veh);
  veh->mass_kg = 1869.0;
  veh->yaw_inertia_kg_m2 = 910.0;
  veh->contact_half_distance_m = 0.7465;
  veh->spring_half_distance_m = 1.0;
  veh->rolling_radius_m = 0.43;
  veh->creep_long_n = 7.99e6;
  veh->creep_lat_n = 7.99e6;
  veh->spring_ratio = 1.351186;
  veh->stiffness_long_n_m = 8.96e6;
  veh->stiffness_lat_n_m = 8.96e6;
  /* Simplified symmetric fit of the measured conicity (docs/MODEL.md section 3). */
  veh->conicity.constant = 0.1358;
  veh->conicity.n_terms = 2;
  veh->conicity.terms[0] = (hm_gaussian){0.7, 0.01, 0.00145};
  veh->conicity.terms[1] = (hm_gaussian){0.7, -0.01, 0.00145};
  veh->flange_alpha1_n_m3 = -1.6e11;
  veh->flange_alpha2_n_m5 = 1.6e15;
}

hm_status hm_vehicle_validate(const hm_vehicle *veh, char *why, size_t why_len) {
  if (!veh) {
    if (why && why_len > 0) snprintf(why, why_len, "vehicle: NULL pointer");
    return HM_EINVAL;
  }
  const hm_field_check checks[] = {
      {"vehicle.mass_kg", veh->mass_kg, HM_RULE_POSITIVE, 0.0, 0.0},
      {"vehicle.yaw_inertia_kg_m2", veh->yaw_inertia_kg_m2, HM_RULE_POSITIVE, 0.0, 0.0},
      {"vehicle.contact_half_distance_m", veh->contact_half_distance_m, HM_RULE_POSITIVE, 0.0, 0.0},
      {"vehicle.spring_half_distance_m", veh->spring_half_distance_m, HM_RULE_POSITIVE, 0.0, 0.0},
      {"vehicle.rolling_radius_m", veh->rolling_radius_m, HM_RULE_RANGE, HM_R0_MIN_M, HM_R0_MAX_M},
      {"vehicle.creep_long_n", veh->creep_long_n, HM_RULE_POSITIVE, 0.0, 0.0},
      {"vehicle.creep_lat_n", veh->creep_lat_n, HM_RULE_POSITIVE, 0.0, 0.0},
      {"vehicle.spring_ratio", veh->spring_ratio, HM_RULE_POSITIVE, 0.0, 0.0},
      {"vehicle.kx_mn_m", veh->stiffness_long_n_m / 1e6, HM_RULE_POSITIVE, 0.0, 0.0},
      {"vehicle.ky_mn_m", veh->stiffness_lat_n_m / 1e6, HM_RULE_NONNEG, 0.0, 0.0},
      {"conicity.constant", veh->conicity.constant, HM_RULE_NONNEG, 0.0, 0.0},
  };
  hm_status st = hm_check_fields(checks, sizeof checks / sizeof checks[0], why, why_len);
  if (st != HM_OK) return st;
  if (veh->conicity.n_terms > HM_CONICITY_MAX_TERMS)
    return hm_reject(why, why_len, "conicity.gaussians", "too many terms (at most 8)", (double)veh->conicity.n_terms);
  for (size_t i = 0; i < veh->conicity.n_terms; ++i) {
    const hm_gaussian *g = &veh->conicity.terms[i];
    const char *part = NULL, *reason = "must be a finite number";
    double got = 0.0;
    if (!isfinite(g->amplitude)) {
      part = "amplitude";
      got = g->amplitude;
    } else if (!isfinite(g->center_m)) {
      part = "center_m";
      got = g->center_m;
    } else if (!isfinite(g->width_m) || g->width_m <= 0.0) {
      part = "width_m";
      reason = "must be finite and > 0";
      got = g->width_m;
    }
    if (part) {
      char field[64];
      snprintf(field, sizeof field, "conicity.gaussians[%zu].%s", i, part);
      return hm_reject(why, why_len, field, reason, got);
    }
  }
  if (!isfinite(veh->flange_alpha1_n_m3))
    return hm_reject(why, why_len, "flange.alpha1_n_m3", "must be a finite number", veh->flange_alpha1_n_m3);
  if (!isfinite(veh->flange_alpha2_n_m5))
    return hm_reject(why, why_len, "flange.alpha2_n_m5", "must be a finite number", veh->flange_alpha2_n_m5);
  return HM_OK;
}

void hm_conicity_eval(const hm_conicity *con, double y_m, double *lambda, double *dlambda_dy) {
  double l = con->constant, dl = 0.0;
  for (size_t i = 0; i < con->n_terms; ++i) {
    const hm_gaussian *g = &con->terms[i];
    const double u = (y_m - g->center_m) / g->width_m;
    const double e = g->amplitude * exp(-u * u);
    l += e;
    dl += -2.0 * u / g->width_m * e;
  }
  if (lambda) *lambda = l;
  if (dlambda_dy) *dlambda_dy = dl;
}

void hm_conicity_derivatives(const hm_conicity *con, double y_m, int kmax, double *d) {
  if (kmax > 8) kmax = 8;
  for (int j = 0; j <= kmax; ++j) d[j] = 0.0;
  d[0] = con->constant;
  for (size_t i = 0; i < con->n_terms; ++i) {
    const hm_gaussian *g = &con->terms[i];
    const double u = (y_m - g->center_m) / g->width_m;
    const double e = g->amplitude * exp(-u * u);
    double h_prev = 1.0, h = 2.0 * u, scale = 1.0; /* H_0, H_1, c^-j */
    d[0] += e;
    for (int j = 1; j <= kmax; ++j) {
      scale /= -g->width_m;
      d[j] += h * scale * e;
      const double h_next = 2.0 * u * h - 2.0 * j * h_prev;
      h_prev = h;
      h = h_next;
    }
  }
}

void hm_vehicle_linearized(const hm_vehicle *veh, hm_vehicle *linear) {
  hm_vehicle out = *veh;
  double lambda0;
  hm_conicity_eval(&veh->conicity, 0.0, &lambda0, NULL);
  memset(&out.conicity, 0, sizeof out.conicity);
  out.conicity.constant = lambda0;
  out.flange_alpha1_n_m3 = 0.0;
  out.flange_alpha2_n_m5 = 0.0;
  *linear = out;
}

hm_status hm_vehicle_set_conicity_at_zero(hm_vehicle *veh, double conicity0) {
  if (!veh) return HM_EINVAL;
  if (!isfinite(conicity0) || conicity0 < 0.0) return HM_EDOMAIN;
  double lambda0;
  hm_conicity_eval(&veh->conicity, 0.0, &lambda0, NULL);
  const double constant = veh->conicity.constant + (conicity0 - lambda0);
  if (constant < 0.0) return HM_EDOMAIN; /* the Gaussians alone exceed the requested lambda(0) */
  veh->conicity.constant = constant;
  return HM_OK;
}

void hm_flange_force(const hm_vehicle *veh, double y_m, double *force_n, double *dforce_dy) {
  const double y2 = y_m * y_m;
  if (force_n) *force_n = y_m * y2 * (veh->flange_alpha1_n_m3 + veh->flange_alpha2_n_m5 * y2);
  if (dforce_dy) *dforce_dy = y2 * (3.0 * veh->flange_alpha1_n_m3 + 5.0 * veh->flange_alpha2_n_m5 * y2);
}

void hm_linear_coef_from_vehicle(const hm_vehicle *veh, hm_linear_coef *coef) {
  const double m = veh->mass_kg, I = veh->yaw_inertia_kg_m2;
  const double d0 = veh->contact_half_distance_m, d1 = veh->spring_half_distance_m;
  const double Kx = veh->stiffness_long_n_m, Ky = veh->stiffness_lat_n_m;
  coef->k_lat_s2 = (Kx / m) * (veh->spring_ratio - 1.0) + Ky / m;
  coef->k_yaw_s2 = Kx * d1 * d1 / I;
  coef->c_lat_m_s2 = 2.0 * veh->creep_lat_n / m;
  coef->c_yaw_m_s2 = 2.0 * d0 * d0 * veh->creep_long_n / I;
  coef->e_yaw_m_s2 = 2.0 * d0 * veh->creep_long_n / (I * veh->rolling_radius_m);
  coef->f1_m2_s2 = veh->flange_alpha1_n_m3 / m;
  coef->f2_m4_s2 = veh->flange_alpha2_n_m5 / m;
}

const char *hm_param_name(hm_param p) {
  switch (p) {
    case HM_PARAM_SPEED: return "v_kmh";
    case HM_PARAM_KX: return "kx_mn_m";
    case HM_PARAM_KY: return "ky_mn_m";
    case HM_PARAM_CONICITY: return "conicity";
  }
  return NULL;
}

hm_status hm_param_from_name(const char *name, hm_param *p) {
  static const struct {
    const char *name;
    hm_param p;
  } names[] = {{"v", HM_PARAM_SPEED},   {"v_kmh", HM_PARAM_SPEED}, {"kx", HM_PARAM_KX},
               {"kx_mn_m", HM_PARAM_KX}, {"ky", HM_PARAM_KY},       {"ky_mn_m", HM_PARAM_KY},
               {"conicity", HM_PARAM_CONICITY}};
  if (!name || !p) return HM_EINVAL;
  for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i)
    if (strcmp(name, names[i].name) == 0) {
      *p = names[i].p;
      return HM_OK;
    }
  return HM_EINVAL;
}

double hm_param_get(const hm_vehicle *veh, double speed_kmh, hm_param p) {
  double l0;
  switch (p) {
    case HM_PARAM_SPEED: return speed_kmh;
    case HM_PARAM_KX: return veh->stiffness_long_n_m / 1e6;
    case HM_PARAM_KY: return veh->stiffness_lat_n_m / 1e6;
    case HM_PARAM_CONICITY: hm_conicity_eval(&veh->conicity, 0.0, &l0, NULL); return l0;
  }
  return NAN;
}

hm_status hm_param_set(hm_vehicle *veh, double *speed_kmh, hm_param p, double value) {
  if (!veh || !speed_kmh) return HM_EINVAL;
  if (!isfinite(value)) return HM_EDOMAIN;
  switch (p) {
    case HM_PARAM_SPEED:
      if (value <= 0.0) return HM_EDOMAIN;
      *speed_kmh = value;
      return HM_OK;
    case HM_PARAM_KX:
      if (value <= 0.0) return HM_EDOMAIN;
      veh->stiffness_long_n_m = value * 1e6;
      return HM_OK;
    case HM_PARAM_KY:
      if (value < 0.0) return HM_EDOMAIN;
      veh->stiffness_lat_n_m = value * 1e6;
      return HM_OK;
    case HM_PARAM_CONICITY: return hm_vehicle_set_conicity_at_zero(veh, value);
  }
  return HM_EINVAL;
}

void hm_model_dparam(const hm_model *mdl, hm_param p, const double *x, double *dfdp) {
  const hm_vehicle *v = &mdl->vehicle;
  const double speed = mdl->speed_mps;
  dfdp[0] = dfdp[1] = dfdp[2] = dfdp[3] = 0.0;
  switch (p) {
    case HM_PARAM_SPEED: /* d/dV of -c/v terms, v = V/3.6 */
      dfdp[1] = mdl->coef.c_lat_m_s2 / (speed * speed) * x[1] / 3.6;
      dfdp[3] = mdl->coef.c_yaw_m_s2 / (speed * speed) * x[3] / 3.6;
      break;
    case HM_PARAM_KX:
      dfdp[1] = -1e6 * (v->spring_ratio - 1.0) / v->mass_kg * x[0];
      dfdp[3] = -1e6 * v->spring_half_distance_m * v->spring_half_distance_m / v->yaw_inertia_kg_m2 * x[2];
      break;
    case HM_PARAM_KY: dfdp[1] = -1e6 / v->mass_kg * x[0]; break;
    case HM_PARAM_CONICITY: dfdp[3] = -mdl->coef.e_yaw_m_s2 * x[0]; break;
  }
}

hm_status hm_model_init(hm_model *mdl, const hm_vehicle *veh, double speed_mps) {
  if (!mdl || !veh) return HM_EINVAL;
  hm_status st = hm_vehicle_validate(veh, NULL, 0);
  if (st != HM_OK) return st;
  if (!isfinite(speed_mps) || speed_mps <= 0.0) return HM_EDOMAIN;
  mdl->vehicle = *veh;
  hm_linear_coef_from_vehicle(veh, &mdl->coef);
  mdl->speed_mps = speed_mps;
  return HM_OK;
}

hm_status hm_model_rhs(double t, const double *x, double *dxdt, void *model) {
  (void)t;
  const hm_model *mdl = (const hm_model *)model;
  return hm_model_rhs_at(mdl, mdl->speed_mps, x, dxdt);
}

hm_status hm_model_rhs_at(const hm_model *mdl, double speed_mps, const double *x, double *dxdt) {
  const hm_linear_coef *c = &mdl->coef;
  const double inv_v = 1.0 / speed_mps;
  const double y = x[0], y2 = y * y;
  double lambda;
  hm_conicity_eval(&mdl->vehicle.conicity, y, &lambda, NULL);
  const double flange = y * y2 * (c->f1_m2_s2 + c->f2_m4_s2 * y2); /* F_T(y)/m */
  const double d1 = x[1];
  const double d2 = -c->k_lat_s2 * y - c->c_lat_m_s2 * inv_v * x[1] + c->c_lat_m_s2 * x[2] - flange;
  const double d3 = x[3];
  const double d4 = -c->e_yaw_m_s2 * lambda * y - c->k_yaw_s2 * x[2] - c->c_yaw_m_s2 * inv_v * x[3];
  if (!isfinite(d2) || !isfinite(d4) || !isfinite(d1) || !isfinite(d3)) return HM_ENONFINITE;
  dxdt[0] = d1;
  dxdt[1] = d2;
  dxdt[2] = d3;
  dxdt[3] = d4;
  return HM_OK;
}

hm_status hm_model_jacobian(double t, const double *x, double *jac, void *model) {
  (void)t;
  const hm_model *mdl = (const hm_model *)model;
  return hm_model_jacobian_at(mdl, mdl->speed_mps, x, jac);
}

hm_status hm_model_jacobian_at(const hm_model *mdl, double speed_mps, const double *x, double *jac) {
  const hm_linear_coef *c = &mdl->coef;
  const double inv_v = 1.0 / speed_mps;
  const double y = x[0], y2 = y * y;
  double lambda, dlambda;
  hm_conicity_eval(&mdl->vehicle.conicity, y, &lambda, &dlambda);
  const double dflange = y2 * (3.0 * c->f1_m2_s2 + 5.0 * c->f2_m4_s2 * y2);
  const double j10 = -c->k_lat_s2 - dflange;
  const double j30 = -c->e_yaw_m_s2 * (lambda + dlambda * y);
  if (!isfinite(j10) || !isfinite(j30)) return HM_ENONFINITE;
  const double J[16] = {
      0.0, 1.0, 0.0, 0.0,
      j10, -c->c_lat_m_s2 * inv_v, c->c_lat_m_s2, 0.0,
      0.0, 0.0, 0.0, 1.0,
      j30, 0.0, -c->k_yaw_s2, -c->c_yaw_m_s2 * inv_v,
  };
  memcpy(jac, J, sizeof J);
  return HM_OK;
}

int hm_conicity_is_even(const hm_conicity *con, double tol) {
  for (size_t i = 0; i < con->n_terms; ++i) {
    const hm_gaussian *g = &con->terms[i];
    if (g->center_m == 0.0) continue;
    int mirrored = 0;
    for (size_t j = 0; j < con->n_terms && !mirrored; ++j) {
      const hm_gaussian *h = &con->terms[j];
      mirrored = fabs(h->center_m + g->center_m) <= tol * fabs(g->center_m) &&
                 fabs(h->amplitude - g->amplitude) <= tol * fabs(g->amplitude) &&
                 fabs(h->width_m - g->width_m) <= tol * g->width_m;
    }
    if (!mirrored) return 0;
  }
  return 1;
}
