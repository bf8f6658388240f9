/*
 * hunting_monitor - the equivalent conicity from the identified hunting mode (issue #9, docs/MODEL.md section 2).
 *
 * The linear model's characteristic polynomial is q(s) + g e lambda with q(s) = (s^2 + c1/v s + a)(s^2 + c2/v s + b)
 * (linear.h), so along the speed v the hunting root s(lambda) moves with ds/dlambda = -g e / q'(s). Given the measured
 * mode s_m = sigma_m + i w_m with standard errors (e_sigma, e_w), the conicity is the lambda whose hunting root is
 * nearest in the weighted sense:
 *     minimise  ((Re s(lambda) - sigma_m) / e_sigma)^2 + ((Im s(lambda) - w_m) / e_w)^2
 * by Gauss-Newton in lambda, the root followed by complex Newton on q(s) + g e lambda = 0 from s_m (converged when
 * the lambda step is below tol; HM_ENOCONV after max_iter). Each residual is weighted by its sensitivity: near the
 * Hopf speed the frequency hardly moves with lambda (on the boundary w^2 = A3/A1 does not at all) and the decay rate
 * carries the estimate; far below it the frequency helps. The standard error is 1/sqrt(J'J), J the weighted
 * sensitivities; chi2 (one degree of freedom) says how well any lambda explains both measured quantities.
 * The errors passed in should include the model's own error (a relative frequency error of the model, the
 * identification's bias), not only the statistical ones: see margin.h.
 */
#ifndef HUNTING_MONITOR_INVERSION_H
#define HUNTING_MONITOR_INVERSION_H

#include "hunting_monitor/model.h"
#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  double conicity;             /* lambda(0) [-] */
  double conicity_se;          /* its standard error */
  double chi2;                 /* weighted misfit at the solution (1 degree of freedom) */
  double model_decay_rate_1_s; /* the hunting root at the solution */
  double model_frequency_hz;
  double dsigma_dconicity;     /* sensitivities there [1/s], [Hz] per unit conicity */
  double dfrequency_dconicity;
  unsigned iterations;
} hm_conicity_inversion;

/* sigma_m [1/s] < 0, w_m [Hz] > 0, errors > 0, speed [km/h] > 0, tol > 0 (in conicity). HM_EDOMAIN for bad input,
 * HM_ENOCONV if the iteration fails or leaves 0 < lambda < 10; out untouched on failure. */
hm_status hm_conicity_from_mode(const hm_linear_coef *coef, double speed_kmh, double decay_rate_1_s,
                                double decay_rate_err_1_s, double frequency_hz, double frequency_err_hz, double tol,
                                unsigned max_iter, hm_conicity_inversion *out);

/* The hunting root (the one of the two complex pairs with the larger real part) of the linear model at a conicity
 * and speed, by dgeev-free closed iteration from a start near it: used by the tests and the margin. */
hm_status hm_hunting_root(const hm_linear_coef *coef, double speed_kmh, double conicity, double *sigma_1_s,
                          double *omega_rad_s);

#ifdef __cplusplus
}
#endif

#endif
