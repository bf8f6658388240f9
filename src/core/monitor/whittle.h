/*
 * Private: the spectral model of the hunting-mode identification and its Whittle fit (modal.h says what it is for).
 *
 * Over the band's bins (angular frequency w_k, u_k = ln(w_k / w_ref), periodogram I_k of a window of T seconds) the
 * model is one or two lightly damped pole pairs over a smooth numerator, plus white sensor noise:
 *     S(w) = B(u) [ P(s1, w) + rho P(s2, w) ] + N,   B(u) = exp(c0 + c1 u + c2 u^2 + c3 u^3),
 * where a pair s = sigma + i w0 (a = -sigma >= 0) contributes, approximately, what its spectrum a / d(s, w), d =
 * |(iw - s)(iw - conj s)|^2, gives in the periodogram of a window of T seconds:
 *     P(s, w) = a_e / ((a_e^2 + (w - w0)^2)(a_e^2 + (w + w0)^2)),   a_e = a + HM_WHITTLE_LEAKAGE / T,
 * the Lorentzian smoothed by the window (a rectangular window's Fejer kernel has the area of a Lorentzian of any
 * width and the peak T / 2 of one of width 2 / T; Lorentzians convolved add their widths). For a T >> 1 this is the
 * rational spectrum a / d; for a T ~ 1 and below the peak keeps the window's width and height, so a mode near its
 * Hopf speed and a line (a = 0: a sinusoid of random phase) are points of one regular model and sigma's standard
 * error stays finite there (a Lorentzian alone narrows onto one bin as sigma -> 0 and its error diverges; the exact
 * kernel, with its nulls, makes the likelihood in w0 as rough as the bins are wide). The factor a_e makes B the
 * pair's power, whatever its damping. The parameters are theta = (sigma1, w01, c0, c1, c2, c3, ln N) for one pair
 * and (..., sigma2, w02, ln rho) for two (rho = 0: one pair); sigma <= 0. The second pair holds a resonance the
 * numerator cannot: a broad mode of the installation or the vehicle (a bogie frame's, 1-3 Hz wide) beside the
 * hunting mode, which a single pair would average with it.
 * Whittle's negative log-likelihood  L = sum_k ln S_k + I_k / S_k  is minimised by Levenberg-damped Fisher scoring
 * (J = d ln S / d theta, step (J'J + mu diag)^-1 J'(I/S - 1)); its Fisher information J'J is returned for the
 * standard errors (the caller scales them for a zero-padded periodogram).
 */
#ifndef HUNTING_MONITOR_WHITTLE_H
#define HUNTING_MONITOR_WHITTLE_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#if defined(__FAST_MATH__)
#error "whittle.h: hm_whittle_exp and the pass's NaN test need IEEE arithmetic (build without -ffast-math)"
#endif

/* The window's leakage as a width [1/s] times T (above). */
#define HM_WHITTLE_LEAKAGE 2.0

enum { HM_WHITTLE_NP1 = 7, HM_WHITTLE_NP2 = 10, HM_WHITTLE_MAX_NP = 10 };
enum { HM_W_SIGMA, HM_W_W0, HM_W_C0, HM_W_C1, HM_W_C2, HM_W_C3, HM_W_LN, HM_W_SIGMA2, HM_W_W02, HM_W_LNRHO };

typedef struct {
  const double *w, *u, *pgram; /* the bins: angular frequency [rad/s], ln(w / w_ref), periodogram (scaled) */
  size_t n;
  double window_s;             /* the data's length T [s] (the leakage's) */
} hm_whittle_data;

/* e^x for the numerator B(u), bin by bin in a loop the compiler can vectorise (libm's exp is a call per bin: 18% of
 * a pass): x = k ln 2 + r, |r| <= ln 2 / 2 (Cody-Waite, ln 2 in two parts), e^r by its Taylor polynomial to r^13 (the
 * remainder below 4e-18 relative), times 2^k built in the exponent's bits. Within 2 ulp of exp (test_whittle) for x
 * in [-708, 708]; outside (2^k beyond the exponent's range) and for NaN the caller takes libm's. */
static inline double hm_whittle_exp(double x) {
  const double shift = 0x1.8p52, t = x * 1.4426950408889634 + shift, k = t - shift;
  const double r = (x - k * 0x1.62e42fefa3800p-1) - k * 0x1.ef35793c76730p-45;
  double p = 1.0 / 6227020800.0;
  p = p * r + 1.0 / 479001600.0;
  p = p * r + 1.0 / 39916800.0;
  p = p * r + 1.0 / 3628800.0;
  p = p * r + 1.0 / 362880.0;
  p = p * r + 1.0 / 40320.0;
  p = p * r + 1.0 / 5040.0;
  p = p * r + 1.0 / 720.0;
  p = p * r + 1.0 / 120.0;
  p = p * r + 1.0 / 24.0;
  p = p * r + 1.0 / 6.0;
  p = p * r + 0.5;
  p = p * r + 1.0;
  p = p * r + 1.0;
  uint64_t bits; /* (unsigned: k < 0 wraps, where a signed shift would be undefined) */
  memcpy(&bits, &t, sizeof bits);
  bits = (bits - 0x4338000000000000u + 1023u) << 52; /* (t's low bits hold k) */
  double scale;
  memcpy(&scale, &bits, sizeof scale);
  return p * scale;
}

/* The number of parameters of a model of `poles` pairs (1 or 2). */
static inline unsigned hm_whittle_np(unsigned poles) { return poles == 2 ? HM_WHITTLE_NP2 : HM_WHITTLE_NP1; }

/* S(w) of theta at one angular frequency w [rad/s] (u = ln(w / w_ref)). */
double hm_whittle_spectrum(const double *theta, unsigned poles, double window_s, double w, double u);

/* The negative log-likelihood of theta over d's bins. */
double hm_whittle_objective(const hm_whittle_data *d, unsigned poles, const double *theta);

/* The noise's floor, ln N (far below any signal: the noise may be absent). */
#define HM_WHITTLE_LN_FLOOR (-60.0)
/* A noise this far below the periodogram's mean, in ln, is negligible: d ln S / d ln N vanishes there. */
#define HM_WHITTLE_LN_NEGLIGIBLE (-10.0)

/* Minimise from theta (updated in place) by at most max_iter scoring steps; converged when an accepted step changes
 * the objective by less than tol (relative) or no step can lower it. A negligible noise can be a trap:
 * hm_whittle_reseed_noise. The objective in *obj, the Fisher information in
 * fisher (np x np, row-major with stride HM_WHITTLE_MAX_NP), the steps in *iters. 1 if converged, else 0. */
int hm_whittle_score(const hm_whittle_data *d, unsigned poles, double *theta, double tol, unsigned max_iter,
                     double *obj, double fisher[HM_WHITTLE_MAX_NP][HM_WHITTLE_MAX_NP], unsigned *iters);

/* The retry's noise, in ln, against the periodogram's mean (e^-3: a twentieth). */
#define HM_WHITTLE_RESEED_LN (-3.0)

/* A converged fit theta (its objective *obj, its Fisher information fisher) whose noise is negligible
 * (HM_WHITTLE_LN_NEGLIGIBLE below the periodogram's mean, in ln) scored again by at most max_iter steps (added to
 * *iters) from a noise of HM_WHITTLE_RESEED_LN against that mean and a flat background at the level the cubic had at
 * the (first) pair's frequency; theta, *obj and fisher replaced if that converges lower. 1 if replaced. Where the
 * noise is negligible d ln S / d ln N vanishes: steps in ln N crawl (about 1 a step, each lowering the objective by
 * less than any tolerance) or go on down to the floor, and a negligible noise can be a local minimum (the objective
 * rising as noise is added, a curved background holding the floor) where a noise the size of the spectrum fits far
 * better (review of 2026-12-04: 1.8 in the objective, a decay rate of -5.72 for -6.54 1/s, twelve fits in a row).
 * One retry finds most of them, not every one: over 1728 synthetic trapped fits 876 ended above the multi-start
 * optimum and 43 still do, most with a noise as large as the median periodogram (test_whittle). */
int hm_whittle_reseed_noise(const hm_whittle_data *d, unsigned poles, double *theta, double tol, unsigned max_iter,
                            double *obj, double fisher[HM_WHITTLE_MAX_NP][HM_WHITTLE_MAX_NP], unsigned *iters);

/* The covariance's diagonal (the inverse of the np x np Fisher information), each times scale; INFINITY where it is
 * singular. */
void hm_whittle_variances(const double fisher[HM_WHITTLE_MAX_NP][HM_WHITTLE_MAX_NP], unsigned np, double scale,
                          double *var);

/* A one-pair start: the peak of the periodogram smoothed over +-halfwidth bins, decay rate sigma0, flat numerator. */
void hm_whittle_cold_start(const hm_whittle_data *d, size_t halfwidth_bins, double sigma0, double *theta);

/* A two-pair start from a one-pair fit th1: at its frequency, a narrower pair (narrow sigma, 0 < narrow < 1) holding
 * 70% of its peak and a broader one (sigma / narrow - 2 1/s) the rest. */
void hm_whittle_split_start(const double *th1, double window_s, double narrow, double *theta2);

/* Pair k's (0 or 1) spectral peak B(u0) P(s, w0) in the periodogram's units. */
double hm_whittle_peak(const double *theta, unsigned pair, double window_s, double w_ref);

#endif
