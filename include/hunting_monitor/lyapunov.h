/*
 * hunting_monitor - Lyapunov exponents of trajectories (Benettin's method with QR re-orthonormalisation).
 *
 * n_exp tangent vectors (initially the first n_exp unit vectors) are carried along the trajectory; every
 * renorm_interval_s they are re-orthonormalised by a QR factorisation (LAPACK dgeqrf/dorgqr) and
 * log|R_ii| is accumulated. After a transient (not counted) the exponents are the accumulated sums divided
 * by the averaging time, sorted in decreasing order [1/s]. Convergence is O(1/duration); no stopping test.
 */
#ifndef HUNTING_MONITOR_LYAPUNOV_H
#define HUNTING_MONITOR_LYAPUNOV_H

#include <stddef.h>

#include "hunting_monitor/integrate.h"
#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
  HM_LYAP_MIDPOINT = 0, /* implicit midpoint rule with its discrete tangent map (the study's method) */
  HM_LYAP_DOPRI = 1     /* Dormand-Prince 5(4) on the variational system */
} hm_lyap_method;

/* Most midpoint steps or renormalisation intervals one call may take (about 10 minutes of work). */
#define HM_LYAP_MAX_STEPS 1e9

typedef struct {
  hm_lyap_method method;
  double step_s;            /* midpoint: fixed step [s] (> 0); the renormalisation interval is rounded to it */
  double rtol, atol;        /* dopri tolerances */
  double newton_tol;        /* midpoint: Newton tolerance (see hm_midpoint_step) */
  size_t newton_max_iter;   /* midpoint: Newton iteration limit */
  double renorm_interval_s; /* time between QR re-orthonormalisations [s], > 0 */
  double transient_s;       /* time integrated before averaging starts [s], >= 0 */
  double duration_s;        /* averaging time [s], > 0 */
} hm_lyap_options;

/* Defaults: midpoint, h = 1e-4 s, Newton tol 1e-12 (20 iterations), rtol 1e-9, atol 1e-12, QR every 0.01 s,
 * no transient, 100 s of averaging. */
void hm_lyap_options_default(hm_lyap_options *opt);

/*
 * The n_exp (1..dim) largest Lyapunov exponents [1/s] of the trajectory of sys from (t0, x0), in decreasing
 * order. The system needs its Jacobian. Allocates its work memory for the duration of the call.
 * x_end (may be NULL) receives the final state. On failure the outputs are untouched; a trajectory that
 * leaves the finite range gives HM_ENONFINITE.
 */
hm_status hm_lyapunov_spectrum(const hm_ode_system *sys, double t0, const double *x0, size_t n_exp,
                               const hm_lyap_options *opt, double *exponents, double *x_end);

#ifdef __cplusplus
}
#endif

#endif
