/*
 * hunting_monitor - linear stability of the origin (docs/MODEL.md section 2).
 *
 * The characteristic polynomial of the linear model factorises as
 *   (s^2 + (c1/v) s + a)(s^2 + (c2/v) s + b) + g e lambda
 * with a = k_lat, b = k_yaw, c1 = c_lat, c2 = c_yaw, g = c_lat (yaw coupling 2 ky/m), e = e_yaw, so
 *   a1 = (c1 + c2)/v,  a2 = a + b + c1 c2/v^2,  a3 = (a c2 + b c1)/v,  a4 = a b + g e lambda.
 * Hurwitz: stable iff a1, a2, a4 > 0 and Delta3 = a1 a2 a3 - a1^2 a4 - a3^2 > 0. Writing A1 = c1 + c2,
 * A3 = a c2 + b c1, P = a + b, Q = c1 c2:
 *   v^4 Delta3 = A1 A3 Q - v^2 D,   D = A1^2 a4 + A3^2 - A1 A3 P,
 * so the critical speed is v_c = sqrt(A1 A3 Q / D) (none if D <= 0), stable below it, and on Delta3 = 0 the
 * purely imaginary pair is +-i w with w^2 = a3/a1 = A3/A1 (independent of v and lambda).
 * Solving Delta3 = 0 for lambda gives the critical conicity
 *   lambda_c(v) = (A1 A3 Q / v^2 + A1 A3 P - A3^2 - A1^2 a b) / (A1^2 g e), stable iff lambda < lambda_c.
 *
 * Here "conicity" is the constant equivalent conicity of the linear model; for a vehicle with a nonlinear
 * lambda(y) the linearisation at the origin uses lambda(0).
 */
#ifndef HUNTING_MONITOR_LINEAR_H
#define HUNTING_MONITOR_LINEAR_H

#include "hunting_monitor/model.h"
#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Coefficients a1..a4 of s^4 + a1 s^3 + a2 s^2 + a3 s + a4 at speed v [m/s] and conicity lambda. */
hm_status hm_linear_char_poly(const hm_vehicle *veh, double conicity, double speed_mps, double coeffs[4]);

/* Hurwitz determinant Delta3 [1/s^6] (positive: stable, given a2, a4 > 0). */
hm_status hm_linear_hurwitz_delta3(const hm_vehicle *veh, double conicity, double speed_mps, double *delta3);

/*
 * Eigenvalues of the Jacobian at the origin via LAPACK dgeev (no eigenvectors), sorted by decreasing real
 * part, then by decreasing imaginary part. re, im: arrays of 4.
 */
hm_status hm_linear_eigenvalues(const hm_vehicle *veh, double conicity, double speed_mps, double re[4], double im[4]);

/* Largest real part of the eigenvalues [1/s] (dgeev). */
hm_status hm_linear_spectral_abscissa(const hm_vehicle *veh, double conicity, double speed_mps, double *abscissa);

/* Closed-form critical (Hopf) speed [m/s]; HM_ENOCRIT if the origin is stable at every speed (D <= 0)
 * or unstable at every speed (a4 <= 0 or a2 <= 0). */
hm_status hm_linear_critical_speed(const hm_vehicle *veh, double conicity, double *speed_mps);

/* The reported Hopf speed [km/h] where the linear model is stable at every speed (or the conicity is not > 0). */
#define HM_LINEAR_NO_HOPF_KMH 1e4
/* The closed-form critical speed in km/h, capped at HM_LINEAR_NO_HOPF_KMH, which it also is where there is none
 * (the margin and the alarm report Hopf speeds so). Never fails, never NaN. */
double hm_linear_hopf_kmh(const hm_vehicle *veh, double conicity);

/* Closed-form critical conicity at speed v [m/s]; HM_ENOCRIT if no conicity >= 0 is stable there. */
hm_status hm_linear_critical_conicity(const hm_vehicle *veh, double speed_mps, double *conicity);

/* Angular frequency [rad/s] of the purely imaginary pair on the critical (Hopf) boundary: sqrt(A3/A1). */
hm_status hm_linear_hopf_omega(const hm_vehicle *veh, double *omega_rad_s);

/*
 * Critical speed by eigenvalues alone, for cross-checks: scans v upward from v_start_mps, doubling until the
 * spectral abscissa becomes positive (up to v_max_mps), then bisects until the bracket is narrower than
 * tol_mps. HM_ENOCRIT if no sign change up to v_max_mps; HM_EINVAL for a bad tolerance or range.
 */
hm_status hm_linear_critical_speed_eig(const hm_vehicle *veh, double conicity, double v_start_mps,
                                       double v_max_mps, double tol_mps, double *speed_mps);

/* Unit conversions used throughout: V [km/h] = 3.6 v [m/s]. */
static inline double hm_kmh_from_mps(double v_mps) { return 3.6 * v_mps; }
static inline double hm_mps_from_kmh(double v_kmh) { return v_kmh / 3.6; }

#ifdef __cplusplus
}
#endif

#endif
