/* delta-r from wheel and rail profiles: rigid single-point contact, roll neglected (contact.h). */
#include "hunting_monitor/contact.h"

#include <math.h>
#include <stdio.h>

void hm_contact_config_default(hm_contact_config *cfg) {
  if (!cfg) return;
  cfg->r0_left_m = cfg->r0_right_m = 0.46;
  cfg->measuring_circle_m = 0.070;
  cfg->flange_back_distance_m = 1.360;
  cfg->gauge_m = 1.435;
  cfg->gauge_depth_m = 0.014;
  cfg->inclination = 1.0 / 40.0;
}

hm_status hm_contact_config_validate(const hm_contact_config *c, char *why, size_t len) {
  if (!c) return HM_EINVAL;
  const struct {
    const char *name;
    double v, lo, hi;
  } f[] = {{"r0_left_m", c->r0_left_m, 0.1, 1.0},
           {"r0_right_m", c->r0_right_m, 0.1, 1.0},
           {"measuring_circle_m", c->measuring_circle_m, 0.0, 0.2},
           {"flange_back_distance_m", c->flange_back_distance_m, 0.5, 2.0},
           {"gauge_m", c->gauge_m, 0.5, 2.0},
           {"gauge_depth_m", c->gauge_depth_m, 0.001, 0.05},
           {"inclination", c->inclination, 0.0, 0.1}};
  for (size_t i = 0; i < sizeof f / sizeof f[0]; ++i)
    if (!(f[i].v >= f[i].lo && f[i].v <= f[i].hi)) {
      if (why && len) snprintf(why, len, "%s: must be in [%g, %g] (got %g)", f[i].name, f[i].lo, f[i].hi, f[i].v);
      return HM_EDOMAIN;
    }
  if (!(c->gauge_m > c->flange_back_distance_m)) {
    if (why && len)
      snprintf(why, len, "gauge_m: must exceed flange_back_distance_m (got %g and %g)", c->gauge_m,
               c->flange_back_distance_m);
    return HM_EDOMAIN;
  }
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

/* The overlap of the rail and the wheel (at y_w = u + off) in u; 0, or -1 if there is none. */
static int overlap(const rail *r, const hm_profile *w, double off, double *lo, double *hi) {
  *lo = fmax(rail_u(r, 0), w->y_m[0] - off);
  *hi = fmin(rail_u(r, r->p->n - 1), w->y_m[w->n - 1] - off);
  return *hi >= *lo ? 0 : -1;
}

/* The contact of a wheel on its rail with the wheel's profile at y_w = u + off: the u maximising
 * z_rail(u) + z_wheel(u + off) over the overlap, tried at every point of both (and the overlap's ends), walking both
 * in order of u: O(n_rail + n_wheel). The overlap must exist. */
static void contact(const rail *r, const hm_profile *w, double off, double *u_best, double *yw_best) {
  double lo, hi;
  overlap(r, w, off, &lo, &hi);
  size_t i = 0, j = 0; /* the rail's and the wheel's segments holding u */
  const size_t nr = r->p->n, nw = w->n;
  double best = -INFINITY, bu = lo, u = lo;
  for (;;) {
    while (i + 2 < nr && rail_u(r, i + 1) <= u) ++i;
    while (j + 2 < nw && w->y_m[j + 1] - off <= u) ++j;
    const double u0 = rail_u(r, i), u1 = rail_u(r, i + 1);
    const double zr = rail_z(r, i) + (rail_z(r, i + 1) - rail_z(r, i)) * (u - u0) / (u1 - u0);
    const double y = u + off;
    const double zw = w->z_m[j] + (w->z_m[j + 1] - w->z_m[j]) * (y - w->y_m[j]) / (w->y_m[j + 1] - w->y_m[j]);
    const double f = zr + zw;
    if (f > best + 1e-15 || f >= best - 1e-15) { /* ties: the later (field side) point */
      if (f > best + 1e-15 || u > bu) bu = u;
      best = fmax(best, f);
    }
    if (u >= hi) break;
    /* the next point of either profile beyond u (the segments' ends: past the last segment there is none) */
    double next = hi;
    if (u1 > u) next = fmin(next, u1);
    if (w->y_m[j + 1] - off > u) next = fmin(next, w->y_m[j + 1] - off);
    u = next > u ? next : hi;
  }
  *u_best = bu;
  *yw_best = bu + off;
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
  const double c = 0.5 * (cfg->gauge_m - cfg->flange_back_distance_m);
  /* every shift first: a wheel off its rail anywhere is refused before anything is written */
  for (size_t i = 0; i < n_shifts; ++i) {
    double lo, hi;
    if (!isfinite(shifts[i]) || overlap(&left, wl, c - shifts[i], &lo, &hi) != 0 ||
        overlap(&right, wr, c + shifts[i], &lo, &hi) != 0) {
      if (why && len)
        snprintf(why, len, "at a shift of %g mm a wheel does not lie over its rail (the profiles do not overlap)",
                 1e3 * shifts[i]);
      return HM_EDOMAIN;
    }
  }
  for (size_t i = 0; i < n_shifts; ++i) {
    hm_contact_point p;
    double ul, ur, gl, gr;
    contact(&left, wl, c - shifts[i], &ul, &p.wheel_y_left_m);
    contact(&right, wr, c + shifts[i], &ur, &p.wheel_y_right_m);
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
