/* Single shooting of the model's cycles with variational equations (see cycles.h). */
#include "shooting.h"

#include <math.h>
#include <string.h>

#include "hunting_monitor/linear.h"

const double hm_sh_res_scale[NX] = {1e-3, 1e-1, 1e-3, 1e-1};

double hm_sh_param_scale(hm_param p) {
  return p == HM_PARAM_SPEED ? 1.0 : p == HM_PARAM_CONICITY ? 1e-3 : 0.03;
}

hm_status hm_sh_init(hm_sh *c, const hm_vehicle *veh, double speed_kmh, hm_param param,
                     const hm_shooting_options *opt, int has_param2, hm_param param2) {
  memset(c, 0, sizeof *c);
  hm_status st = hm_vehicle_validate(veh, NULL, 0);
  if (st != HM_OK) return st;
  if (!(speed_kmh > 0.0) || !isfinite(speed_kmh)) return HM_EDOMAIN;
  c->base = *veh;
  c->base_speed_kmh = speed_kmh;
  if (!(opt->rtol > 0.0) || !(opt->atol >= 0.0)) return HM_EINVAL;
  c->param = param;
  c->param2 = param2;
  c->has_param2 = has_param2;
  c->opt = *opt;
  c->symmetric = opt->use_symmetry && hm_conicity_is_even(&veh->conicity, 1e-12);
  const double sc[NW] = {1e-3, 1e-3, 1e-1, 1e-2, hm_sh_param_scale(param), hm_sh_param_scale(param2)};
  memcpy(c->sc, sc, sizeof sc);
  /* without p2 its sensitivity columns are left out of the integration (and of the error control) */
  c->integ = hm_dop853_create(has_param2 ? NZ : NZ - NX);
  return c->integ ? HM_OK : HM_ENOMEM;
}

void hm_sh_free(hm_sh *c) {
  hm_dop853_destroy(c->integ);
  c->integ = NULL;
}

/* x' = f, Phi' = J Phi, s1' = J s1 + df/dp1, s2' = J s2 + df/dp2: MODEL.md's right-hand side (as hm_model_rhs) and
 * its Jacobian (as hm_model_jacobian) in one pass, the conicity lambda(y) and lambda'(y) evaluated once, and J's
 * sparsity used: only rows 1 and 3 of J depend on the state (J = [0 1 0 0; j10 a11 a12 0; 0 0 0 1; j30 0 a32 a33]). */
static hm_status aug_rhs(double t, const double *z, double *dz, void *ctx) {
  (void)t;
  hm_sh *c = (hm_sh *)ctx;
  const hm_model *m = &c->model;
  const hm_linear_coef *k = &m->coef;
  const double inv_v = 1.0 / m->speed_mps, y = z[0], y2 = y * y;
  double lambda, dlambda;
  hm_conicity_eval(&m->vehicle.conicity, y, &lambda, &dlambda);
  const double flange = y * y2 * (k->f1_m2_s2 + k->f2_m4_s2 * y2);
  const double dflange = y2 * (3.0 * k->f1_m2_s2 + 5.0 * k->f2_m4_s2 * y2);
  const double a11 = -k->c_lat_m_s2 * inv_v, a12 = k->c_lat_m_s2, a32 = -k->k_yaw_s2, a33 = -k->c_yaw_m_s2 * inv_v;
  const double j10 = -k->k_lat_s2 - dflange, j30 = -k->e_yaw_m_s2 * (lambda + dlambda * y);
  dz[0] = z[1];
  dz[1] = -k->k_lat_s2 * y + a11 * z[1] + a12 * z[2] - flange;
  dz[2] = z[3];
  dz[3] = -k->e_yaw_m_s2 * lambda * y + a32 * z[2] + a33 * z[3];
  if (!isfinite(dz[1]) || !isfinite(dz[3]) || !isfinite(j10) || !isfinite(j30)) return HM_ENONFINITE;
  double dfdp[2][NX];
  hm_model_dparam(m, c->param, z, dfdp[0]);
  const int ncols = NX + 1 + c->has_param2;
  if (c->has_param2) hm_model_dparam(m, c->param2, z, dfdp[1]);
  for (int col = 0; col < ncols; ++col) {
    const double *v = z + NX + NX * col;
    double *dv = dz + NX + NX * col;
    dv[0] = v[1];
    dv[1] = j10 * v[0] + a11 * v[1] + a12 * v[2];
    dv[2] = v[3];
    dv[3] = j30 * v[0] + a32 * v[2] + a33 * v[3];
    if (col >= NX) {
      const double *f = dfdp[col - NX];
      dv[0] += f[0];
      dv[1] += f[1];
      dv[2] += f[2];
      dv[3] += f[3];
    }
  }
  return HM_OK;
}

/* The largest |q| over a step of a coordinate q whose velocity and acceleration are known at both ends (q = y with
 * y' = x2 and y'' = f2; q = psi likewise): at the ends, and where q' changes sign inside, at the root of q''s cubic
 * Hermite interpolant (bisection), with q from its quintic Hermite interpolant (error O(h^6)). */
double hm_sh_extreme(double h, double q0, double v0, double a0, double q1, double v1, double a1) {
  double m = fmax(fabs(q0), fabs(q1));
  if ((v0 > 0.0) == (v1 > 0.0) || v0 == 0.0 || v1 == 0.0) return m;
  double lo = 0.0, hi = 1.0; /* s in [0, 1], t = t0 + s h */
  for (int it = 0; it < 40; ++it) {
    const double s = 0.5 * (lo + hi), s2 = s * s, s3 = s2 * s;
    const double v = (2 * s3 - 3 * s2 + 1) * v0 + (s3 - 2 * s2 + s) * h * a0 + (-2 * s3 + 3 * s2) * v1 +
                     (s3 - s2) * h * a1;
    if ((v > 0.0) == (v0 > 0.0)) lo = s;
    else hi = s;
  }
  const double s = 0.5 * (lo + hi), s2 = s * s, s3 = s2 * s, s4 = s3 * s, s5 = s4 * s;
  /* quintic Hermite basis on [0, 1] (values, first and second derivatives at both ends) */
  const double h00 = 1 - 10 * s3 + 15 * s4 - 6 * s5, h01 = 10 * s3 - 15 * s4 + 6 * s5;
  const double h10 = s - 6 * s3 + 8 * s4 - 3 * s5, h11 = -4 * s3 + 7 * s4 - 3 * s5;
  const double h20 = 0.5 * s2 - 1.5 * s3 + 1.5 * s4 - 0.5 * s5, h21 = 0.5 * s3 - s4 + 0.5 * s5;
  const double q = h00 * q0 + h01 * q1 + h * (h10 * v0 + h11 * v1) + h * h * (h20 * a0 + h21 * a1);
  return fmax(m, fabs(q));
}

/* Track max |y| and |psi| over every accepted step. */
static int amp_observer(double t_old, const double *x_old, const double *f_old, double t_new, const double *x_new,
                        const double *f_new, void *ctx) {
  hm_sh *c = (hm_sh *)ctx;
  const double h = t_new - t_old;
  c->amp_y = fmax(c->amp_y, hm_sh_extreme(h, x_old[0], x_old[1], f_old[1], x_new[0], x_new[1], f_new[1]));
  c->amp_psi = fmax(c->amp_psi, hm_sh_extreme(h, x_old[2], x_old[3], f_old[3], x_new[2], x_new[3], f_new[3]));
  return 0;
}

static hm_status set_model(hm_sh *c, double p1, double p2) {
  hm_vehicle v = c->base;
  double speed = c->base_speed_kmh;
  hm_status st = hm_param_set(&v, &speed, c->param, p1);
  if (st == HM_OK && c->has_param2) st = hm_param_set(&v, &speed, c->param2, p2);
  if (st != HM_OK) return st;
  return hm_model_init(&c->model, &v, hm_mps_from_kmh(speed));
}

hm_status hm_sh_shoot(hm_sh *c, const double *u, hm_shot *s) {
  const double T = u[3];
  if (!(T > 0.0) || !isfinite(T)) return HM_EDOMAIN;
  hm_status st = set_model(c, u[4], c->has_param2 ? u[5] : 0.0);
  if (st != HM_OK) return st;
  const double x0[NX] = {u[0], 0.0, u[1], u[2]};
  double z[NZ];
  memset(z, 0, sizeof z);
  memcpy(z, x0, sizeof x0);
  for (int i = 0; i < NX; ++i) z[NX + NX * i + i] = 1.0;
  const double tau = c->symmetric ? 0.5 * T : T, sigma = c->symmetric ? -1.0 : 1.0;
  c->amp_y = fabs(x0[0]);
  c->amp_psi = fabs(x0[2]);
  const hm_ode_system sys = {c->has_param2 ? NZ : NZ - NX, aug_rhs, NULL, c};
  /* the error is controlled on the state: the variations follow its steps (their own error control would
   * take a third more steps and move the fold speeds by about 1e-7 km/h) */
  const hm_dopri_options dopt = {c->opt.rtol, c->opt.atol, 0.0, 0.0, 0, NX};
  ++c->n_shots;
  hm_dopri_stats ds;
  st = hm_dop853_integrate(c->integ, &sys, &dopt, 0.0, tau, z, amp_observer, c, &ds);
  c->n_steps += ds.n_accepted + ds.n_rejected;
  if (st != HM_OK) return st;
  double f[NX];
  if ((st = hm_model_rhs(0.0, z, f, &c->model)) != HM_OK) return st;
  memcpy(s->u, u, NU * sizeof(double));
  s->u[5] = c->has_param2 ? u[5] : 0.0;
  static const int state_of_unknown[3] = {0, 2, 3};
  for (int i = 0; i < NX; ++i) {
    s->res[i] = z[i] - sigma * x0[i];
    for (int k = 0; k < 3; ++k) {
      const int j = state_of_unknown[k];
      s->jac[NW * i + k] = z[NX + NX * j + i] - (i == j ? sigma : 0.0);
    }
    s->jac[NW * i + 3] = f[i] * (tau / T);
    s->jac[NW * i + 4] = z[NX + NX * NX + i];
    s->jac[NW * i + 5] = c->has_param2 ? z[NX + NX * NX + NX + i] : 0.0;
  }
  memcpy(s->phi, z + NX, sizeof s->phi);
  s->amp_y = c->amp_y;
  s->amp_psi = c->amp_psi;
  return HM_OK;
}
