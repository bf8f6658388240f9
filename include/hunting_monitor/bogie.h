/*
 * hunting_monitor - the two-axle bogie (issue #28): two wheelsets of docs/MODEL.md at x = +b (leading) and x = -b
 * on a bogie frame with lateral and yaw freedom, under a carbody held fixed.
 *
 * States (SI), HM_BOGIE_DIM = 13:
 *   x[0..3]   leading wheelset:  y1 [m], y1' [m/s], psi1 [rad], psi1' [rad/s]
 *   x[4..7]   trailing wheelset: y2, y2', psi2, psi2'
 *   x[8..11]  frame:             yf [m], yf' [m/s], psif [rad], psif' [rad/s]
 *   x[12]     u [m]: the yaw dampers' own displacement (each damper a Maxwell element: the damper in series with
 *             the stiffness of its joints and mounts)
 * Equations (per wheelset MODEL.md's creep kx, ky, conicity lambda(y) and flange force F_T(y) on its own
 * displacement; its primary springs now to the frame; Kg = Kx (l0/l1 - 1), MODEL.md's geometric term, on the
 * wheelset's own y; q_i = y_i - yf - x_i psif the primary lateral deflection, x_1 = b, x_2 = -b):
 *   m y_i''   = -2 ky / v y_i' + 2 ky psi_i - Kg y_i - Ky q_i - F_T(y_i)
 *   I psi_i'' = -2 kx d0 lambda(y_i) y_i / r0 - 2 kx d0^2 / v psi_i' - Kx d1^2 (psi_i - psif)
 *   mf yf''   = sum_i Ky q_i - Ksy yf - Csy yf'
 *   If psif'' = sum_i [x_i Ky q_i + Kx d1^2 (psi_i - psif)] - 2 ka da^2 psif - 2 dd kd (dd psif - u)
 *   cd u'     = kd (dd psif - u)
 * Ksy, Csy: the secondary lateral stiffness and damping to the carbody (totals for the bogie); ka: the longitudinal
 * stiffness of each of the two air springs, at lateral arm da (their yaw stiffness 2 ka da^2); cd, kd: the damping of
 * each of the two yaw dampers and the stiffness in series with it, at lateral arm dd (at low frequency a yaw damping
 * 2 cd dd^2, at high frequency a yaw stiffness 2 kd dd^2).
 * With the frame held (frame_held: yf = psif = u = 0, 8 states) each wheelset is MODEL.md's exactly: the lone
 * wheelset's eigenvalues, each twice, and its Hopf speed (517.618 km/h for the defaults).
 * Linear stability (critical speed, which body the critical mode moves) through system.h.
 */
#ifndef HUNTING_MONITOR_BOGIE_H
#define HUNTING_MONITOR_BOGIE_H

#include <stddef.h>

#include "hunting_monitor/model.h"
#include "hunting_monitor/status.h"
#include "hunting_monitor/system.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HM_BOGIE_DIM 13
#define HM_BOGIE_HELD_DIM 8

/* The bogie's parameters, SI units. Plain data: fill it (hm_bogie_default), then hm_bogie_validate. */
typedef struct {
  hm_vehicle wheelset;                    /* each of the two wheelsets (primary Kx, Ky to the frame) */
  double frame_mass_kg;                   /* mf */
  double frame_yaw_inertia_kg_m2;         /* If */
  double half_wheelbase_m;                /* b */
  double secondary_lat_stiffness_n_m;     /* Ksy, frame to carbody */
  double secondary_lat_damping_n_s_m;     /* Csy */
  double airspring_long_stiffness_n_m;    /* ka, each air spring */
  double airspring_half_distance_m;       /* da, their lateral arm */
  double yaw_damper_damping_n_s_m;        /* cd, each yaw damper */
  double yaw_damper_stiffness_n_m;        /* kd, in series with each damper */
  double yaw_damper_half_distance_m;      /* dd, their lateral arm */
} hm_bogie;

/* MODEL.md's wheelsets (hm_vehicle_default) on a high-speed bogie frame: mf 2600 kg, If 1800 kg m^2, b 1.25 m,
 * Ksy 0.25 MN/m, Csy 30 kN s/m, ka 0.15 MN/m at da 1.0 m, yaw dampers cd 1 MN s/m, kd 50 MN/m at dd 1.3 m. */
void hm_bogie_default(hm_bogie *bogie);

/* Check every field (the wheelset's as hm_vehicle_validate; mf, If, b, da, dd, cd, kd > 0; Ksy, Csy, ka >= 0).
 * On failure HM_EDOMAIN and "field: reason (got value)" in why, with the config's names ("bogie.frame_mass_kg"). */
hm_status hm_bogie_validate(const hm_bogie *bogie, char *why, size_t why_len);

/* The bogie as a system (system.h): what its callbacks read. */
typedef struct {
  hm_bogie bogie;
  hm_linear_coef coef;  /* the wheelset's coefficients (MODEL.md section 2) */
  int frame_held;       /* 1: the frame held at rest, 8 states */
  double inertia[HM_BOGIE_DIM], scale[HM_BOGIE_DIM], x_m[2];
  size_t y_state[2];
  int body[HM_BOGIE_DIM];
} hm_bogie_model;

/* Validate and fill *m and *sys (sys points into m: keep m). Bodies: 0 "wheelsets", 1 "bogie frame"; a cycle's
 * amplitude is the largest |y| of its two wheelsets (the phase on the leading one's); odd when lambda(y) is even. */
hm_status hm_bogie_model_init(hm_bogie_model *m, const hm_bogie *bogie, int frame_held, hm_system *sys);

/* f(x; v) at track displacements y_track[2] under the two wheelsets (NULL: 0): lambda and F_T act on y_i - y_track_i.
 * (system.h's rhs is this with no track.) HM_ENONFINITE if a derivative is not finite. */
hm_status hm_bogie_rhs(const hm_bogie_model *m, double speed_mps, const double *x, const double *y_track_m,
                       double *dxdt);

/* The same under a moving carbody (car.h): the secondary suspension acts on the frame's motion relative to the
 * carbody's at the bogie centre, att = {lateral [m], its rate [m/s], yaw [rad], its rate [rad/s]} (the lateral spring
 * and damper on yf - att[0] and yf' - att[1], the air springs and yaw dampers on psif - att[2]); also the secondary's
 * force [N] and yaw moment [N m] on the carbody there. (hm_bogie_rhs: att = 0.) Not for a held frame. */
hm_status hm_bogie_rhs_under(const hm_bogie_model *m, double speed_mps, const double *x, const double *y_track_m,
                             const double att[4], double *dxdt, double *force_on_car_n, double *moment_on_car_nm);

/* Where an accelerometer sits: "axlebox" (the leading wheelset's lateral acceleration y1''), "frame" (the frame's
 * over the leading axle, yf'' + b psif''; not with the frame held). HM_EINVAL for another name. */
hm_status hm_bogie_sensor(const hm_bogie_model *m, const char *where, hm_sensor_point *out);

/* df/dv [per m/s] (the creep damping's 1/v terms). */
hm_status hm_bogie_dfdv(const hm_bogie_model *m, double speed_mps, const double *x, double *dfdv);

/* df/dx (row-major, dim x dim, dim 13 or 8 with the frame held), analytic. */
hm_status hm_bogie_jacobian(const hm_bogie_model *m, double speed_mps, const double *x, double *jac);

#ifdef __cplusplus
}
#endif

#endif
