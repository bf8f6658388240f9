/*
 * hunting_monitor - Hopf bifurcations of the origin and their Lyapunov coefficients (docs/MODEL.md section 4).
 *
 * Convention (MATCONT's): A q = i w q, A^T p = -i w p, <q, q> = 1, <p, q> = 1 with <u, v> = conj(u)^T v;
 * B, C, D, E the 2nd..5th derivative multilinear forms of the right-hand side at the origin;
 *   c1 = 1/2 <p, C(q,q,q~) + B(q~,h20) + 2 B(q,h11)>,  l1 = Re c1,
 *   h20 = (2iw - A)^-1 B(q,q), h11 = -A^-1 B(q,q~), and the second coefficient
 *   l2 = 1/12 Re <p, E(q,q,q,q~,q~) + D(q,q,q,h20~) + 3 D(q,q~,q~,h20) + 6 D(q,q,q~,h11) + C(q~,q~,h30)
 *        + 3 C(q,q,h21~) + 6 C(q,q~,h21) + 3 C(q,h20~,h20) + 6 C(q,h11,h11) + 6 C(q~,h20,h11) + 2 B(q~,h31)
 *        + 3 B(q,h22) + B(h20~,h30) + 3 B(h21~,h20) + 6 B(h11,h21)>
 * (Kuznetsov, Elements of Applied Bifurcation Theory, 3rd ed., 8.7.2; ~ is complex conjugation), with h30, h21
 * (bordered, <p, h21> = 0), h31, h22 the centre-manifold coefficients. l2 is meaningful where l1 = 0 (GH).
 * The nonlinearity of the model acts through y alone, so every form is a fixed vector times a product of first
 * components; for a symmetric lambda(y) the even forms B and D vanish.
 */
#ifndef HUNTING_MONITOR_HOPF_H
#define HUNTING_MONITOR_HOPF_H

#include <stddef.h>

#include "hunting_monitor/model.h"
#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  double speed_kmh;     /* the Hopf point: speed and the vehicle's Kx, Ky, lambda(0) */
  double kx_mn_m;
  double ky_mn_m;
  double conicity;
  double omega_rad_s;   /* frequency of the critical pair */
  double l1;            /* first Lyapunov coefficient: < 0 supercritical, > 0 subcritical */
  double l2;            /* second Lyapunov coefficient (meaningful at GH points, l1 = 0) */
} hm_hopf_point;

/*
 * Lyapunov coefficients at (veh, speed) assumed to be a Hopf point: uses the eigenvalue pair of the Jacobian
 * at the origin closest to the imaginary axis (dgeev with eigenvectors) and LAPACK zgesv for the
 * centre-manifold solves. HM_ENOCRIT if there is no complex pair.
 */
hm_status hm_hopf_coefficients(const hm_vehicle *veh, double speed_kmh, double *omega_rad_s, double *l1, double *l2);

/* The critical eigenvector q (A q = i w q, <q, q> = 1) at (veh, speed) as real and imaginary parts, and w. */
hm_status hm_hopf_eigenvector(const hm_vehicle *veh, double speed_kmh, double q_re[4], double q_im[4],
                              double *omega_rad_s);

/*
 * Hopf points of the origin as parameter p varies in [lo, hi] (user units) with the other parameters as in
 * (veh, speed_kmh). Speed: closed form (linear.h). Kx, Ky, conicity: Delta3 sampled at 256 points over the
 * range and each sign change refined by Brent's method to xtol. Up to max_points are written to points
 * (in increasing p), *n_found says how many exist; coefficients filled in for each.
 */
hm_status hm_hopf_find(const hm_vehicle *veh, double speed_kmh, hm_param p, double lo, double hi, double xtol,
                       hm_hopf_point *points, size_t max_points, size_t *n_found);

typedef enum {
  HM_PLANE_KX_V = 0,   /* Hopf speed as a function of Kx (closed form per point) */
  HM_PLANE_KY_V = 1,   /* Hopf speed as a function of Ky */
  HM_PLANE_KX_KY = 2   /* Ky on the Hopf curve as a function of Kx at a fixed speed */
} hm_plane;

typedef struct {
  hm_plane plane;
  double from, to;             /* range of the first parameter (Kx, or Ky for ky-v) [MN/m] */
  size_t n_points;             /* samples of the first parameter, >= 2 */
  double speed_kmh;            /* kx-ky: the fixed speed */
  double ky_min, ky_max;       /* kx-ky: search range of Ky [MN/m] */
  double xtol;                 /* tolerance of located points (GH, Ky roots) [MN/m] */
} hm_hopf_curve_options;

typedef struct {
  hm_hopf_point point;
  int branch;                  /* kx-ky: index of the Ky root at this Kx (0, 1); 0 otherwise */
} hm_hopf_curve_point;

/*
 * Two-parameter Hopf curve with l1 at every sample, and its generalised Hopf (GH) points: sign changes of l1
 * between samples of one branch, located by Brent's method along the curve to xtol, with l2 there.
 * points: room for max_points (n_points, or 2 n_points for kx-ky); gh: room for max_gh. Counts in *n_points_out
 * and *n_gh (as many as exist; only the first max_* are written).
 */
hm_status hm_hopf_curve(const hm_vehicle *veh, const hm_hopf_curve_options *opt, hm_hopf_curve_point *points,
                        size_t max_points, size_t *n_points_out, hm_hopf_point *gh, size_t max_gh, size_t *n_gh);

#ifdef __cplusplus
}
#endif

#endif
