/* Brent's root finder (R. P. Brent, Algorithms for Minimization without Derivatives, 1973, ch. 4). */
#include "hunting_monitor/roots.h"

#include <float.h>
#include <math.h>

hm_status hm_brent_root(hm_scalar_fn g, void *ctx, double a, double b, double ga, double gb, double xtol,
                        size_t max_iter, double *root) {
  if (!g || !root || !(xtol > 0.0) || !isfinite(a) || !isfinite(b)) return HM_EINVAL;
  if (ga == 0.0) {
    *root = a;
    return HM_OK;
  }
  if (gb == 0.0) {
    *root = b;
    return HM_OK;
  }
  if ((ga > 0.0) == (gb > 0.0) || !isfinite(ga) || !isfinite(gb)) return HM_EINVAL;
  double c = a, gc = ga, d = b - a, e = d;
  for (size_t it = 0; it < max_iter; ++it) {
    if ((gb > 0.0) == (gc > 0.0)) {
      c = a;
      gc = ga;
      d = e = b - a;
    }
    if (fabs(gc) < fabs(gb)) {
      a = b;
      b = c;
      c = a;
      ga = gb;
      gb = gc;
      gc = ga;
    }
    const double tol = 2.0 * DBL_EPSILON * fabs(b) + 0.5 * xtol;
    const double m = 0.5 * (c - b);
    if (fabs(m) <= tol || gb == 0.0) {
      *root = b;
      return HM_OK;
    }
    if (fabs(e) >= tol && fabs(ga) > fabs(gb)) {
      double p, q, r;
      const double s = gb / ga;
      if (a == c) {
        p = 2.0 * m * s;
        q = 1.0 - s;
      } else {
        q = ga / gc;
        r = gb / gc;
        p = s * (2.0 * m * q * (q - r) - (b - a) * (r - 1.0));
        q = (q - 1.0) * (r - 1.0) * (s - 1.0);
      }
      if (p > 0.0)
        q = -q;
      else
        p = -p;
      if (2.0 * p < fmin(3.0 * m * q - fabs(tol * q), fabs(e * q))) {
        e = d;
        d = p / q;
      } else {
        d = m;
        e = m;
      }
    } else {
      d = m;
      e = m;
    }
    a = b;
    ga = gb;
    b += fabs(d) > tol ? d : (m > 0.0 ? tol : -tol);
    hm_status st = g(b, &gb, ctx);
    if (st != HM_OK) return st;
    if (!isfinite(gb)) return HM_ENONFINITE;
  }
  return HM_ENOCONV;
}
