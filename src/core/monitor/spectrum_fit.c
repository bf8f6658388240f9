/* A conicity from the whole spectrum a vehicle model predicts at its sensor (see spectrum_fit.h). */
#include "hunting_monitor/spectrum_fit.h"

#include <math.h>
#include <string.h>

enum { SCAN = 24, REFINE_SCAN = 9, GOLDEN_MAX = 200, PROFILE_MAX = 200, SHAPE_PARTS = HM_SPECTRUM_FIT_SHAPE_PARTS };

void hm_spectrum_fit_options_default(hm_spectrum_fit_options *o) {
  if (!o) return;
  o->conicity_min = 0.02;
  o->conicity_max = 0.8;
  o->tol = 1e-4;
  o->window_s = 0.0;
  o->passes = HM_SPECTRUM_FIT_MAX_PASSES;
}

/* sum_k p_k / m_k + ln m_k with m_k = a g_k + c, a and c > 0 chosen to minimise it (-log L per degree of freedom
 * pair, Whittle): Fisher scoring in (ln a, ln c), steps clipped to a factor e^2, c kept above 1e-6 of the least p. */
static double profile(const double *g, const double *p, size_t n, double *amp, double *floor_) {
  double gmean = 0.0, pmean = 0.0, pmin = INFINITY;
  for (size_t k = 0; k < n; ++k) gmean += g[k], pmean += p[k], pmin = fmin(pmin, p[k]);
  if (!(gmean > 0.0) || !isfinite(gmean)) return INFINITY;
  double la = log(0.9 * pmean / gmean), lc = log(0.1 * pmean);
  const double lc_min = log(1e-6 * pmin);
  for (int it = 0; it < PROFILE_MAX; ++it) {
    const double a = exp(la), c = exp(lc);
    double s1 = 0.0, s2 = 0.0, i11 = 0.0, i12 = 0.0, i22 = 0.0;
    for (size_t k = 0; k < n; ++k) {
      const double mk = a * g[k] + c, d1 = a * g[k] / mk, d2 = c / mk, r = p[k] / mk - 1.0;
      s1 += d1 * r, s2 += d2 * r;
      i11 += d1 * d1, i12 += d1 * d2, i22 += d2 * d2;
    }
    const double det = i11 * i22 - i12 * i12;
    double x1 = s1 / i11, x2 = 0.0;
    if (det > 1e-12 * i11 * i22) x1 = (i22 * s1 - i12 * s2) / det, x2 = (i11 * s2 - i12 * s1) / det;
    x1 = fmax(fmin(x1, 2.0), -2.0), x2 = fmax(fmin(x2, 2.0), -2.0);
    la += x1, lc = fmax(lc + x2, lc_min);
    if (fabs(x1) + fabs(x2) < 1e-10) break;
  }
  *amp = exp(la), *floor_ = exp(lc);
  double l = 0.0;
  for (size_t k = 0; k < n; ++k) {
    const double mk = *amp * g[k] + *floor_;
    l += p[k] / mk + log(mk);
  }
  return isfinite(l) ? l : INFINITY;
}

typedef struct {
  hm_mode_model m;
  double v_kmh;
  const hm_sensor_point *point;
  const hm_running *run;
  const double *f, *p;
  size_t n;
  double *g;
  double amp, floor_; /* of the last evaluation */
} fit_ctx;

static double objective(fit_ctx *c, double lambda) {
  if (hm_mode_model_running_spectrum(c->m, lambda, c->v_kmh, c->point, c->run, c->f, c->n, c->g) != HM_OK)
    return INFINITY;
  return profile(c->g, c->p, c->n, &c->amp, &c->floor_);
}

/* The mean of x = psd / (amp g + fl) over m bins, less 1, in its standard error sqrt(2 / (dof m)) (x of m bins of
 * dof / 2 periodograms each: about N(0, 1) where the model explains them); non-finite where an x is. */
static double mean_ratio_z(const double *psd, const double *g, size_t m, double amp, double fl, double dof) {
  double sx = 0.0;
  for (size_t k = 0; k < m; ++k) sx += psd[k] / (amp * g[k] + fl);
  return (sx / (double)m - 1.0) / sqrt(2.0 / (dof * (double)m));
}

/* The minimum over [lo, hi]: a geometric scan of `scan` points, then golden section in ln(conicity) over the best
 * point's neighbours to tol. 0 where it lies at an end of the range (not bracketed) or nothing was finite. */
static int minimise(fit_ctx *c, double lo, double hi, int scan, double tol, double *lambda) {
  double best = INFINITY;
  int kb = -1;
  double lv[SCAN];
  for (int k = 0; k < scan; ++k) {
    lv[k] = lo * pow(hi / lo, (double)k / (scan - 1));
    const double o = objective(c, lv[k]);
    if (o < best) best = o, kb = k;
  }
  if (kb <= 0 || kb >= scan - 1) return 0;
  double a = log(lv[kb - 1]), b = log(lv[kb + 1]);
  const double r = 0.5 * (sqrt(5.0) - 1.0);
  double x1 = b - r * (b - a), x2 = a + r * (b - a), f1 = objective(c, exp(x1)), f2 = objective(c, exp(x2));
  for (int it = 0; it < GOLDEN_MAX && exp(b) - exp(a) > tol; ++it) {
    if (f1 < f2) b = x2, x2 = x1, f2 = f1, x1 = b - r * (b - a), f1 = objective(c, exp(x1));
    else a = x1, x1 = x2, f1 = f2, x2 = a + r * (b - a), f2 = objective(c, exp(x2));
  }
  *lambda = exp(0.5 * (a + b));
  return 1;
}

/* The motion found within HM_SPECTRUM_FIT_MOTION_TOL of the one linearised about, for every wheelset. */
static int motion_settled(const double *found, const double *about) {
  for (size_t i = 0; i < HM_SYSTEM_MAX_WHEELSETS; ++i)
    if (!(fabs(found[i] - about[i]) <= HM_SPECTRUM_FIT_MOTION_TOL * found[i])) return 0;
  return 1;
}

static int options_ok(const hm_spectrum_fit_options *o) {
  return o && o->conicity_min > 0.0 && o->conicity_max > o->conicity_min && isfinite(o->conicity_max) &&
         o->tol > 0.0 && isfinite(o->tol) && o->window_s >= 0.0 && isfinite(o->window_s) &&
         o->passes <= HM_SPECTRUM_FIT_MAX_PASSES;
}

hm_status hm_spectrum_fit_conicity(hm_mode_model m, double speed_kmh, const hm_sensor_point *point, const double *f_hz,
                                   const double *psd, size_t n, double dof, const hm_spectrum_fit_options *o,
                                   hm_spectrum_fit *out) {
  if (!m || !point || !f_hz || !psd || !out || !options_ok(o) || n < 4 * HM_SPECTRUM_FIT_SHAPE_PARTS ||
      n > HM_SPECTRUM_FIT_MAX_BINS || !(dof >= 2.0 / 64.0) || !isfinite(dof) || !(speed_kmh > 0.0) ||
      !isfinite(speed_kmh))
    return HM_EDOMAIN;
  for (size_t k = 0; k < n; ++k)
    if (!(psd[k] > 0.0) || !isfinite(psd[k]) || !(f_hz[k] > 0.0) || !isfinite(f_hz[k]) ||
        (k > 0 && !(f_hz[k] > f_hz[k - 1])))
      return HM_EDOMAIN;
  double g[HM_SPECTRUM_FIT_MAX_BINS];
  hm_running run;
  memset(&run, 0, sizeof run);
  run.window_s = o->window_s;
  fit_ctx c = {m, speed_kmh, point, &run, f_hz, psd, n, g, 0.0, 0.0};
  double lam, at_rest = NAN, motion[HM_SYSTEM_MAX_WHEELSETS] = {0.0};
  for (unsigned pass = 0;; ++pass) {
    /* the first over the range; each later one about the conicity before it (the motion changes it by 5-10%) */
    const int ok = pass == 0 ? minimise(&c, o->conicity_min, o->conicity_max, SCAN, o->tol, &lam)
                             : minimise(&c, fmax(lam / 1.5, o->conicity_min), fmin(lam * 1.5, o->conicity_max),
                                        REFINE_SCAN, o->tol, &lam);
    if (!ok) return HM_ENOCONV;
    if (pass == 0) at_rest = lam;
    if (!isfinite(objective(&c, lam))) return HM_ENOCONV;
    if (hm_mode_model_motion_rms(m, lam, speed_kmh, &run, c.amp, motion) != HM_OK) return HM_ENOCONV;
    if (pass == o->passes) break;
    if (pass > 0 && motion_settled(motion, run.motion_rms_m)) break; /* converged */
    memcpy(run.motion_rms_m, motion, sizeof motion);
  }
  /* not settled within the passes: no conicity (a motion this large is no Gaussian's either) */
  if (o->passes > 0 && !motion_settled(motion, run.motion_rms_m)) return HM_ENOCONV;
  const double l0 = objective(&c, lam), amp = c.amp, fl = c.floor_;
  double dev = 0.0, carried = 0.0, total = 0.0; /* Whittle's deviance: 2 sum (x - ln x - 1), x = p / m */
  for (size_t k = 0; k < n; ++k) {
    const double x = psd[k] / (amp * g[k] + fl);
    dev += 2.0 * (x - log(x) - 1.0);
    carried += amp * g[k], total += amp * g[k] + fl;
  }
  /* the fit's shape against the spectrum's: the mean of x over each of SHAPE_PARTS equal parts of the bins is 1 within
   * its standard error where the model explains them; their chi2 */
  double shape = 0.0;
  for (int j = 0; j < SHAPE_PARTS; ++j) {
    const size_t k0 = n * (size_t)j / SHAPE_PARTS, k1 = n * (size_t)(j + 1) / SHAPE_PARTS;
    const double z = mean_ratio_z(psd + k0, g + k0, k1 - k0, amp, fl, dof);
    shape += z * z;
  }
  const double dl = 0.01 * lam, lp = objective(&c, lam + dl), lm = objective(&c, lam - dl);
  const double curv = dof * (lp - 2.0 * l0 + lm) / (dl * dl);
  if (!isfinite(l0) || !isfinite(curv)) return HM_ENOCONV;
  out->conicity = lam;
  out->conicity_se = curv > 0.0 ? sqrt(2.0 / curv) : INFINITY;
  out->conicity_at_rest = at_rest;
  out->amplitude = amp;
  out->noise = fl;
  out->motion_rms_m = motion[0];
  out->neg2_log_lik = dof * l0;
  out->bins = n;
  out->deviance_per_bin = dev / (double)n;
  out->shape_chi2 = shape;
  out->model_share = carried / total;
  out->running = run;
  return HM_OK;
}

hm_status hm_spectrum_fit_peak_z(hm_mode_model m, double speed_kmh, const hm_sensor_point *point,
                                 const hm_spectrum_fit *fit, const double *f_hz, const double *psd, size_t n,
                                 double dof, double f_lo_hz, double f_hi_hz, double *z) {
  const double mid = 0.5 * (f_lo_hz + f_hi_hz);
  if (!m || !point || !fit || !f_hz || !psd || !z || n == 0 || n > HM_SPECTRUM_FIT_MAX_BINS || !(dof > 0.0) ||
      !isfinite(dof) || !(f_hi_hz >= f_lo_hz) || !isfinite(f_lo_hz) || !isfinite(f_hi_hz) || !(mid >= f_hz[0]) ||
      !(mid <= f_hz[n - 1]) || !(fit->conicity > 0.0) || !(fit->amplitude > 0.0) || !isfinite(fit->amplitude) ||
      !(fit->noise >= 0.0) || !isfinite(fit->noise))
    return HM_EDOMAIN;
  size_t k0 = 0;
  while (k0 < n && f_hz[k0] < f_lo_hz) ++k0;
  size_t k1 = k0;
  while (k1 < n && f_hz[k1] <= f_hi_hz) ++k1; /* [k0, k1): the bins in the range */
  if (k1 == k0) { /* none: the nearest to the middle */
    size_t kn = 0;
    for (size_t k = 1; k < n; ++k)
      if (fabs(f_hz[k] - mid) < fabs(f_hz[kn] - mid)) kn = k;
    k0 = kn, k1 = kn + 1;
  }
  for (size_t k = k0; k < k1; ++k)
    if (!(psd[k] >= 0.0) || !isfinite(psd[k])) return HM_EDOMAIN; /* (a density, finite and not negative) */
  double g[HM_SPECTRUM_FIT_MAX_BINS];
  if (hm_mode_model_running_spectrum(m, fit->conicity, speed_kmh, point, &fit->running, f_hz + k0, k1 - k0, g) !=
      HM_OK)
    return HM_ENOCONV;
  const double zk = mean_ratio_z(psd + k0, g, k1 - k0, fit->amplitude, fit->noise, dof);
  if (!isfinite(zk)) return HM_EDOMAIN;
  *z = zk;
  return HM_OK;
}
