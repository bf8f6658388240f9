/* Periodic track excitation: a comb of spectral lines at multiples of V / L (see lines.h). */
#include "hunting_monitor/lines.h"

#include "hunting_monitor/model.h"

#include "select.h"
#include "validate.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

enum { MAX_CANDIDATES = 32, MAX_DIVISOR = 12 };

struct hm_lines_s {
  hm_lines_config cfg;
  size_t max_bins;
  double *window;  /* scratch for a median's selection */
};

void hm_lines_config_default(hm_lines_config *c) {
  c->candidate_ratio = 8.0;
  c->background_halfwidth_hz = 0.5;
  c->min_fundamental_hz = 1.5;
  c->min_harmonics = 3;
  c->leakage = 0.1;
}

hm_status hm_lines_config_validate(const hm_lines_config *c, char *why, size_t len) {
  if (!c) return HM_EINVAL;
  const hm_field_check f[] = {
      {"candidate_ratio", c->candidate_ratio, HM_RULE_RANGE, 3.0, 1e4},
      {"background_halfwidth_hz", c->background_halfwidth_hz, HM_RULE_RANGE, 0.05, 5.0},
      {"min_fundamental_hz", c->min_fundamental_hz, HM_RULE_RANGE, 0.1, 100.0},
      {"min_harmonics", (double)c->min_harmonics, HM_RULE_RANGE, 2.0, 20.0},
      {"leakage", c->leakage, HM_RULE_RANGE_OPEN, 0.0, 1.0}};
  return hm_check_fields(f, HM_COUNT_OF(f), why, len);
}

hm_status hm_lines_create(const hm_lines_config *cfg, size_t max_bins, hm_lines *out, char *why, size_t len) {
  if (!cfg || !out || max_bins == 0) return HM_EINVAL;
  const hm_status st = hm_lines_config_validate(cfg, why, len);
  if (st != HM_OK) return st;
  hm_lines l = calloc(1, sizeof *l);
  if (!l) return HM_ENOMEM;
  l->cfg = *cfg;
  l->max_bins = max_bins;
  l->window = malloc(max_bins * sizeof(double));
  if (!l->window) {
    hm_lines_destroy(l);
    return HM_ENOMEM;
  }
  *out = l;
  return HM_OK;
}

void hm_lines_destroy(hm_lines l) {
  if (!l) return;
  free(l->window);
  free(l);
}

typedef struct {
  double f, ratio;
  size_t k;
} candidate;

size_t hm_lines_mark(const hm_lines l, double f, double ratio, double spread_rel, size_t n, double df, double T,
                     unsigned char *exclude) {
  if (!l || !exclude || !(df > 0.0) || !(T > 0.0) || n == 0) return 0;
  const hm_lines_config *c = &l->cfg;
  const double w = fmin(c->background_halfwidth_hz, fmax(2.0 / T, sqrt(fmax(ratio, 1.0) / c->leakage) / (HM_PI * T))) +
                   fabs(f) * (isfinite(spread_rel) && spread_rel > 0.0 ? fmin(spread_rel, 0.1) : 0.0);
  const double a = fmax(0.0, ceil((f - w) / df)), b = fmin((double)(n - 1), floor((f + w) / df));
  size_t marked = 0;
  for (double k = a; k <= b; k += 1.0)
    if (!exclude[(size_t)k]) exclude[(size_t)k] = 1, ++marked;
  return marked;
}

/* The candidates in bins k_lo..k_hi: local maxima over +- a main lobe (at least two bins) at least candidate_ratio above
 * their local background, the median of the bins within +-h; at most MAX_CANDIDATES, the strongest kept. Their
 * count before that limit in *seen. */
static size_t find_candidates(hm_lines l, const double *p, size_t n, double df, double T, size_t k_lo, size_t k_hi,
                              size_t h, candidate *cand, unsigned *seen) {
  const hm_lines_config *c = &l->cfg;
  const size_t lobe = (size_t)fmax(2.0, round(0.5 / (T * df)));
  size_t nc = 0;
  for (size_t k = k_lo; k <= k_hi; ++k) {
    int is_max = 1;
    for (size_t j = k > lobe ? k - lobe : 0; j <= k + lobe && j < n && is_max; ++j)
      if (j != k && p[j] > p[k]) is_max = 0;
    if (!is_max) continue;
    const size_t a = k > h ? k - h : 1, b = k + h < n ? k + h + 1 : n;
    /* the median is at most p_k ln 2 / ratio exactly when more than half the window is: counted first (a pass
     * without branches), the median selected for the few that pass */
    const double thr = p[k] * log(2.0) / c->candidate_ratio * (1.0 + 1e-12);
    size_t below = 0;
    for (size_t j = a; j < b; ++j) below += p[j] <= thr;
    if (below < (b - a) / 2 + 1) continue;
    memcpy(l->window, p + a, (b - a) * sizeof(double));
    const double bg = hm_select_kth(l->window, b - a, (b - a) / 2) / log(2.0);
    if (!(bg > 0.0)) continue;
    const double ratio = p[k] / bg;
    if (ratio < c->candidate_ratio) continue;
    ++*seen;
    /* the parabola through the logarithms of the three bins at the peak */
    const double ym = log(fmax(p[k - 1], 1e-300)), y0 = log(p[k]), yp = log(fmax(p[k + 1], 1e-300));
    const double den = ym - 2.0 * y0 + yp;
    const double delta = den < 0.0 ? fmax(-0.5, fmin(0.5, 0.5 * (ym - yp) / den)) : 0.0;
    const candidate cd = {((double)k + delta) * df, ratio, k};
    if (nc < MAX_CANDIDATES) {
      cand[nc++] = cd;
    } else { /* keep the strongest */
      size_t weakest = 0;
      for (size_t i = 1; i < nc; ++i)
        if (cand[i].ratio < cand[weakest].ratio) weakest = i;
      if (cand[weakest].ratio < ratio) cand[weakest] = cd;
    }
  }
  return nc;
}

/* A tooth's half-width [Hz] (lines.h): a candidate within it of m f1, f1 a candidate's frequency over d, is on the
 * comb (the candidate's own error, half a bin of 1 / T, plus f1's carried to the m-th multiple, m / d of it). One rule
 * for the search, the fit through the matched harmonics and the lines left out. */
static double tooth_halfwidth(double m, int d, double T) { return (0.5 + 0.5 * m / d) / T; }

/* The comb that best explains the candidates (lines.h): each one on a tooth counts 1, each tooth in the range without
 * one costs 1/2 (a sub-harmonic comb f1 / j holds every line of f1 and chance candidates, but misses most of its
 * teeth); then the largest spacing. Its spacing (0 if none), its divisor and its count of candidates on a tooth. */
static double best_comb(const hm_lines_config *c, const candidate *cand, size_t nc, double T, double f_lo, double f_hi,
                        int *d_out, unsigned *count_out) {
  double best_f1 = 0.0, best_score = -INFINITY;
  unsigned best_count = 0;
  int best_d = 1;
  for (size_t i = 0; i < nc; ++i)
    for (int d = 1; d <= MAX_DIVISOR; ++d) {
      const double f1 = cand[i].f / d;
      if (f1 < c->min_fundamental_hz) break;
      unsigned count = 0;
      for (size_t j = 0; j < nc; ++j) {
        const double m = floor(cand[j].f / f1 + 0.5);
        if (m >= 1.0 && fabs(cand[j].f - m * f1) <= tooth_halfwidth(m, d, T)) ++count;
      }
      const double teeth = floor(f_hi / f1) - ceil(f_lo / f1) + 1.0;
      const double score = (double)count - 0.5 * fmax(0.0, teeth - (double)count);
      if (score > best_score || (score == best_score && f1 > best_f1))
        best_score = score, best_count = count, best_f1 = f1, best_d = d;
    }
  *d_out = best_d;
  *count_out = best_count;
  return best_f1;
}

/* The comb of spacing f1 into r: the least-squares spacing through the matched harmonics (f_j = m_j f1), its strongest
 * line, and every multiple in the range left out over its line's leakage (exclude); on_comb marks the candidates
 * matched. */
static void take_comb(hm_lines l, const candidate *cand, size_t nc, double f1_search, int d, double T, double f_hi,
                      double spread_rel, size_t n, double df, unsigned char *exclude, unsigned char *on_comb,
                      hm_lines_result *r) {
  double smf = 0.0, smm = 0.0;
  for (size_t j = 0; j < nc; ++j) {
    const double m = floor(cand[j].f / f1_search + 0.5);
    if (m >= 1.0 && fabs(cand[j].f - m * f1_search) <= tooth_halfwidth(m, d, T)) {
      on_comb[j] = 1;
      smf += m * cand[j].f, smm += m * m;
      if (cand[j].ratio > r->strongest_ratio) {
        r->strongest_ratio = cand[j].ratio;
        r->strongest_hz = cand[j].f;
        r->strongest_bin = cand[j].k;
      }
    }
  }
  const double f1 = smm > 0.0 ? smf / smm : f1_search;
  r->fundamental_hz = f1;
  /* every multiple in the range, over its line's leakage */
  for (double m = 1.0; m * f1 <= f_hi + l->cfg.background_halfwidth_hz; m += 1.0) {
    const double fm = m * f1;
    double ratio = 1.0;
    for (size_t j = 0; j < nc; ++j)
      if (fabs(cand[j].f - fm) <= tooth_halfwidth(m, d, T)) ratio = fmax(ratio, cand[j].ratio);
    r->bins_excluded += hm_lines_mark(l, fm, ratio, spread_rel, n, df, T, exclude);
  }
}

/* The candidates on no comb into r's lone lines, strongest first (a candidate taken is marked 2). */
static void take_lone(const candidate *cand, size_t nc, unsigned char *on_comb, hm_lines_result *r) {
  for (unsigned slot = 0; slot < HM_LINES_MAX_LONE; ++slot) {
    size_t best = nc;
    for (size_t j = 0; j < nc; ++j)
      if (!on_comb[j] && (best == nc || cand[j].ratio > cand[best].ratio)) best = j;
    if (best == nc) break;
    on_comb[best] = 2;
    r->lone_hz[slot] = cand[best].f;
    r->lone_ratio[slot] = cand[best].ratio;
    r->lone_bin[slot] = cand[best].k;
    r->n_lone = slot + 1;
  }
}

hm_status hm_lines_find(hm_lines l, const double *p, size_t n, double df, double T, double f_lo, double f_hi,
                        double spread_rel, unsigned char *exclude, hm_lines_result *out) {
  if (!l || !p || !exclude || !out || n == 0 || n > l->max_bins || !(df > 0.0) || !(T > 0.0)) return HM_EINVAL;
  const hm_lines_config *c = &l->cfg;
  hm_lines_result r;
  memset(&r, 0, sizeof r);
  memset(exclude, 0, n);
  const size_t h = (size_t)fmax(2.0, round(c->background_halfwidth_hz / df));
  size_t k_lo = (size_t)fmax(1.0, ceil(f_lo / df)), k_hi = (size_t)fmin((double)(n - 2), floor(f_hi / df));
  if (k_hi <= k_lo + 2) {
    *out = r;
    return HM_OK;
  }
  candidate cand[MAX_CANDIDATES];
  const size_t nc = find_candidates(l, p, n, df, T, k_lo, k_hi, h, cand, &r.candidates);
  unsigned best_count = 0;
  int best_d = 1;
  const double best_f1 = best_comb(c, cand, nc, T, f_lo, f_hi, &best_d, &best_count);
  /* where fewer whole multiples of the spacing fit in the range than min_harmonics, all of them (at least two) */
  const double best_teeth = best_f1 > 0.0 ? floor(f_hi / best_f1) - ceil(f_lo / best_f1) + 1.0 : 0.0;
  const unsigned needed = (unsigned)fmax(2.0, fmin((double)c->min_harmonics, best_teeth));
  r.found = best_count >= needed;
  unsigned char on_comb[MAX_CANDIDATES] = {0};
  if (r.found) {
    r.harmonics = best_count;
    take_comb(l, cand, nc, best_f1, best_d, T, f_hi, spread_rel, n, df, exclude, on_comb, &r);
  }
  take_lone(cand, nc, on_comb, &r);
  *out = r;
  return HM_OK;
}

/* D(d) = sum_{t<n} e^{-i d t} (d in rad per sample) as (re, im). */
static void dirichlet(double d, size_t n, double *dr, double *di) {
  const double h = 0.5 * d, s = sin(h);
  const double mag = fabs(s) < 1e-12 ? (double)n : sin((double)n * h) / s, ph = -h * (double)(n - 1);
  *dr = mag * cos(ph);
  *di = mag * sin(ph);
}

/* The line at frequency wl [rad per sample] fitted over bins k-m..k+m: its complex amplitude and the power it
 * explains (-1 if D vanishes there). */
static double line_at(const double *re, const double *im, size_t k, size_t m, size_t n, size_t nfft, double wl,
                      double *ar, double *ai) {
  double sxr = 0.0, sxi = 0.0, sdd = 0.0;
  for (size_t j = k - m; j <= k + m; ++j) {
    double dr, di;
    dirichlet(2.0 * HM_PI * (double)j / (double)nfft - wl, n, &dr, &di);
    sxr += re[j] * dr + im[j] * di; /* X conj(D) */
    sxi += im[j] * dr - re[j] * di;
    sdd += dr * dr + di * di;
  }
  if (!(sdd > 0.0)) return -1.0;
  *ar = sxr / sdd;
  *ai = sxi / sdd;
  return (sxr * sxr + sxi * sxi) / sdd;
}

hm_status hm_lines_fit_sinusoid(const double *re, const double *im, size_t nbins, size_t k, size_t n, size_t nfft,
                                hm_lines_sinusoid *out) {
  if (!re || !im || !out || n < 4 || nfft < n || k >= nbins) return HM_EINVAL;
  const size_t m = (size_t)ceil(3.0 * (double)nfft / (double)n); /* -+3 bins per 1 / T */
  if (k < m || k + m >= nbins) return HM_EINVAL;
  double total = 0.0;
  for (size_t j = k - m; j <= k + m; ++j) total += re[j] * re[j] + im[j] * im[j];
  /* the frequency: a grid of 1/20 of 1 / T over -+0.6 of it about the bin, then of 1/200 about the best point, then
   * the parabola through the best three (the subtraction of a line 40 dB above the continuum needs it to 1e-3) */
  const double unit = 2.0 * HM_PI * (double)nfft / (double)n / (double)nfft; /* 1 / T in rad per sample */
  const double w_bin = 2.0 * HM_PI * (double)k / (double)nfft;
  double best_w = w_bin, best = -1.0, ar, ai;
  for (int step = -12; step <= 12; ++step) {
    const double w = w_bin + 0.05 * step * unit, e = line_at(re, im, k, m, n, nfft, w, &ar, &ai);
    if (e > best) best = e, best_w = w;
  }
  const double h = 0.005 * unit;
  double ew[21];
  int ib = 0; /* the best so far among those computed (ew[10] is not yet when the first ten are compared) */
  for (int step = -10; step <= 10; ++step) {
    ew[step + 10] = line_at(re, im, k, m, n, nfft, best_w + step * h, &ar, &ai);
    if (ew[step + 10] > ew[ib]) ib = step + 10;
  }
  double w = best_w + (ib - 10) * h;
  if (ib > 0 && ib < 20) {
    const double den = ew[ib - 1] - 2.0 * ew[ib] + ew[ib + 1];
    if (den < 0.0) w += 0.5 * h * (ew[ib - 1] - ew[ib + 1]) / den;
  }
  const double explained = line_at(re, im, k, m, n, nfft, w, &ar, &ai);
  if (explained < 0.0) return HM_EINVAL;
  const double residual = total - explained, dof = 2.0 * (double)(2 * m + 1) - 2.0;
  out->omega = w;
  out->amp_re = ar;
  out->amp_im = ai;
  out->f_stat = residual > 0.0 ? (explained / 2.0) / (residual / dof) : INFINITY;
  return HM_OK;
}

void hm_lines_subtract(double *re, double *im, size_t k_lo, size_t k_hi, size_t n, size_t nfft,
                       const hm_lines_sinusoid *line) {
  if (!re || !im || !line || n == 0 || nfft == 0) return;
  for (size_t j = k_lo; j <= k_hi; ++j) {
    double dr, di;
    dirichlet(2.0 * HM_PI * (double)j / (double)nfft - line->omega, n, &dr, &di);
    re[j] -= line->amp_re * dr - line->amp_im * di; /* A D */
    im[j] -= line->amp_re * di + line->amp_im * dr;
  }
}
