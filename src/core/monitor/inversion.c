/* The equivalent conicity from the identified hunting mode (see inversion.h). */
#include "hunting_monitor/inversion.h"

#include <complex.h>
#include <math.h>
#include <string.h>

#include "hunting_monitor/linear.h"
#include "lapack.h"

typedef struct {
  double c1, c2, a, b, ge; /* q(s) = (s^2 + c1 s + a)(s^2 + c2 s + b), plus ge lambda */
} quartic;

static quartic quartic_at(const hm_linear_coef *c, double speed_kmh) {
  const double v = hm_mps_from_kmh(speed_kmh);
  const quartic q = {c->c_lat_m_s2 / v, c->c_yaw_m_s2 / v, c->k_lat_s2, c->k_yaw_s2, c->c_lat_m_s2 * c->e_yaw_m_s2};
  return q;
}

static double complex q_prime(const quartic *q, double complex s) {
  const double complex p1 = s * s + q->c1 * s + q->a, p2 = s * s + q->c2 * s + q->b;
  return (2.0 * s + q->c1) * p2 + p1 * (2.0 * s + q->c2);
}

/* The root with the largest real part (and positive imaginary part) of q(s) + ge lambda, by dgeev on the
 * companion matrix. */
static hm_status root_at(const quartic *q, double lambda, double complex *root) {
  /* s^4 + a1 s^3 + a2 s^2 + a3 s + a4 */
  const double a1 = q->c1 + q->c2, a2 = q->a + q->b + q->c1 * q->c2, a3 = q->a * q->c2 + q->b * q->c1,
               a4 = q->a * q->b + q->ge * lambda;
  double m[16] = {0}; /* column-major companion matrix */
  m[0 + 4 * 0] = -a1;
  m[0 + 4 * 1] = -a2;
  m[0 + 4 * 2] = -a3;
  m[0 + 4 * 3] = -a4;
  m[1 + 4 * 0] = m[2 + 4 * 1] = m[3 + 4 * 2] = 1.0;
  const int n = 4, one = 1;
  enum { LWORK = 128 };
  double work[LWORK], wr[4], wi[4], dummy[1];
  const int lwork = LWORK;
  int info = 0;
  dgeev_("N", "N", &n, m, &n, wr, wi, dummy, &one, dummy, &one, work, &lwork, &info, 1, 1);
  if (info != 0) return HM_ELAPACK;
  int best = -1;
  for (int k = 0; k < 4; ++k)
    if (wi[k] > 0.0 && (best < 0 || wr[k] > wr[best])) best = k;
  if (best < 0) return HM_ENOCRIT; /* no oscillatory mode */
  *root = wr[best] + I * wi[best];
  return HM_OK;
}

hm_status hm_hunting_root(const hm_linear_coef *coef, double speed_kmh, double conicity, double *sigma, double *omega) {
  if (!coef || !sigma || !omega || !(speed_kmh > 0.0) || !isfinite(speed_kmh) || !isfinite(conicity)) return HM_EINVAL;
  const quartic q = quartic_at(coef, speed_kmh);
  double complex s;
  const hm_status st = root_at(&q, conicity, &s);
  if (st != HM_OK) return st;
  *sigma = creal(s);
  *omega = cimag(s);
  return HM_OK;
}

hm_status hm_conicity_from_mode(const hm_linear_coef *coef, double speed_kmh, double sigma_m, double e_sigma,
                                double f_m, double e_f, double tol, unsigned max_iter, hm_conicity_inversion *out) {
  if (!coef || !out) return HM_EINVAL;
  if (!(speed_kmh > 0.0 && speed_kmh < 1e4) || !(sigma_m < 0.0) || !isfinite(sigma_m) || !(f_m > 0.0 && f_m < 1e3) ||
      !(e_sigma > 0.0) || !isfinite(e_sigma) || !(e_f > 0.0) || !isfinite(e_f) || !(tol > 0.0) || max_iter < 1)
    return HM_EDOMAIN;
  const quartic q = quartic_at(coef, speed_kmh);
  const double w_m = 2.0 * HM_PI * f_m, e_w = 2.0 * HM_PI * e_f;
  /* start: the lambda that would put a root exactly at s_m, were it real */
  const double complex s_m = sigma_m + I * w_m;
  const double complex p1 = s_m * s_m + q.c1 * s_m + q.a, p2 = s_m * s_m + q.c2 * s_m + q.b;
  double lambda = fmin(fmax(creal(-p1 * p2 / q.ge), 1e-3), 5.0);
  for (unsigned it = 1; it <= max_iter; ++it) {
    double complex s;
    hm_status st = root_at(&q, lambda, &s);
    if (st != HM_OK) return HM_ENOCONV;
    const double complex ds = -q.ge / q_prime(&q, s);
    const double jr = creal(ds) / e_sigma, ji = cimag(ds) / e_w;
    const double rr = (creal(s) - sigma_m) / e_sigma, ri = (cimag(s) - w_m) / e_w;
    const double jj = jr * jr + ji * ji;
    if (!(jj > 0.0) || !isfinite(jj)) return HM_ENOCONV;
    double step = -(jr * rr + ji * ri) / jj;
    step = fmax(fmin(step, 0.5 * lambda + 0.01), -0.5 * lambda); /* keep lambda positive */
    lambda += step;
    if (fabs(step) <= tol) {
      if (!(lambda > 0.0 && lambda < 10.0)) return HM_ENOCONV;
      if ((st = root_at(&q, lambda, &s)) != HM_OK) return HM_ENOCONV;
      const double complex d = -q.ge / q_prime(&q, s);
      const double j1 = creal(d) / e_sigma, j2 = cimag(d) / e_w;
      const double r1 = (creal(s) - sigma_m) / e_sigma, r2 = (cimag(s) - w_m) / e_w;
      hm_conicity_inversion r;
      memset(&r, 0, sizeof r);
      r.conicity = lambda;
      r.conicity_se = 1.0 / sqrt(j1 * j1 + j2 * j2);
      r.chi2 = r1 * r1 + r2 * r2;
      r.model_decay_rate_1_s = creal(s);
      r.model_frequency_hz = cimag(s) / (2.0 * HM_PI);
      r.dsigma_dconicity = creal(d);
      r.dfrequency_dconicity = cimag(d) / (2.0 * HM_PI);
      r.iterations = it;
      *out = r;
      return HM_OK;
    }
  }
  return HM_ENOCONV;
}
