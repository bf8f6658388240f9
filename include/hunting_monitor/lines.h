/*
 * hunting_monitor - periodic excitation of the track in a periodogram: lines at multiples of V / L (issue #18).
 *
 * A line repeating every L metres (rail joints of 20-35 m, bridge spans of 24-32 m, slabs of 6.45 m) forces the
 * wheelset at f_m = m V / L: a comb of spectral lines that move with speed. A line on or near the hunting mode is
 * not the mode's damping: fitted as part of the mode's peak it makes a damped mode look nearly undamped (issue #18
 * item 1: a false ALARM 24 km/h below the true Hopf speed). This module finds such a comb so that the identification
 * leaves its bins out of the fit.
 *
 * Method, on the power |X_k|^2 of a window of T seconds (bins k df, any zero-padding):
 *  - the local background of a bin is the median over +-background_halfwidth_hz divided by ln 2 (the mean of an
 *    exponential variable, as a periodogram ordinate of a smooth spectrum is); a candidate line is a local maximum
 *    at least candidate_ratio above it (for a smooth spectrum a chance exceedance has probability exp(-ratio) per
 *    bin: 3e-4 at the default 8, so a few in a band of a thousand bins, which is why one line alone is never taken
 *    for a comb);
 *  - the candidates' frequencies are refined by a parabola through the logarithms of the three bins at the peak;
 *  - a comb is a fundamental f1 >= min_fundamental_hz with at least min_harmonics candidates (or, where fewer
 *    whole multiples of f1 lie in the range, all of them and at least two: a pattern of 6.45 m at 350 km/h, f1 15 Hz,
 *    has two in 2.5-30 Hz) within
 *    (0.5 + 0.5 m / n) / T of whole multiples m f1 (f1 tried as each candidate's frequency over n = 1..12). The comb
 *    kept scores best: one per candidate on a tooth, less one half per tooth in the range without one (a
 *    sub-harmonic comb f1 / j holds every line of f1 and some chance candidates but misses most of its teeth), then
 *    the largest f1; f1 is then the least-squares fit through the harmonics matched by the same tolerance (with the
 *    n of the f1 kept), which also picks each multiple's line for the width left out below. A lightly damped mode is
 *    one peak, not a comb: near the Hopf speed the mode itself is as narrow as a line and must not be left out.
 *  - every multiple of f1 in the range is excluded over +-w, w = max(2 / T, sqrt(ratio / leakage) / (pi T)) (the
 *    rectangular window's leakage of a line `ratio` times its background falls below leakage of the background
 *    there), at most background_halfwidth_hz.
 * No allocation after create; cost per call: for each local maximum (about n / 5 of n bins) a count of the 2 h + 1
 * bins around it below its threshold (the median is below exactly when more than half are), a selection of the
 * median for those that pass, and the comb's search over the candidates.
 */
#ifndef HUNTING_MONITOR_LINES_H
#define HUNTING_MONITOR_LINES_H

#include <stddef.h>

#include "hunting_monitor/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
  double candidate_ratio;          /* a bin this many times its local background is a candidate line */
  double background_halfwidth_hz;  /* the median's half-width [Hz] */
  double min_fundamental_hz;       /* lowest comb spacing [Hz] */
  unsigned min_harmonics;          /* candidates on the comb needed to declare it */
  double leakage;                  /* excluded until a line's leakage falls below this fraction of the background */
} hm_lines_config;

/* Defaults: ratio 8, +-0.5 Hz, fundamental from 1.5 Hz, three harmonics, leakage 0.1. */
void hm_lines_config_default(hm_lines_config *cfg);
/* HM_EDOMAIN with "field: reason" in why for an invalid configuration. */
hm_status hm_lines_config_validate(const hm_lines_config *cfg, char *why, size_t why_len);

/* Lone candidates reported at most (the strongest). */
#define HM_LINES_MAX_LONE 4

typedef struct {
  int found;                /* a comb was found */
  double fundamental_hz;    /* its spacing f1 [Hz] (0 if none) */
  unsigned harmonics;       /* candidates on it */
  unsigned candidates;      /* candidate lines in the range (on a comb or not) */
  double strongest_hz;      /* the comb's strongest line [Hz] and its ratio to the local background */
  double strongest_ratio;
  size_t strongest_bin;
  size_t bins_excluded;     /* bins marked in exclude */
  /* candidates on no comb (all of them when none was found), strongest first: a lone line (a slab's fundamental, a
   * machine's frequency) or the peak of a lightly damped mode; the identification tells them apart (modal.h) */
  unsigned n_lone;
  double lone_hz[HM_LINES_MAX_LONE], lone_ratio[HM_LINES_MAX_LONE];
  size_t lone_bin[HM_LINES_MAX_LONE];
} hm_lines_result;

typedef struct hm_lines_s *hm_lines;

/* For spectra of at most max_bins bins. HM_EDOMAIN (reason in why) for a bad configuration, HM_ENOMEM. */
hm_status hm_lines_create(const hm_lines_config *cfg, size_t max_bins, hm_lines *out, char *why, size_t why_len);
void hm_lines_destroy(hm_lines l);

/* Mark in exclude[0..n) the bins of one line at f_hz, ratio times its background, in a window of window_s seconds (the
 * width the comb's teeth get, above), widened by f_hz spread_rel on each side (a line of the track moves with the speed:
 * over a window whose speed ranged over spread_rel of its mean it covers that much); the number of bins newly marked. */
size_t hm_lines_mark(const hm_lines l, double f_hz, double ratio, double spread_rel, size_t n, double df_hz,
                     double window_s, unsigned char *exclude);

/* A line fitted to a peak: its frequency [rad per sample], complex amplitude in the DFT's units (X_j = A D(w_j -
 * omega) with D(d) = sum_{t<n} e^{-i d t}) and the harmonic F statistic (below). */
typedef struct {
  double omega;
  double amp_re, amp_im;
  double f_stat;
} hm_lines_sinusoid;

/*
 * Is the peak at bin k a sinusoid (a harmonic F test)? The rectangular window of n_samples samples (zero-padded to
 * nfft) turns a line at w into the kernel D(w_j - w) at the bins j about it: the complex DFT (re, im) over k -+ 3
 * bins per 1 / T is fitted by one line (its frequency within -+0.6 of 1 / T of the bin, its complex amplitude by least
 * squares) and F = (power explained / 2) / (residual / (2 (2m + 1) - 2)) returned with it for the 2m + 1 bins. Over a
 * spectrum that is smooth across them (a mode broader than about 3 / T, noise) the bins are independent and F follows
 * F(2, 2 (2m + 1) - 2) (12 degrees of freedom without padding: P(F > 20) = 1.5e-4, a little more for the search in
 * frequency); a line leaves the continuum only and F grows with its power. A mode narrower than about 1 / T is,
 * within one window, a line too. HM_EINVAL for bad arguments or a bin too near either end (out untouched).
 */
hm_status hm_lines_fit_sinusoid(const double *re, const double *im, size_t nbins, size_t k, size_t n_samples,
                                size_t nfft, hm_lines_sinusoid *out);
/* Subtract a fitted line from the DFT over bins k_lo..k_hi: its main lobe and its leakage, the continuum beneath
 * left (a line set aside this way biases no fit beside it; leaving its bins out leaves its side lobes). */
void hm_lines_subtract(double *re, double *im, size_t k_lo, size_t k_hi, size_t n_samples, size_t nfft,
                       const hm_lines_sinusoid *line);

/*
 * Look for a comb in power[0..n) (bin k at k df_hz) between f_lo_hz and f_hi_hz, for a window of window_s seconds
 * whose speed ranged over spread_rel of its mean (its teeth widened by that, hm_lines_mark). exclude[0..n) is set to
 * 1 on the bins to leave out (all of them 0 when no comb is found). HM_EINVAL for NULL
 * arguments, n above max_bins, or a non-positive df_hz or window_s; outputs untouched then.
 */
hm_status hm_lines_find(hm_lines l, const double *power, size_t n, double df_hz, double window_s, double f_lo_hz,
                        double f_hi_hz, double spread_rel, unsigned char *exclude, hm_lines_result *out);

#ifdef __cplusplus
}
#endif

#endif
