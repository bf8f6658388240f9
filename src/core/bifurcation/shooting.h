/* Private to the core: single shooting of the wheelset model's cycles, shared by cycles.c and lpc.c.
 * See cycles.h for the method and the unknowns. */
#ifndef HM_CORE_SHOOTING_H
#define HM_CORE_SHOOTING_H

#include "hunting_monitor/cycles.h"
#include "hunting_monitor/integrate.h"

#define NX 4  /* state dimension */
#define NU 5  /* one-parameter unknowns: y0, psi0, dpsi0, T, p1 */
#define NW 6  /* two-parameter unknowns: ... and p2 */
#define NZ (NX + NX * NX + 2 * NX) /* state, monodromy columns, sensitivities to p1 and p2 */

/* Residual scales (m, m/s, rad, rad/s) that make Newton's rows O(1). */
extern const double hm_sh_res_scale[NX];

typedef struct {
  hm_vehicle base;
  double base_speed_kmh;
  hm_param param;        /* p1 */
  hm_param param2;       /* p2 (only if has_param2) */
  int has_param2;
  int symmetric;         /* half-period shooting with x(T/2) = -x(0) */
  hm_shooting_options opt;
  hm_dop853 integ;
  hm_model model;
  double sc[NW];         /* scale of each unknown */
  double amp_y, amp_psi; /* running maxima during an integration */
  size_t n_shots;        /* integrations so far */
  size_t n_steps;        /* their integration steps (accepted and rejected) */
} hm_sh;

/* One evaluation of the shooting map. */
typedef struct {
  double u[NW];
  double res[NX];        /* x(tau) - sigma x0 (unscaled) */
  double jac[NX * NW];   /* d res / d u, row-major (unscaled); column 5 is zero without p2 */
  double phi[NX * NX];   /* Phi(tau), column-major */
  double amp_y, amp_psi; /* max |y|, |psi| over the cycle */
} hm_shot;

/* Validate, choose symmetric shooting, set scales, allocate the integrator (HM_ENOMEM). */
hm_status hm_sh_init(hm_sh *c, const hm_vehicle *veh, double speed_kmh, hm_param param,
                     const hm_shooting_options *opt, int has_param2, hm_param param2);
void hm_sh_free(hm_sh *c);
/* Integrate over T/2 (symmetric) or T from x0 = (u0, 0, u1, u2) at p1 = u4 (and p2 = u5). */
hm_status hm_sh_shoot(hm_sh *c, const double *u, hm_shot *s);
/* Scale of an unknown in the continuation parameter's units. */
double hm_sh_param_scale(hm_param p);
/* The largest |q| over a step of length h of a coordinate q whose value, rate and acceleration are known at both
 * ends (quintic Hermite interpolation where the rate changes sign inside). Also system_cycles.c's. */
double hm_sh_extreme(double h, double q0, double v0, double a0, double q1, double v1, double a1);

#endif
