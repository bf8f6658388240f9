/* Track lines in the distance domain: order tracking of one window (see order_lines.h). */
#include "hunting_monitor/order_lines.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fft.h"
#include "select.h"
#include "hunting_monitor/model.h"
#include "validate.h"

struct hm_order_lines_s {
  hm_order_lines_config cfg;
  size_t max_n, nfft_max;
  double *s;                    /* each sample's distance from the first [m]; then the resampled window's copy */
  double *dre, *dim, *dpow;     /* the distance-resampled window's DFT and power */
  double *tre, *tim, *tpow;     /* the time window's (hm_order_lines_clean's) */
  double *cosw, *sinw;          /* twiddles (nfft_max / 2) */
  double *scratch;              /* a median's selection */
  double halfwidth_hz;          /* the median's half-width (lines.h's background_halfwidth_hz) */
  unsigned char *exclude;       /* lines.h's marks (unused here) */
  hm_lines lines;
};

void hm_order_lines_config_default(hm_order_lines_config *c) {
  c->min_ratio = 25.0;
  c->min_f = 20.0;
  c->dominance = 8.0;
}

hm_status hm_order_lines_config_validate(const hm_order_lines_config *c, char *why, size_t len) {
  if (!c) return HM_EINVAL;
  const hm_field_check f[] = {{"min_ratio", c->min_ratio, HM_RULE_RANGE, 3.0, 1e6},
                              {"min_f", c->min_f, HM_RULE_RANGE, 1.0, 1e6},
                              {"dominance", c->dominance, HM_RULE_RANGE, 1.0, 1e6}};
  return hm_check_fields(f, HM_COUNT_OF(f), why, len);
}

void hm_order_lines_destroy(hm_order_lines o) {
  if (!o) return;
  free(o->s);
  free(o->dre);
  free(o->dim);
  free(o->dpow);
  free(o->tre);
  free(o->tim);
  free(o->tpow);
  free(o->cosw);
  free(o->sinw);
  free(o->exclude);
  free(o->scratch);
  hm_lines_destroy(o->lines);
  free(o);
}

hm_status hm_order_lines_create(const hm_order_lines_config *cfg, const hm_lines_config *lines_cfg, size_t max_n,
                                size_t nfft_max, hm_order_lines *out, char *why, size_t len) {
  if (!cfg || !lines_cfg || !out) return HM_EINVAL;
  hm_status st = hm_order_lines_config_validate(cfg, why, len);
  if (st != HM_OK) return st;
  if (max_n < 8) {
    if (why && len) snprintf(why, len, "max_n: must be at least 8 (got %zu)", max_n);
    return HM_EDOMAIN;
  }
  if (nfft_max < max_n || (nfft_max & (nfft_max - 1)) != 0) {
    if (why && len) snprintf(why, len, "nfft_max: must be a power of two >= max_n (got %zu for %zu)", nfft_max, max_n);
    return HM_EDOMAIN;
  }
  hm_order_lines o = calloc(1, sizeof *o);
  if (!o) return HM_ENOMEM;
  o->cfg = *cfg;
  o->max_n = max_n;
  o->nfft_max = nfft_max;
  const size_t nb = nfft_max / 2 + 1;
  o->s = malloc(max_n * sizeof(double));
  o->dre = malloc(nfft_max * sizeof(double));
  o->dim = malloc(nb * sizeof(double));
  o->dpow = malloc(nb * sizeof(double));
  o->tre = malloc(nfft_max * sizeof(double));
  o->tim = malloc(nb * sizeof(double));
  o->tpow = malloc(nb * sizeof(double));
  o->cosw = malloc(nfft_max / 2 * sizeof(double));
  o->sinw = malloc(nfft_max / 2 * sizeof(double));
  o->exclude = malloc(nb);
  o->scratch = malloc(nb * sizeof(double));
  o->halfwidth_hz = lines_cfg->background_halfwidth_hz;
  if (!o->s || !o->dre || !o->dim || !o->dpow || !o->tre || !o->tim || !o->tpow || !o->cosw || !o->sinw ||
      !o->exclude || !o->scratch) {
    hm_order_lines_destroy(o);
    return HM_ENOMEM;
  }
  st = hm_lines_create(lines_cfg, nb, &o->lines, why, len);
  if (st != HM_OK) {
    hm_order_lines_destroy(o);
    return st;
  }
  hm_fft_twiddles(o->cosw, o->sinw, nfft_max);
  *out = o;
  return HM_OK;
}

/* Catmull-Rom through x[i-1..i+2] at u in [0, 1) past x[i] (the ends repeated). */
static double cubic(const double *x, size_t n, size_t i, double u) {
  const double p0 = x[i > 0 ? i - 1 : 0], p1 = x[i];
  const double p2 = x[i + 1 < n ? i + 1 : n - 1], p3 = x[i + 2 < n ? i + 2 : n - 1];
  return 0.5 * (2.0 * p1 + (p2 - p0) * u + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * u * u +
                (3.0 * (p1 - p2) + p3 - p0) * u * u * u);
}

/* The mean-removed x zero-padded to nfft, its DFT into re / im and |X|^2 into pw. */
static void spectrum(const hm_order_lines o, const double *x, size_t n, size_t nfft, double *re, double *im,
                     double *pw) {
  double mean = 0.0;
  for (size_t i = 0; i < n; ++i) mean += x[i];
  mean /= (double)n;
  for (size_t i = 0; i < nfft; ++i) re[i] = i < n ? x[i] - mean : 0.0;
  hm_fft_real(re, im, nfft, o->cosw, o->sinw, o->nfft_max);
  for (size_t k = 0; k <= nfft / 2; ++k) pw[k] = re[k] * re[k] + im[k] * im[k];
}

/* The strongest bin of pw within [f - half, f + half] (bins of df) where a line can be fitted (m bins from the
 * ends); 0 if none. */
static size_t strongest(const double *pw, size_t nb, double df, double f, double half, size_t m) {
  const double lo = fmax((double)m, ceil((f - half) / df)), hi = fmin((double)(nb - 1 - m), floor((f + half) / df));
  size_t best = 0;
  for (double j = lo; j <= hi; j += 1.0)
    if (best == 0 || pw[(size_t)j] > pw[best]) best = (size_t)j;
  return best;
}

/* The distance [m] from sample i - 1 to sample i at fs (the trapezoid of their speeds). */
static double step_m(const double *v, size_t i, double fs) { return 0.5 * (v[i - 1] + v[i]) / fs; }

/* pw[k] over its local background: the median of pw within +-half_hz (bins of df) over ln 2 (lines.h). */
static double ratio_at(const hm_order_lines o, const double *pw, size_t nb, double df, size_t k) {
  const size_t h = (size_t)ceil(o->halfwidth_hz / df), a = k > h ? k - h : 0, b = k + h + 1 < nb ? k + h + 1 : nb;
  memcpy(o->scratch, pw + a, (b - a) * sizeof(double));
  const double bg = hm_select_kth(o->scratch, b - a, (b - a) / 2) / log(2.0);
  return bg > 0.0 ? pw[k] / bg : INFINITY;
}

/* hm_order_lines_clean's arguments' checks (order_lines.h; dft: 0 when not given, else its three arrays all given). */
static hm_status check(const hm_order_lines o, const double *x, const double *v, size_t n, double fs, size_t nfft,
                       double f_lo, double f_hi, int dft, const void *out) {
  if (!o || !x || !v || !out || !dft || n < 8 || n > o->max_n || nfft < n || nfft > o->nfft_max ||
      (nfft & (nfft - 1)) != 0 || !(fs > 0.0) || !(f_lo > 0.0) || !(f_hi > f_lo))
    return HM_EINVAL;
  for (size_t i = 0; i < n; ++i)
    if (!(isfinite(v[i]) && v[i] > 0.0)) return HM_EDOMAIN;
  return HM_OK;
}

static void clean(hm_order_lines o, double *x, const double *v, size_t n, double fs, size_t nfft, double f_lo,
                  double f_hi, const double *tre, const double *tim, const double *tpow, hm_order_lines_result *out);

hm_status hm_order_lines_clean(hm_order_lines o, double *x, const double *v, size_t n, double fs, size_t nfft,
                               double f_lo, double f_hi, hm_order_lines_result *out) {
  const hm_status st = check(o, x, v, n, fs, nfft, f_lo, f_hi, 1, out);
  if (st != HM_OK) return st;
  spectrum(o, x, n, nfft, o->tre, o->tim, o->tpow);
  clean(o, x, v, n, fs, nfft, f_lo, f_hi, o->tre, o->tim, o->tpow, out);
  return HM_OK;
}

hm_status hm_order_lines_clean_dft(hm_order_lines o, double *x, const double *v, size_t n, double fs, size_t nfft,
                                   double f_lo, double f_hi, const double *re, const double *im, const double *pw,
                                   hm_order_lines_result *out) {
  const hm_status st = check(o, x, v, n, fs, nfft, f_lo, f_hi, re && im && pw, out);
  if (st != HM_OK) return st;
  clean(o, x, v, n, fs, nfft, f_lo, f_hi, re, im, pw, out);
  return HM_OK;
}

/* The lines found in distance and taken out of x (the window's DFT in time in tre, tim, tpow). */
static void clean(hm_order_lines o, double *x, const double *v, size_t n, double fs, size_t nfft, double f_lo,
                  double f_hi, const double *tre, const double *tim, const double *tpow, hm_order_lines_result *out) {
  hm_order_lines_result r;
  memset(&r, 0, sizeof r);
  /* each sample's distance (and the speed's range), and the window resampled equally in distance (its virtual
   * time: distance / mean speed) */
  double vmin = v[0], vmax = v[0];
  o->s[0] = 0.0;
  for (size_t i = 1; i < n; ++i) {
    o->s[i] = o->s[i - 1] + step_m(v, i, fs);
    vmin = fmin(vmin, v[i]), vmax = fmax(vmax, v[i]);
  }
  const double total = o->s[n - 1], step = total / (double)(n - 1);
  r.speed_mean_mps = total * fs / (double)(n - 1);
  const double spread = (vmax - vmin) / r.speed_mean_mps;
  size_t i = 0;
  for (size_t j = 0; j < n; ++j) {
    const double sj = (double)j * step;
    while (i + 2 < n && o->s[i + 1] <= sj) ++i;
    const double u = fmin(fmax((sj - o->s[i]) / (o->s[i + 1] - o->s[i]), 0.0), 1.0);
    o->dre[j] = cubic(x, n, i, u);
  }
  memcpy(o->s, o->dre, n * sizeof(double)); /* (spectrum() reads its input from a separate array: s is free now) */
  spectrum(o, o->s, n, nfft, o->dre, o->dim, o->dpow);
  const size_t nb = nfft / 2 + 1;
  const double df = fs / (double)nfft, T = (double)n / fs;
  hm_lines_result lr;
  if (hm_lines_find(o->lines, o->dpow, nb, df, T, f_lo, f_hi, 0.0, o->exclude, &lr) != HM_OK) {
    *out = r;
    return;
  }
  /* the candidates: a comb's teeth, then the lone ones */
  double cand[HM_ORDER_LINES_MAX];
  unsigned nc = 0;
  if (lr.found && lr.fundamental_hz > 0.0)
    for (double f = ceil(f_lo / lr.fundamental_hz) * lr.fundamental_hz; f <= f_hi && nc < HM_ORDER_LINES_MAX_TEETH;
         f += lr.fundamental_hz)
      cand[nc++] = f;
  const unsigned n_teeth = nc; /* (a comb is evidence of its own: no min_ratio for its teeth) */
  if (n_teeth > 0) r.comb_fundamental_hz = lr.fundamental_hz;
  for (unsigned k = 0; k < lr.n_lone; ++k) cand[nc++] = lr.lone_hz[k];
  const size_t m = (size_t)ceil(3.0 * (double)nfft / (double)n) + 1;
  hm_lines_sinusoid fits[HM_ORDER_LINES_MAX];
  for (unsigned c = 0; c < nc && r.n < HM_ORDER_LINES_MAX; ++c) {
    const size_t kd = strongest(o->dpow, nb, df, cand[c], 1.0 / T, m);
    hm_lines_sinusoid fd, ft;
    if (kd == 0 || (c >= n_teeth && !(ratio_at(o, o->dpow, nb, df, kd) >= o->cfg.min_ratio)) ||
        hm_lines_fit_sinusoid(o->dre, o->dim, nb, kd, n, nfft, &fd) != HM_OK || !(fd.f_stat >= o->cfg.min_f))
      continue;
    const double f = fd.omega * fs / (2.0 * HM_PI);
    /* in time: the most line-like peak over the band the line swept */
    const size_t kt = strongest(tpow, nb, df, f, 0.5 * f * spread + 1.0 / T, m);
    const double ft_stat =
        kt != 0 && hm_lines_fit_sinusoid(tre, tim, nb, kt, n, nfft, &ft) == HM_OK ? ft.f_stat : 0.0;
    if (!(fd.f_stat >= o->cfg.dominance * ft_stat)) continue;
    int dup = 0; /* a tooth also listed as a lone candidate */
    for (unsigned q = 0; q < r.n; ++q) dup |= fabs(r.f_hz[q] - f) < 1.0 / T;
    if (dup) continue;
    fits[r.n] = fd;
    r.f_hz[r.n] = f;
    r.wavelength_m[r.n] = r.speed_mean_mps / f;
    r.amp_mps2[r.n] = 2.0 * hypot(fd.amp_re, fd.amp_im);
    r.f_distance[r.n] = fd.f_stat;
    r.f_time[r.n] = ft_stat;
    ++r.n;
  }
  /* each line out of the time samples at its phase in distance (virtual time tau_i = s_i / step samples), by a
   * rotation recomputed where the distance between samples changed (from the speeds: their difference of s would
   * differ by rounding and recompute it at a tenth of the samples of a held speed) */
  for (unsigned q = 0; q < r.n; ++q) {
    double c = 1.0, sn = 0.0, rc = 1.0, rs = 0.0, ds_last = NAN; /* (s[0] = 0: phase 0) */
    for (size_t k = 0; k < n; ++k) {
      if (k > 0) {
        const double ds = step_m(v, k, fs);
        if (ds != ds_last) rc = cos(fits[q].omega * ds / step), rs = sin(fits[q].omega * ds / step), ds_last = ds;
        const double c1 = c * rc - sn * rs;
        sn = sn * rc + c * rs, c = c1;
      }
      x[k] -= 2.0 * (fits[q].amp_re * c - fits[q].amp_im * sn);
    }
  }
  *out = r;
}
