/* hunting_monitor - scalar root finding (Brent's method), shared by the bifurcation and estimator modules. */
#ifndef HUNTING_MONITOR_ROOTS_H
#define HUNTING_MONITOR_ROOTS_H

#include <stddef.h>

#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* g(x) into *value; an error status stops the search and is returned. */
typedef hm_status (*hm_scalar_fn)(double x, double *value, void *ctx);

/*
 * Root of g in [a, b] with g(a) = ga and g(b) = gb of opposite signs (or one of them zero), by Brent's method
 * (inverse quadratic interpolation safeguarded by bisection). Stops when the bracket is no wider than
 * xtol + 4 eps |x| (roots.c: half-width m against 0.5 xtol + 2 eps |x|) or g(x) == 0. HM_EINVAL if the signs do not differ or xtol <= 0; HM_ENOCONV after
 * max_iter evaluations. *root untouched on failure.
 */
hm_status hm_brent_root(hm_scalar_fn g, void *ctx, double a, double b, double ga, double gb, double xtol,
                        size_t max_iter, double *root);

#ifdef __cplusplus
}
#endif

#endif
