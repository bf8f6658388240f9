/* Hopf points of the origin, first and second Lyapunov coefficients, Hopf curves and GH points. */
#include "hunting_monitor/hopf.h"

#include <complex.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hunting_monitor/linear.h"
#include "hunting_monitor/roots.h"
#include "lapack.h"

typedef double complex cplx;
#define N 4

/* Everything the normal-form formulas need at one Hopf point. */
typedef struct {
  double A[N * N];     /* Jacobian at the origin, row-major */
  double form[6][N];   /* form[k]: the vector of the k-th multilinear form (k = 2..5) */
  double omega;
  cplx q[N], p[N];
} hopf_data;

/* x = (z I - A)^-1 b (complex), via zgesv. */
static hm_status solve_shifted(const hopf_data *h, cplx z, const cplx *b, cplx *x) {
  cplx M[N * N], rhs[N];
  int ipiv[N], info = 0;
  const int n = N, one = 1;
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) M[i + j * N] = (i == j ? z : 0.0) - h->A[i * N + j];
  memcpy(rhs, b, sizeof rhs);
  zgesv_(&n, &one, M, &n, ipiv, rhs, &n, &info);
  if (info != 0) return HM_ELAPACK;
  memcpy(x, rhs, sizeof rhs);
  return HM_OK;
}

/* Bordered solve of (i w I - A) x = b with <p, x> = 0 (b must lie in the range). */
static hm_status solve_bordered(const hopf_data *h, const cplx *b, cplx *x) {
  enum { M5 = N + 1 };
  cplx M[M5 * M5], rhs[M5];
  int ipiv[M5], info = 0;
  const int n = M5, one = 1;
  memset(M, 0, sizeof M);
  for (int i = 0; i < N; ++i) {
    for (int j = 0; j < N; ++j) M[i + j * M5] = (i == j ? I * h->omega : 0.0) - h->A[i * N + j];
    M[i + N * M5] = h->q[i];
    M[N + i * M5] = conj(h->p[i]);
    rhs[i] = b[i];
  }
  rhs[N] = 0.0;
  zgesv_(&n, &one, M, &n, ipiv, rhs, &n, &info);
  if (info != 0) return HM_ELAPACK;
  memcpy(x, rhs, N * sizeof(cplx));
  return HM_OK;
}

/* out += coeff * form_k (a form evaluated at vectors whose first components multiply to coeff). */
static void add_form(cplx *out, const hopf_data *h, int k, cplx coeff) {
  for (int i = 0; i < N; ++i) out[i] += coeff * h->form[k][i];
}

static cplx inner(const cplx *p, const cplx *v) {
  cplx s = 0.0;
  for (int i = 0; i < N; ++i) s += conj(p[i]) * v[i];
  return s;
}

/* Jacobian, forms and normalised eigenvectors at (veh, speed). */
static hm_status hopf_setup(const hm_vehicle *veh, double speed_kmh, hopf_data *h) {
  hm_model m;
  hm_status st = hm_model_init(&m, veh, hm_mps_from_kmh(speed_kmh));
  if (st != HM_OK) return st;
  const double origin[N] = {0, 0, 0, 0};
  if ((st = hm_model_jacobian(0.0, origin, h->A, &m)) != HM_OK) return st;
  /* k-th derivatives at y = 0 of the y-only nonlinearities: f2 = ... - F_T(y)/m, f4 = ... - e y lambda(y). */
  double dl[8];
  hm_conicity_derivatives(&veh->conicity, 0.0, 5, dl);
  memset(h->form, 0, sizeof h->form);
  for (int k = 2; k <= 5; ++k) {
    const double ft = k == 3 ? 6.0 * veh->flange_alpha1_n_m3 : k == 5 ? 120.0 * veh->flange_alpha2_n_m5 : 0.0;
    h->form[k][1] = -ft / veh->mass_kg;
    h->form[k][3] = -m.coef.e_yaw_m_s2 * k * dl[k - 1]; /* (y lambda)^(k)(0) = k lambda^(k-1)(0) */
  }
  /* Eigenvectors: dgeev on A^T's storage = A in column-major. */
  double a[N * N], wr[N], wi[N], vl[N * N], vr[N * N], work[256];
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) a[i + j * N] = h->A[i * N + j];
  const int n = N, lwork = 256;
  int info = 0;
  dgeev_("V", "V", &n, a, &n, wr, wi, vl, &n, vr, &n, work, &lwork, &info, 1, 1);
  if (info != 0) return HM_ELAPACK;
  int best = -1;
  for (int j = 0; j < N; ++j)
    if (wi[j] > 0.0 && (best < 0 || fabs(wr[j]) < fabs(wr[best]))) best = j;
  if (best < 0) return HM_ENOCRIT;
  h->omega = wi[best];
  double qn = 0.0;
  for (int i = 0; i < N; ++i) {
    h->q[i] = vr[i + best * N] + I * vr[i + (best + 1) * N];
    h->p[i] = vl[i + best * N] + I * vl[i + (best + 1) * N];
    qn += creal(h->q[i] * conj(h->q[i]));
  }
  qn = sqrt(qn);
  for (int i = 0; i < N; ++i) h->q[i] /= qn;
  const cplx s = inner(h->p, h->q);
  if (cabs(s) == 0.0) return HM_ELAPACK;
  for (int i = 0; i < N; ++i) h->p[i] /= conj(s);
  return HM_OK;
}

hm_status hm_hopf_eigenvector(const hm_vehicle *veh, double speed_kmh, double q_re[4], double q_im[4],
                              double *omega_rad_s) {
  if (!veh || !q_re || !q_im || !omega_rad_s) return HM_EINVAL;
  hopf_data h;
  hm_status st = hopf_setup(veh, speed_kmh, &h);
  if (st != HM_OK) return st;
  for (int i = 0; i < N; ++i) {
    q_re[i] = creal(h.q[i]);
    q_im[i] = cimag(h.q[i]);
  }
  *omega_rad_s = h.omega;
  return HM_OK;
}

hm_status hm_hopf_coefficients(const hm_vehicle *veh, double speed_kmh, double *omega_rad_s, double *l1,
                               double *l2) {
  if (!veh) return HM_EINVAL;
  hopf_data h;
  hm_status st = hopf_setup(veh, speed_kmh, &h);
  if (st != HM_OK) return st;
  const double w = h.omega;
  const cplx q0 = h.q[0], qb0 = conj(q0);
  cplx r[N], h20[N], h11[N], h30[N], h21[N], h31[N], h22[N], g[N];
  /* h20 = (2iw - A)^-1 B(q,q);  h11 = -A^-1 B(q,q~) = (0 - A)^-1 B(q,q~) */
  memset(r, 0, sizeof r);
  add_form(r, &h, 2, q0 * q0);
  if ((st = solve_shifted(&h, 2.0 * I * w, r, h20)) != HM_OK) return st;
  memset(r, 0, sizeof r);
  add_form(r, &h, 2, q0 * qb0);
  if ((st = solve_shifted(&h, 0.0, r, h11)) != HM_OK) return st;
  /* c1 */
  cplx t21[N] = {0};
  add_form(t21, &h, 3, q0 * q0 * qb0);
  add_form(t21, &h, 2, qb0 * h20[0]);
  add_form(t21, &h, 2, 2.0 * q0 * h11[0]);
  const cplx c1 = 0.5 * inner(h.p, t21);
  /* h30, h21 */
  memset(r, 0, sizeof r);
  add_form(r, &h, 3, q0 * q0 * q0);
  add_form(r, &h, 2, 3.0 * q0 * h20[0]);
  if ((st = solve_shifted(&h, 3.0 * I * w, r, h30)) != HM_OK) return st;
  for (int i = 0; i < N; ++i) r[i] = t21[i] - 2.0 * c1 * h.q[i];
  if ((st = solve_bordered(&h, r, h21)) != HM_OK) return st;
  /* h31 */
  memset(r, 0, sizeof r);
  add_form(r, &h, 4, q0 * q0 * q0 * qb0);
  add_form(r, &h, 3, 3.0 * q0 * q0 * h11[0] + 3.0 * q0 * qb0 * h20[0]);
  add_form(r, &h, 2, 3.0 * h20[0] * h11[0] + qb0 * h30[0] + 3.0 * q0 * h21[0]);
  for (int i = 0; i < N; ++i) r[i] -= 6.0 * c1 * h20[i];
  if ((st = solve_shifted(&h, 2.0 * I * w, r, h31)) != HM_OK) return st;
  /* h22 = -A^-1 [...] */
  memset(r, 0, sizeof r);
  add_form(r, &h, 4, q0 * q0 * qb0 * qb0);
  add_form(r, &h, 3, 4.0 * q0 * qb0 * h11[0] + qb0 * qb0 * h20[0] + q0 * q0 * conj(h20[0]));
  add_form(r, &h, 2, 2.0 * h11[0] * h11[0] + 2.0 * q0 * conj(h21[0]) + 2.0 * qb0 * h21[0] + conj(h20[0]) * h20[0]);
  for (int i = 0; i < N; ++i) r[i] -= 4.0 * (c1 + conj(c1)) * h11[i];
  if ((st = solve_shifted(&h, 0.0, r, h22)) != HM_OK) return st;
  /* fifth-order resonant term */
  memset(g, 0, sizeof g);
  add_form(g, &h, 5, q0 * q0 * q0 * qb0 * qb0);
  add_form(g, &h, 4, q0 * q0 * q0 * conj(h20[0]) + 3.0 * q0 * qb0 * qb0 * h20[0] + 6.0 * q0 * q0 * qb0 * h11[0]);
  add_form(g, &h, 3,
           qb0 * qb0 * h30[0] + 3.0 * q0 * q0 * conj(h21[0]) + 6.0 * q0 * qb0 * h21[0] +
               3.0 * q0 * conj(h20[0]) * h20[0] + 6.0 * q0 * h11[0] * h11[0] + 6.0 * qb0 * h20[0] * h11[0]);
  add_form(g, &h, 2,
           2.0 * qb0 * h31[0] + 3.0 * q0 * h22[0] + conj(h20[0]) * h30[0] + 3.0 * conj(h21[0]) * h20[0] +
               6.0 * h11[0] * h21[0]);
  const double l2v = creal(inner(h.p, g)) / 12.0;
  if (!isfinite(creal(c1)) || !isfinite(l2v)) return HM_ENONFINITE;
  if (omega_rad_s) *omega_rad_s = w;
  if (l1) *l1 = creal(c1);
  if (l2) *l2 = l2v;
  return HM_OK;
}

/* ---- locating Hopf points ---- */

typedef struct {
  hm_vehicle veh;
  double speed_kmh;
  hm_param p;
} delta3_ctx;

/* Hurwitz Delta3 at parameter value x (scaled by v^4 to be O(1)-conditioned in v). */
static hm_status delta3_of(double x, double *value, void *ctx) {
  delta3_ctx *c = (delta3_ctx *)ctx;
  hm_vehicle v = c->veh;
  double speed = c->speed_kmh;
  hm_status st = hm_param_set(&v, &speed, c->p, x);
  if (st != HM_OK) return st;
  double lambda0, d3;
  hm_conicity_eval(&v.conicity, 0.0, &lambda0, NULL);
  st = hm_linear_hurwitz_delta3(&v, lambda0, hm_mps_from_kmh(speed), &d3);
  if (st != HM_OK) return st;
  *value = d3;
  return HM_OK;
}

static hm_status fill_point(const hm_vehicle *veh, double speed_kmh, hm_hopf_point *pt) {
  hm_hopf_point out;
  out.speed_kmh = speed_kmh;
  out.kx_mn_m = veh->stiffness_long_n_m / 1e6;
  out.ky_mn_m = veh->stiffness_lat_n_m / 1e6;
  hm_conicity_eval(&veh->conicity, 0.0, &out.conicity, NULL);
  hm_status st = hm_hopf_coefficients(veh, speed_kmh, &out.omega_rad_s, &out.l1, &out.l2);
  if (st != HM_OK) return st;
  *pt = out;
  return HM_OK;
}

/* A zero of Delta3 is a Hopf point only where a2, a4 > 0 (then the pair is +-i sqrt(a3/a1)). */
static int is_hopf(const hm_vehicle *veh, double speed_kmh) {
  double a[4], lambda0;
  hm_conicity_eval(&veh->conicity, 0.0, &lambda0, NULL);
  if (hm_linear_char_poly(veh, lambda0, hm_mps_from_kmh(speed_kmh), a) != HM_OK) return 0;
  return a[1] > 0.0 && a[3] > 0.0 && a[0] * a[2] > 0.0;
}

hm_status hm_hopf_find(const hm_vehicle *veh, double speed_kmh, hm_param p, double lo, double hi, double xtol,
                       hm_hopf_point *points, size_t max_points, size_t *n_found) {
  if (!veh || !n_found || (max_points > 0 && !points) || !(hi > lo) || !isfinite(lo) || !isfinite(hi) ||
      !(xtol > 0.0))
    return HM_EINVAL;
  hm_status st = hm_vehicle_validate(veh, NULL, 0);
  if (st != HM_OK) return st;
  size_t found = 0;
  if (p == HM_PARAM_SPEED) {
    double lambda0, v_mps;
    hm_conicity_eval(&veh->conicity, 0.0, &lambda0, NULL);
    st = hm_linear_critical_speed(veh, lambda0, &v_mps);
    if (st != HM_OK && st != HM_ENOCRIT) return st;
    const double v = hm_kmh_from_mps(v_mps);
    if (st == HM_OK && v >= lo && v <= hi) {
      hm_hopf_point pt;
      if (max_points > 0 && (st = fill_point(veh, v, &pt)) != HM_OK) return st;
      if (max_points > 0) points[0] = pt;
      found = 1;
    }
    *n_found = found;
    return HM_OK;
  }
  delta3_ctx c = {*veh, speed_kmh, p};
  enum { SAMPLES = 256 };
  /* the points found go to a local array first: the outputs stay untouched if a later step fails (at most one
   * root per sample interval) */
  hm_hopf_point local[SAMPLES];
  double x_prev = lo, g_prev;
  if ((st = delta3_of(lo, &g_prev, &c)) != HM_OK) return st;
  for (int i = 1; i <= SAMPLES; ++i) {
    const double x = lo + (hi - lo) * i / SAMPLES;
    double g;
    if ((st = delta3_of(x, &g, &c)) != HM_OK) return st;
    if ((g_prev > 0.0) != (g > 0.0) || g == 0.0) {
      double root;
      if (g_prev == 0.0) {
        x_prev = x;
        g_prev = g;
        continue; /* counted at the previous sample */
      }
      if ((st = hm_brent_root(delta3_of, &c, x_prev, x, g_prev, g, xtol, 200, &root)) != HM_OK) return st;
      hm_vehicle v = *veh;
      double s = speed_kmh;
      hm_param_set(&v, &s, p, root);
      if (is_hopf(&v, s)) {
        if (found < max_points && (st = fill_point(&v, s, &local[found])) != HM_OK) return st;
        ++found;
      }
    }
    x_prev = x;
    g_prev = g;
  }
  for (size_t k = 0; k < found && k < max_points; ++k) points[k] = local[k];
  *n_found = found;
  return HM_OK;
}

/* ---- Hopf curves and GH points ---- */

typedef struct {
  const hm_vehicle *veh;
  const hm_hopf_curve_options *opt;
  int branch;
} curve_ctx;

/* The Hopf point at first-parameter value x on the given branch. */
static hm_status curve_point_at(const curve_ctx *c, double x, hm_hopf_point *pt, size_t *n_branches) {
  hm_vehicle v = *c->veh;
  double speed = c->opt->speed_kmh;
  const hm_plane plane = c->opt->plane;
  hm_status st = hm_param_set(&v, &speed, plane == HM_PLANE_KY_V ? HM_PARAM_KY : HM_PARAM_KX, x);
  if (st != HM_OK) return st;
  if (plane == HM_PLANE_KX_KY) {
    hm_hopf_point pts[2];
    size_t n = 0;
    st = hm_hopf_find(&v, speed, HM_PARAM_KY, c->opt->ky_min, c->opt->ky_max, c->opt->xtol * 1e-3, pts, 2, &n);
    if (st != HM_OK) return st;
    if (n_branches) *n_branches = n;
    if ((size_t)c->branch >= n) return HM_ENOCRIT;
    *pt = pts[c->branch];
    return HM_OK;
  }
  hm_hopf_point pts[1];
  size_t n = 0;
  st = hm_hopf_find(&v, speed, HM_PARAM_SPEED, 1e-3, 1e5, 1e-9, pts, 1, &n);
  if (st != HM_OK) return st;
  if (n_branches) *n_branches = n;
  if (n == 0) return HM_ENOCRIT;
  *pt = pts[0];
  return HM_OK;
}

static hm_status l1_along_curve(double x, double *value, void *ctx) {
  hm_hopf_point pt;
  hm_status st = curve_point_at((const curve_ctx *)ctx, x, &pt, NULL);
  if (st == HM_OK) *value = pt.l1;
  return st;
}

static int curve_options_valid(const hm_hopf_curve_options *o) {
  if (!(o->to > o->from) || !isfinite(o->from) || !isfinite(o->to) || o->n_points < 2 || !(o->xtol > 0.0))
    return 0;
  if (o->plane == HM_PLANE_KX_KY)
    return o->speed_kmh > 0.0 && isfinite(o->speed_kmh) && o->ky_max > o->ky_min && o->ky_min >= 0.0;
  return o->plane == HM_PLANE_KX_V || o->plane == HM_PLANE_KY_V;
}

static hm_status curve_branches(const hm_vehicle *veh, const hm_hopf_curve_options *opt, int n_branch_max,
                                hm_hopf_curve_point *points, size_t max_points, size_t *np_out, hm_hopf_point *gh,
                                size_t max_gh, size_t *ng_out);

hm_status hm_hopf_curve(const hm_vehicle *veh, const hm_hopf_curve_options *opt, hm_hopf_curve_point *points,
                        size_t max_points, size_t *n_points_out, hm_hopf_point *gh, size_t max_gh, size_t *n_gh) {
  if (!veh || !opt || !n_points_out || !n_gh || !curve_options_valid(opt)) return HM_EINVAL;
  if ((max_points && !points) || (max_gh && !gh)) return HM_EINVAL;
  hm_status st = hm_vehicle_validate(veh, NULL, 0);
  if (st != HM_OK) return st;
  const int n_branch_max = opt->plane == HM_PLANE_KX_KY ? 2 : 1;
  size_t np = 0, ng = 0;
  /* results go to work copies first, so that the outputs stay untouched when a later step fails */
  hm_hopf_curve_point *pts = max_points ? malloc(max_points * sizeof *pts) : NULL;
  hm_hopf_point *ghs = max_gh ? malloc(max_gh * sizeof *ghs) : NULL;
  if ((max_points && !pts) || (max_gh && !ghs)) {
    free(pts);
    free(ghs);
    return HM_ENOMEM;
  }
  st = curve_branches(veh, opt, n_branch_max, pts, max_points, &np, ghs, max_gh, &ng);
  if (st == HM_OK) {
    if (np) memcpy(points, pts, (np < max_points ? np : max_points) * sizeof *pts);
    if (ng) memcpy(gh, ghs, (ng < max_gh ? ng : max_gh) * sizeof *ghs);
    *n_points_out = np;
    *n_gh = ng;
  }
  free(pts);
  free(ghs);
  return st;
}

static hm_status curve_branches(const hm_vehicle *veh, const hm_hopf_curve_options *opt, int n_branch_max,
                                hm_hopf_curve_point *points, size_t max_points, size_t *np_out, hm_hopf_point *gh,
                                size_t max_gh, size_t *ng_out) {
  hm_status st;
  size_t np = 0, ng = 0;
  for (int b = 0; b < n_branch_max; ++b) {
    curve_ctx c = {veh, opt, b};
    int have_prev = 0;
    double x_prev = 0.0, l1_prev = 0.0;
    for (size_t i = 0; i < opt->n_points; ++i) {
      const double x = opt->from + (opt->to - opt->from) * (double)i / (double)(opt->n_points - 1);
      hm_hopf_point pt;
      st = curve_point_at(&c, x, &pt, NULL);
      if (st == HM_ENOCRIT) {
        have_prev = 0; /* no Hopf point on this branch here: the branch is interrupted */
        continue;
      }
      if (st != HM_OK) return st;
      if (np < max_points) points[np] = (hm_hopf_curve_point){pt, b};
      ++np;
      if (have_prev && (l1_prev > 0.0) != (pt.l1 > 0.0)) {
        double root;
        st = hm_brent_root(l1_along_curve, &c, x_prev, x, l1_prev, pt.l1, opt->xtol, 200, &root);
        if (st != HM_OK) return st;
        hm_hopf_point g;
        if ((st = curve_point_at(&c, root, &g, NULL)) != HM_OK) return st;
        if (ng < max_gh) gh[ng] = g;
        ++ng;
      }
      have_prev = 1;
      x_prev = x;
      l1_prev = pt.l1;
    }
  }
  *np_out = np;
  *ng_out = ng;
  return HM_OK;
}
