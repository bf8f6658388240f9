/* A model of any dimension: its spectrum at the origin and its linear critical speed (see system.h). */
#include "hunting_monitor/system.h"

#include <complex.h>
#include <math.h>
#include <string.h>

#include "hunting_monitor/linear.h"
#include "lapack.h"

enum { N_MAX = HM_SYSTEM_MAX_DIM, LWORK = 8 * HM_SYSTEM_MAX_DIM };

const char *hm_model_kind_name(hm_model_kind kind) {
  return kind == HM_MODEL_WHEELSET ? "wheelset" : kind == HM_MODEL_BOGIE ? "bogie" : kind == HM_MODEL_CAR ? "car"
                                                                                                    : "unknown";
}

void hm_system_critical_options_default(hm_system_critical_options *opt) {
  opt->v_min_mps = hm_mps_from_kmh(100.0);
  opt->v_max_mps = hm_mps_from_kmh(1500.0);
  opt->v_step_mps = hm_mps_from_kmh(5.0);
  opt->tol_mps = hm_mps_from_kmh(1e-9);
}

hm_status hm_system_validate(const hm_system *sys) {
  if (!sys || !sys->rhs || !sys->jacobian || !sys->dfdv || sys->dim < 2 || sys->dim > N_MAX || sys->n_bodies < 1 ||
      sys->n_bodies > HM_SYSTEM_MAX_BODIES || !sys->body_names || !sys->state_body || !sys->state_inertia ||
      !sys->state_scale || sys->amp_state >= sys->dim || sys->phase_state >= sys->dim ||
      sys->amp_state == sys->phase_state)
    return HM_EINVAL;
  double total = 0.0;
  for (size_t i = 0; i < sys->dim; ++i) {
    const int b = sys->state_body[i];
    const double w = sys->state_inertia[i], sc = sys->state_scale[i];
    if (b < -1 || b >= (int)sys->n_bodies || !isfinite(w) || w < 0.0 || (b < 0 && w > 0.0)) return HM_EINVAL;
    if (!isfinite(sc) || !(sc > 0.0)) return HM_EINVAL;
    total += w;
  }
  if (!sys->rhs_track || sys->n_wheelsets < 1 || sys->n_wheelsets > HM_SYSTEM_MAX_WHEELSETS || !sys->wheelset_x_m ||
      !sys->wheelset_y_state)
    return HM_EINVAL;
  for (size_t i = 0; i < sys->n_wheelsets; ++i)
    if (!isfinite(sys->wheelset_x_m[i]) || (i > 0 && !(sys->wheelset_x_m[i] < sys->wheelset_x_m[i - 1])) ||
        sys->wheelset_y_state[i] + 1 >= sys->dim)
      return HM_EINVAL;
  return total > 0.0 ? HM_OK : HM_EINVAL;
}

int hm_sensor_point_valid(const hm_system *sys, const hm_sensor_point *p) {
  if (!sys || !p || p->n_terms < 1 || p->n_terms > 4) return 0;
  for (size_t j = 0; j < p->n_terms; ++j)
    if (p->state[j] >= sys->dim || !isfinite(p->weight[j])) return 0;
  return 1;
}

/* Order: decreasing real part, then decreasing imaginary part; perm follows (insertion sort). */
static void sort_spectrum(size_t n, double *re, double *im, int *perm) {
  for (size_t i = 1; i < n; ++i) {
    const double r = re[i], m = im[i];
    const int p = perm[i];
    size_t j = i;
    while (j > 0 && (re[j - 1] < r || (re[j - 1] == r && im[j - 1] < m))) {
      re[j] = re[j - 1], im[j] = im[j - 1], perm[j] = perm[j - 1];
      --j;
    }
    re[j] = r, im[j] = m, perm[j] = p;
  }
}

hm_status hm_system_eig(const hm_system *sys, double speed_mps, double *re, double *im, double *vr) {
  const int n = (int)sys->dim, one = 1, lwork = LWORK;
  double jac[N_MAX * N_MAX], a[N_MAX * N_MAX], work[LWORK], dummy[1], x0[N_MAX];
  memset(x0, 0, sizeof x0);
  hm_status st = sys->jacobian(sys->model, speed_mps, x0, jac);
  if (st != HM_OK) return st;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      if (!isfinite(jac[n * i + j])) return HM_ENONFINITE;
      a[i + n * j] = jac[n * i + j]; /* column-major for LAPACK */
    }
  int info = 0;
  dgeev_("N", vr ? "V" : "N", &n, a, &n, re, im, dummy, &one, vr ? vr : dummy, vr ? &n : &one, work, &lwork, &info,
         1, 1);
  return info == 0 ? HM_OK : HM_ELAPACK;
}

/* Eigenvalues of the Jacobian at the origin, sorted; with vr != NULL also the right eigenvectors (dgeev's packing)
 * and perm[i] the unsorted index of re[i]. */
static hm_status eig_at(const hm_system *sys, double speed_mps, double *re, double *im, double *vr, int *perm) {
  hm_status st = hm_system_eig(sys, speed_mps, re, im, vr);
  if (st != HM_OK) return st;
  int local[N_MAX];
  for (size_t i = 0; i < sys->dim; ++i) local[i] = (int)i;
  sort_spectrum(sys->dim, re, im, perm ? perm : local);
  return HM_OK;
}

/* The kinetic energy of eigenvector k (unsorted index k in dgeev's packing) by body, normalised to sum 1. */
static void body_shares(const hm_system *sys, const double *vr, const double *wi, int k, double *share, int *dom) {
  const size_t n = sys->dim;
  double e[HM_SYSTEM_MAX_BODIES] = {0.0}, total = 0.0;
  /* dgeev: for a pair (wi[k] > 0, wi[k+1] < 0) the vector is vr[:,k] + i vr[:,k+1]; for wi[k] < 0 the conjugate of
   * the one at k-1 (same moduli) */
  const int re_col = wi[k] < 0.0 ? k - 1 : k;
  const int has_im = wi[k] != 0.0;
  for (size_t i = 0; i < n; ++i) {
    const int b = sys->state_body[i];
    if (b < 0 || sys->state_inertia[i] <= 0.0) continue;
    const double xr = vr[i + n * (size_t)re_col], xi = has_im ? vr[i + n * (size_t)(re_col + 1)] : 0.0;
    const double ke = sys->state_inertia[i] * (xr * xr + xi * xi);
    e[b] += ke;
    total += ke;
  }
  int best = 0;
  for (size_t b = 0; b < sys->n_bodies; ++b) {
    share[b] = total > 0.0 ? e[b] / total : 0.0;
    if (share[b] > share[best]) best = (int)b;
  }
  for (size_t b = sys->n_bodies; b < HM_SYSTEM_MAX_BODIES; ++b) share[b] = 0.0;
  *dom = best;
}

hm_status hm_system_spectrum_at(const hm_system *sys, double speed_mps, hm_system_spectrum *out) {
  hm_status st = hm_system_validate(sys);
  if (st != HM_OK || !out) return st != HM_OK ? st : HM_EINVAL;
  if (!isfinite(speed_mps) || !(speed_mps > 0.0)) return HM_EDOMAIN;
  double re[N_MAX], im[N_MAX], vr[N_MAX * N_MAX], wi_raw[N_MAX];
  int perm[N_MAX];
  for (size_t i = 0; i < sys->dim; ++i) perm[i] = (int)i;
  if ((st = eig_at(sys, speed_mps, re, im, vr, perm)) != HM_OK) return st;
  /* dgeev's unsorted order, to read the eigenvector's packing */
  for (size_t i = 0; i < sys->dim; ++i) wi_raw[perm[i]] = im[i];
  hm_system_spectrum s;
  memset(&s, 0, sizeof s);
  s.dim = sys->dim;
  memcpy(s.re, re, sys->dim * sizeof(double));
  memcpy(s.im, im, sys->dim * sizeof(double));
  s.abscissa_1_s = re[0];
  s.frequency_hz = fabs(im[0]) / (2.0 * HM_PI);
  body_shares(sys, vr, wi_raw, perm[0], s.body_share, &s.dominant_body);
  *out = s;
  return HM_OK;
}

static hm_status abscissa_at(const hm_system *sys, double v, double *s) {
  double re[N_MAX], im[N_MAX];
  hm_status st = eig_at(sys, v, re, im, NULL, NULL);
  if (st == HM_OK) *s = re[0];
  return st;
}

hm_status hm_system_critical_speed(const hm_system *sys, const hm_system_critical_options *opt, double *speed_mps,
                                   hm_system_spectrum *at_crit) {
  hm_status st = hm_system_validate(sys);
  if (st != HM_OK) return st;
  if (!opt || !speed_mps || !isfinite(opt->v_min_mps) || !(opt->v_min_mps > 0.0) || !isfinite(opt->v_max_mps) ||
      !(opt->v_max_mps > opt->v_min_mps) || !isfinite(opt->v_step_mps) || !(opt->v_step_mps > 0.0) ||
      !isfinite(opt->tol_mps) || !(opt->tol_mps > 0.0))
    return HM_EINVAL;
  double lo = opt->v_min_mps, s;
  if ((st = abscissa_at(sys, lo, &s)) != HM_OK) return st;
  if (s >= 0.0) return HM_ENOCRIT; /* unstable already at v_min */
  double hi = lo;
  for (;;) {
    hi = fmin(lo + opt->v_step_mps, opt->v_max_mps);
    if ((st = abscissa_at(sys, hi, &s)) != HM_OK) return st;
    if (s >= 0.0) break;
    if (hi >= opt->v_max_mps) return HM_ENOCRIT;
    lo = hi;
  }
  while (hi - lo > opt->tol_mps) {
    const double mid = 0.5 * (lo + hi);
    if (!(mid > lo && mid < hi)) break; /* the bracket is as narrow as doubles allow */
    if ((st = abscissa_at(sys, mid, &s)) != HM_OK) return st;
    if (s >= 0.0) hi = mid;
    else lo = mid;
  }
  hm_system_spectrum spec;
  if (at_crit && (st = hm_system_spectrum_at(sys, hi, &spec)) != HM_OK) return st;
  *speed_mps = 0.5 * (lo + hi);
  if (at_crit) *at_crit = spec;
  return HM_OK;
}

/* ---- docs/MODEL.md's wheelset ---- */

static const char *const WHEELSET_BODIES[] = {"wheelsets"};

static hm_status ws_rhs(const void *model, double v, const double *x, double *dx) {
  return hm_model_rhs_at(&((const hm_wheelset_system *)model)->model, v, x, dx);
}

static hm_status ws_jac(const void *model, double v, const double *x, double *jac) {
  return hm_model_jacobian_at(&((const hm_wheelset_system *)model)->model, v, x, jac);
}

static hm_status ws_dfdv(const void *model, double v, const double *x, double *dfdv) {
  const hm_linear_coef *c = &((const hm_wheelset_system *)model)->model.coef;
  const double iv2 = 1.0 / (v * v);
  dfdv[0] = 0.0;
  dfdv[1] = c->c_lat_m_s2 * iv2 * x[1];
  dfdv[2] = 0.0;
  dfdv[3] = c->c_yaw_m_s2 * iv2 * x[3];
  return isfinite(dfdv[1]) && isfinite(dfdv[3]) ? HM_OK : HM_ENONFINITE;
}

/* The wheel-rail terms on y - y_track, the springs on y (as excitation.c's). */
static hm_status ws_rhs_track(const void *model, double v, const double *x, const double *yt, double *dx) {
  const hm_model *m = &((const hm_wheelset_system *)model)->model;
  const double xr[4] = {x[0] - yt[0], x[1], x[2], x[3]};
  hm_status st = hm_model_rhs_at(m, v, xr, dx);
  if (st != HM_OK) return st;
  dx[1] -= m->coef.k_lat_s2 * yt[0];
  return isfinite(dx[1]) ? HM_OK : HM_ENONFINITE;
}

hm_status hm_wheelset_system_init(hm_wheelset_system *ws, const hm_vehicle *veh, hm_system *sys) {
  if (!ws || !veh || !sys) return HM_EINVAL;
  hm_wheelset_system w;
  hm_status st = hm_model_init(&w.model, veh, 1.0);
  if (st != HM_OK) return st;
  const double inertia[4] = {0.0, veh->mass_kg, 0.0, veh->yaw_inertia_kg_m2};
  const double scale[4] = {1e-3, 0.1, 1e-3, 0.1};
  memcpy(w.inertia, inertia, sizeof inertia);
  memcpy(w.scale, scale, sizeof scale);
  for (int i = 0; i < 4; ++i) w.body[i] = 0;
  w.x_m[0] = 0.0;
  w.y_state[0] = 0;
  *ws = w;
  *sys = (hm_system){4, ws_rhs, ws_jac, ws_dfdv, ws, 1, WHEELSET_BODIES, ws->body, ws->inertia, ws->scale, 0, 1,
                     hm_conicity_is_even(&veh->conicity, 1e-12), ws_rhs_track, 1, ws->x_m, ws->y_state};
  return HM_OK;
}
