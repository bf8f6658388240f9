/*
 * hunting_monitor - the whole vehicle (issue #28): a carbody with lateral and yaw freedom on two bogies (bogie.h) at
 * x = +a (leading) and x = -a, and optionally its roll on the secondary suspension (car.roll in a config).
 *
 * States (SI), HM_CAR_RIGID_DIM = 30 without roll, HM_CAR_DIM = 32 with it:
 *   x[0..12]   the leading bogie (bogie.h's 13: its leading wheelset first, so x[0] is the vehicle's leading y)
 *   x[13..25]  the trailing bogie
 *   x[26..29]  carbody: yc [m], yc' [m/s], psic [rad], psic' [rad/s]
 *   x[30..31]  with roll: phic [rad], phic' [rad/s]; positive phic moves the carbody's underside towards +y (a point
 *              z above the centre of mass moves laterally by -z phic)
 * Each bogie's secondary suspension acts on its frame's motion relative to the carbody at the bogie centre, at the
 * secondary's level h below the carbody's centre of mass (bogie.h's hm_bogie_rhs_under with
 * att_j = {yc + x_j psic + h phic, yc' + x_j psic' + h phic', psic, psic'}); the carbody:
 *   mc yc''   = sum_j F_j                     F_j: bogie j's secondary lateral force on the carbody
 *   Ic psic'' = sum_j (x_j F_j + M_j)         M_j: its air springs' and yaw dampers' moment, x_1 = a, x_2 = -a
 *   Ix phic'' = sum_j (h F_j - kr phic - cr phic') + mc g h phic
 * kr, cr: each bogie's roll stiffness and damping (its air springs' vertical stiffness and the vertical dampers at
 * their lateral arm, an anti-roll bar); mc g h: the carbody's weight on the secondary, whose tops move with the roll
 * (the second-order change of the preloaded springs' energy: it lowers the roll stiffness). Without roll (Ix = 0)
 * h phic = 0 and the carbody's lower sway mode is a pure lateral one.
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

#define HM_CAR_DIM 32       /* with roll */
#define HM_CAR_RIGID_DIM 30 /* without */
#define HM_CAR_HELD_DIM 26
#define HM_CAR_GRAVITY_MPS2 9.80665

typedef struct {
  hm_bogie bogie;                   /* both bogies (and their wheelsets) */
  double carbody_mass_kg;           /* mc */
  double carbody_yaw_inertia_kg_m2; /* Ic */
  double half_bogie_distance_m;     /* a: the bogie centres at +a and -a */
  /* roll (0 inertia: the carbody does not roll, the three below unused) */
  double carbody_roll_inertia_kg_m2;       /* Ix, about the centre of mass */
  double carbody_cg_height_m;              /* h: the centre of mass above the secondary suspension's level */
  double secondary_roll_stiffness_n_m_rad; /* kr, each bogie's */
  double secondary_roll_damping_n_m_s_rad; /* cr, each bogie's */
} hm_car;

/* The default bogies (hm_bogie_default) under a high-speed carbody: mc 35 t, Ic 1.8e6 kg m^2, a 8.75 m. */
void hm_car_default(hm_car *car);

/* The bogie's checks (hm_bogie_validate), then mc, Ic, a > 0 ("car.carbody_mass_kg: must be > 0 (got -1)"); Ix 0 (no
 * roll) or in [1e3, 1e7] kg m^2, h in [0, 5] m, kr in [0, 1e8] N m/rad, cr in [0, 1e7] N m s/rad, and with roll
 * 2 kr > mc g h (else the carbody falls over on its springs; the message gives the bound). */
hm_status hm_car_validate(const hm_car *car, char *why, size_t why_len);

typedef struct {
  hm_car car;
  hm_bogie_model bogie;   /* the bogies' equations (frame free) */
  int carbody_held;
  int rolls;              /* Ix > 0: the states x[30..31] */
  double inertia[HM_CAR_DIM], scale[HM_CAR_DIM], x_m[4];
  size_t y_state[4];
  int body[HM_CAR_DIM];
} hm_car_model;

/* Validate and fill *m and *sys (sys points into m). Bodies: 0 "wheelsets", 1 "bogie frame", 2 "carbody". */
hm_status hm_car_model_init(hm_car_model *m, const hm_car *car, int carbody_held, hm_system *sys);

/* Where an accelerometer sits: "axlebox" (the leading wheelset), "frame" (the leading bogie's frame over its
 * leading axle), "carbody" (the carbody over the leading bogie's centre at its centre of mass's height,
 * yc'' + a psic''; not with it held). */
hm_status hm_car_sensor(const hm_car_model *m, const char *where, hm_sensor_point *out);

/* f(x; v), the track under the four wheelsets y_track_m[4] (leading first; NULL: 0). */
hm_status hm_car_rhs(const hm_car_model *m, double speed_mps, const double *x, const double *y_track_m, double *dxdt);
/* df/dx, row-major (32 x 32 with roll, 30 x 30 without, 26 x 26 with the carbody held), analytic; df/dv. */
hm_status hm_car_jacobian(const hm_car_model *m, double speed_mps, const double *x, double *jac);
hm_status hm_car_dfdv(const hm_car_model *m, double speed_mps, const double *x, double *dfdv);

#ifdef __cplusplus
}
#endif

#endif
