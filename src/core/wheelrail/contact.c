/* delta-r from wheel and rail profiles: rigid single-point contact, roll neglected (contact.h). */
#include "hunting_monitor/contact.h"

#include <math.h>
#include <stdio.h>

#include "validate.h"

void hm_contact_config_default(hm_contact_config *cfg) {
  if (!cfg) return;
  cfg->r0_left_m = cfg->r0_right_m = 0.46;
  cfg->measuring_circle_m = 0.070;
  cfg->flange_back_distance_m = 1.360;
  cfg->gauge_m = 1.435;
  cfg->gauge_depth_m = 0.014;
  cfg->inclination = 1.0 / 40.0;
  cfg->include_roll = 0;
}

hm_status hm_contact_config_validate(const hm_contact_config *c, char *why, size_t len) {
  if (!c) return HM_EINVAL;
  const hm_field_check f[] = {{"r0_left_m", c->r0_left_m, HM_RULE_RANGE, HM_R0_MIN_M, HM_R0_MAX_M},
                              {"r0_right_m", c->r0_right_m, HM_RULE_RANGE, HM_R0_MIN_M, HM_R0_MAX_M},
                              {"measuring_circle_m", c->measuring_circle_m, HM_RULE_RANGE, 0.0, 0.2},
                              {"flange_back_distance_m", c->flange_back_distance_m, HM_RULE_RANGE, 0.5, 2.0},
                              {"gauge_m", c->gauge_m, HM_RULE_RANGE, 0.5, 2.0},
                              {"gauge_depth_m", c->gauge_depth_m, HM_RULE_RANGE, 0.001, 0.05},
                              {"inclination", c->inclination, HM_RULE_RANGE, 0.0, 0.1},
                              {"include_roll", (double)c->include_roll, HM_RULE_FLAG, 0.0, 0.0}};
  const hm_status st = hm_check_fields(f, HM_COUNT_OF(f), why, len);
  if (st != HM_OK) return st;
  if (!(c->gauge_m > c->flange_back_distance_m))
    return hm_reject(why, len, "gauge_m", "must exceed flange_back_distance_m", c->gauge_m);
  return HM_OK;
}

hm_status hm_profile_check(const hm_profile *p, const char *what, char *why, size_t len) {
  if (!p || !what) return HM_EINVAL;
  if (!p->y_m || !p->z_m || p->n < 3) {
    if (why && len) snprintf(why, len, "%s profile: %zu points, at least 3 are needed", what, p->y_m ? p->n : 0);
    return HM_EDOMAIN;
  }
  for (size_t k = 0; k < p->n; ++k) {
    if (!isfinite(p->y_m[k]) || !isfinite(p->z_m[k])) {
      if (why && len) snprintf(why, len, "%s profile: point %zu is not finite", what, k + 1);
      return HM_EDOMAIN;
    }
    if (fabs(p->y_m[k]) > 0.5 || fabs(p->z_m[k]) > 0.2) {
      if (why && len)
        snprintf(why, len, "%s profile: point %zu (%g, %g mm) lies beyond 500 mm across or 200 mm up or down: not a "
                 "wheel or rail profile", what, k + 1, 1e3 * p->y_m[k], 1e3 * p->z_m[k]);
      return HM_EDOMAIN;
    }
    if (k > 0 && !(p->y_m[k] > p->y_m[k - 1])) {
      if (why && len)
        snprintf(why, len, "%s profile: y must increase strictly (point %zu: %g mm after %g mm)", what, k + 1,
                 1e3 * p->y_m[k], 1e3 * p->y_m[k - 1]);
      return HM_EDOMAIN;
    }
  }
  return HM_OK;
}

/* A rail inclined toward the track centre, measured from its gauge point: u (field side +) and z of point k. */
typedef struct {
  const hm_profile *p;
  double c, s, u_gp; /* cos, sin of the inclination; the gauge point's rotated y */
} rail;

static double rail_u(const rail *r, size_t k) { return r->c * r->p->y_m[k] - r->s * r->p->z_m[k] - r->u_gp; }
static double rail_z(const rail *r, size_t k) { return r->s * r->p->y_m[k] + r->c * r->p->z_m[k]; }

/* The inclined rail and its gauge point; HM_EDOMAIN if the inclined head is not a function of u (an undercut gauge
 * face) or never lies depth below its top on the gauge side. */
static hm_status rail_setup(const hm_profile *p, const hm_contact_config *cfg, const char *what, rail *r, char *why,
                            size_t len) {
  const double a = atan(cfg->inclination);
  r->p = p;
  r->c = cos(a);
  r->s = sin(a);
  r->u_gp = 0.0;
  size_t top = 0;
  for (size_t k = 0; k < p->n; ++k) {
    if (k > 0 && !(rail_u(r, k) > rail_u(r, k - 1))) {
      if (why && len) snprintf(why, len, "%s rail profile: its gauge face is undercut once inclined (point %zu)", what, k + 1);
      return HM_EDOMAIN;
    }
    if (rail_z(r, k) > rail_z(r, top)) top = k;
  }
  const double level = rail_z(r, top) - cfg->gauge_depth_m;
  for (size_t k = top; k > 0; --k)
    if (rail_z(r, k - 1) <= level) { /* crossing in [k - 1, k] */
      const double z0 = rail_z(r, k - 1), z1 = rail_z(r, k), u0 = rail_u(r, k - 1), u1 = rail_u(r, k);
      r->u_gp = u0 + (u1 - u0) * (level - z0) / (z1 - z0);
      return HM_OK;
    }
  if (why && len)
    snprintf(why, len, "%s rail profile: its gauge side does not reach %g mm below the top (the gauge point)", what,
             1e3 * cfg->gauge_depth_m);
  return HM_EDOMAIN;
}

/* The wheel profile at y (inside it) and its slope there. */
static double wheel_z(const hm_profile *w, double y, double *slope) {
  size_t lo = 0, hi = w->n - 1;
  while (hi - lo > 1) {
    const size_t mid = (lo + hi) / 2;
    if (w->y_m[mid] <= y) lo = mid;
    else hi = mid;
  }
  const double g = (w->z_m[lo + 1] - w->z_m[lo]) / (w->y_m[lo + 1] - w->y_m[lo]);
  if (slope) *slope = g;
  return w->z_m[lo] + g * (y - w->y_m[lo]);
}

/* A wheel over its rail: the wheelset shifted by s (to the left) and rolled by phi (the left side up) about its centre
 * on the axle; side +1 left, -1 right. Its profile's point k in the rail's coordinate u (from the gauge point, field
 * side +) and its height below the axle (negative), so that the axle must be at least z_rail(u) - zrel(u) high. */
typedef struct {
  const hm_profile *w;
  double sign, r0, half_fb, half_g, s, c, sn; /* cos and sin of the roll */
} wheel;

static double wheel_u(const wheel *w, size_t k) {
  const double yw = w->sign * (w->half_fb + w->w->y_m[k]), zw = -(w->r0 + w->w->z_m[k]);
  return w->sign * (yw * w->c - zw * w->sn + w->s) - w->half_g;
}
static double wheel_zrel(const wheel *w, size_t k) {
  const double yw = w->sign * (w->half_fb + w->w->y_m[k]), zw = -(w->r0 + w->w->z_m[k]);
  return yw * w->sn + zw * w->c;
}

/* The overlap of the rail and the wheel in u; 0, or -1 if there is none (or the rolled wheel is not a function of
 * u, a flank steeper than the roll allows). */
static int overlap(const rail *r, const wheel *w, double *lo, double *hi) {
  for (size_t k = 1; k < w->w->n; ++k)
    if (!(wheel_u(w, k) > wheel_u(w, k - 1))) return -1;
  *lo = fmax(rail_u(r, 0), wheel_u(w, 0));
  *hi = fmin(rail_u(r, r->p->n - 1), wheel_u(w, w->w->n - 1));
  return *hi >= *lo ? 0 : -1;
}

/* The contact: the u maximising z_rail(u) - zrel(u) over the overlap (the height the axle needs there), tried at
 * every point of both profiles and the overlap's ends, walking both in order of u: O(n_rail + n_wheel). The
 * overlap must exist. The height, u and the wheel profile's y there. */
static void contact(const rail *r, const wheel *w, double *height, double *u_best, double *yw_best) {
  double lo, hi;
  overlap(r, w, &lo, &hi);
  size_t i = 0, j = 0; /* the rail's and the wheel's segments holding u */
  const size_t nr = r->p->n, nw = w->w->n;
  double best = -INFINITY, bu = lo, by = 0.0, u = lo;
  for (;;) {
    while (i + 2 < nr && rail_u(r, i + 1) <= u) ++i;
    while (j + 2 < nw && wheel_u(w, j + 1) <= u) ++j;
    const double u0 = rail_u(r, i), u1 = rail_u(r, i + 1), v0 = wheel_u(w, j), v1 = wheel_u(w, j + 1);
    const double zr = rail_z(r, i) + (rail_z(r, i + 1) - rail_z(r, i)) * (u - u0) / (u1 - u0);
    const double t = (u - v0) / (v1 - v0);
    const double zw = wheel_zrel(w, j) + (wheel_zrel(w, j + 1) - wheel_zrel(w, j)) * t;
    const double f = zr - zw;
    if (f > best + 1e-15 || (f >= best - 1e-15 && u > bu)) { /* ties: the later (field side) point */
      best = fmax(best, f);
      bu = u;
      by = w->w->y_m[j] + (w->w->y_m[j + 1] - w->w->y_m[j]) * t;
    }
    if (u >= hi) break;
    /* the next point of either profile beyond u (the segments' ends: past the last segment there is none) */
    double next = hi;
    if (u1 > u) next = fmin(next, u1);
    if (v1 > u) next = fmin(next, v1);
    u = next > u ? next : hi;
  }
  *height = best;
  *u_best = bu;
  *yw_best = by;
}

/* The roll the wheelset takes when both wheels rest on their rails is within -+ this [rad]. */
#define MAX_ROLL_RAD 0.02

/* Both wheels of the wheelset rolled by phi. */
static void roll_to(wheel *l, wheel *r, double phi) {
  l->c = r->c = cos(phi);
  l->sn = r->sn = sin(phi);
}

hm_status hm_contact_delta_r(const hm_contact_config *cfg, const hm_profile *wl, const hm_profile *wr,
                             const hm_profile *rl, const hm_profile *rr, const double *shifts, size_t n_shifts,
                             hm_contact_point *out, char *why, size_t len) {
  if (!cfg || !wl || !rl || !shifts || !out) return HM_EINVAL;
  if (!wr) wr = wl;
  if (!rr) rr = rl;
  hm_status st = hm_contact_config_validate(cfg, why, len);
  if (st == HM_OK) st = hm_profile_check(wl, "left wheel", why, len);
  if (st == HM_OK) st = hm_profile_check(wr, "right wheel", why, len);
  if (st == HM_OK) st = hm_profile_check(rl, "left rail", why, len);
  if (st == HM_OK) st = hm_profile_check(rr, "right rail", why, len);
  if (st != HM_OK) return st;
  rail left, right;
  st = rail_setup(rl, cfg, "left", &left, why, len);
  if (st == HM_OK) st = rail_setup(rr, cfg, "right", &right, why, len);
  if (st != HM_OK) return st;
  wheel L = {wl, 1.0, cfg->r0_left_m, 0.5 * cfg->flange_back_distance_m, 0.5 * cfg->gauge_m, 0.0, 1.0, 0.0};
  wheel R = {wr, -1.0, cfg->r0_right_m, 0.5 * cfg->flange_back_distance_m, 0.5 * cfg->gauge_m, 0.0, 1.0, 0.0};
  /* every shift first (with roll: at both ends of the roll's range, and a root between): a wheel off its rail
   * anywhere is refused before anything is written */
  const int n_ends = cfg->include_roll ? 2 : 1;
  const double ends[2] = {cfg->include_roll ? -MAX_ROLL_RAD : 0.0, MAX_ROLL_RAD};
  for (size_t i = 0; i < n_shifts; ++i) {
    double lo, hi, hl, hr, u, y;
    int bad = !isfinite(shifts[i]);
    L.s = R.s = shifts[i];
    for (int e = 0; !bad && e < n_ends; ++e) {
      roll_to(&L, &R, ends[e]);
      bad = overlap(&left, &L, &lo, &hi) != 0 || overlap(&right, &R, &lo, &hi) != 0;
      if (!bad && cfg->include_roll) {
        contact(&left, &L, &hl, &u, &y);
        contact(&right, &R, &hr, &u, &y);
        bad = e == 0 ? !(hl >= hr) : !(hl <= hr); /* the left side's need falls as it rolls up */
      }
    }
    if (bad) {
      if (why && len)
        snprintf(why, len,
                 cfg->include_roll ? "at a shift of %g mm the wheels do not rest on both rails within a roll of "
                                     "-+0.02 rad (or a wheel does not lie over its rail)"
                                   : "at a shift of %g mm a wheel does not lie over its rail (the profiles do not "
                                     "overlap)",
                 1e3 * shifts[i]);
      return HM_EDOMAIN;
    }
  }
  for (size_t i = 0; i < n_shifts; ++i) {
    hm_contact_point p;
    double ul, ur, hl, hr, gl, gr, phi = 0.0;
    L.s = R.s = shifts[i];
    if (cfg->include_roll) { /* both wheels on their rails: the roll where the axle heights they need agree */
      double a = -MAX_ROLL_RAD, b = MAX_ROLL_RAD;
      for (int it = 0; it < 80 && b - a > 1e-13; ++it) {
        phi = 0.5 * (a + b);
        roll_to(&L, &R, phi);
        contact(&left, &L, &hl, &ul, &p.wheel_y_left_m);
        contact(&right, &R, &hr, &ur, &p.wheel_y_right_m);
        if (hl > hr) a = phi;
        else b = phi;
      }
      phi = 0.5 * (a + b);
    }
    roll_to(&L, &R, phi);
    contact(&left, &L, &hl, &ul, &p.wheel_y_left_m);
    contact(&right, &R, &hr, &ur, &p.wheel_y_right_m);
    p.roll_rad = phi;
    p.r_left_m = cfg->r0_left_m + wheel_z(wl, p.wheel_y_left_m, &gl);
    p.r_right_m = cfg->r0_right_m + wheel_z(wr, p.wheel_y_right_m, &gr);
    p.delta_r_m = p.r_left_m - p.r_right_m;
    p.contact_left_m = 0.5 * cfg->gauge_m + ul;
    p.contact_right_m = -(0.5 * cfg->gauge_m + ur);
    p.contact_angle_left_rad = -atan(gl);
    p.contact_angle_right_rad = -atan(gr);
    out[i] = p;
  }
  return HM_OK;
}
