/* Private to the core: what the explicit Runge-Kutta integrators (integrate.c's Dormand-Prince 5(4), dop853.c)
 * share. */
#ifndef HM_CORE_RK_H
#define HM_CORE_RK_H

#include "hunting_monitor/integrate.h"

/* The common argument checks: HM_EINVAL for a missing or mismatched system or options, t1 < t0, bad tolerances;
 * HM_ENONFINITE for a non-finite start. */
hm_status hm_rk_check(const hm_ode_system *sys, size_t dim, const hm_dopri_options *opt, double t0, double t1,
                      const double *x);

/* The number of leading components whose error is controlled (opt->err_dim, or all of dim). */
static inline size_t hm_rk_err_dim(const hm_dopri_options *opt, size_t dim) {
  return opt->err_dim && opt->err_dim < dim ? opt->err_dim : dim;
}

/* An explicit pair as the adaptive loop sees it. */
typedef struct {
  /* One step of size h from t: HM_OK with the error norm in *err (+inf for a step that is not finite), or an
   * error that ends the run. */
  hm_status (*attempt)(void *ctx, double t, double h, double *err);
  /* The attempted step to t_new was accepted: make it current; a nonzero *stop ends the run there. */
  hm_status (*accept)(void *ctx, double t_old, double t_new, double h, int *stop);
  void *ctx;
  double expo;                   /* 1 / (the lower order + 1): the error goes as h^(1/expo) */
  double fac_min, fac_max;       /* step-size change limits */
  size_t rhs_per_attempt, rhs_per_accept;
} hm_rk_method;

/* The adaptive loop from t0 (the method's state current there) with first step h to t1: the last step shortened
 * to land on t1; h_new = h 0.9 err^-expo within [fac_min, fac_max] (no growth right after a rejection, at most
 * opt->h_max); a non-finite step retried at h/5; HM_ESTEP when h falls below 1e-14 max(1, |t|) (HM_ENONFINITE if
 * that came from non-finite steps) or the step limit is reached. *t_reached and *s (counts added) on return. */
hm_status hm_rk_drive(const hm_rk_method *m, const hm_dopri_options *opt, double t0, double t1, double h,
                      double *t_reached, hm_dopri_stats *s);

#endif
