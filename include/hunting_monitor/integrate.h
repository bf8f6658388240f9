/*
 * hunting_monitor - time integration of autonomous or non-autonomous ODE systems x' = f(t, x).
 *
 * Two integrators:
 *  - hm_dopri: the Dormand-Prince 5(4) embedded Runge-Kutta pair with error control and Shampine's
 *    4th-order continuous extension (dense output) [Hairer, Norsett, Wanner, Solving ODEs I, II.5-6].
 *  - hm_midpoint: the implicit midpoint rule x_{n+1} = x_n + h f(t_n + h/2, (x_n + x_{n+1})/2), solved by
 *    Newton's method with the analytic Jacobian and LAPACK dgesv (the study's choice for Lyapunov exponents:
 *    symplectic, A-stable, second order). It can propagate tangent vectors through the exact derivative of
 *    the discrete map.
 * Both are objects with a life cycle: all memory is allocated by create, none by the stepping functions.
 */
#ifndef HUNTING_MONITOR_INTEGRATE_H
#define HUNTING_MONITOR_INTEGRATE_H

#include <stddef.h>

#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Right-hand side: dxdt = f(t, x). Returns HM_OK, or an error that stops the integration. */
typedef hm_status (*hm_ode_fn)(double t, const double *x, double *dxdt, void *params);
/* Jacobian df/dx, row-major dim x dim (jac[dim*i + j] = d f_i / d x_j). */
typedef hm_status (*hm_ode_jac_fn)(double t, const double *x, double *jac, void *params);

typedef struct {
  size_t dim;           /* state dimension */
  hm_ode_fn rhs;
  hm_ode_jac_fn jac;    /* may be NULL where no Jacobian is needed (hm_dopri on the plain system) */
  void *params;
} hm_ode_system;

/*
 * Variational (first-order sensitivity) system of a base system: the state is z = [x, Phi] with Phi a
 * dim x k matrix stored column-major after x (column j is a tangent vector), and Phi' = J(t, x) Phi.
 * Fill base, k and jac_work (dim*dim doubles owned by the caller), then integrate an hm_ode_system with
 * dim + dim*k, rhs = hm_variational_rhs and params = the hm_variational.
 */
typedef struct {
  const hm_ode_system *base;
  size_t k;
  double *jac_work;
} hm_variational;

hm_status hm_variational_rhs(double t, const double *z, double *dzdt, void *variational);

/* ---- Dormand-Prince 5(4) ---- */

typedef struct hm_dopri_s *hm_dopri;

typedef struct {
  double rtol;         /* relative tolerance, > 0 */
  double atol;         /* absolute tolerance, >= 0 (rtol and atol not both 0) */
  double h_init;       /* first step; 0 chooses one automatically */
  double h_max;        /* largest step; 0 means |t1 - t0| */
  size_t max_steps;    /* accepted + rejected step limit; 0 means 10^8 */
  size_t err_dim;      /* the error is controlled on components [0, err_dim) only; 0 means all */
} hm_dopri_options;

typedef struct {
  size_t n_accepted;
  size_t n_rejected;
  size_t n_rhs;        /* right-hand-side evaluations */
} hm_dopri_stats;

/*
 * Called after every accepted step from t_old to t_new with the new state. Inside it,
 * hm_dopri_dense(integ, t, out) interpolates any t in [t_old, t_new]. Return 0 to continue, nonzero to stop
 * the integration there (hm_dopri_integrate then returns HM_OK with *t_end = t_new).
 */
typedef int (*hm_dopri_observer)(hm_dopri integ, double t_old, double t_new, const double *x_new, void *ctx);

/* Allocate an integrator for systems of dimension dim; NULL if dim == 0 or out of memory. */
hm_dopri hm_dopri_create(size_t dim);
void hm_dopri_destroy(hm_dopri integ);

/*
 * Integrate from t0 to t1 > t0 starting at x (length dim). Error per step: the weighted RMS norm of the
 * embedded error estimate over the controlled components (opt->err_dim, or all), weights atol + rtol
 * max(|x_old|, |x_new|), must be <= 1 (the first step is chosen from the same components); the step size follows
 * h_new = h min(5, max(0.2, 0.9 err^(-1/5))); a step whose stages are not finite is rejected and retried
 * with h/5. Fails with HM_ESTEP if the step falls below 1e-14 max(1, |t|) or the step limit is hit,
 * HM_ENONFINITE if that collapse came from non-finite values or x is not finite, or the rhs's own error.
 * On success x holds x(t_end) (t_end = t1 unless the observer stopped early); on failure x is untouched.
 * stats may be NULL. The last step is shortened to land exactly on t1.
 */
hm_status hm_dopri_integrate(hm_dopri integ, const hm_ode_system *sys, const hm_dopri_options *opt, double t0,
                             double t1, double *x, double *t_end, hm_dopri_observer observer, void *ctx,
                             hm_dopri_stats *stats);

/* Dense output inside the last accepted step (only valid inside an observer callback or right after
 * integration). HM_EINVAL if t is outside [t_old, t_new] of that step by more than 1e-12 of its length. */
hm_status hm_dopri_dense(const hm_dopri integ, double t, double *x_out);

/* Dense output of components [first, first + count) only (for cheap monitoring of a few states). */
hm_status hm_dopri_dense_partial(const hm_dopri integ, double t, size_t first, size_t count, double *x_out);

/* ---- Dormand-Prince 8(5,3) (DOP853) ---- */

typedef struct hm_dop853_s *hm_dop853;

/* Called after every accepted step with the state and its derivative at both ends (for Hermite interpolation; the
 * 8th-order pair has no cheap dense output). Return nonzero to stop there. */
typedef int (*hm_step_observer)(double t_old, const double *x_old, const double *f_old, double t_new,
                                const double *x_new, const double *f_new, void *ctx);

hm_dop853 hm_dop853_create(size_t dim);
void hm_dop853_destroy(hm_dop853 integ);

/*
 * Integrate from t0 to t1 >= t0 with the 8th-order pair of Hairer, Norsett and Wanner (Solving ODEs I, II.10): 12
 * right-hand sides per step; the error of the 5th- and 3rd-order embedded formulas combined as in their DOP853,
 * weights atol + rtol max(|x_old|, |x_new|) over the controlled components (opt->err_dim or all), must be <= 1;
 * h_new = h min(6, max(0.333, 0.9 err^(-1/8))). The same options, statuses and failure rules as hm_dopri_integrate
 * (HM_ESTEP, HM_ENONFINITE; x untouched on failure). At tolerances of 1e-9 and below it takes about a quarter of
 * DOPRI5's steps and half its right-hand-side evaluations on the wheelset's cycles.
 */
hm_status hm_dop853_integrate(hm_dop853 integ, const hm_ode_system *sys, const hm_dopri_options *opt, double t0,
                              double t1, double *x, hm_step_observer observer, void *ctx, hm_dopri_stats *stats);

/* ---- implicit midpoint rule ---- */

typedef struct hm_midpoint_s *hm_midpoint;

/* Allocate for dimension dim (and tangent matrices of up to dim columns). NULL on failure. */
hm_midpoint hm_midpoint_create(size_t dim);
void hm_midpoint_destroy(hm_midpoint mp);

/*
 * One step of size h > 0 from (t, x). Newton's iteration from the explicit-Euler predictor stops when the
 * update satisfies max_i |dz_i| <= newton_tol (1 + max_i |z_i|); more than max_iter iterations give
 * HM_ENOCONV. The system needs its Jacobian. If tangent != NULL it is a dim x k column-major matrix that
 * is replaced by M tangent with M = (I - h/2 J)^{-1} (I + h/2 J), J at the final midpoint: the exact
 * derivative of the step map for linear systems and the standard discrete variational map otherwise.
 * On failure x and tangent are untouched.
 */
hm_status hm_midpoint_step(hm_midpoint mp, const hm_ode_system *sys, double t, double h, double newton_tol,
                           size_t max_iter, double *x, double *tangent, size_t k);

#ifdef __cplusplus
}
#endif

#endif
