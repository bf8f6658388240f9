/* Online identification of the hunting mode by a Whittle fit of the window's spectrum (see modal.h). */
#include "hunting_monitor/modal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "biquad.h"
#include "envelope.h"
#include "fft.h"
#include "hunting_monitor/lines.h"
#include "hunting_monitor/order_lines.h"
#include "whittle.h"
#include "validate.h"

enum { NPM = HM_WHITTLE_MAX_NP };
/* The two-pair fit: at most this many scoring steps (a second pair that needs more is not there), the one pair's
 * split starts tried every this many fits besides the warm start, and converged at this relative change of the
 * objective (the choice by likelihood ratio needs no more). */
enum { HM_MODAL_MAX_ITER2 = 25, HM_MODAL_SCREEN_ITER2 = 8, HM_MODAL_SPLIT_EVERY = 5 };
#define HM_MODAL_TOL2 1e-7
#define HM_MODAL_WARM2_MIN_LR (0.5 * HM_MODAL_TWO_PAIR_LR_WEAK)

/* The warm start of one kind of reading (the window's, and the one with its lone lines left out). */
typedef struct {
  double th1[NPM], th2[NPM];
  int have1, have2;
  unsigned since_split;        /* fits since the two-pair fit last tried the one pair's split starts */
} warm_start;

struct hm_modal_s {
  hm_modal_config cfg;
  double fs, fd;               /* input and decimated rates [Hz] */
  unsigned r, phase;           /* decimation factor, samples since the last kept one */
  hm_biquad hp, lp[2];
  double *ring;                /* decimated samples */
  double *speed;               /* the speed [m/s] at each (NAN: unknown) */
  double v_now;                /* the latest speed given (hm_modal_set_speed) [m/s] */
  double *x, *xv;              /* a fit's window, oldest first, and its speeds: the periodograms' input */
  size_t x_len;
  hm_order_lines order;        /* track lines in distance (order_lines.h) */
  double order_hz[HM_ORDER_LINES_MAX]; /* those the fit's window gave [Hz] */
  unsigned n_order;
  double order_comb_hz;        /* and the spacing of a comb found in distance [Hz] (0: none) */
  size_t cap, n_win, head, n_in, since_fit;
  size_t min_n;                /* decimated samples in min_window_s (as many as arrive in it: rounded down) */
  double fit_every;            /* decimated samples between fits (fit_interval_s) */
  size_t nfft_max, nfft;
  double *re, *im, *cosw, *sinw; /* FFT work and twiddles (nfft_max / 2) */
  double *w, *pgram, *u;       /* the bins of the reading being fitted: angular frequency, periodogram, ln(w / w_ref) */
  double *power;               /* |X_k|^2 of every bin (the line search) */
  unsigned char *excluded;     /* the bins of a comb of lines; after it, those set aside before a narrow peak's */
  unsigned char *set_aside;    /* the comb's and the lone lines' */
  double *spec;                /* the last fit's window: its periodogram (power), the bins set aside for lines, */
  unsigned char *spec_mask;    /* its samples and FFT length (hm_modal_window_spectrum; spec_n 0: none kept) */
  size_t spec_n, spec_nfft;
  double *env_work;            /* the narrow peak's envelope (envelope.h) */
  size_t env_work_len;
  hm_lines lines;
  warm_start warm[3];          /* the window's reading, the line reading, the line reading without the skirt */
};

void hm_modal_config_default(hm_modal_config *c) {
  c->window_s = 40.0;
  c->min_window_s = 20.0;
  c->decimated_rate_hz = 100.0;
  c->band_low_hz = 6.0;
  c->band_high_hz = 22.0;
  c->fit_interval_s = 1.0;
  c->tol = 1e-7;
  c->max_iter = 80;
  hm_lines_config lc;
  hm_lines_config_default(&lc);
  c->reject_lines = 1;
  c->line_candidate_ratio = lc.candidate_ratio;
  c->line_min_fundamental_hz = lc.min_fundamental_hz;
  c->line_min_harmonics = lc.min_harmonics;
  c->min_peak_prominence = 0.0;
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

hm_status hm_modal_config_validate(const hm_modal_config *c, char *why, size_t len) {
  if (!c) return HM_EINVAL;
  const hm_field_check f[] = {{"window_s", c->window_s, HM_RULE_RANGE, 5.0, 300.0},
                              {"decimated_rate_hz", c->decimated_rate_hz, HM_RULE_RANGE, 20.0, 1000.0},
                              {"band_low_hz", c->band_low_hz, HM_RULE_RANGE_OPEN, 2.0, 500.0},
                              {"tol", c->tol, HM_RULE_OPEN, 0.0, 1e-2},
                              {"max_iter", (double)c->max_iter, HM_RULE_RANGE, 1.0, 10000.0},
                              {"reject_lines", (double)c->reject_lines, HM_RULE_FLAG, 0.0, 0.0},
                              /* (about 1 holds any hump: no test) */
                              {"min_peak_prominence", c->min_peak_prominence, HM_RULE_OFF_OR_RANGE, 2.0, 100.0}};
  const hm_status st = hm_check_fields(f, HM_COUNT_OF(f), why, len);
  if (st != HM_OK) return st;
  if (!(c->min_window_s >= 2.0 && c->min_window_s <= c->window_s))
    return hm_reject(why, len, "min_window_s", "must be in [2, window_s]", c->min_window_s);
  if (!(c->band_high_hz > c->band_low_hz + 2.0 && c->band_high_hz <= 0.4 * c->decimated_rate_hz))
    return hm_reject(why, len, "band_high_hz", "must be 2 Hz above band_low_hz and at most 0.4 decimated_rate_hz",
                     c->band_high_hz);
  if (!(c->fit_interval_s >= 0.01 && c->fit_interval_s <= c->window_s))
    return hm_reject(why, len, "fit_interval_s", "must be in [0.01, window_s]", c->fit_interval_s);
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

double hm_modal_filter_power_gain(const void *modal, double f_hz) {
  const hm_modal m = (const hm_modal)modal;
  if (!m || !(f_hz >= 0.0) || !isfinite(f_hz)) return NAN;
  const double th = 2.0 * HM_PI * f_hz / m->fs;
  const double g = hm_biquad_gain(&m->hp, th) * hm_biquad_gain(&m->lp[0], th) * hm_biquad_gain(&m->lp[1], th);
  return g * g;
}

hm_status hm_modal_window_spectrum(const hm_modal m, double low_hz, double high_hz, double *f_hz, double *psd,
                                   size_t cap, size_t *n, double *dof, double *window_s) {
  if (!m || !f_hz || !psd || !n || !dof || !window_s) return HM_EINVAL;
  if (!(low_hz > 0.0) || !(high_hz > low_hz) || !(high_hz < 0.5 * m->fd)) return HM_EDOMAIN;
  if (m->spec_n == 0) return HM_ENOCONV;
  const double df = m->fd / (double)m->spec_nfft, norm = (double)m->spec_n * m->fd;
  size_t nb = 0;
  for (int write = 0; write < 2; ++write) { /* counted first: the outputs untouched on a failure */
    nb = 0;
    for (size_t k = (size_t)ceil(low_hz / df); (double)k * df <= high_hz && k <= m->spec_nfft / 2; ++k) {
      const double f = (double)k * df, gain = hm_modal_filter_power_gain(m, f);
      if (m->spec_mask[k] || !(gain >= HM_MODAL_SPECTRUM_MIN_GAIN) || !(m->spec[k] > 0.0)) continue;
      if (write) f_hz[nb] = f, psd[nb] = m->spec[k] / norm / gain;
      ++nb;
    }
    if (nb < 8) return HM_ENOCONV;
    if (nb > cap) return HM_EDOMAIN;
  }
  *n = nb;
  *dof = 2.0 * (double)m->spec_n / (double)m->spec_nfft;
  *window_s = (double)m->spec_n / m->fd;
  return HM_OK;
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
  if (!rate_plan(cfg, fs, &r, &fd))
    return hm_reject(why, len, "sample_rate_hz", "must be in [100, 5000] and above decimated_rate_hz", fs);
  hm_modal m = calloc(1, sizeof *m);
  if (!m) return HM_ENOMEM;
  m->cfg = *cfg;
  m->cap = (size_t)ceil(cfg->window_s * 2.0 * cfg->decimated_rate_hz);
  m->nfft_max = pow2_at_least((double)m->cap);
  m->ring = malloc(m->cap * sizeof(double));
  m->speed = malloc(m->cap * sizeof(double));
  m->v_now = NAN;
  m->x = malloc(m->cap * sizeof(double));
  m->xv = malloc(m->cap * sizeof(double));
  m->re = malloc(m->nfft_max * sizeof(double));
  m->im = malloc(m->nfft_max * sizeof(double));
  m->cosw = malloc(m->nfft_max / 2 * sizeof(double));
  m->sinw = malloc(m->nfft_max / 2 * sizeof(double));
  m->w = malloc((m->nfft_max / 2 + 1) * sizeof(double));
  m->pgram = malloc((m->nfft_max / 2 + 1) * sizeof(double));
  m->u = malloc((m->nfft_max / 2 + 1) * sizeof(double));
  m->power = malloc((m->nfft_max / 2 + 1) * sizeof(double));
  m->excluded = malloc(m->nfft_max / 2 + 1);
  m->set_aside = malloc(m->nfft_max / 2 + 1);
  m->spec = malloc((m->nfft_max / 2 + 1) * sizeof(double));
  m->spec_mask = malloc(m->nfft_max / 2 + 1);
  /* (the decimated rate is below twice the one asked for: rate_plan) */
  m->env_work_len = hm_envelope_work_size(m->cap, 2.0 * cfg->decimated_rate_hz, HM_MODAL_ENVELOPE_BAND_HZ);
  m->env_work = malloc(m->env_work_len * sizeof(double));
  const hm_lines_config lc = lines_config(cfg);
  hm_order_lines_config oc;
  hm_order_lines_config_default(&oc);
  if (!m->ring || !m->speed || !m->x || !m->xv || !m->re || !m->im || !m->cosw || !m->sinw || !m->w || !m->pgram ||
      !m->u || !m->power || !m->excluded || !m->set_aside || !m->spec || !m->spec_mask || !m->env_work ||
      hm_lines_create(&lc, m->nfft_max / 2 + 1, &m->lines, NULL, 0) != HM_OK ||
      hm_order_lines_create(&oc, &lc, m->cap, m->nfft_max, &m->order, NULL, 0) != HM_OK) {
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
  free(m->speed);
  free(m->x);
  free(m->xv);
  hm_order_lines_destroy(m->order);
  free(m->re);
  free(m->im);
  free(m->cosw);
  free(m->sinw);
  free(m->w);
  free(m->pgram);
  free(m->u);
  free(m->power);
  free(m->excluded);
  free(m->spec);
  free(m->spec_mask);
  free(m->set_aside);
  free(m->env_work);
  hm_lines_destroy(m->lines);
  free(m);
}

void hm_modal_reset(hm_modal m) {
  if (!m) return;
  hm_biquad_clear(&m->hp);
  hm_biquad_clear(&m->lp[0]);
  hm_biquad_clear(&m->lp[1]);
  m->phase = 0;
  m->head = m->n_in = m->since_fit = 0; /* (v_now is the caller's: kept) */
  m->spec_n = 0;
  for (int k = 0; k < 3; ++k) {
    m->warm[k].have1 = m->warm[k].have2 = 0;
    m->warm[k].since_split = HM_MODAL_SPLIT_EVERY - 1; /* the first fit tries the splits */
  }
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
  m->speed[m->head] = m->v_now;
  m->head = (m->head + 1) % m->n_win;
  if (m->n_in < m->n_win) ++m->n_in;
  ++m->since_fit;
}

void hm_modal_set_speed(hm_modal m, double v_mps) {
  if (m) m->v_now = isfinite(v_mps) && v_mps > 0.0 ? v_mps : NAN;
}

int hm_modal_fit_due(const hm_modal m) {
  return m && m->n_in >= m->min_n && (double)m->since_fit >= m->fit_every;
}


const hm_mode_reading *hm_mode_estimate_beside_line(const hm_mode_estimate *e) {
  return e->narrow_peak_tracked ? &e->line_reading_wide : &e->line_reading;
}

void hm_mode_estimate_use_reading(hm_mode_estimate *e, const hm_mode_reading *r) {
  if (!e || !r) return;
  e->valid = r->valid;
  e->informative = r->informative;
  e->frequency_hz = r->frequency_hz;
  e->frequency_se_hz = r->frequency_se_hz;
  e->decay_rate_1_s = r->decay_rate_1_s;
  e->decay_rate_se_1_s = r->decay_rate_se_1_s;
  e->damping_ratio = r->damping_ratio;
  e->damping_ratio_se = r->damping_ratio_se;
  e->peak_to_mean = r->peak_to_mean;
  e->peak_prominence = r->peak_prominence;
  e->poles = r->poles;
  e->second_frequency_hz = r->second_frequency_hz;
  e->second_decay_rate_1_s = r->second_decay_rate_1_s;
  e->two_pair_lr = r->two_pair_lr;
  e->decay_rate_alt_1_s = r->decay_rate_alt_1_s;
  e->peak_core_z = r->peak_core_z;
  e->iterations = r->iterations;
}

void hm_mode_estimate_reading(const hm_mode_estimate *e, hm_mode_reading *r) {
  if (!e || !r) return;
  memset(r, 0, sizeof *r);
  r->valid = e->valid;
  r->informative = e->informative;
  r->frequency_hz = e->frequency_hz;
  r->frequency_se_hz = e->frequency_se_hz;
  r->decay_rate_1_s = e->decay_rate_1_s;
  r->decay_rate_se_1_s = e->decay_rate_se_1_s;
  r->damping_ratio = e->damping_ratio;
  r->damping_ratio_se = e->damping_ratio_se;
  r->peak_to_mean = e->peak_to_mean;
  r->peak_prominence = e->peak_prominence;
  r->poles = e->poles;
  r->second_frequency_hz = e->second_frequency_hz;
  r->second_decay_rate_1_s = e->second_decay_rate_1_s;
  r->two_pair_lr = e->two_pair_lr;
  r->decay_rate_alt_1_s = e->decay_rate_alt_1_s;
  r->peak_core_z = e->peak_core_z;
  r->iterations = e->iterations;
}

/* One window's geometry: its band bins k0..k1, bin spacing, length, the periodogram's reference frequency, the
 * padding's factor nfft / n and the speed's relative range. */
typedef struct {
  size_t k0, k1;
  double df, T, w_ref, padding;
  double spread_rel; /* the window's speed range over its mean: a track line moves over that share of its frequency */
} window_geometry;

/* The band's bins not marked in mask (NULL: all) into m->w, u, pgram, scaled to mean 1 (*scale the factor); their
 * count. */
static size_t load_bins(hm_modal m, const window_geometry *g, const unsigned char *mask, double *scale) {
  size_t nb = 0;
  double sum = 0.0;
  for (size_t k = g->k0; k <= g->k1; ++k) {
    if (mask && mask[k]) continue;
    m->w[nb] = 2.0 * HM_PI * (double)k * g->df;
    m->u[nb] = log(m->w[nb] / g->w_ref);
    m->pgram[nb] = m->power[k];
    sum += m->pgram[nb++];
  }
  *scale = nb ? sum / (double)nb : 0.0;
  if (!(*scale > 0.0)) return 0;
  for (size_t k = 0; k < nb; ++k) m->pgram[k] /= *scale;
  return nb;
}

/* The fitted spectrum's prominence at the mode's w0: S(w0) over the larger of S's least values below and above it
 * over the fitted bins; 1 where either side holds none, or where S rises again towards that side's edge (above
 * HM_MODAL_PROMINENCE_EDGE_REL times its least value there: another resonance beyond the dip, a wheelset's 14 Hz mode
 * beside a frame's 8 Hz one, on which the pair reads the mode lighter damped). A resonance stands above its band on
 * both sides however much of the band it fills; a rising or falling spectrum (1/f^2 noise, a slope, a pair at the
 * band's edge) has no dip on one side. */
static double prominence(const hm_whittle_data *d, const double *th, unsigned poles, const window_geometry *g,
                         double w0) {
  double low = INFINITY, high = INFINITY, low_edge = NAN, high_edge = NAN;
  for (size_t k = 0; k < d->n; ++k) {
    const double s = hm_whittle_spectrum(th, poles, g->T, d->w[k], d->u[k]);
    if (d->w[k] < w0) {
      low = fmin(low, s);
      if (isnan(low_edge)) low_edge = s;
    } else {
      high = fmin(high, s);
      high_edge = s;
    }
  }
  if (!isfinite(low) || !isfinite(high)) return 1.0;
  if (low_edge > HM_MODAL_PROMINENCE_EDGE_REL * low || high_edge > HM_MODAL_PROMINENCE_EDGE_REL * high) return 1.0;
  const double top = hm_whittle_spectrum(th, poles, g->T, w0, log(w0 / g->w_ref));
  return top / fmax(low, high);
}

/* The reading of a fit theta (poles pairs, Fisher information f): the least-damped pair is the mode. */
static void reading_of(const hm_modal m, const window_geometry *g, const hm_whittle_data *d, const double *th,
                       unsigned poles, const double f[NPM][NPM], hm_mode_reading *r) {
  double var[NPM];
  hm_whittle_variances(f, hm_whittle_np(poles), g->padding, var);
  const int second = poles == 2 && fabs(th[HM_W_SIGMA2]) < fabs(th[HM_W_SIGMA]); /* the mode is the second pair */
  const int is = second ? HM_W_SIGMA2 : HM_W_SIGMA, iw = second ? HM_W_W02 : HM_W_W0;
  const double sg = -fabs(th[is]), w0 = fabs(th[iw]), mag = sqrt(sg * sg + w0 * w0);
  r->poles = poles;
  r->frequency_hz = w0 / (2.0 * HM_PI);
  r->frequency_se_hz = sqrt(var[iw]) / (2.0 * HM_PI);
  r->decay_rate_1_s = sg;
  r->decay_rate_se_1_s = sqrt(var[is]);
  r->damping_ratio = -sg / mag;
  /* d zeta / d sigma = w0^2 / |s|^3 (w0's share of the error is second order for light damping) */
  r->damping_ratio_se = r->decay_rate_se_1_s * w0 * w0 / (mag * mag * mag);
  r->peak_to_mean = hm_whittle_peak(th, (unsigned)second, g->T, g->w_ref); /* the periodogram is scaled to mean 1 */
  r->second_frequency_hz = poles == 2 ? fabs(th[second ? HM_W_W0 : HM_W_W02]) / (2.0 * HM_PI) : 0.0;
  r->second_decay_rate_1_s = poles == 2 ? -fabs(th[second ? HM_W_SIGMA : HM_W_SIGMA2]) : 0.0;
  /* the peak's core (within half its width a_e of w0): sum (I/S - 1) over its bins, standardised (a padded bin
   * counts 1 / padding); a narrower resonance inside the pair's fitted peak leaves an excess there */
  const double ae = -sg + HM_WHITTLE_LEAKAGE / g->T, half = 0.5 * ae; /* the pair's width with the leakage */
  double sum = 0.0;
  size_t n_core = 0;
  for (size_t k = 0; k < d->n; ++k)
    if (fabs(d->w[k] - w0) <= half) {
      sum += d->pgram[k] / hm_whittle_spectrum(th, poles, g->T, d->w[k], d->u[k]) - 1.0;
      ++n_core;
    }
  r->peak_core_z = n_core ? sum / sqrt((double)n_core * g->padding) : 0.0;
  r->informative = isfinite(r->decay_rate_se_1_s) &&
                   r->decay_rate_se_1_s <= HM_MODAL_INFORMATIVE_SE_1_S + HM_MODAL_INFORMATIVE_REL * fabs(sg);
  const double margin_hz = 3.0 * r->frequency_se_hz + 2.0 * g->df;
  /* a peak: over 3 times the band's mean, and for one narrower than a few bins over what the largest of the band's
   * ordinates reaches by chance (about ln n: the peak's bins, a_e T / pi of them, average that much less) */
  const double cover = fmax(1.0, ae * g->T / HM_PI), chance = log((double)d->n) / cover;
  /* or, with min_peak_prominence set, a resonance too broad for the band's mean: holding half the band's power, a
   * pair of width a_e stands about B / (2 pi a_e) above the mean of a band B rad/s wide, below 3 for a_e > B / (6 pi)
   * (2.7 1/s over 5-13 Hz); a narrower peak that fails the mean's test is a minor one (a frame's weak 6.6 Hz peak at
   * -1 to -2 1/s beside its 8 Hz mode, which the model does not read) */
  const double band = 2.0 * HM_PI * (m->cfg.band_high_hz - m->cfg.band_low_hz);
  const int broad = m->cfg.min_peak_prominence > 0.0 && band / (2.0 * HM_PI * ae) < 3.0;
  r->peak_prominence = broad ? prominence(d, th, poles, g, w0) : NAN; /* (a pass over the bins: only where it counts) */
  const int peak = r->peak_to_mean > 3.0 + chance ||
                   (broad && r->peak_prominence > m->cfg.min_peak_prominence + chance);
  r->valid = r->informative && isfinite(r->frequency_se_hz) && r->frequency_hz > m->cfg.band_low_hz + margin_hz &&
             r->frequency_hz < m->cfg.band_high_hz - margin_hz && r->damping_ratio < 0.5 && peak;
}

/* An angular frequency [rad/s] inside the band. */
static int in_band(const hm_modal m, double w) {
  const double f = fabs(w) / (2.0 * HM_PI);
  return f > m->cfg.band_low_hz && f < m->cfg.band_high_hz;
}

/* A two-pair fit th that tells a mode beside another resonance, against the one-pair fit th1: both pairs inside the
 * band (a pair outside is the numerator's business), the less damped one inside the one pair's peak (within its
 * half-width |sigma| of its frequency, or 2 / T: the resonance the one pair averaged) and that peak's top: at least
 * half the spectrum at its frequency and above the other pair's peak. A second pair that fits a chance bump on a
 * resonance's flank is less damped, but none of these. */
static int two_pairs_tell(const hm_modal m, const window_geometry *g, const double *th, const double *th1) {
  if (!in_band(m, th[HM_W_W0]) || !in_band(m, th[HM_W_W02])) return 0;
  const unsigned ld = fabs(th[HM_W_SIGMA2]) < fabs(th[HM_W_SIGMA]) ? 1u : 0u;
  const double w = fabs(th[ld ? HM_W_W02 : HM_W_W0]);
  if (fabs(w - fabs(th1[HM_W_W0])) > fmax(fabs(th1[HM_W_SIGMA]), 2.0 * 2.0 * HM_PI / g->T)) return 0;
  const double peak = hm_whittle_peak(th, ld, g->T, g->w_ref), other = hm_whittle_peak(th, 1u - ld, g->T, g->w_ref);
  return peak >= 0.5 * hm_whittle_spectrum(th, 2, g->T, w, log(w / g->w_ref)) && peak >= other;
}

/* The best converged fit of `poles` pairs from the starts given (n_starts of them, each NPM values); 1 if any
 * converged (th, obj, f set), 0 otherwise. *iters accumulates the steps. */
static int best_of(const hm_whittle_data *d, unsigned poles, const double (*starts)[NPM], int n_starts,
                   unsigned max_iter, double tol, double *th, double *obj, double f[NPM][NPM], unsigned *iters) {
  int found = 0;
  *obj = INFINITY;
  for (int k = 0; k < n_starts; ++k) {
    double t[NPM], o, fk[NPM][NPM];
    unsigned it = 0;
    memcpy(t, starts[k], sizeof t);
    const int ok = hm_whittle_score(d, poles, t, tol, max_iter, &o, fk, &it);
    *iters += it;
    if (ok && o < *obj) {
      memcpy(th, t, sizeof t);
      memcpy(f, fk, sizeof fk);
      *obj = o;
      found = 1;
    }
  }
  return found;
}

/* The best two-pair fit from the starts given (the choice needs the objective to HM_MODAL_TOL2 only); a start whose
 * objective after HM_MODAL_SCREEN_ITER2 steps is not within half the choice's margin of the one pair's obj1 is
 * screened out (not scored further: a second pair that far off is not there, or not yet), the others get
 * HM_MODAL_MAX_ITER2 steps in all. 1 if any start ended below obj1 (th, obj, f set: a converged fit's, else the lowest
 * unfinished one, screened out or out of steps; *converged says which). An unfinished fit bounds the two pairs'
 * likelihood ratio from below, and it is followed from fit to fit (the warm start) so that the descent goes on a few
 * steps a fit: a broad resonance beside the mode sits on a ridge with the numerator's cubic that the scoring crosses
 * slowly (broad_386's 20 s windows, -1.57 1/s at 14.15 Hz beside -5.75 at 13.66 Hz: screened out at ratios of 3-10
 * with the mode at -1.7 to -2.0, where one pair read -2.4 to -4.7; given 80 steps most converged at ratios of 10-16
 * with the same mode). */
static int fit_two_pairs(const hm_modal m, const hm_whittle_data *d, const window_geometry *g,
                         const double (*starts)[NPM], int n_starts, double obj1, double *th, double *obj,
                         double f[NPM][NPM], int *converged, unsigned *iters) {
  const double tol = fmax(m->cfg.tol, HM_MODAL_TOL2), reach = obj1 - 0.25 * HM_MODAL_TWO_PAIR_LR * g->padding;
  const unsigned screen = HM_MODAL_SCREEN_ITER2 < m->cfg.max_iter ? HM_MODAL_SCREEN_ITER2 : m->cfg.max_iter;
  const unsigned rest = m->cfg.max_iter > HM_MODAL_MAX_ITER2 ? HM_MODAL_MAX_ITER2 - screen : m->cfg.max_iter - screen;
  int found = 0;
  *obj = INFINITY;
  *converged = 0;
  for (int k = 0; k < n_starts; ++k) {
    double t[NPM], o, fk[NPM][NPM];
    unsigned it = 0;
    memcpy(t, starts[k], sizeof t);
    int ok = hm_whittle_score(d, 2, t, tol, screen, &o, fk, &it);
    *iters += it;
    if (!ok && o < reach && rest > 0) {
      ok = hm_whittle_score(d, 2, t, tol, rest, &o, fk, &it);
      *iters += it;
    }
    if (isfinite(o) && o < obj1 && (ok > *converged || (ok == *converged && o < *obj))) {
      memcpy(th, t, sizeof t);
      memcpy(f, fk, sizeof fk);
      *obj = o;
      *converged = ok;
      found = 1;
    }
  }
  return found;
}

/* Fit one reading over the nb bins loaded: one pair (from the warm start, else from two cold ones), two pairs (from
 * the warm start and from the one pair split), the likelihood ratio chooses; the chosen theta in th and its pairs in
 * *poles. 0 if not even one pair converged (ws forgotten). */
static int fit_reading(hm_modal m, warm_start *ws, const window_geometry *g, size_t nb, hm_mode_reading *r,
                       double *th, unsigned *poles) {
  const hm_whittle_data d = {m->w, m->u, m->pgram, nb, g->T};
  double starts[2][NPM], th1[NPM], f1[NPM][NPM], obj1;
  unsigned iters = 0;
  int found = 0;
  if (ws->have1) { /* a converged warm start is enough, with its mode in the band (else it is lost: cold starts) */
    memcpy(starts[0], ws->th1, sizeof starts[0]);
    found = best_of(&d, 1, (const double(*)[NPM])starts, 1, m->cfg.max_iter, m->cfg.tol, th1, &obj1, f1, &iters) &&
            in_band(m, th1[HM_W_W0]);
  }
  /* ... and a peak: a pair below the band's mean level is no mode, and warm-started it would be followed for good
   * (a bogie frame's first windows held a 17 Hz bump of 0.07 times the mean, and the 8 Hz mode that grew beside it
   * later was never fitted: cold starts again, the better likelihood kept) */
  const int stuck = found && hm_whittle_peak(th1, 0, g->T, g->w_ref) < HM_MODAL_WARM_MIN_PEAK;
  if (!found || stuck) {
    const size_t h = (size_t)fmax(1.0, round(0.1 / g->df)); /* 0.1 Hz half-width */
    double th_c[NPM], f_c[NPM][NPM], obj_c;
    hm_whittle_cold_start(&d, h, -0.7, starts[0]);
    hm_whittle_cold_start(&d, h, -4.0, starts[1]);
    if (best_of(&d, 1, (const double(*)[NPM])starts, 2, m->cfg.max_iter, m->cfg.tol, th_c, &obj_c, f_c, &iters) &&
        (!found || obj_c < obj1)) {
      memcpy(th1, th_c, sizeof th_c);
      memcpy(f1, f_c, sizeof f_c);
      obj1 = obj_c;
      found = 1;
    }
  }
  ws->have1 = found;
  if (!found) {
    ws->have2 = 0;
    return 0;
  }
  /* a negligible noise tried again from a noise the spectrum's size at the splits' pace: a local minimum the scoring
   * cannot leave, which the warm start would otherwise follow from fit to fit (whittle.h) */
  const int splits = ws->since_split + 1 >= HM_MODAL_SPLIT_EVERY;
  if (splits) hm_whittle_reseed_noise(&d, 1, th1, m->cfg.tol, m->cfg.max_iter, &obj1, f1, &iters);
  memcpy(ws->th1, th1, sizeof th1);
  /* two pairs */
  double th2[NPM], f2[NPM][NPM], obj2, starts2[3][NPM];
  int n2 = 0;
  if (ws->have2) memcpy(starts2[n2++], ws->th2, sizeof starts2[0]);
  /* the one pair's splits every HM_MODAL_SPLIT_EVERY fits (from the first): the warm start follows a resonance once
   * found, the splits find a new one */
  if (splits) {
    hm_whittle_split_start(th1, g->T, 0.4, starts2[n2++]);
    hm_whittle_split_start(th1, g->T, 0.15, starts2[n2++]);
    ws->since_split = 0;
  } else {
    ++ws->since_split;
  }
  int conv2 = 0;
  const int found2 =
      n2 > 0 && fit_two_pairs(m, &d, g, (const double(*)[NPM])starts2, n2, obj1, th2, &obj2, f2, &conv2, &iters);
  const double lr = found2 ? 2.0 * (obj1 - obj2) / g->padding : 0.0;
  /* followed from fit to fit where the second pair holds something (half the weak alternative's evidence); else only
   * the splits look again (a second pair warm-started at every fit for nothing was 45% of a ramp's scoring steps) */
  ws->have2 = found2 && lr > HM_MODAL_WARM2_MIN_LR && in_band(m, th2[HM_W_W0]) && in_band(m, th2[HM_W_W02]);
  if (found2) memcpy(ws->th2, th2, sizeof th2);
  /* an unfinished fit's line-like pair (narrower than the window resolves, 1 / T) is no alternative: a finished one
   * there reads sigma = 0, none (a joint's line beside a mode of -10.4 1/s had read -0.0009 and added 10.4 to its
   * error) */
  const double alt = -fmin(fabs(th2[HM_W_SIGMA]), fabs(th2[HM_W_SIGMA2]));
  const int tells = found2 && lr > HM_MODAL_TWO_PAIR_LR_WEAK && (conv2 || -alt >= 1.0 / g->T) &&
                    two_pairs_tell(m, g, th2, th1);
  const int two = tells && conv2 && lr > HM_MODAL_TWO_PAIR_LR;
  *poles = two ? 2 : 1;
  memcpy(th, two ? th2 : th1, sizeof(double) * NPM);
  reading_of(m, g, &d, th, *poles, two ? (const double(*)[NPM])f2 : (const double(*)[NPM])f1, r);
  r->two_pair_lr = lr;
  r->decay_rate_alt_1_s = tells && !two ? alt : 0.0;
  r->iterations = iters;
  return 1;
}

/* A mode as narrow as a line (line_narrow: |sigma| within two standard errors of the a line's reading, which the
 * window's leakage puts below 10 / T) and a line at f_hz inside its peak (in_peak: three of its half-widths |sigma| +
 * 2 / T, two frequency errors more): the line and the mode near its Hopf speed look alike in one window (modal.h); a
 * narrow mode's own peak, over a window a few times its correlation time 1 / |sigma|, holds a few such "lines" (at 510
 * km/h, -0.4 1/s, one 0.05 Hz off its centre passed the F test and, set aside, took the mode with it). */
static int line_narrow(const window_geometry *g, const hm_mode_reading *r) {
  return fabs(r->decay_rate_1_s) <= 10.0 / g->T + 2.0 * r->decay_rate_se_1_s;
}
static int in_peak(const window_geometry *g, const hm_mode_reading *r, double f_hz) {
  const double half_hz = (fabs(r->decay_rate_1_s) + HM_WHITTLE_LEAKAGE / g->T) / (2.0 * HM_PI);
  return fabs(f_hz - r->frequency_hz) <= 3.0 * half_hz + 2.0 * r->frequency_se_hz;
}
static int narrow_on(const window_geometry *g, const hm_mode_reading *r, double f_hz) {
  return line_narrow(g, r) && in_peak(g, r, f_hz);
}

/* Which of the lone candidates in the band are sinusoids (lines.h's harmonic F test at HM_MODAL_LINE_F or more, or at
 * HM_MODAL_LINE_F_ON_MODE for one the window's mode sits on as narrow as a line: that one goes to the narrow-peak
 * question rather than being set aside, modal.h, and a weak line fitted as a narrow mode must reach it):
 * their indices in lr into idx, their fitted lines into fits and their local backgrounds into bgs; their count. */
static unsigned sinusoids(const hm_modal m, const window_geometry *g, const hm_lines_result *lr,
                          const hm_mode_reading *rd, size_t n, unsigned *idx, hm_lines_sinusoid *fits, double *bgs) {
  unsigned count = 0;
  for (unsigned j = 0; j < lr->n_lone; ++j) {
    const size_t k = lr->lone_bin[j];
    if (k < g->k0 || k > g->k1 || m->set_aside[k]) continue;
    hm_lines_sinusoid fit;
    if (hm_lines_fit_sinusoid(m->re, m->im, m->nfft / 2 + 1, k, n, m->nfft, &fit) != HM_OK) continue;
    /* a line that swept more than a bin in the window (f spread_rel > 1 / T on a ramp) is no fixed sinusoid and may
     * fail any F test: under a reading as narrow as a line it is the narrow-peak question whatever its F */
    const int swept = lr->lone_hz[j] * g->spread_rel > 1.0 / g->T;
    const double needed = narrow_on(g, rd, lr->lone_hz[j]) ? (swept ? 0.0 : HM_MODAL_LINE_F_ON_MODE) : HM_MODAL_LINE_F;
    if (fit.f_stat >= needed) idx[count] = j, bgs[count] = m->power[k] / lr->lone_ratio[j], fits[count++] = fit;
  }
  return count;
}

/* A reading as narrow as a line, inside whose peak a track line was taken out in distance (take_window) or a comb
 * found there has a tooth, in a window
 * whose speed moved that line by more than a bin (f spread_rel > 1 / T): what stands is that line's residue (its
 * amplitude and phase change as it crosses the mode's resonance, which one sinusoid in distance does not follow) or
 * the mode near its Hopf speed. It is the narrow-peak question (modal.h) like a listed candidate: the line fitted at
 * the peak's strongest bin (fit), its background the mean of the continuum beside the sweep (bg). 1 if so. (Without
 * the line taken out in distance as evidence, a bogie's own narrow mode on a notched ramp went that way and the
 * reading beside it, its flanks, was used: the interval wholly above the truth, bogie_unstable_148.) On slab_127 of
 * the campaign (6.18 m slabs, a ramp across 13 Hz at 280-292 km/h) the residue read -0.8 1/s nine times, counted as
 * misfits: model_mismatch, and the model-free interval alone gave WARN 60 km/h below the Hopf speed. */
static int swept_peak(const hm_modal m, const window_geometry *g, const hm_mode_reading *rd, size_t n,
                      hm_lines_sinusoid *fit, double *bg) {
  if (!isfinite(rd->decay_rate_1_s) || !line_narrow(g, rd) || !(rd->frequency_hz * g->spread_rel > 1.0 / g->T))
    return 0;
  int taken = 0; /* a line taken out inside the peak, or a tooth of a comb found in distance there */
  for (unsigned q = 0; q < m->n_order; ++q) taken |= in_peak(g, rd, m->order_hz[q]);
  const double f1 = m->order_comb_hz;
  if (f1 > 0.0) taken |= in_peak(g, rd, f1 * fmax(1.0, round(rd->frequency_hz / f1)));
  if (!taken) return 0;
  const double f = rd->frequency_hz, reach = 1.0 / g->T + rd->frequency_se_hz;
  size_t k = 0;
  for (size_t j = (size_t)fmax((double)g->k0 + 3.0 * g->padding, ceil((f - reach) / g->df));
       j <= (size_t)fmin((double)g->k1 - 3.0 * g->padding, floor((f + reach) / g->df)); ++j)
    if (!m->set_aside[j] && (k == 0 || m->power[j] > m->power[k])) k = j;
  if (k == 0 || hm_lines_fit_sinusoid(m->re, m->im, m->nfft / 2 + 1, k, n, m->nfft, fit) != HM_OK) return 0;
  const double inner = f * g->spread_rel + 2.0 / g->T, outer = inner + 0.5;
  double sum = 0.0;
  size_t count = 0;
  for (size_t j = g->k0; j <= g->k1; ++j) {
    const double d = fabs((double)j * g->df - f);
    if (d >= inner && d <= outer && !m->set_aside[j]) sum += m->power[j], ++count;
  }
  if (count == 0) return 0;
  *bg = sum / (double)count;
  return 1;
}

/* Set a line aside: its fitted sinusoid subtracted from the band's DFT (the power there recomputed), and the bins
 * its residue still stands above the continuum in left out (its main lobe, -+2 / T, for a line the subtraction
 * removed; as wide as a line of that residue's strength leaks, lines.h, for one whose frequency moved in the window);
 * listed in e. bg: the line's local background (|X|^2 of the continuum there). */
static void set_line_aside(hm_modal m, const window_geometry *g, const hm_lines_sinusoid *fit, double bg, size_t n,
                           hm_mode_estimate *e) {
  const double f = fit->omega * m->fd / (2.0 * HM_PI);
  if (e->lone_lines < HM_MODAL_MAX_LONE) {
    e->lone_line_hz[e->lone_lines] = f;
    /* a sinusoid of amplitude A over n samples has |X| = A n / 2 at its bin: |amp| = A / 2 */
    e->lone_line_mps2[e->lone_lines++] = 2.0 * hypot(fit->amp_re, fit->amp_im);
  }
  hm_lines_subtract(m->re, m->im, g->k0, g->k1, n, m->nfft, fit);
  double residue = 0.0;
  const size_t kc = (size_t)llround(f / g->df), h = (size_t)ceil(2.0 * g->padding);
  for (size_t k = g->k0; k <= g->k1; ++k) {
    m->power[k] = m->re[k] * m->re[k] + m->im[k] * m->im[k];
    if (k + h >= kc && k <= kc + h) residue = fmax(residue, m->power[k]);
  }
  hm_lines_mark(m->lines, f, bg > 0.0 ? residue / bg : 1.0, g->spread_rel, m->nfft / 2 + 1, g->df, g->T,
                m->set_aside);
}

/* A narrow peak's line inside the peak of the mode beside it (modal.h): its bins left out as far as the line search's
 * background reaches (lines.h's background_halfwidth_hz, 0.5 Hz). The vehicle is not linear: a strong line modulated
 * by the vehicle's own response keeps a skirt that the subtraction of one sinusoid leaves (a 6.08 m slab's 5 m/s^2
 * line at 12.8 Hz at 280 km/h: its residue 6-10 times the continuum over +-0.3 Hz; with the main lobe alone left out,
 * the mode beside it, -8.45 1/s at 13.42 Hz, read -5.5 at 12.8; with +-0.5 Hz, -7.8 at 13.05). The bins newly left
 * out. */
static size_t skirt_aside(hm_modal m, const window_geometry *g, double f_hz) {
  return hm_lines_mark(m->lines, f_hz, HUGE_VAL, g->spread_rel, m->nfft / 2 + 1, g->df, g->T, m->set_aside);
}

/* Leave out the bins of the lone candidates in the band that are neither set aside nor inside the mode's peak (three
 * of its half-widths |sigma| + 2 / T, two frequency errors more): a line that failed the F test because its frequency
 * moved in the window (a slab's line on a ramp sweeps V / L times the speed's spread: at 508 km/h over 7 km/h, 0.3 Hz in
 * 20 s) is neither subtracted nor left out otherwise, and a strong one distorts the fit beside it (a 6.76 m slab's
 * 20.8 Hz line read a mode of -3.5 1/s at 14.1 Hz as -1.5 +- 0.3, WARN 54 km/h below the Hopf speed; with the line
 * removed from the recording, -3.4). Leaving out bins where the mode's peak is not biases nothing; nothing is left
 * out for a reading as narrow as a line (it may be the line, the mode among the candidates). The count. */
static unsigned mask_far_candidates(hm_modal m, const window_geometry *g, const hm_lines_result *lr,
                                    const hm_mode_reading *rd) {
  if (!isfinite(rd->decay_rate_1_s) || !isfinite(rd->frequency_hz)) return 0;
  if (line_narrow(g, rd)) return 0;
  const size_t nbins = m->nfft / 2 + 1;
  /* a chance candidate (a bin exp(-ratio) likely) in the band's bins, harmless and in most windows, costs no refit:
   * only one beyond chance at 1e-3 over the band counts */
  const double chance_ratio = log((double)(g->k1 - g->k0 + 1) / g->padding) + log(1e3);
  unsigned count = 0;
  for (unsigned j = 0; j < lr->n_lone; ++j) {
    const size_t k = lr->lone_bin[j];
    if (k < g->k0 || k > g->k1 || m->set_aside[k] || lr->lone_ratio[j] < chance_ratio) continue;
    if (in_peak(g, rd, lr->lone_hz[j])) continue;
    count += hm_lines_mark(m->lines, lr->lone_hz[j], lr->lone_ratio[j], g->spread_rel, nbins, g->df, g->T,
                           m->set_aside) > 0;
  }
  return count;
}

/* The window's periodogram (m->power, every bin) from the newest n decimated samples, oldest first, without their
 * mean, zero-padded. */
static void periodogram_part(hm_modal m, size_t n, size_t start, size_t len);
static void periodogram(hm_modal m, size_t n) { periodogram_part(m, n, 0, n); }

/* The periodogram of len samples from start of the newest n of the fit's window m->x (zero-padded to nfft) into
 * m->power. */
static void periodogram_part(hm_modal m, size_t n, size_t start, size_t len) {
  const double *x = m->x + (m->x_len - n + start);
  double mean = 0.0;
  for (size_t k = 0; k < len; ++k) mean += x[k];
  mean /= (double)len;
  for (size_t k = 0; k < m->nfft; ++k) m->re[k] = k < len ? x[k] - mean : 0.0;
  hm_fft_real(m->re, m->im, m->nfft, m->cosw, m->sinw, m->nfft_max);
  for (size_t k = 0; k <= m->nfft / 2; ++k) m->power[k] = m->re[k] * m->re[k] + m->im[k] * m->im[k];
}

/* The comb of lines (lines.h) into r's fields and m->excluded; the search's result in *lr. */
static void find_comb(hm_modal m, size_t n, double df, double T, double spread_rel, hm_lines_result *lr,
                      hm_mode_estimate *r) {
  const size_t nbins = m->nfft / 2 + 1;
  if (hm_lines_find(m->lines, m->power, nbins, df, T, 2.5, 0.3 * m->fd, spread_rel, m->excluded, lr) != HM_OK) {
    memset(lr, 0, sizeof *lr);
    memset(m->excluded, 0, nbins);
  }
  if (!m->cfg.reject_lines) { /* reported, not left out */
    memset(m->excluded, 0, nbins);
    lr->n_lone = 0;
  }
  r->lines_found = lr->found;
  r->line_fundamental_hz = lr->fundamental_hz;
  r->line_harmonics = lr->harmonics;
  r->line_strongest_hz = lr->strongest_hz;
  r->line_strongest_mps2 = lr->found ? 2.0 * sqrt(m->power[lr->strongest_bin]) / (double)n : 0.0;
  memcpy(m->set_aside, m->excluded, nbins);
}

/* The centroid [Hz] of the periodogram's excess over its local background within [f_lo, f_hi] (the bins set aside
 * before the narrow peak's left out, m->excluded: the narrow peak is the one measured; the background the mean of the flanks, half as wide, either side) and its standard error (the ordinates
 * exponential about the spectrum, their variance its square, taken as the ordinate itself; a padded bin counts 1 /
 * padding). For a smeared line it is the mean of its instantaneous frequency; for a mode with fixed poles, its
 * frequency (the Lorentzian is symmetric). 0 if no excess. */
static int centroid(const hm_modal m, const window_geometry *g, double f_lo, double f_hi, double *f, double *se) {
  const double w = f_hi - f_lo;
  double bg = 0.0, nbg = 0.0;
  for (size_t k = g->k0; k <= g->k1; ++k) {
    const double fk = (double)k * g->df;
    if (!m->excluded[k] && ((fk >= f_lo - 0.5 * w && fk < f_lo) || (fk > f_hi && fk <= f_hi + 0.5 * w)))
      bg += m->power[k], nbg += 1.0;
  }
  if (!(nbg > 0.0)) return 0;
  bg /= nbg;
  double s0 = 0.0, s1 = 0.0;
  for (size_t k = g->k0; k <= g->k1; ++k) {
    const double fk = (double)k * g->df;
    if (m->excluded[k] || fk < f_lo || fk > f_hi) continue;
    s0 += m->power[k] - bg;
    s1 += fk * (m->power[k] - bg);
  }
  if (!(s0 > 0.0)) return 0;
  const double c = s1 / s0;
  if (!(c >= f_lo && c <= f_hi)) return 0; /* an excess that partly cancels: no peak's centroid */
  double v = 0.0;
  for (size_t k = g->k0; k <= g->k1; ++k) {
    const double fk = (double)k * g->df;
    if (m->excluded[k] || fk < f_lo || fk > f_hi) continue;
    v += (fk - c) * (fk - c) * m->power[k] * m->power[k];
  }
  *f = c;
  *se = sqrt(v * g->padding) / s0;
  return 1;
}

/* Order tracking (modal.h's speed_tracking): the centroid of the reading's peak in each half of the newest n samples,
 * over its width (three half-widths of the pair widened by the half's leakage) and the distance a line moves with the
 * halves' speed ratio q; d ln f / d ln V from the two. 0 if a half shows no peak there. Overwrites m->power. */
static int halves_tracking(hm_modal m, size_t n, const window_geometry *g, const hm_mode_reading *rd, double q,
                           double *k, double *k_se) {
  const size_t h = n / 2;
  window_geometry gh = *g;
  gh.T = (double)h / m->fd;
  gh.padding = (double)m->nfft / (double)h;
  const double lq = log(q), f0 = rd->frequency_hz;
  const double half = 3.0 * (fabs(rd->decay_rate_1_s) + HM_WHITTLE_LEAKAGE / gh.T) / (2.0 * HM_PI) +
                      fabs(lq) * f0 + 2.0 * gh.df;
  double f[2], se[2];
  for (int part = 0; part < 2; ++part) {
    periodogram_part(m, n, part ? n - h : 0, h);
    if (!centroid(m, &gh, f0 - half, f0 + half, &f[part], &se[part])) return 0;
  }
  *k = log(f[1] / f[0]) / lq;
  *k_se = hypot(se[0] / f[0], se[1] / f[1]) / fabs(lq);
  return 1;
}

/* The last window_s (at least the n to fit) copied oldest first into m->x, with its speeds, and the newest n's
 * periodogram (periodogram()); where their speed trend moved a line at band_high_hz by more than two bins, the track
 * lines taken out of them in distance (order_lines.h, from that periodogram), reported in r, and the periodogram
 * computed again if any was. (Only the newest n: the halves' order tracking over window_s reads the older part as
 * it came.) */
static void take_window(hm_modal m, size_t n, hm_mode_estimate *r) {
  const size_t len = (size_t)fmax((double)n, fmin((double)m->n_in, floor(m->cfg.window_s * m->fd + 1e-6)));
  const size_t oldest = (m->head + m->n_win - len) % m->n_win;
  for (size_t k = 0; k < len; ++k) {
    const size_t j = (oldest + k) % m->n_win;
    m->x[k] = m->ring[j], m->xv[k] = m->speed[j];
  }
  m->x_len = len;
  m->n_order = 0;
  m->order_comb_hz = 0.0;
  periodogram(m, n);
  double *x = m->x + (len - n);
  const double *v = m->xv + (len - n);
  /* the speed's least-squares trend over the window (a speed signal's noise of 0.3 km/h moves its range by 2 km/h
   * at a steady speed, and every fit would search for nothing; review of issue #26) */
  double sum = 0.0, skv = 0.0;
  for (size_t k = 0; k < n; ++k) {
    if (!(v[k] > 0.0)) return; /* (NAN: unknown) */
    sum += v[k], skv += ((double)k - 0.5 * (double)(n - 1)) * v[k];
  }
  const double nn = (double)n, slope = skv / (nn * (nn * nn - 1.0) / 12.0); /* per sample */
  const double T = nn / m->fd, trend_rel = fabs(slope) * (nn - 1.0) / (sum / nn);
  if (!(m->cfg.reject_lines && m->cfg.band_high_hz * trend_rel > 2.0 / T)) return;
  hm_order_lines_result o;
  if (hm_order_lines_clean_dft(m->order, x, v, n, m->fd, m->nfft, 2.5, 0.3 * m->fd, m->re, m->im, m->power, &o) !=
      HM_OK)
    return;
  m->order_comb_hz = o.comb_fundamental_hz;
  if (o.n == 0) return;
  periodogram(m, n); /* (of the samples without the lines) */
  unsigned best = 0;
  for (unsigned q = 1; q < o.n; ++q)
    if (o.amp_mps2[q] > o.amp_mps2[best]) best = q;
  r->order_lines = m->n_order = o.n;
  memcpy(m->order_hz, o.f_hz, sizeof o.f_hz);
  r->order_line_wavelength_m = o.wavelength_m[best];
  r->order_line_hz = o.f_hz[best];
  r->order_line_mps2 = o.amp_mps2[best];
}

/* The geometry of a fit over the newest n decimated samples (padded to nfft) and the band's bins. */
static window_geometry geometry(const hm_modal m, size_t n, double speed_spread_rel) {
  window_geometry g;
  g.df = m->fd / (double)m->nfft;
  g.T = (double)n / m->fd;
  g.w_ref = 2.0 * HM_PI * 0.5 * (m->cfg.band_low_hz + m->cfg.band_high_hz);
  g.padding = (double)m->nfft / (double)n;
  g.spread_rel = isfinite(speed_spread_rel) && speed_spread_rel > 0.0 ? speed_spread_rel : 0.0;
  g.k0 = (size_t)ceil(m->cfg.band_low_hz / g.df);
  g.k1 = (size_t)fmin(floor(m->cfg.band_high_hz / g.df), (double)(m->nfft / 2));
  return g;
}

/* The narrow peak's envelope (modal.h, envelope.h) from the window's newest n samples: the line hypothesis holds the
 * band's power above the continuum beside the peak, bg (|X|^2 = n fd S for a two-sided density S: S B in the band). */
static void narrow_peak_envelope(hm_modal m, const window_geometry *g, double bg, size_t n, hm_mode_estimate *r) {
  const double band = fmax(HM_MODAL_ENVELOPE_BAND_HZ, 2.0 * r->narrow_peak_hz * g->spread_rel + 4.0 / g->T);
  hm_envelope_stats es;
  if (!(bg > 0.0) || hm_envelope_stats_of(m->x + (m->x_len - n), n, m->fd, r->narrow_peak_hz, band, m->env_work,
                                          m->env_work_len, &es) != HM_OK)
    return;
  const double kappa = fmax(es.band_power / (bg / ((double)n * m->fd) * band) - 1.0, 0.0);
  r->narrow_peak_envelope_ratio = es.ratio;
  r->narrow_peak_line_ratio = hm_envelope_line_ratio(kappa);
}

/* A narrow peak (modal.h): reported as such, and the reading with its line set aside too (r->line_reading), then,
 * where that line lies inside the peak of the mode beside it, with the line's skirt left out as well
 * (r->line_reading_wide; skirt_aside: a narrow mode's own core is no skirt: left out, the flanks of a bogie's mode at
 * -0.6 1/s read -5.5). */
static void narrow_peak_readings(hm_modal m, const window_geometry *g, const hm_lines_sinusoid *fit, double bg,
                                 size_t n, hm_mode_estimate *r) {
  r->narrow_peak = 1;
  r->narrow_peak_hz = fit->omega * m->fd / (2.0 * HM_PI);
  r->narrow_peak_mps2 = 2.0 * hypot(fit->amp_re, fit->amp_im);
  narrow_peak_envelope(m, g, bg, n, r);
  const unsigned listed = r->lone_lines;
  set_line_aside(m, g, fit, bg, n, r);
  r->lone_lines = listed; /* the narrow peak is reported as such, not as a lone line */
  double th_l[NPM], scale;
  unsigned poles_l;
  size_t nb_l = load_bins(m, g, m->set_aside, &scale);
  const int ok = nb_l >= 4 * HM_WHITTLE_NP2 && fit_reading(m, &m->warm[1], g, nb_l, &r->line_reading, th_l, &poles_l);
  if (!ok) memset(&r->line_reading, 0, sizeof r->line_reading);
  r->line_reading_wide = r->line_reading;
  if (ok && isfinite(r->line_reading.decay_rate_1_s) && in_peak(g, &r->line_reading, r->narrow_peak_hz) &&
      skirt_aside(m, g, r->narrow_peak_hz) > 0) {
    if (!m->warm[2].have1) m->warm[2] = m->warm[1]; /* from the main-lobe reading's, then its own */
    nb_l = load_bins(m, g, m->set_aside, &scale);
    if (nb_l < 4 * HM_WHITTLE_NP2 || !fit_reading(m, &m->warm[2], g, nb_l, &r->line_reading_wide, th_l, &poles_l))
      memset(&r->line_reading_wide, 0, sizeof r->line_reading_wide);
  }
}

hm_status hm_modal_fit(hm_modal m, double max_window_s, double speed_spread_rel, double halves_speed_ratio,
                       hm_mode_estimate *out) {
  if (!m || !out || !(max_window_s > 0.0)) return HM_EINVAL;
  m->since_fit = 0;
  hm_mode_estimate r;
  memset(&r, 0, sizeof r);
  r.speed_tracking = r.speed_tracking_se = NAN;
  r.narrow_peak_envelope_ratio = r.narrow_peak_line_ratio = NAN;
  const size_t n = (size_t)fmin((double)m->n_in, floor(max_window_s * m->fd + 1e-6));
  r.window_s = (double)n / m->fd;
  if (n < m->min_n) {
    *out = r;
    return HM_OK;
  }
  take_window(m, n, &r);
  const window_geometry g = geometry(m, n, speed_spread_rel);
  hm_lines_result lr;
  find_comb(m, n, g.df, g.T, g.spread_rel, &lr, &r);
  /* the window's reading, without the comb; then without the lone lines it does not explain */
  double scale, th[NPM];
  unsigned poles;
  size_t nb = load_bins(m, &g, m->set_aside, &scale);
  if (nb < 4 * HM_WHITTLE_NP2) {
    *out = r;
    return HM_OK;
  }
  hm_mode_reading rd;
  memset(&rd, 0, sizeof rd);
  /* (a fit that fails, or leaves the band, still lets the lines be found and set aside: the refit may succeed) */
  const int fitted = fit_reading(m, &m->warm[0], &g, nb, &rd, th, &poles);
  if (!fitted || !in_band(m, 2.0 * HM_PI * rd.frequency_hz)) rd.decay_rate_1_s = -INFINITY, rd.decay_rate_se_1_s = 0.0;
  /* lone lines (sinusoids among the lone candidates): set aside, but for one the mode sits on while as narrow as a
   * line, which is the narrow-peak question (modal.h) */
  unsigned lines[HM_LINES_MAX_LONE];
  hm_lines_sinusoid fits[HM_LINES_MAX_LONE + 1]; /* (and a swept peak's, swept_peak) */
  double bgs[HM_LINES_MAX_LONE + 1];
  const unsigned n_lines = sinusoids(m, &g, &lr, &rd, n, lines, fits, bgs);
  int narrow = -1;
  for (unsigned i = 0; i < n_lines; ++i)
    if (narrow < 0 && narrow_on(&g, &rd, lr.lone_hz[lines[i]])) narrow = (int)i;
  if (narrow < 0 && swept_peak(m, &g, &rd, n, &fits[n_lines], &bgs[n_lines])) narrow = (int)n_lines;
  /* the lines off the mode's peak are set aside; inside a narrow mode's peak the strongest is the narrow-peak question
   * and the others are the mode's own */
  unsigned n_aside = 0;
  for (unsigned i = 0; i < n_lines; ++i)
    if ((int)i != narrow && !(narrow >= 0 && narrow_on(&g, &rd, lr.lone_hz[lines[i]])))
      set_line_aside(m, &g, &fits[i], bgs[i], n, &r), ++n_aside;
  n_aside += mask_far_candidates(m, &g, &lr, &rd);
  if (n_aside > 0) {
    nb = load_bins(m, &g, m->set_aside, &scale);
    if (nb < 4 * HM_WHITTLE_NP2 || !fit_reading(m, &m->warm[0], &g, nb, &rd, th, &poles)) {
      *out = r;
      return HM_OK;
    }
  } else if (!fitted) {
    return HM_ENOCONV;
  }
  size_t n_band = 0, n_out = 0;
  for (size_t k = g.k0; k <= g.k1; ++k) ++n_band, n_out += m->set_aside[k] != 0;
  r.band_excluded_fraction = n_band ? (double)n_out / (double)n_band : 0.0;
  memcpy(m->excluded, m->set_aside, m->nfft / 2 + 1); /* the order tracking's bins (centroid) */
  memcpy(m->spec, m->power, (m->nfft / 2 + 1) * sizeof m->spec[0]); /* the window's spectrum, kept */
  memcpy(m->spec_mask, m->set_aside, m->nfft / 2 + 1);
  m->spec_n = n, m->spec_nfft = m->nfft;
  if (narrow >= 0) narrow_peak_readings(m, &g, &fits[narrow], bgs[narrow], n, &r);
  hm_mode_estimate_use_reading(&r, &rd);
  /* order tracking over the whole window (the peak is the same; a ramp's 24 s window alone leaves the halves' slope
   * three times as uncertain) */
  double k, k_se;
  const size_t n_track = (size_t)fmin((double)m->n_in, floor(m->cfg.window_s * m->fd + 1e-6));
  if (isfinite(halves_speed_ratio) && halves_speed_ratio > 0.0 && fabs(log(halves_speed_ratio)) >= HM_MODAL_TRACK_MIN_LOG &&
      rd.valid && halves_tracking(m, n_track, &g, &rd, halves_speed_ratio, &k, &k_se))
    r.speed_tracking = k, r.speed_tracking_se = k_se;
  *out = r;
  return HM_OK;
}
