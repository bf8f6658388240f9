/* Online identification of the hunting mode by a Whittle fit of the window's spectrum (see modal.h). */
#include "hunting_monitor/modal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "biquad.h"
#include "fft.h"
#include "hunting_monitor/lines.h"

enum { NP = 7 }; /* sigma, w0, c0, c1, c2, c3, ln N */
enum { P_SIGMA, P_W0, P_C0, P_C1, P_C2, P_C3, P_LN };

struct hm_modal_s {
  hm_modal_config cfg;
  double fs, fd;               /* input and decimated rates [Hz] */
  unsigned r, phase;           /* decimation factor, samples since the last kept one */
  hm_biquad hp, lp[2];
  double *ring;                /* decimated samples */
  size_t cap, n_win, head, n_in, since_fit;
  size_t min_n;                /* decimated samples in min_window_s (as many as arrive in it: rounded down) */
  double fit_every;            /* decimated samples between fits (fit_interval_s) */
  size_t nfft_max, nfft;
  double *re, *im, *cosw, *sinw; /* FFT work and twiddles (nfft_max / 2) */
  double *w, *pgram, *u;       /* band bins: angular frequency, periodogram, ln(w / w_ref) */
  double *power;               /* |X_k|^2 of every bin (the line search) */
  unsigned char *excluded;     /* the bins of a comb of lines */
  hm_lines lines;
  double theta[NP];
  int have_theta;
};

void hm_modal_config_default(hm_modal_config *c) {
  c->window_s = 40.0;
  c->min_window_s = 20.0;
  c->decimated_rate_hz = 100.0;
  c->band_low_hz = 6.0;
  c->band_high_hz = 22.0;
  c->fit_interval_s = 1.0;
  c->tol = 1e-10;
  c->max_iter = 80;
  hm_lines_config lc;
  hm_lines_config_default(&lc);
  c->reject_lines = 1;
  c->line_candidate_ratio = lc.candidate_ratio;
  c->line_min_fundamental_hz = lc.min_fundamental_hz;
  c->line_min_harmonics = lc.min_harmonics;
}

/* The line search's settings from the identification's. */
static hm_lines_config lines_config(const hm_modal_config *c) {
  hm_lines_config lc;
  hm_lines_config_default(&lc);
  lc.candidate_ratio = c->line_candidate_ratio;
  lc.min_fundamental_hz = c->line_min_fundamental_hz;
  lc.min_harmonics = c->line_min_harmonics;
  return lc;
}

static hm_status bad(char *why, size_t len, const char *field, const char *reason, double got) {
  if (why && len) snprintf(why, len, "%s: %s (got %g)", field, reason, got);
  return HM_EDOMAIN;
}

hm_status hm_modal_config_validate(const hm_modal_config *c, char *why, size_t len) {
  if (!c) return HM_EINVAL;
  if (!(c->window_s >= 5.0 && c->window_s <= 300.0)) return bad(why, len, "window_s", "must be in 5..300", c->window_s);
  if (!(c->min_window_s >= 2.0 && c->min_window_s <= c->window_s))
    return bad(why, len, "min_window_s", "must be in 2..window_s", c->min_window_s);
  if (!(c->decimated_rate_hz >= 20.0 && c->decimated_rate_hz <= 1000.0))
    return bad(why, len, "decimated_rate_hz", "must be in 20..1000", c->decimated_rate_hz);
  if (!(c->band_low_hz > 2.0)) return bad(why, len, "band_low_hz", "must be above 2 Hz (the high-pass)", c->band_low_hz);
  if (!(c->band_high_hz > c->band_low_hz + 2.0 && c->band_high_hz <= 0.4 * c->decimated_rate_hz))
    return bad(why, len, "band_high_hz", "must be 2 Hz above band_low_hz and at most 0.4 decimated_rate_hz",
               c->band_high_hz);
  if (!(c->fit_interval_s >= 0.01 && c->fit_interval_s <= c->window_s))
    return bad(why, len, "fit_interval_s", "must be in 0.01..window_s", c->fit_interval_s);
  if (!(c->tol > 0.0 && c->tol < 1e-2)) return bad(why, len, "tol", "must be in (0, 0.01)", c->tol);
  if (c->max_iter < 1 || c->max_iter > 10000) return bad(why, len, "max_iter", "must be 1..10000", c->max_iter);
  if (c->reject_lines != 0 && c->reject_lines != 1) return bad(why, len, "reject_lines", "must be 0 or 1", c->reject_lines);
  const hm_lines_config lc = lines_config(c);
  char tmp[160] = "";
  if (hm_lines_config_validate(&lc, tmp, sizeof tmp) != HM_OK) {
    if (why && len) snprintf(why, len, "line_%s", tmp);
    return HM_EDOMAIN;
  }
  return HM_OK;
}

static size_t pow2_at_least(double n) {
  size_t p = 1;
  while ((double)p < n) p <<= 1;
  return p;
}

/* Decimation for an input rate: the largest factor keeping the decimated rate at or above the target (so it is in
 * [target, 2 target) when the input is faster than the target). */
static int rate_plan(const hm_modal_config *c, double fs, unsigned *r, double *fd) {
  if (!(fs >= 100.0 && fs <= 5000.0) || fs < c->decimated_rate_hz) return 0;
  *r = (unsigned)floor(fs / c->decimated_rate_hz);
  *fd = fs / (double)*r;
  return 1;
}

static void apply_rate(hm_modal m, double fs, unsigned r, double fd) {
  m->fs = fs;
  m->r = r;
  m->fd = fd;
  m->hp = hm_biquad_design(1, 2.0, HM_BUTTERWORTH_Q2, fs);
  m->lp[0] = hm_biquad_design(0, 0.3 * fd, HM_BUTTERWORTH_Q4[0], fs);
  m->lp[1] = hm_biquad_design(0, 0.3 * fd, HM_BUTTERWORTH_Q4[1], fs);
  m->n_win = (size_t)ceil(m->cfg.window_s * fd);
  if (m->n_win > m->cap) m->n_win = m->cap;
  m->nfft = pow2_at_least((double)m->n_win);
  m->min_n = (size_t)floor(m->cfg.min_window_s * fd + 1e-6);
  m->fit_every = m->cfg.fit_interval_s * fd;
  hm_modal_reset(m);
}

hm_status hm_modal_create(const hm_modal_config *cfg, double fs, hm_modal *out, char *why, size_t len) {
  if (!cfg || !out) return HM_EINVAL;
  hm_status st = hm_modal_config_validate(cfg, why, len);
  if (st != HM_OK) return st;
  unsigned r;
  double fd;
  if (!rate_plan(cfg, fs, &r, &fd)) return bad(why, len, "sample_rate_hz", "must be in 100..5000 and above decimated_rate_hz", fs);
  hm_modal m = calloc(1, sizeof *m);
  if (!m) return HM_ENOMEM;
  m->cfg = *cfg;
  m->cap = (size_t)ceil(cfg->window_s * 2.0 * cfg->decimated_rate_hz);
  m->nfft_max = pow2_at_least((double)m->cap);
  m->ring = malloc(m->cap * sizeof(double));
  m->re = malloc(m->nfft_max * sizeof(double));
  m->im = malloc(m->nfft_max * sizeof(double));
  m->cosw = malloc(m->nfft_max / 2 * sizeof(double));
  m->sinw = malloc(m->nfft_max / 2 * sizeof(double));
  m->w = malloc((m->nfft_max / 2 + 1) * sizeof(double));
  m->pgram = malloc((m->nfft_max / 2 + 1) * sizeof(double));
  m->u = malloc((m->nfft_max / 2 + 1) * sizeof(double));
  m->power = malloc((m->nfft_max / 2 + 1) * sizeof(double));
  m->excluded = malloc(m->nfft_max / 2 + 1);
  const hm_lines_config lc = lines_config(cfg);
  if (!m->ring || !m->re || !m->im || !m->cosw || !m->sinw || !m->w || !m->pgram || !m->u || !m->power ||
      !m->excluded || hm_lines_create(&lc, m->nfft_max / 2 + 1, &m->lines, NULL, 0) != HM_OK) {
    hm_modal_destroy(m);
    return HM_ENOMEM;
  }
  hm_fft_twiddles(m->cosw, m->sinw, m->nfft_max);
  apply_rate(m, fs, r, fd);
  *out = m;
  return HM_OK;
}

void hm_modal_destroy(hm_modal m) {
  if (!m) return;
  free(m->ring);
  free(m->re);
  free(m->im);
  free(m->cosw);
  free(m->sinw);
  free(m->w);
  free(m->pgram);
  free(m->u);
  free(m->power);
  free(m->excluded);
  hm_lines_destroy(m->lines);
  free(m);
}

void hm_modal_reset(hm_modal m) {
  if (!m) return;
  hm_biquad_clear(&m->hp);
  hm_biquad_clear(&m->lp[0]);
  hm_biquad_clear(&m->lp[1]);
  m->phase = 0;
  m->head = m->n_in = m->since_fit = 0;
  m->have_theta = 0;
}

hm_status hm_modal_set_rate(hm_modal m, double fs) {
  if (!m) return HM_EINVAL;
  unsigned r;
  double fd;
  if (!rate_plan(&m->cfg, fs, &r, &fd)) return HM_EDOMAIN;
  apply_rate(m, fs, r, fd);
  return HM_OK;
}

void hm_modal_push(hm_modal m, double a) {
  double x = hm_biquad_step(&m->hp, a);
  x = hm_biquad_step(&m->lp[0], x);
  x = hm_biquad_step(&m->lp[1], x);
  if (++m->phase < m->r) return;
  m->phase = 0;
  m->ring[m->head] = x;
  m->head = (m->head + 1) % m->n_win;
  if (m->n_in < m->n_win) ++m->n_in;
  ++m->since_fit;
}

int hm_modal_fit_due(const hm_modal m) {
  return m && m->n_in >= m->min_n && (double)m->since_fit >= m->fit_every;
}

/* S_k (its gradient of ln S_k in grad, if not NULL) for bin k; n = exp(th[P_LN]), the noise level (one exp per pass). */
static double spectrum(const double *th, double n, double w, double u, double *grad) {
  const double sg = th[P_SIGMA], w0 = th[P_W0];
  const double re = sg * sg + w0 * w0 - w * w, d = re * re + 4.0 * sg * sg * w * w;
  const double b = exp(th[P_C0] + u * (th[P_C1] + u * (th[P_C2] + u * th[P_C3])));
  const double mode = b / d, s = mode + n;
  if (grad) {
    const double dd_sg = 4.0 * re * sg + 8.0 * sg * w * w, dd_w0 = 4.0 * re * w0, ms = mode / s;
    grad[P_SIGMA] = -ms / d * dd_sg;
    grad[P_W0] = -ms / d * dd_w0;
    grad[P_C0] = ms;
    grad[P_C1] = ms * u;
    grad[P_C2] = ms * u * u;
    grad[P_C3] = ms * u * u * u;
    grad[P_LN] = n / s;
  }
  return s;
}

/* The negative Whittle log-likelihood over the band's nb bins at th and, when f is not NULL, the Fisher information
 * J'J in f and the score J'(I/S - 1) in g there: one pass, one exp and one log a bin. */
static double evaluate(const hm_modal m, size_t nb, const double *th, double f[NP][NP], double *g) {
  double l = 0.0;
  const double noise = exp(th[P_LN]);
  if (f) {
    memset(f, 0, sizeof(double) * NP * NP);
    memset(g, 0, sizeof(double) * NP);
  }
  for (size_t k = 0; k < nb; ++k) {
    double j[NP];
    const double sk = spectrum(th, noise, m->w[k], m->u[k], f ? j : NULL), q = m->pgram[k] / sk;
    l += log(sk) + q;
    if (!f) continue;
    for (int a = 0; a < NP; ++a) {
      g[a] += j[a] * (q - 1.0);
      for (int b = 0; b <= a; ++b) f[a][b] += j[a] * j[b];
    }
  }
  if (f)
    for (int a = 0; a < NP; ++a)
      for (int b = a + 1; b < NP; ++b) f[a][b] = f[b][a];
  return l;
}

/* Cholesky solve of the NP x NP system a x = b (a overwritten); 0 if not positive definite. */
static int chol_solve(double a[NP][NP], double *b) {
  for (int j = 0; j < NP; ++j) {
    double d = a[j][j];
    for (int k = 0; k < j; ++k) d -= a[j][k] * a[j][k];
    if (!(d > 0.0)) return 0;
    a[j][j] = sqrt(d);
    for (int i = j + 1; i < NP; ++i) {
      double s = a[i][j];
      for (int k = 0; k < j; ++k) s -= a[i][k] * a[j][k];
      a[i][j] = s / a[j][j];
    }
  }
  for (int i = 0; i < NP; ++i) {
    double s = b[i];
    for (int k = 0; k < i; ++k) s -= a[i][k] * b[k];
    b[i] = s / a[i][i];
  }
  for (int i = NP - 1; i >= 0; --i) {
    double s = b[i];
    for (int k = i + 1; k < NP; ++k) s -= a[k][i] * b[k];
    b[i] = s / a[i][i];
  }
  return 1;
}

/* Levenberg-damped Fisher scoring from th (updated in place); the final objective in *obj, its Fisher information in
 * fisher, steps in *iters. 1 if converged (relative objective change below tol on an accepted step), 0 otherwise.
 * A step that raises the objective by less than tol (relative) ends it too: th is at the optimum to the tolerance. */
static int score(const hm_modal m, size_t nb, double *th, double *obj, unsigned *iters, double fisher[NP][NP]) {
  double f[NP][NP], g[NP];
  double l = evaluate(m, nb, th, f, g), mu = 1e-3;
  int converged = 0;
  for (unsigned it = 0; it < m->cfg.max_iter && !converged; ++it) {
    int accepted = 0;
    for (int tries = 0; tries < 30 && !accepted && !converged; ++tries) {
      double a[NP][NP], step[NP], trial[NP], ft[NP][NP], gt[NP];
      memcpy(a, f, sizeof a);
      memcpy(step, g, sizeof step);
      for (int i = 0; i < NP; ++i) a[i][i] += mu * f[i][i] + 1e-12;
      if (!chol_solve(a, step)) {
        mu *= 10.0;
        continue;
      }
      for (int i = 0; i < NP; ++i) trial[i] = th[i] + step[i];
      trial[P_LN] = fmax(trial[P_LN], -60.0); /* a floor far below any signal: the noise may be absent */
      /* the first try is usually taken: its scoring system comes in the same pass; after a refusal only the
       * objective, and the scoring system once a try is taken */
      const double lt = evaluate(m, nb, trial, tries == 0 ? ft : NULL, gt);
      if (isfinite(lt) && lt <= l) {
        const double change = (l - lt) / (fabs(l) + 1.0);
        if (tries > 0) evaluate(m, nb, trial, ft, gt);
        memcpy(th, trial, sizeof trial);
        memcpy(f, ft, sizeof f);
        memcpy(g, gt, sizeof g);
        l = lt;
        mu = fmax(mu * 0.3, 1e-9);
        *iters = it + 1;
        accepted = 1;
        converged = change < m->cfg.tol;
        continue;
      }
      if (isfinite(lt) && (lt - l) / (fabs(l) + 1.0) < m->cfg.tol) { /* at the optimum to the tolerance: a step
                                                                         that changes nothing but rounding */
        *iters = it + 1;
        converged = 1;
        continue;
      }
      mu *= 10.0;
      if (mu > 1e12) { /* no descent direction left: a stationary point */
        *iters = it + 1;
        converged = 1;
      }
    }
  }
  *obj = l;
  memcpy(fisher, f, sizeof f);
  return converged;
}

/* A cold start: the smoothed periodogram's peak, a given decay rate, a flat background, a low noise floor. */
static void cold_start(const hm_modal m, size_t nb, double sigma0, double *th) {
  const size_t h = (size_t)fmax(1.0, round(0.1 / (m->fd / (double)m->nfft))); /* 0.1 Hz half-width */
  double best = -1.0, lo = INFINITY;
  size_t kbest = nb / 2;
  for (size_t k = 0; k < nb; ++k) {
    double s = 0.0;
    size_t n = 0;
    for (size_t j = k >= h ? k - h : 0; j <= k + h && j < nb; ++j, ++n) s += m->pgram[j];
    s /= (double)n;
    if (s > best) best = s, kbest = k;
    if (s < lo) lo = s;
  }
  const double w0 = m->w[kbest];
  th[P_SIGMA] = sigma0;
  th[P_W0] = w0;
  th[P_C0] = log(fmax(best - 0.5 * lo, 1e-300) * 4.0 * sigma0 * sigma0 * w0 * w0);
  th[P_C1] = th[P_C2] = th[P_C3] = 0.0;
  th[P_LN] = log(fmax(0.5 * lo, 1e-300));
}

hm_status hm_modal_fit(hm_modal m, double max_window_s, hm_mode_estimate *out) {
  if (!m || !out || !(max_window_s > 0.0)) return HM_EINVAL;
  m->since_fit = 0;
  hm_mode_estimate r;
  memset(&r, 0, sizeof r);
  const size_t n = (size_t)fmin((double)m->n_in, floor(max_window_s * m->fd + 1e-6));
  r.window_s = (double)n / m->fd;
  if (n < m->min_n) {
    *out = r;
    return HM_OK;
  }
  /* the newest n samples, oldest first, without their mean, zero-padded */
  const size_t oldest = (m->head + m->n_win - n) % m->n_win;
  double mean = 0.0;
  for (size_t k = 0; k < n; ++k) mean += m->ring[(oldest + k) % m->n_win];
  mean /= (double)n;
  for (size_t k = 0; k < m->nfft; ++k) m->re[k] = k < n ? m->ring[(oldest + k) % m->n_win] - mean : 0.0;
  hm_fft_real(m->re, m->im, m->nfft, m->cosw, m->sinw, m->nfft_max);
  const double df = m->fd / (double)m->nfft, w_ref = 2.0 * HM_PI * 0.5 * (m->cfg.band_low_hz + m->cfg.band_high_hz);
  /* a comb of lines (a periodic excitation of the track) over the decimated signal's band */
  const size_t nbins = m->nfft / 2 + 1;
  for (size_t k = 0; k < nbins; ++k) m->power[k] = m->re[k] * m->re[k] + m->im[k] * m->im[k];
  hm_lines_result lr;
  if (hm_lines_find(m->lines, m->power, nbins, df, r.window_s, 2.5, 0.3 * m->fd, m->excluded, &lr) != HM_OK)
    memset(&lr, 0, sizeof lr);
  const int drop = m->cfg.reject_lines && lr.found;
  r.lines_found = lr.found;
  r.line_fundamental_hz = lr.fundamental_hz;
  r.line_harmonics = lr.harmonics;
  r.line_strongest_hz = lr.strongest_hz;
  /* a sinusoid of amplitude A over n samples has |X| = A n / 2 at its bin */
  r.line_strongest_mps2 = lr.found ? 2.0 * sqrt(m->power[lr.strongest_bin]) / (double)n : 0.0;
  /* the band's bins (less a comb's), the periodogram scaled to mean 1 (the fit is scale-free; it keeps exp() in
   * range) */
  size_t nb = 0, n_band = 0;
  double scale = 0.0;
  for (size_t k = (size_t)ceil(m->cfg.band_low_hz / df); (double)k * df <= m->cfg.band_high_hz && k <= m->nfft / 2; ++k) {
    ++n_band;
    if (drop && m->excluded[k]) continue;
    m->w[nb] = 2.0 * HM_PI * (double)k * df;
    m->u[nb] = log(m->w[nb] / w_ref);
    m->pgram[nb] = m->re[k] * m->re[k] + m->im[k] * m->im[k];
    scale += m->pgram[nb++];
  }
  r.band_excluded_fraction = n_band ? 1.0 - (double)nb / (double)n_band : 0.0;
  scale /= (double)nb;
  if (!(scale > 0.0) || nb < 4 * NP) {
    *out = r;
    return HM_OK;
  }
  for (size_t k = 0; k < nb; ++k) m->pgram[k] /= scale;
  /* warm start from the last fit, and cold starts at two decay rates; the best likelihood wins */
  double best[NP], best_f[NP][NP], best_obj = INFINITY;
  int found = 0;
  unsigned iters = 0;
  for (int start = m->have_theta ? 0 : 1; start < 3; ++start) {
    double th[NP], obj, fisher[NP][NP];
    unsigned it = 0;
    if (start == 0) {
      memcpy(th, m->theta, sizeof th);
    } else {
      cold_start(m, nb, start == 1 ? -0.7 : -4.0, th);
    }
    const int ok = score(m, nb, th, &obj, &it, fisher);
    iters += it;
    if (ok && obj < best_obj) {
      memcpy(best, th, sizeof best);
      memcpy(best_f, fisher, sizeof best_f);
      best_obj = obj;
      found = 1;
    }
    if (start == 0 && ok) break; /* a converged warm start is enough */
  }
  if (!found) {
    m->have_theta = 0;
    return HM_ENOCONV;
  }
  memcpy(m->theta, best, sizeof best);
  m->have_theta = 1;
  /* standard errors from Whittle's covariance (J'J)^-1, for the n independent ordinates of nfft padded ones */
  double var[NP];
  const double padding = (double)m->nfft / (double)n;
  for (int i = 0; i < NP; ++i) {
    double a[NP][NP], e[NP] = {0};
    memcpy(a, best_f, sizeof a);
    e[i] = 1.0;
    var[i] = chol_solve(a, e) ? e[i] * padding : INFINITY;
  }
  const double sg = -fabs(best[P_SIGMA]), w0 = fabs(best[P_W0]), mag = sqrt(sg * sg + w0 * w0);
  r.frequency_hz = w0 / (2.0 * HM_PI);
  r.frequency_se_hz = sqrt(var[P_W0]) / (2.0 * HM_PI);
  r.decay_rate_1_s = sg;
  r.decay_rate_se_1_s = sqrt(var[P_SIGMA]);
  r.damping_ratio = -sg / mag;
  /* d zeta / d sigma = w0^2 / |s|^3 (w0's share of the error is second order for light damping) */
  r.damping_ratio_se = r.decay_rate_se_1_s * w0 * w0 / (mag * mag * mag);
  const double uw = log(w0 / w_ref);
  const double peak = exp(best[P_C0] + best[P_C1] * uw + best[P_C2] * uw * uw + best[P_C3] * uw * uw * uw) /
                      (4.0 * sg * sg * w0 * w0);
  r.peak_to_mean = peak; /* the periodogram is scaled to mean 1 over the band */
  r.iterations = iters;
  const double margin_hz = 3.0 * r.frequency_se_hz + 2.0 * df;
  r.valid = isfinite(r.decay_rate_se_1_s) && isfinite(r.frequency_se_hz) &&
            r.frequency_hz > m->cfg.band_low_hz + margin_hz && r.frequency_hz < m->cfg.band_high_hz - margin_hz &&
            r.damping_ratio < 0.5 && r.peak_to_mean > 3.0;
  *out = r;
  return HM_OK;
}
