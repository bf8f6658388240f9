/*
 * hunting_monitor - rolling-radius difference delta-r from wheel and rail profiles (rigid single-point contact,
 * roll neglected by default, as EN 15302's reference cases are computed, or included; issue #19).
 *
 * Conventions (all lengths in m here, mm in the CSV files of `hunting delta-r`):
 *  - a wheel profile: y from the wheel's flange back (inner face) toward the field side, z the rolling radius there
 *    less the nominal radius at the measuring circle (so z = 0 at y = measuring_circle_m, 70 mm; the flange is
 *    z > 0). Points in order of y (strictly increasing): the tread and the flange's running side; the flange's back
 *    is not needed.
 *  - a rail profile, in the rail's own axes (before its inclination): y across the head toward the field side, z up,
 *    any origin; strictly increasing y (the head seen from above). The rail is inclined toward the track centre by
 *    atan(inclination) (1:40: 0.025; 0: upright); the gauge point is where the inclined head's gauge side lies
 *    gauge_depth_m (14 mm) below its top.
 *  - the track: gauge_m (1435 mm) between the gauge points, the left rail at +gauge/2, lateral Y positive to the left;
 *    the wheelset: the flange backs flange_back_distance_m (1360 mm) apart; shifted by s to the left. The right side
 *    is the mirror image (its own profiles or the left ones).
 * For each shift s, each wheel is lowered onto its rail (roll neglected: independently): the contact is where
 * wheel and rail surfaces first touch, i.e. where the axle height the wheel needs over the rail, z_rail(Y) -
 * z_wheel_below_axle(Y), is largest over the lateral positions Y where both profiles exist; for piecewise-linear
 * profiles that maximum lies at a point of one of them, and all of those are tried (exact). With include_roll the
 * rigid wheelset rolls about its centre (within -+0.02 rad) until both wheels need the same axle height: both rest
 * on their rails (bisection on the roll to 1e-13 rad; the contacts then move by the roll's lateral and vertical
 * displacement of the profiles). delta-r(s) = r_left(s) - r_right(s), r = r0 + z_wheel at the contact. Two points of equal height
 * (a two-point contact) give the one nearer the field side.
 * Cost: O(n_wheel + n_rail) per shift and side (both profiles walked in order); 161 shifts of a 1251-point wheel
 * on a 721-point rail take 10 ms. No allocation: the caller gives the output arrays.
 */
#ifndef HUNTING_MONITOR_CONTACT_H
#define HUNTING_MONITOR_CONTACT_H

#include <stddef.h>

#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  const double *y_m, *z_m; /* n points, y strictly increasing */
  size_t n;
} hm_profile;

typedef struct {
  double r0_left_m, r0_right_m;   /* nominal rolling radii at the measuring circle [m] */
  double measuring_circle_m;      /* the wheel profile's y of the nominal radius, from the flange back [m] */
  double flange_back_distance_m;  /* between the wheels' flange backs [m] */
  double gauge_m;                 /* between the rails' gauge points [m] */
  double gauge_depth_m;           /* the gauge point below the rail top [m] */
  double inclination;             /* tan of the rails' inclination toward the track centre (1/40, 1/20, 0) */
  int include_roll;               /* 1: the rigid wheelset rolls until both wheels rest on their rails */
} hm_contact_config;

/* 0.46 m both, 70 mm, 1360 mm, 1435 mm, 14 mm, 1/40, roll neglected. */
void hm_contact_config_default(hm_contact_config *cfg);
/* "field: reason" (HM_EDOMAIN). */
hm_status hm_contact_config_validate(const hm_contact_config *cfg, char *why, size_t why_len);
/* A profile: at least 3 finite points within 500 mm across and 200 mm up or down, y strictly increasing; what names
 * it in the message (e.g. "left wheel").
 * HM_EDOMAIN with the reason and the point. */
hm_status hm_profile_check(const hm_profile *p, const char *what, char *why, size_t why_len);

typedef struct {
  double delta_r_m;                 /* r_left - r_right */
  double r_left_m, r_right_m;       /* rolling radii at the contacts */
  double contact_left_m, contact_right_m; /* the contacts' lateral positions on the track, Y (left +) */
  double wheel_y_left_m, wheel_y_right_m; /* and on the wheel profiles (y from the flange back) */
  double contact_angle_left_rad, contact_angle_right_rad; /* the wheel profile's slope there, atan(-dz/dy):
                                                             positive where the radius falls toward the field side */
  double roll_rad;                  /* the wheelset's roll (left side up; 0 with roll neglected) */
} hm_contact_point;

/* delta-r at shifts[k] (m, to the left), k < n_shifts, into out[k]. The right wheel and rail are the mirror images of
 * wheel_right / rail_right (NULL: of the left ones). HM_EDOMAIN with the reason in why for an invalid profile or
 * configuration, or a shift where a wheel and its rail do not overlap laterally (the wheel off its rail); out
 * untouched on failure. */
hm_status hm_contact_delta_r(const hm_contact_config *cfg, const hm_profile *wheel_left, const hm_profile *wheel_right,
                             const hm_profile *rail_left, const hm_profile *rail_right, const double *shifts_m,
                             size_t n_shifts, hm_contact_point *out, char *why, size_t why_len);

#ifdef __cplusplus
}
#endif

#endif
