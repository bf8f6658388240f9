/*
 * hunting_monitor - the whole vehicle (issue #28): a carbody with lateral and yaw freedom on two bogies (bogie.h) at
 * x = +a (leading) and x = -a; no roll (the carbody's roll on the air springs couples with its lateral motion
 * through the height of its centre of mass: left out, so the carbody's lower sway mode is a pure lateral one here).
 *
 * States (SI), HM_CAR_DIM = 30:
 *   x[0..12]   the leading bogie (bogie.h's 13: its leading wheelset first, so x[0] is the vehicle's leading y)
 *   x[13..25]  the trailing bogie
 *   x[26..29]  carbody: yc [m], yc' [m/s], psic [rad], psic' [rad/s]
 * Each bogie's secondary suspension acts on its frame's motion relative to the carbody at the bogie centre
 * (bogie.h's hm_bogie_rhs_under with att_j = {yc + x_j psic, yc' + x_j psic', psic, psic'}); the carbody:
 *   mc yc''   = sum_j F_j                     F_j: bogie j's secondary lateral force on the carbody
 *   Ic psic'' = sum_j (x_j F_j + M_j)         M_j: its air springs' and yaw dampers' moment, x_1 = a, x_2 = -a
 * With the carbody held (carbody_held: 26 states) the two bogies are bogie.h's exactly: its eigenvalues each twice
 * and its critical speed. At low conicity the wheelsets' kinematic frequency falls to the carbody's suspension
 * frequencies (1-3 Hz) and a carbody mode can go unstable first: carbody hunting (hunting critical says whose mode).
 */
#ifndef HUNTING_MONITOR_CAR_H
#define HUNTING_MONITOR_CAR_H

#include <stddef.h>

#include "hunting_monitor/bogie.h"
#include "hunting_monitor/status.h"
#include "hunting_monitor/system.h"

#ifdef __cplusplus
extern "C" {
#endif

#define HM_CAR_DIM 30
#define HM_CAR_HELD_DIM 26

typedef struct {
  hm_bogie bogie;                   /* both bogies (and their wheelsets) */
  double carbody_mass_kg;           /* mc */
  double carbody_yaw_inertia_kg_m2; /* Ic */
  double half_bogie_distance_m;     /* a: the bogie centres at +a and -a */
} hm_car;

/* The default bogies (hm_bogie_default) under a high-speed carbody: mc 35 t, Ic 1.8e6 kg m^2, a 8.75 m. */
void hm_car_default(hm_car *car);

/* The bogie's checks (hm_bogie_validate), then mc, Ic, a > 0 ("car.carbody_mass_kg: must be > 0 (got -1)"). */
hm_status hm_car_validate(const hm_car *car, char *why, size_t why_len);

typedef struct {
  hm_car car;
  hm_bogie_model bogie;   /* the bogies' equations (frame free) */
  int carbody_held;
  double inertia[HM_CAR_DIM], scale[HM_CAR_DIM], x_m[4];
  size_t y_state[4];
  int body[HM_CAR_DIM];
} hm_car_model;

/* Validate and fill *m and *sys (sys points into m). Bodies: 0 "wheelsets", 1 "bogie frame", 2 "carbody". */
hm_status hm_car_model_init(hm_car_model *m, const hm_car *car, int carbody_held, hm_system *sys);

/* Where an accelerometer sits: "axlebox" (the leading wheelset), "frame" (the leading bogie's frame over its
 * leading axle), "carbody" (the carbody over the leading bogie's centre, yc'' + a psic''; not with it held). */
hm_status hm_car_sensor(const hm_car_model *m, const char *where, hm_sensor_point *out);

/* f(x; v), the track under the four wheelsets y_track_m[4] (leading first; NULL: 0). */
hm_status hm_car_rhs(const hm_car_model *m, double speed_mps, const double *x, const double *y_track_m, double *dxdt);
/* df/dx, row-major (30 x 30, or 26 x 26 with the carbody held), analytic; df/dv. */
hm_status hm_car_jacobian(const hm_car_model *m, double speed_mps, const double *x, double *jac);
hm_status hm_car_dfdv(const hm_car_model *m, double speed_mps, const double *x, double *dfdv);

#ifdef __cplusplus
}
#endif

#endif
