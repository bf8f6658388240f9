/*
 * hunting_monitor - equivalent conicity tan gamma_e from the rolling-radius difference delta-r (EN 15302, UIC 519;
 * issue #19).
 *
 * Input: delta-r(y) = r_left - r_right [m] as the wheelset moves y [m] to the left, tabulated (y strictly
 * increasing, linear between the points): from a profile gauge's wheel and rail profiles or measured. Any function
 * that restores the wheelset (delta-r rising through zero at an equilibrium y_eq): symmetric, asymmetric, or offset
 * (unequal wheel radii move y_eq).
 *
 * Two methods:
 *  - integration (EN 15302's): the kinematic (Klingel) oscillation of the wheelset rolling without slip obeys
 *        y'' = -delta-r(y) / (2 e0 r0)      (' : d/dx along the track; e0 half the distance between the contact
 *                                            points, r0 the nominal rolling radius)
 *    For an amplitude a (half the peak-to-peak motion y2 - y1 between its turning points, which have equal
 *    potential V(y) = int_{y_eq}^{y} delta-r / (2 e0 r0)) its wavelength is
 *        L(a) = 2 sqrt(e0 r0) int_{y1}^{y2} dy / sqrt(J - I(y)),   I(y) = int_{y_eq}^{y} delta-r,  J = I(y1) = I(y2)
 *    and tan gamma_e(a) is the cone's conicity with Klingel's wavelength L = 2 pi sqrt(e0 r0 / tan gamma):
 *        tan gamma_e = e0 r0 (2 pi / L)^2.
 *    I is exact for the piecewise-linear table; the turning points are found by bisection on J; the integral, split
 *    at y_eq and with y = y_turn -+ (y_turn - y_eq) s^2 (which removes the turning points' inverse square roots), by
 *    composite 8-point Gauss-Legendre, panels doubled until two estimates agree to tol.
 *  - regression: the linear regression of delta-r over y_eq -+ a weighted with the distribution of a sinusoidal
 *    motion of amplitude a, i.e. with y = y_eq + a sin(phi), phi uniform; its slope is 2 tan gamma_e:
 *        tan gamma_e = (1 / (pi a)) int_{-pi/2}^{pi/2} delta-r(y_eq + a sin phi) sin phi dphi
 *    (the harmonic linearisation; the same quadrature).
 * A dead zone (delta-r = 0 about the equilibrium, as worn profile pairs have: EN 15302's case E4) restores nothing:
 * an amplitude within it has tan gamma_e = 0 and an infinite wavelength.
 * Both give tan gamma at every amplitude for a cone (delta-r = 2 y tan gamma) and for an offset one; for delta-r
 * = 2 (t y + k y^3) the integration gives Duffing's period (a complete elliptic integral) and the regression t + 3/4
 * k a^2; a dead zone the closed form of arcs joined by a drift (test_eqcon). On EN 15302's nine reference delta-r
 * functions (Annex E, test/cli/en15302) the integration lies within 0.01-0.12 of the allowed band at 1-5 mm.
 * An amplitude whose oscillation leaves the table (or, for the regression, y_eq -+ a) is undefined: HM_EDOMAIN.
 * Allocation only at create.
 */
#ifndef HUNTING_MONITOR_EQCON_H
#define HUNTING_MONITOR_EQCON_H

#include <stddef.h>

#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { HM_EQCON_INTEGRATION = 0, HM_EQCON_REGRESSION = 1 } hm_eqcon_method;

typedef struct {
  double r0_m;               /* nominal rolling radius r0 [m] */
  double contact_distance_m; /* distance between the contact points 2 e0 [m] */
  double tol;                /* relative tolerance of the quadratures and of the turning points */
} hm_eqcon_config;

/* 0.46 m, 1.5 m, 1e-7. */
void hm_eqcon_config_default(hm_eqcon_config *cfg);
/* "field: reason (got value)" in why (HM_EDOMAIN): r0_m in [0.1, 1] (a wheel's rolling radius, as everywhere),
 * contact_distance_m in (0, 5], tol in [1e-14, 1e-2]. */
hm_status hm_eqcon_config_validate(const hm_eqcon_config *cfg, char *why, size_t why_len);

/* A delta-r table: n >= 3 points, finite and within -+100 mm, y strictly increasing by at least 1 nm, a restoring
 * equilibrium (delta-r rising through zero) inside. HM_EINVAL for NULL, HM_EDOMAIN with the reason (and the point) in why. */
hm_status hm_eqcon_check(const double *y_m, const double *delta_r_m, size_t n, char *why, size_t why_len);

typedef struct hm_eqcon_s *hm_eqcon;

/* For a delta-r table (copied, with its cumulative integral: 3 n doubles) and the settings. HM_EDOMAIN with the
 * reason in why for an invalid table or configuration, HM_ENOMEM; *out untouched on failure. */
hm_status hm_eqcon_create(const hm_eqcon_config *cfg, const double *y_m, const double *delta_r_m, size_t n,
                          hm_eqcon *out, char *why, size_t why_len);
void hm_eqcon_destroy(hm_eqcon e);
/* The restoring equilibrium nearest y = 0 (delta-r rising through zero, linear between the points) [m]. */
double hm_eqcon_equilibrium_m(const hm_eqcon e);

typedef struct {
  double tan_gamma_e;    /* equivalent conicity at the amplitude */
  double wavelength_m;   /* the kinematic oscillation's wavelength (Klingel's at tan_gamma_e for the regression) */
  double y_low_m, y_high_m; /* its turning points (the regression: y_eq -+ amplitude) */
  double equilibrium_m;  /* y_eq */
} hm_eqcon_result;

/* tan gamma_e at amplitude_m (1e-7 .. 0.1 m) by the method. HM_EDOMAIN if the oscillation leaves the table
 * (undefined there) or for a bad amplitude or method; HM_ENOCONV if a quadrature does not reach tol, HM_ENONFINITE
 * if the result is not finite; out untouched on failure. Cost:
 * O(log n) per integrand evaluation, about 1e4-1e5 of them. */
hm_status hm_eqcon_at(const hm_eqcon e, hm_eqcon_method method, double amplitude_m, hm_eqcon_result *out);

#ifdef __cplusplus
}
#endif

#endif
