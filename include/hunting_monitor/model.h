/*
 * hunting_monitor - the nonlinear wheelset model of docs/MODEL.md sections 2 and 3.
 *
 * States (SI): x[0] = y lateral displacement [m], x[1] = dy/dt [m/s],
 *              x[2] = psi yaw angle [rad],       x[3] = dpsi/dt [rad/s].
 *   x1' = x2
 *   x2' = -(Kx/m)(l0/l1 - 1) x1 - (Ky/m) x1 - (2 ky/(m v)) x2 + (2 ky/m) x3 - F_T(x1)/m
 *   x3' = x4
 *   x4' = -(2 d0 kx lambda(x1)/(I r0)) x1 - (Kx d1^2/I) x3 - (2 d0^2 kx/(I v)) x4
 * with lambda(y) = constant + sum_i a_i exp(-((y - b_i)/c_i)^2) and F_T(y) = alpha1 y^3 + alpha2 y^5.
 * The linear model is the special case without Gaussian terms and with alpha1 = alpha2 = 0
 * (see hm_vehicle_linearized).
 */
#ifndef HUNTING_MONITOR_MODEL_H
#define HUNTING_MONITOR_MODEL_H

#include <stddef.h>

#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HM_STATE_DIM 4
#define HM_PI 3.14159265358979323846
#define HM_CONICITY_MAX_TERMS 8

/* One term a exp(-((y - b)/c)^2) of the equivalent-conicity function. */
typedef struct {
  double amplitude;  /* a, dimensionless */
  double center_m;   /* b [m] */
  double width_m;    /* c [m], > 0 */
} hm_gaussian;

/* Equivalent conicity lambda(y) = constant + sum of n_terms Gaussians (dimensionless). */
typedef struct {
  double constant;
  size_t n_terms;
  hm_gaussian terms[HM_CONICITY_MAX_TERMS];
} hm_conicity;

/* Vehicle (wheelset) parameters, SI units throughout. Plain data: fill it, then hm_vehicle_validate. */
typedef struct {
  double mass_kg;                 /* m, wheelset mass */
  double yaw_inertia_kg_m2;       /* I, wheelset yaw moment of inertia */
  double contact_half_distance_m; /* d0, half distance between wheel-rail contact points */
  double spring_half_distance_m;  /* d1, half lateral distance between primary longitudinal springs */
  double rolling_radius_m;        /* r0, nominal rolling radius */
  double creep_long_n;            /* kx, longitudinal creep coefficient [N] */
  double creep_lat_n;             /* ky, lateral creep coefficient [N] */
  double spring_ratio;            /* l0/l1, geometric ratio of the longitudinal-spring term (dimensionless) */
  double stiffness_long_n_m;      /* Kx, primary longitudinal stiffness [N/m] */
  double stiffness_lat_n_m;       /* Ky, primary lateral stiffness [N/m] */
  hm_conicity conicity;           /* lambda(y) */
  double flange_alpha1_n_m3;      /* alpha1 of F_T [N/m^3] */
  double flange_alpha2_n_m5;      /* alpha2 of F_T [N/m^5] */
} hm_vehicle;

/* Coefficients of the linear part of the model, derived from an hm_vehicle (docs/MODEL.md section 2). */
typedef struct {
  double k_lat_s2;     /* (Kx/m)(l0/l1 - 1) + Ky/m [1/s^2] */
  double k_yaw_s2;     /* Kx d1^2 / I [1/s^2] */
  double c_lat_m_s2;   /* 2 ky / m [m/s^2]; lateral damping is c_lat/v [1/s], yaw coupling 2 ky/m [m/(s^2 rad)] */
  double c_yaw_m_s2;   /* 2 d0^2 kx / I [m/s^2]; yaw damping is c_yaw/v [1/s] */
  double e_yaw_m_s2;   /* 2 d0 kx / (I r0) [1/(m s^2)], multiplied by the conicity */
  double f1_m2_s2;     /* alpha1 / m [1/(m^2 s^2)] */
  double f2_m4_s2;     /* alpha2 / m [1/(m^4 s^2)] */
} hm_linear_coef;

/* The model at one running speed: what the right-hand side and Jacobian callbacks take as params. */
typedef struct {
  hm_vehicle vehicle;
  hm_linear_coef coef;
  double speed_mps;    /* v [m/s], > 0 */
} hm_model;

/* The shipped CRH380-class defaults of docs/MODEL.md sections 2 and 3 (Kx = Ky = 8.96 MN/m, simplified fit). */
void hm_vehicle_default(hm_vehicle *veh);

/*
 * Check every field: finite, masses, inertia, distances, creep coefficients, l0/l1 and Kx > 0, the rolling radius in
 * [0.1, 1] m, Ky >= 0, conicity constant >= 0, n_terms <= HM_CONICITY_MAX_TERMS, Gaussian widths > 0.
 * On failure returns HM_EDOMAIN and writes "field: reason (got value)" into why (if why != NULL);
 * field names are those of the YAML config (e.g. "vehicle.mass_kg").
 */
hm_status hm_vehicle_validate(const hm_vehicle *veh, char *why, size_t why_len);

/* Copy of veh with lambda(y) replaced by the constant lambda(0) and no flange force: the linear model. */
void hm_vehicle_linearized(const hm_vehicle *veh, hm_vehicle *linear);

/* Shift the conicity constant so that lambda(0) = conicity0 (keeps the Gaussian shape). */
hm_status hm_vehicle_set_conicity_at_zero(hm_vehicle *veh, double conicity0);

/* lambda(y) and dlambda/dy [1/m]; either output may be NULL. */
void hm_conicity_eval(const hm_conicity *con, double y_m, double *lambda, double *dlambda_dy);

/* Whether lambda(y) is even (every Gaussian term has a mirror term with equal amplitude and width) so that
 * the model is odd-symmetric; relative tolerance tol on the term values. */
int hm_conicity_is_even(const hm_conicity *con, double tol);

/* Derivatives d^j lambda / dy^j at y for j = 0..kmax (kmax <= 8) into d[0..kmax], by Hermite polynomials:
 * d^j/dy^j exp(-u^2) = (-1)^j H_j(u) exp(-u^2) / c^j with u = (y - b)/c. */
void hm_conicity_derivatives(const hm_conicity *con, double y_m, int kmax, double *d);

/* F_T(y) [N] and dF_T/dy [N/m]; either output may be NULL. */
void hm_flange_force(const hm_vehicle *veh, double y_m, double *force_n, double *dforce_dy);

/* Derive the linear coefficients (no validation: call hm_vehicle_validate first). */
void hm_linear_coef_from_vehicle(const hm_vehicle *veh, hm_linear_coef *coef);

/* The parameters a bifurcation analysis can vary, in user units. */
typedef enum {
  HM_PARAM_SPEED = 0,    /* running speed V [km/h] */
  HM_PARAM_KX = 1,       /* primary longitudinal stiffness Kx [MN/m] */
  HM_PARAM_KY = 2,       /* primary lateral stiffness Ky [MN/m] */
  HM_PARAM_CONICITY = 3  /* equivalent conicity at y = 0, lambda(0) (shifts the constant term) */
} hm_param;

/* "v_kmh", "kx_mn_m", "ky_mn_m", "conicity"; NULL for an unknown parameter. */
const char *hm_param_name(hm_param p);
/* Parse one of the names above or the short forms "v", "kx", "ky", "conicity"; HM_EINVAL if unknown. */
hm_status hm_param_from_name(const char *name, hm_param *p);
/* Value of parameter p of (veh, speed_kmh) in user units. */
double hm_param_get(const hm_vehicle *veh, double speed_kmh, hm_param p);
/* Set parameter p to value (user units) in *veh or *speed_kmh. HM_EDOMAIN for a non-finite or out-of-domain
 * value (speed or Kx <= 0, Ky or conicity < 0); outputs untouched on failure. */
hm_status hm_param_set(hm_vehicle *veh, double *speed_kmh, hm_param p, double value);
/* df/dp at state x for the model mdl, with p in user units (per km/h, per MN/m, per unit conicity). */
void hm_model_dparam(const hm_model *mdl, hm_param p, const double *x, double *dfdp);

/* Validate veh and speed (finite, > 0) and fill mdl. mdl untouched on failure. */
hm_status hm_model_init(hm_model *mdl, const hm_vehicle *veh, double speed_mps);

/*
 * Right-hand side f(x) of the model; signature of an hm_ode_fn (params = hm_model *).
 * t is unused (the model is autonomous). Returns HM_ENONFINITE if a derivative is not finite.
 */
hm_status hm_model_rhs(double t, const double *x, double *dxdt, void *model);

/* Analytic Jacobian df/dx, row-major 4x4 (jac[4*i + j] = d f_i / d x_j); signature of an hm_ode_jac_fn. */
hm_status hm_model_jacobian(double t, const double *x, double *jac, void *model);

/* The same two at speed_mps instead of mdl->speed_mps (system.h's wheelset: one model, any speed). */
hm_status hm_model_rhs_at(const hm_model *mdl, double speed_mps, const double *x, double *dxdt);
hm_status hm_model_jacobian_at(const hm_model *mdl, double speed_mps, const double *x, double *jac);

#ifdef __cplusplus
}
#endif

#endif
