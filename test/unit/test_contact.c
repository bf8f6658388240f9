/* delta-r from wheel and rail profiles (contact.h) against closed forms: a conical wheel on a knife-edge rail
 * (delta-r = 2 s tan gamma), unequal radii (a constant offset), a circular wheel on a circular rail (the contact on
 * the line through both centres), and the chain to the equivalent conicity (eqcon.h). */
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/contact.h"
#include "hunting_monitor/eqcon.h"

enum { NW = 2801, NR = 2001 };
static double wy[NW], wz[NW], ry[NR], rz[NR];

/* A cone: z = -(y - 70 mm) tan(gamma) over 0..140 mm every 0.05 mm. */
static hm_profile cone_wheel(double tan_g) {
  for (int k = 0; k < NW; ++k) {
    wy[k] = 0.14 * k / (NW - 1);
    wz[k] = -(wy[k] - 0.07) * tan_g;
  }
  return (hm_profile){wy, wz, NW};
}

/* A knife edge: a 2.5:1 triangle 20 mm to each side of its tip (its gauge point 5.6 mm from the tip). */
static hm_profile knife_rail(void) {
  static double y[3] = {-0.02, 0.0, 0.02}, z[3] = {-0.05, 0.0, -0.05};
  return (hm_profile){y, z, 3};
}

static hm_contact_config upright(void) {
  hm_contact_config c;
  hm_contact_config_default(&c);
  c.inclination = 0.0;
  return c;
}

/* A cone of 0.05 on knife edges, upright rails: the contact stays at the tips (Y = +-(717.5 + 5.6) mm), the wheel's
 * contact moves by the shift, delta-r = 2 s tan(gamma) (to 1e-12 m) over +-8 mm every 0.1 mm, the contact angle
 * gamma; with radii 460 / 459 mm the same plus 1 mm; the equivalent conicity of that delta-r 0.05 at every amplitude. */
static void cone_on_knife_edges(void) {
  const double tan_g = 0.05;
  const hm_profile w = cone_wheel(tan_g), r = knife_rail();
  hm_contact_config c = upright();
  double s[161];
  static hm_contact_point p[161];
  for (int k = 0; k < 161; ++k) s[k] = 1e-4 * (k - 80);
  char why[160] = "";
  HM_CHECK(hm_contact_delta_r(&c, &w, NULL, &r, NULL, s, 161, p, why, sizeof why) == HM_OK, "%s", why);
  double worst = 0.0;
  for (int k = 0; k < 161; ++k) {
    worst = fmax(worst, fabs(p[k].delta_r_m - 2.0 * s[k] * tan_g));
    HM_CHECK_DELTA(p[k].contact_left_m, 0.7175 + 0.0056, 1e-12, "left contact at the tip");
    HM_CHECK_DELTA(p[k].contact_right_m, -(0.7175 + 0.0056), 1e-12, "right contact at the tip");
    HM_CHECK_DELTA(p[k].wheel_y_left_m, 0.0056 + 0.0375 - s[k], 1e-12, "the left wheel's contact moves with it");
    HM_CHECK_DELTA(p[k].contact_angle_left_rad, atan(tan_g), 1e-12, "contact angle");
  }
  HM_CHECK(worst < 1e-12, "delta-r off 2 s tan gamma by %.2g m", worst);
  double y[161], dr[161];
  for (int k = 0; k < 161; ++k) y[k] = s[k], dr[k] = p[k].delta_r_m;
  hm_eqcon_config ec;
  hm_eqcon_config_default(&ec);
  hm_eqcon e = NULL;
  HM_CHECK(hm_eqcon_create(&ec, y, dr, 161, &e, why, sizeof why) == HM_OK, "%s", why);
  for (double a = 1e-3; a <= 7.5e-3 + 1e-12; a += 0.5e-3) {
    hm_eqcon_result res;
    HM_CHECK(hm_eqcon_at(e, HM_EQCON_INTEGRATION, a, &res) == HM_OK, "amplitude %g", a);
    HM_CHECK_REL(res.tan_gamma_e, tan_g, 1e-9, "the chain: tan gamma_e");
  }
  hm_eqcon_destroy(e);
  c.r0_right_m = 0.459;
  HM_CHECK(hm_contact_delta_r(&c, &w, NULL, &r, NULL, s, 161, p, why, sizeof why) == HM_OK, "%s", why);
  for (int k = 0; k < 161; ++k) HM_CHECK_DELTA(p[k].delta_r_m, 2.0 * s[k] * tan_g + 0.001, 1e-12, "unequal radii");
  printf("  cone 0.05 on knife edges: delta-r = 2 s tan gamma to %.1e m, tan gamma_e 0.05 from it\n", worst);
}

/* A barrel wheel (a circle of radius Rw = 0.5 m in profile, its centre 5 mm to the field side of the measuring
 * circle) on a round rail head (Rr = 0.08 m), inclined 1:40: the contact lies on the line through both centres,
 * P = C_rail + Rr (C_wheel - C_rail) / (Rw + Rr), so the wheel's contact point and rolling radius follow in closed
 * form; the profiles tabulated every 0.05 mm: the rolling radii to 2e-6 m (the tabulation), the contact on the
 * rail to 0.1 mm. */
static void circle_on_circle(void) {
  const double Rw = 0.5, Rr = 0.08, yc = 0.075;
  for (int k = 0; k < NW; ++k) {
    wy[k] = 0.14 * k / (NW - 1);
    wz[k] = sqrt(Rw * Rw - (wy[k] - yc) * (wy[k] - yc)) - sqrt(Rw * Rw - (0.07 - yc) * (0.07 - yc));
  }
  for (int k = 0; k < NR; ++k) { /* rail axes: centre at y = 0, top at z = 0 */
    ry[k] = -0.06 + 0.12 * k / (NR - 1);
    rz[k] = sqrt(Rr * Rr - ry[k] * ry[k]) - Rr;
  }
  const hm_profile w = {wy, wz, NW}, r = {ry, rz, NR};
  hm_contact_config c;
  hm_contact_config_default(&c); /* 1:40 */
  double s[17];
  hm_contact_point p[17];
  for (int k = 0; k < 17; ++k) s[k] = 1e-3 * (k - 8);
  char why[160] = "";
  HM_CHECK(hm_contact_delta_r(&c, &w, NULL, &r, NULL, s, 17, p, why, sizeof why) == HM_OK, "%s", why);
  /* the inclined rail: its centre, rotated by the inclination, and its gauge point 14 mm below its top; a circle
   * rotated about its own centre's origin stays a circle: the centre C = rot(0, -Rr), the top C + (0, Rr) */
  const double a = atan(1.0 / 40.0), cy = Rr * sin(a);
  const double u_gp = cy - sqrt(Rr * Rr - (Rr - 0.014) * (Rr - 0.014)); /* gauge side, 14 mm below the top */
  double worst = 0.0, worst_c = 0.0;
  for (int k = 0; k < 17; ++k) {
    for (int side = 0; side < 2; ++side) {
      const double sh = side == 0 ? s[k] : -s[k];
      /* in the side's rail coordinates u (from the gauge point, field +): the rail centre and the wheel's */
      const double rail_cu = cy - u_gp, wheel_cu = yc - 0.0375 + sh; /* y_w = u + 37.5 mm -+ s */
      /* external tangency, |C_w - C_r| = Rw + Rr: the contact's lateral position */
      const double pu = rail_cu + Rr * (wheel_cu - rail_cu) / (Rw + Rr);
      const double yw = pu + 0.0375 - sh;
      const double r_expected = (side == 0 ? c.r0_left_m : c.r0_right_m) + sqrt(Rw * Rw - (yw - yc) * (yw - yc)) -
                                sqrt(Rw * Rw - (0.07 - yc) * (0.07 - yc));
      const double got = side == 0 ? p[k].r_left_m : p[k].r_right_m;
      worst = fmax(worst, fabs(got - r_expected));
      const double cu = side == 0 ? p[k].contact_left_m - 0.7175 : -p[k].contact_right_m - 0.7175;
      worst_c = fmax(worst_c, fabs(cu - pu));
    }
  }
  HM_CHECK(worst < 2e-6, "rolling radii off the closed form by %.2g m", worst);
  HM_CHECK(worst_c < 1e-4, "contact on the rail off by %.2g m", worst_c);
  printf("  circle on circle, 1:40: rolling radii within %.1e m, contacts within %.1e m of the line of centres\n", worst,
         worst_c);
}

/* With the roll (include_roll): the cone on knife edges with radii 460 / 459 mm. The rigid wheelset rests on both
 * tips (Y = -+a, a = 723.1 mm), so its roll is (r_left - r_right) / (2 a) at the radii where it touches, to first
 * order (to 1e-3 of it); rolled, the wheels touch the tips at points moved by the roll's lateral displacement
 * r phi (so delta-r differs from the unrolled one by 2 r phi tan(gamma), to 1e-2 of that: the next order); and equal radii at zero
 * shift give no roll (1e-12 rad). */
static void roll_rests_both_wheels(void) {
  const double tan_g = 0.05, a = 0.7175 + 0.0056;
  const hm_profile w = cone_wheel(tan_g), r = knife_rail();
  hm_contact_config c = upright();
  c.include_roll = 1;
  c.r0_right_m = 0.459;
  double s[5] = {-0.004, -0.002, 0.0, 0.002, 0.004};
  hm_contact_point p[5], q[5];
  char why[200] = "";
  HM_CHECK(hm_contact_delta_r(&c, &w, NULL, &r, NULL, s, 5, p, why, sizeof why) == HM_OK, "%s", why);
  const double roll_at_0 = p[2].roll_rad, dr_at_0 = p[2].r_left_m - p[2].r_right_m;
  c.include_roll = 0;
  HM_CHECK(hm_contact_delta_r(&c, &w, NULL, &r, NULL, s, 5, q, why, sizeof why) == HM_OK, "%s", why);
  for (int k = 0; k < 5; ++k) {
    HM_CHECK_REL(p[k].roll_rad, (p[k].r_left_m - p[k].r_right_m) / (2.0 * a), 1e-3, "roll");
    HM_CHECK(q[k].roll_rad == 0.0, "no roll without include_roll");
    const double expected = q[k].delta_r_m + 2.0 * 0.4595 * p[k].roll_rad * tan_g;
    HM_CHECK(fabs(p[k].delta_r_m - expected) <= 1e-2 * fabs(expected - q[k].delta_r_m), "rolled delta-r %.9g vs %.9g",
             p[k].delta_r_m, expected);
  }
  c.include_roll = 1;
  c.r0_right_m = 0.46;
  HM_CHECK(hm_contact_delta_r(&c, &w, NULL, &r, NULL, s + 2, 1, p, why, sizeof why) == HM_OK &&
               fabs(p[0].roll_rad) < 1e-12,
           "symmetric: roll %g", p[0].roll_rad);
  printf("  roll: 460 / 459 mm radii on knife edges roll the wheelset by %.4e rad at zero shift (r_l - r_r / 2a "
         "%.4e)\n", roll_at_0, dr_at_0 / (2.0 * a));
}

/* Bad input: named one-line reasons, out untouched. */
static void bad_input(void) {
  const hm_profile w = cone_wheel(0.05), r = knife_rail();
  hm_contact_config c = upright();
  hm_contact_point p[2];
  memset(p, 0x5a, sizeof p);
  const hm_contact_point before = p[0];
  double s[2] = {0.0, 0.2}; /* 200 mm: off the rail */
  char why[160] = "";
  HM_CHECK(hm_contact_delta_r(&c, &w, NULL, &r, NULL, s, 2, p, why, sizeof why) == HM_EDOMAIN &&
               strstr(why, "does not lie over its rail") && memcmp(&p[0], &before, sizeof before) == 0,
           "off the rail: %s", why);
  static double by[3] = {0.0, 0.01, 0.005}, bz[3] = {0.0, 0.0, 0.0};
  const hm_profile back = {by, bz, 3};
  s[1] = 0.0;
  HM_CHECK(hm_contact_delta_r(&c, &back, NULL, &r, NULL, s, 2, p, why, sizeof why) == HM_EDOMAIN &&
               strstr(why, "left wheel profile: y must increase strictly (point 3"),
           "%s", why);
  static double fy[3] = {-0.02, 0.0, 0.02}, fz[3] = {-0.005, 0.0, -0.005};
  const hm_profile flat = {fy, fz, 3};
  HM_CHECK(hm_contact_delta_r(&c, &w, NULL, &flat, NULL, s, 2, p, why, sizeof why) == HM_EDOMAIN &&
               strstr(why, "does not reach 14 mm below the top"),
           "%s", why);
  c.gauge_m = 1.3;
  HM_CHECK(hm_contact_delta_r(&c, &w, NULL, &r, NULL, s, 2, p, why, sizeof why) == HM_EDOMAIN &&
               strstr(why, "gauge_m"),
           "%s", why);
}

int main(void) {
  HM_RUN(cone_on_knife_edges);
  HM_RUN(circle_on_circle);
  HM_RUN(roll_rests_both_wheels);
  HM_RUN(bad_input);
  HM_TEST_EXIT();
}
