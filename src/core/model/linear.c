/* Linear stability of the origin: closed forms from the Hurwitz criterion, and LAPACK eigenvalues. */
#include "hunting_monitor/linear.h"

#include <math.h>
#include <string.h>

#include "lapack.h"

/* The grouped constants of the header comment, at conicity lambda. */
typedef struct {
  double A1, A3, P, Q, a, b, ge;
} hurwitz_terms;

static hm_status terms_of(const hm_vehicle *veh, double conicity, hurwitz_terms *h) {
  if (!veh) return HM_EINVAL;
  hm_status st = hm_vehicle_validate(veh, NULL, 0);
  if (st != HM_OK) return st;
  if (!isfinite(conicity) || conicity < 0.0) return HM_EDOMAIN;
  hm_linear_coef c;
  hm_linear_coef_from_vehicle(veh, &c);
  h->a = c.k_lat_s2;
  h->b = c.k_yaw_s2;
  h->A1 = c.c_lat_m_s2 + c.c_yaw_m_s2;
  h->A3 = c.k_lat_s2 * c.c_yaw_m_s2 + c.k_yaw_s2 * c.c_lat_m_s2;
  h->P = c.k_lat_s2 + c.k_yaw_s2;
  h->Q = c.c_lat_m_s2 * c.c_yaw_m_s2;
  h->ge = c.c_lat_m_s2 * c.e_yaw_m_s2;
  return HM_OK;
}

static int speed_ok(double v) { return isfinite(v) && v > 0.0; }

hm_status hm_linear_char_poly(const hm_vehicle *veh, double conicity, double speed_mps, double coeffs[4]) {
  hurwitz_terms h;
  hm_status st = terms_of(veh, conicity, &h);
  if (st != HM_OK) return st;
  if (!coeffs) return HM_EINVAL;
  if (!speed_ok(speed_mps)) return HM_EDOMAIN;
  const double v = speed_mps;
  coeffs[0] = h.A1 / v;
  coeffs[1] = h.P + h.Q / (v * v);
  coeffs[2] = h.A3 / v;
  coeffs[3] = h.a * h.b + h.ge * conicity;
  return HM_OK;
}

hm_status hm_linear_hurwitz_delta3(const hm_vehicle *veh, double conicity, double speed_mps, double *delta3) {
  double a[4];
  hm_status st = hm_linear_char_poly(veh, conicity, speed_mps, a);
  if (st != HM_OK) return st;
  if (!delta3) return HM_EINVAL;
  *delta3 = a[0] * a[1] * a[2] - a[0] * a[0] * a[3] - a[2] * a[2];
  return HM_OK;
}

/* Order: decreasing real part, then decreasing imaginary part (insertion sort of 4). */
static void sort_eigenvalues(double re[4], double im[4]) {
  for (int i = 1; i < 4; ++i) {
    const double r = re[i], m = im[i];
    int j = i - 1;
    while (j >= 0 && (re[j] < r || (re[j] == r && im[j] < m))) {
      re[j + 1] = re[j];
      im[j + 1] = im[j];
      --j;
    }
    re[j + 1] = r;
    im[j + 1] = m;
  }
}

hm_status hm_linear_eigenvalues(const hm_vehicle *veh, double conicity, double speed_mps, double re[4], double im[4]) {
  if (!veh || !re || !im) return HM_EINVAL;
  hm_vehicle lin = *veh;
  memset(&lin.conicity, 0, sizeof lin.conicity);
  lin.conicity.constant = conicity;
  lin.flange_alpha1_n_m3 = lin.flange_alpha2_n_m5 = 0.0;
  hm_model mdl;
  hm_status st = hm_model_init(&mdl, &lin, speed_mps);
  if (st != HM_OK) return st;
  const double x0[4] = {0.0, 0.0, 0.0, 0.0};
  double jac[16], a[16];
  st = hm_model_jacobian(0.0, x0, jac, &mdl);
  if (st != HM_OK) return st;
  /* LAPACK is column-major: the transpose of a row-major matrix; eigenvalues are the same. */
  memcpy(a, jac, sizeof a);
  const int n = 4, one = 1;
  enum { LWORK = 128 }; /* >= 3n, and above dgeev's optimal size for n = 4 (tested) */
  double work[LWORK], wr[4], wi[4], dummy[1];
  const int lwork = LWORK;
  int info = 0;
  dgeev_("N", "N", &n, a, &n, wr, wi, dummy, &one, dummy, &one, work, &lwork, &info, 1, 1);
  if (info != 0) return HM_ELAPACK;
  sort_eigenvalues(wr, wi);
  memcpy(re, wr, sizeof wr);
  memcpy(im, wi, sizeof wi);
  return HM_OK;
}

hm_status hm_linear_spectral_abscissa(const hm_vehicle *veh, double conicity, double speed_mps, double *abscissa) {
  double re[4], im[4];
  if (!abscissa) return HM_EINVAL;
  hm_status st = hm_linear_eigenvalues(veh, conicity, speed_mps, re, im);
  if (st != HM_OK) return st;
  *abscissa = re[0];
  return HM_OK;
}

double hm_linear_hopf_kmh(const hm_vehicle *veh, double conicity) {
  double v_mps;
  if (!veh || !(conicity > 0.0) || hm_linear_critical_speed(veh, conicity, &v_mps) != HM_OK)
    return HM_LINEAR_NO_HOPF_KMH;
  return fmin(hm_kmh_from_mps(v_mps), HM_LINEAR_NO_HOPF_KMH);
}

hm_status hm_linear_critical_speed(const hm_vehicle *veh, double conicity, double *speed_mps) {
  hurwitz_terms h;
  hm_status st = terms_of(veh, conicity, &h);
  if (st != HM_OK) return st;
  if (!speed_mps) return HM_EINVAL;
  const double a4 = h.a * h.b + h.ge * conicity;
  if (a4 <= 0.0 || h.A3 <= 0.0) return HM_ENOCRIT; /* unstable at every speed */
  const double D = h.A1 * h.A1 * a4 + h.A3 * h.A3 - h.A1 * h.A3 * h.P;
  if (D <= 0.0) return HM_ENOCRIT; /* Delta3 > 0 at every speed */
  const double v2 = h.A1 * h.A3 * h.Q / D;
  if (h.P + h.Q / v2 <= 0.0) return HM_ENOCRIT; /* a2 <= 0 at the crossing: no Hopf point */
  *speed_mps = sqrt(v2);
  return HM_OK;
}

hm_status hm_linear_critical_conicity(const hm_vehicle *veh, double speed_mps, double *conicity) {
  hurwitz_terms h;
  hm_status st = terms_of(veh, 0.0, &h);
  if (st != HM_OK) return st;
  if (!conicity) return HM_EINVAL;
  if (!speed_ok(speed_mps)) return HM_EDOMAIN;
  if (h.ge <= 0.0 || h.A3 <= 0.0) return HM_ENOCRIT;
  const double v2 = speed_mps * speed_mps;
  const double lc =
      (h.A1 * h.A3 * h.Q / v2 + h.A1 * h.A3 * h.P - h.A3 * h.A3 - h.A1 * h.A1 * h.a * h.b) / (h.A1 * h.A1 * h.ge);
  if (!(lc > 0.0)) return HM_ENOCRIT;
  *conicity = lc;
  return HM_OK;
}

hm_status hm_linear_hopf_omega(const hm_vehicle *veh, double *omega_rad_s) {
  hurwitz_terms h;
  hm_status st = terms_of(veh, 0.0, &h);
  if (st != HM_OK) return st;
  if (!omega_rad_s) return HM_EINVAL;
  if (h.A3 <= 0.0) return HM_ENOCRIT;
  *omega_rad_s = sqrt(h.A3 / h.A1);
  return HM_OK;
}

hm_status hm_linear_critical_speed_eig(const hm_vehicle *veh, double conicity, double v_start_mps,
                                       double v_max_mps, double tol_mps, double *speed_mps) {
  if (!speed_mps || !speed_ok(v_start_mps) || !(v_max_mps > v_start_mps) || !isfinite(v_max_mps) ||
      !(tol_mps > 0.0))
    return HM_EINVAL;
  double lo = v_start_mps, s;
  hm_status st = hm_linear_spectral_abscissa(veh, conicity, lo, &s);
  if (st != HM_OK) return st;
  if (s >= 0.0) return HM_ENOCRIT; /* already unstable at the start */
  double hi = lo;
  for (;;) {
    hi = fmin(2.0 * hi, v_max_mps);
    st = hm_linear_spectral_abscissa(veh, conicity, hi, &s);
    if (st != HM_OK) return st;
    if (s > 0.0) break;
    if (hi >= v_max_mps) return HM_ENOCRIT;
    lo = hi;
  }
  while (hi - lo > tol_mps) {
    const double mid = 0.5 * (lo + hi);
    st = hm_linear_spectral_abscissa(veh, conicity, mid, &s);
    if (st != HM_OK) return st;
    if (s > 0.0)
      hi = mid;
    else
      lo = mid;
  }
  *speed_mps = 0.5 * (lo + hi);
  return HM_OK;
}
