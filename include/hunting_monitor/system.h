/*
 * hunting_monitor - a vehicle model of any state dimension, and its linear stability at the origin (issue #28).
 *
 * A model is its state dimension, its right-hand side f(x; v) and Jacobian df/dx at a running speed v, and what its
 * states are: the body each belongs to (a category: "wheelsets", "bogie frame", "carbody") and the mass or inertia of
 * each velocity state, so that a mode can be said to move the wheelsets, the frame or the carbody (its kinetic
 * energy's shares). The wheelset of docs/MODEL.md (hm_wheelset_system_init below) and the two-axle bogie (bogie.h)
 * give one.
 *
 * Linear stability: the Jacobian's eigenvalues at x = 0 (LAPACK dgeev), sorted by decreasing real part; the least
 * damped one and its mode's body shares; the linear critical (Hopf) speed: a scan upward from v_min in steps of
 * v_step for the first speed where the largest real part is >= 0, then bisection to tol. Nothing is allocated
 * (dimension at most HM_SYSTEM_MAX_DIM; the work arrays are on the stack, about 50 kB).
 */
#ifndef HUNTING_MONITOR_SYSTEM_H
#define HUNTING_MONITOR_SYSTEM_H

#include <stddef.h>

#include "hunting_monitor/model.h"
#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HM_SYSTEM_MAX_DIM 40

/* The vehicle models the core holds (a vehicle config's `model:` key). */
typedef enum {
  HM_MODEL_WHEELSET = 0, /* docs/MODEL.md's wheelset on fixed springs (model.h) */
  HM_MODEL_BOGIE = 1,    /* two such wheelsets on a bogie frame (bogie.h) */
  HM_MODEL_CAR = 2       /* a carbody on two such bogies (car.h) */
} hm_model_kind;

/* "wheelset", "bogie", "car"; "unknown" otherwise. */
const char *hm_model_kind_name(hm_model_kind kind);
#define HM_SYSTEM_MAX_BODIES 4

/* f(x; v) and df/dx (row-major, dim x dim: jac[dim * i + j] = d f_i / d x_j) of the model's parameters at speed v
 * [m/s]. HM_ENONFINITE if a value is not finite. */
typedef hm_status (*hm_system_rhs_fn)(const void *model, double speed_mps, const double *x, double *dxdt);
typedef hm_status (*hm_system_jac_fn)(const void *model, double speed_mps, const double *x, double *jac);
/* df/dv [per m/s] at x. */
typedef hm_status (*hm_system_dfdv_fn)(const void *model, double speed_mps, const double *x, double *dfdv);
/* f(x; v) over a track whose lateral position under wheelset i is y_track_m[i] (the wheel-rail terms see y_i -
 * y_track_i): the simulators' right-hand side. */
typedef hm_status (*hm_system_track_fn)(const void *model, double speed_mps, const double *x, const double *y_track_m,
                                        double *dxdt);

#define HM_SYSTEM_MAX_WHEELSETS 4

typedef struct {
  size_t dim;                    /* state dimension, 1..HM_SYSTEM_MAX_DIM */
  hm_system_rhs_fn rhs;
  hm_system_jac_fn jacobian;
  hm_system_dfdv_fn dfdv;
  const void *model;             /* what the callbacks read (kept by the caller while the system is used) */
  size_t n_bodies;               /* 1..HM_SYSTEM_MAX_BODIES */
  const char *const *body_names; /* n_bodies names */
  const int *state_body;         /* per state: its body (0..n_bodies-1), or -1 (a damper's internal state) */
  const double *state_inertia;   /* per state: the mass [kg] or inertia [kg m^2] of a velocity state, else 0 */
  const double *state_scale;     /* per state: a typical size (1e-3 m, 0.1 m/s, ...): the cycles' Newton scales */
  size_t amp_state;              /* the state a cycle starts from at an extreme (the leading wheelset's y) */
  size_t phase_state;            /* its rate (x[amp_state]' = x[phase_state]): a cycle starts where it is 0 */
  int odd;                       /* 1 if f(-x) = -f(x) (lambda(y) even): symmetric cycles, half-period shooting */
  hm_system_track_fn rhs_track;  /* the right-hand side over a track */
  size_t n_wheelsets;            /* 1..HM_SYSTEM_MAX_WHEELSETS, leading first */
  const double *wheelset_x_m;    /* their longitudinal positions [m], decreasing (the leading one first) */
  const size_t *wheelset_y_state; /* the state of each one's lateral displacement y (its rate the next state): a
                                    cycle's amplitude is the largest |y| over them all */
} hm_system;

/* An accelerometer on a model: sum of weight[j] * dx[state[j]] [m/s^2] over velocity states (a lateral
 * acceleration at a point of a body: y'' + x psi'' of its lateral and yaw states). */
typedef struct {
  size_t n_terms;    /* 1..4 */
  size_t state[4];
  double weight[4];  /* 1 for a lateral acceleration, the lever arm [m] for a yaw one */
} hm_sensor_point;

/* The spectrum at one speed. */
typedef struct {
  size_t dim;
  double re[HM_SYSTEM_MAX_DIM], im[HM_SYSTEM_MAX_DIM]; /* eigenvalues [1/s]: decreasing real part, of a pair the
                                                          one with im > 0 first */
  double abscissa_1_s;           /* re[0]: the least-damped eigenvalue's real part (the decay rate) */
  double frequency_hz;           /* im[0] / 2 pi (0: a real eigenvalue) */
  double body_share[HM_SYSTEM_MAX_BODIES]; /* its mode's kinetic energy by body, summing to 1 */
  int dominant_body;             /* the largest share's body */
} hm_system_spectrum;

/* Speeds of the critical-speed search [m/s]; tol the bisection's final bracket width. */
typedef struct {
  double v_min_mps, v_max_mps, v_step_mps, tol_mps;
} hm_system_critical_options;

/* 100 km/h to 1500 km/h in 5 km/h steps, to 1e-9 km/h. */
void hm_system_critical_options_default(hm_system_critical_options *opt);

/* Every field present and consistent (dim and n_bodies in range, callbacks set, bodies in range, inertias finite and
 * >= 0 and at least one > 0, scales finite and > 0, amp_state and phase_state distinct states, the wheelsets' count
 * and positions); HM_EINVAL otherwise. */
hm_status hm_system_validate(const hm_system *sys);
/* 1 if the point's states are in range and its weights finite (n_terms 1..4). */
int hm_sensor_point_valid(const hm_system *sys, const hm_sensor_point *point);

/* The eigenvalues of df/dx at x = 0 and speed_mps in dgeev's order (re, im: dim each), and with vr != NULL its right
 * eigenvectors (column-major dim x dim, dgeev's packing: a pair's real and imaginary parts in columns k, k + 1). No
 * validation of sys (the callers' own); HM_ELAPACK, HM_ENONFINITE. */
hm_status hm_system_eig(const hm_system *sys, double speed_mps, double *re, double *im, double *vr);

/* The spectrum of df/dx at x = 0 and speed_mps (> 0). out untouched on failure. */
hm_status hm_system_spectrum_at(const hm_system *sys, double speed_mps, hm_system_spectrum *out);

/* The linear critical speed (the first speed from v_min where the largest real part reaches 0) and the spectrum
 * there (at the bracket's unstable end). HM_ENOCRIT if the origin is already unstable at v_min or still stable at
 * v_max; HM_EINVAL for inconsistent options. Outputs untouched on failure (at_crit may be NULL). */
hm_status hm_system_critical_speed(const hm_system *sys, const hm_system_critical_options *opt, double *speed_mps,
                                   hm_system_spectrum *at_crit);

/* docs/MODEL.md's wheelset as a system: one body ("wheelsets"), its mass and yaw inertia on states 1 and 3; amplitude
 * y (state 0), phase dy/dt (state 1), scales 1 mm, 0.1 m/s, 1 mrad, 0.1 rad/s. */
typedef struct {
  hm_model model; /* the vehicle and its coefficients; the speed is given per call */
  double inertia[4], scale[4], x_m[1];
  size_t y_state[1];
  int body[4];
} hm_wheelset_system;

/* Validate veh and fill *ws and *sys (sys points into ws: keep ws). Outputs untouched on failure. */
hm_status hm_wheelset_system_init(hm_wheelset_system *ws, const hm_vehicle *veh, hm_system *sys);

#ifdef __cplusplus
}
#endif

#endif
