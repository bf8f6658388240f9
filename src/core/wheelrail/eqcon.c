/* Equivalent conicity from delta-r, EN 15302's integration method and the weighted regression (eqcon.h). */
#include "hunting_monitor/eqcon.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "validate.h"

#define PI 3.14159265358979323846

void hm_eqcon_config_default(hm_eqcon_config *cfg) {
  if (!cfg) return;
  cfg->r0_m = 0.46;
  cfg->contact_distance_m = 1.5;
  cfg->tol = 1e-7;
}

hm_status hm_eqcon_config_validate(const hm_eqcon_config *cfg, char *why, size_t why_len) {
  if (!cfg) return HM_EINVAL;
  const hm_field_check f[] = {{"r0_m", cfg->r0_m, HM_RULE_RANGE, HM_R0_MIN_M, HM_R0_MAX_M},
                              {"contact_distance_m", cfg->contact_distance_m, HM_RULE_RANGE_OPEN, 0.0, 5.0},
                              {"tol", cfg->tol, HM_RULE_RANGE, 1e-14, 1e-2}};
  return hm_check_fields(f, HM_COUNT_OF(f), why, why_len);
}

/* The restoring equilibrium nearest y = 0; 0 and *y_eq, or -1. */
static int equilibrium(const double *y, const double *dr, size_t n, double *y_eq) {
  double best = NAN;
  for (size_t k = 0; k + 1 < n; ++k) {
    if (!(dr[k] <= 0.0 && dr[k + 1] > 0.0)) continue; /* rising through zero (or from it) */
    const double z = y[k] + (y[k + 1] - y[k]) * (-dr[k]) / (dr[k + 1] - dr[k]);
    if (isnan(best) || fabs(z) < fabs(best)) best = z;
  }
  if (isnan(best)) return -1;
  *y_eq = best;
  return 0;
}

hm_status hm_eqcon_check(const double *y, const double *dr, size_t n, char *why, size_t why_len) {
  if (!y || !dr) return HM_EINVAL;
  if (n < 3) {
    if (why && why_len) snprintf(why, why_len, "delta-r: %zu points, at least 3 are needed", n);
    return HM_EDOMAIN;
  }
  for (size_t k = 0; k < n; ++k) {
    if (!isfinite(y[k]) || !isfinite(dr[k])) {
      if (why && why_len) snprintf(why, why_len, "delta-r: point %zu is not finite", k + 1);
      return HM_EDOMAIN;
    }
    if (k > 0 && !(y[k] > y[k - 1])) {
      if (why && why_len)
        snprintf(why, why_len, "delta-r: y must increase strictly (point %zu: %g after %g)", k + 1, y[k], y[k - 1]);
      return HM_EDOMAIN;
    }
    if (fabs(y[k]) > 0.1 || fabs(dr[k]) > 0.1 || (k > 0 && y[k] - y[k - 1] < 1e-9)) {
      if (why && why_len)
        snprintf(why, why_len,
                 "delta-r: point %zu (%g, %g mm) lies beyond -+100 mm or closer than 1 nm to the previous one: not a "
                 "wheelset's delta-r in metres",
                 k + 1, 1e3 * y[k], 1e3 * dr[k]);
      return HM_EDOMAIN;
    }
  }
  double y_eq;
  if (equilibrium(y, dr, n, &y_eq) != 0) {
    if (why && why_len)
      snprintf(why, why_len, "delta-r: no restoring equilibrium (delta-r never rises through zero): not a wheelset's");
    return HM_EDOMAIN;
  }
  return HM_OK;
}

struct hm_eqcon_s {
  hm_eqcon_config cfg;
  size_t n;
  double *y, *dr, *cum; /* the table and int_{y[0]}^{y[k]} delta-r (exact: trapezoids) */
  double y_eq, i_eq;    /* the equilibrium and the integral up to it */
};

typedef struct hm_eqcon_s table;

static double cumulative(const table *t, double y);

hm_status hm_eqcon_create(const hm_eqcon_config *cfg, const double *y, const double *dr, size_t n, hm_eqcon *out,
                          char *why, size_t why_len) {
  if (!cfg || !y || !dr || !out) return HM_EINVAL;
  hm_status st = hm_eqcon_config_validate(cfg, why, why_len);
  if (st == HM_OK) st = hm_eqcon_check(y, dr, n, why, why_len);
  if (st != HM_OK) return st;
  table *t = malloc(sizeof *t);
  double *buf = malloc(3 * n * sizeof *buf);
  if (!t || !buf) {
    free(t);
    free(buf);
    return HM_ENOMEM;
  }
  t->cfg = *cfg;
  t->n = n;
  t->y = buf;
  t->dr = buf + n;
  t->cum = buf + 2 * n;
  for (size_t k = 0; k < n; ++k) {
    t->y[k] = y[k];
    t->dr[k] = dr[k];
    t->cum[k] = k ? t->cum[k - 1] + 0.5 * (dr[k - 1] + dr[k]) * (y[k] - y[k - 1]) : 0.0;
  }
  equilibrium(y, dr, n, &t->y_eq);
  t->i_eq = cumulative(t, t->y_eq);
  *out = t;
  return HM_OK;
}

void hm_eqcon_destroy(hm_eqcon e) {
  if (!e) return;
  free(e->y);
  free(e);
}

double hm_eqcon_equilibrium_m(const hm_eqcon e) { return e ? e->y_eq : NAN; }

/* delta-r at y in segment k: linear. */
static double dr_in(const table *t, size_t k, double y) {
  return t->dr[k] + (t->dr[k + 1] - t->dr[k]) * (y - t->y[k]) / (t->y[k + 1] - t->y[k]);
}

/* The segment holding y (clamped to the table). */
static size_t segment(const table *t, double y) {
  size_t lo = 0, hi = t->n - 1;
  while (hi - lo > 1) {
    const size_t mid = (lo + hi) / 2;
    if (t->y[mid] <= y) lo = mid;
    else hi = mid;
  }
  return lo;
}

/* int_{y[0]}^{y} delta-r (exact for the table). */
static double cumulative(const table *t, double y) {
  const size_t k = segment(t, y);
  return t->cum[k] + 0.5 * (t->dr[k] + dr_in(t, k, y)) * (y - t->y[k]);
}

/* I(y) = int_{y_eq}^{y} delta-r. */
static double potential(const table *t, double y) { return cumulative(t, y) - t->i_eq; }

/* int_{ya}^{yb} delta-r, exactly within one segment (no cancellation where the turning point's inverse square root
 * needs the small differences right). */
static double between(const table *t, double ya, double yb) {
  const size_t ka = segment(t, ya), kb = segment(t, yb);
  if (ka == kb) return 0.5 * (dr_in(t, ka, ya) + dr_in(t, ka, yb)) * (yb - ya);
  return cumulative(t, yb) - cumulative(t, ya);
}

/* The turning point on side (+1 right, -1 left) of y_eq where I first reaches J > 0: 0 and *yt, or -1 if the table
 * ends first; bisection in the segment where it happens, to tol of the segment. */
static int turning_point(const table *t, int side, double J, double tol, double *yt) {
  const size_t k0 = segment(t, t->y_eq);
  for (size_t i = 0;; ++i) {
    double a, b; /* the part of a segment outward from y_eq, a nearer to it */
    if (side > 0) {
      const size_t k = k0 + i;
      if (k + 1 >= t->n) return -1;
      a = fmax(t->y[k], t->y_eq);
      b = t->y[k + 1];
    } else {
      if (i > k0) return -1;
      const size_t k = k0 - i;
      a = fmin(t->y[k + 1], t->y_eq);
      b = t->y[k];
    }
    if (potential(t, b) < J) continue;
    const double width = fabs(b - a);
    for (int it = 0; it < 200 && fabs(b - a) > tol * width; ++it) {
      const double mid = 0.5 * (a + b);
      if (potential(t, mid) >= J) b = mid;
      else a = mid;
    }
    *yt = 0.5 * (a + b);
    return 0;
  }
}

static const double GL_X[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290, -0.1834346424956498,
                               0.1834346424956498,  0.5255324099163290,  0.7966664774136267,  0.9602898564975363};
static const double GL_W[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873, 0.3626837833783620,
                               0.3626837833783620, 0.3137066458778873, 0.2223810344533745, 0.1012285362903763};

typedef double (*integrand)(const table *t, const void *p, double s);

/* int_a^b f by composite 8-point Gauss-Legendre, panels doubled (from 16 to 8192) until two agree to tol. */
static hm_status quad(const table *t, const void *p, integrand f, double a, double b, double tol, double *out) {
  double prev = NAN;
  for (unsigned panels = 16; panels <= 8192; panels *= 2) {
    const double h = (b - a) / panels;
    double s = 0.0;
    for (unsigned i = 0; i < panels; ++i) {
      const double c = a + (i + 0.5) * h;
      for (int j = 0; j < 8; ++j) s += GL_W[j] * f(t, p, c + 0.5 * h * GL_X[j]);
    }
    s *= 0.5 * h;
    if (!isfinite(s)) return HM_ENONFINITE;
    if (isfinite(prev) && fabs(s - prev) <= tol * fabs(s)) {
      *out = s;
      return HM_OK;
    }
    prev = s;
  }
  return HM_ENOCONV;
}

/* The half of the integral from y_eq to a turning point: y = yt - (yt - y_eq) s^2, dy = 2 (yt - y_eq) s ds. */
typedef struct {
  double yt;
} half;

static double half_integrand(const table *t, const void *p, double s) {
  const half *h = p;
  const double d = h->yt - t->y_eq, y = h->yt - d * s * s;
  /* I(yt) - I(y), measured from the turning point found (not from J: its bisection error would sit under the
   * square root at s -> 0) */
  const double gap = d > 0.0 ? between(t, y, h->yt) : between(t, h->yt, y) * -1.0;
  if (!(gap > 0.0)) { /* s at rounding level from the turning point: the limit 2 sqrt(d / delta-r(yt)) */
    const double g = dr_in(t, segment(t, h->yt), h->yt);
    return 2.0 * sqrt(fabs(d) / fabs(g));
  }
  return 2.0 * fabs(d) * s / sqrt(gap);
}

/* The regression's integrand delta-r(y_eq + a sin phi) sin phi. */
typedef struct {
  double a;
} harm;

static double harm_integrand(const table *t, const void *p, double phi) {
  const double y = fmin(fmax(t->y_eq + ((const harm *)p)->a * sin(phi), t->y[0]), t->y[t->n - 1]);
  return dr_in(t, segment(t, y), y) * sin(phi);
}

hm_status hm_eqcon_at(const hm_eqcon t, hm_eqcon_method method, double amplitude_m, hm_eqcon_result *out) {
  if (!t || !out) return HM_EINVAL;
  if (!(amplitude_m >= 1e-7 && amplitude_m <= 0.1) ||
      (method != HM_EQCON_INTEGRATION && method != HM_EQCON_REGRESSION))
    return HM_EDOMAIN;
  const double *y = t->y, tol = t->cfg.tol;
  const size_t n = t->n;
  const double e0r0 = 0.5 * t->cfg.contact_distance_m * t->cfg.r0_m;
  hm_eqcon_result r;
  r.equilibrium_m = t->y_eq;
  if (method == HM_EQCON_REGRESSION) {
    const double slack = 1e-9 * amplitude_m; /* an oscillation reaching the table's end is inside it */
    if (t->y_eq - amplitude_m < y[0] - slack || t->y_eq + amplitude_m > y[n - 1] + slack) return HM_EDOMAIN;
    const harm h = {amplitude_m};
    double s;
    const hm_status st = quad(t, &h, harm_integrand, -0.5 * PI, 0.5 * PI, tol, &s);
    if (st != HM_OK) return st;
    r.tan_gamma_e = s / (PI * amplitude_m);
    r.wavelength_m = r.tan_gamma_e > 0.0 ? 2.0 * PI * sqrt(e0r0 / r.tan_gamma_e) : INFINITY;
    r.y_low_m = t->y_eq - amplitude_m;
    r.y_high_m = t->y_eq + amplitude_m;
    if (!isfinite(r.tan_gamma_e) || !(r.wavelength_m > 0.0)) return HM_ENONFINITE;
    *out = r;
    return HM_OK;
  }
  /* a dead zone (delta-r = 0 about the equilibrium, as a worn profile pair can have): an oscillation within it has
   * no restoring term, tan gamma_e = 0 (an infinite wavelength) */
  size_t kl = segment(t, t->y_eq), kr = kl + 1;
  while (kl > 0 && t->dr[kl] == 0.0 && t->dr[kl - 1] == 0.0) --kl;
  while (kr + 1 < n && t->dr[kr] == 0.0 && t->dr[kr + 1] == 0.0) ++kr;
  const double zl = t->dr[kl] == 0.0 ? y[kl] : t->y_eq, zr = t->dr[kr] == 0.0 ? y[kr] : t->y_eq;
  if (amplitude_m <= 0.5 * (zr - zl) * (1.0 + 1e-6)) {
    r.tan_gamma_e = 0.0;
    r.wavelength_m = INFINITY;
    r.y_low_m = zl;
    r.y_high_m = zr;
    *out = r;
    return HM_OK;
  }
  /* J for the amplitude: half the distance between the turning points rises with J; bisection on J between 0 and
   * the largest J the table holds on both sides */
  const double j_max = fmin(potential(t, y[n - 1]), potential(t, y[0]));
  double ylo, yhi;
  if (!(j_max > 0.0) || turning_point(t, 1, j_max, tol, &yhi) != 0 || turning_point(t, -1, j_max, tol, &ylo) != 0 ||
      0.5 * (yhi - ylo) < amplitude_m * (1.0 - 1e-12))
    return HM_EDOMAIN;
  double ja = 0.0, jb = j_max;
  for (int it = 0; it < 300; ++it) {
    const double jm = 0.5 * (ja + jb);
    if (turning_point(t, 1, jm, tol, &yhi) != 0 || turning_point(t, -1, jm, tol, &ylo) != 0) return HM_EDOMAIN;
    const double a = 0.5 * (yhi - ylo);
    if (fabs(a - amplitude_m) <= tol * amplitude_m) {
      ja = jb = jm;
      break;
    }
    if (a < amplitude_m) ja = jm;
    else jb = jm;
  }
  const double J = 0.5 * (ja + jb);
  if (turning_point(t, 1, J, tol, &yhi) != 0 || turning_point(t, -1, J, tol, &ylo) != 0) return HM_EDOMAIN;
  const half right = {yhi}, left = {ylo};
  double ir, il;
  hm_status st = quad(t, &right, half_integrand, 0.0, 1.0, tol, &ir);
  if (st != HM_OK) return st;
  st = quad(t, &left, half_integrand, 0.0, 1.0, tol, &il);
  if (st != HM_OK) return st;
  r.wavelength_m = 2.0 * sqrt(e0r0) * (ir + il);
  r.tan_gamma_e = e0r0 * pow(2.0 * PI / r.wavelength_m, 2.0);
  r.y_low_m = ylo;
  r.y_high_m = yhi;
  if (!isfinite(r.tan_gamma_e) || !(r.wavelength_m > 0.0)) return HM_ENONFINITE;
  *out = r;
  return HM_OK;
}
