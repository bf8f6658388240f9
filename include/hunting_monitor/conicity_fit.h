/*
 * hunting_monitor - fit of the equivalent conicity lambda(y) to measured (y, lambda) pairs.
 *
 * Model: lambda(y) = constant + sum of n_terms Gaussians a_i exp(-((y - b_i)/c_i)^2) (docs/MODEL.md section 3), or
 * its symmetric form (pairs at +-b sharing a and c; an odd count adds one term centred at 0), with the constant
 * free or fixed at 0 (MATLAB's gauss3 has none). Widths are kept positive by fitting log c.
 *
 * Method: Levenberg-Marquardt (Marquardt's diagonal scaling, Nielsen's damping update) with the analytic
 * Jacobian; each step solves the damped normal equations by Cholesky (LAPACK dposv). Convergence: the step is
 * below tol (|p| + tol) or the relative decrease of SSE below tol. Several automatic starting points (peaks of
 * the data with half-maximum widths, the same with halved and doubled widths, evenly spaced centres) are tried
 * and the lowest SSE kept.
 *
 * Statistics as curve-fitting tools define them (MATLAB's Curve Fitting Toolbox): SSE = sum (lambda - fit)^2,
 * R^2 = 1 - SSE/SST, adjusted R^2 = 1 - (SSE/dof) / (SST/(n - 1)), RMSE = sqrt(SSE/dof) with dof = n - m for
 * m fitted parameters; standard errors sqrt(diag(RMSE^2 (J^T J)^-1)) with J the Jacobian in (constant, a, b, c).
 */
#ifndef HUNTING_MONITOR_CONICITY_FIT_H
#define HUNTING_MONITOR_CONICITY_FIT_H

#include <stddef.h>

#include "hunting_monitor/model.h"
#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  size_t n_terms;     /* Gaussians, 1..HM_CONICITY_MAX_TERMS */
  int symmetric;      /* pairs at +-b with shared amplitude and width */
  int fit_constant;   /* 1: the constant is fitted; 0: fixed at 0 */
  size_t max_iter;    /* Levenberg-Marquardt iterations per start */
  double tol;         /* convergence tolerance (relative) */
} hm_fit_options;

/* Defaults: 2 terms, not symmetric, constant fitted, 400 iterations, tol 1e-12. */
void hm_fit_options_default(hm_fit_options *opt);

typedef struct {
  hm_conicity conicity;       /* the fitted lambda(y) (pairs expanded into two terms) */
  double constant_se;         /* standard errors; NaN only if (J^T J) is singular (then se_available = 0) */
  double amplitude_se[HM_CONICITY_MAX_TERMS];
  double center_se[HM_CONICITY_MAX_TERMS];
  double width_se[HM_CONICITY_MAX_TERMS];
  int se_available;
  double sse, r2, adj_r2, rmse;
  size_t n_points, n_params, dof;
  size_t iterations;          /* of the best start */
  size_t starts_tried;
} hm_fit_result;

/*
 * Fit n points (y_m [m], conicity). HM_EDOMAIN with a reason in why for: fewer points than parameters + 1,
 * a non-finite value, all displacements equal, or a constant conicity (nothing to fit); HM_EINVAL for bad
 * options; HM_ENOCONV if no start converged to a finite fit. Allocates its work memory during the call.
 */
hm_status hm_conicity_fit(const double *y_m, const double *conicity, size_t n, const hm_fit_options *opt,
                          hm_fit_result *out, char *why, size_t why_len);

#ifdef __cplusplus
}
#endif

#endif
