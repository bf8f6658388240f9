/* Private: an in-place radix-2 complex FFT (forward, e^{-i}), shared by the hunting-mode identification and the
 * track generator. Twiddles for the largest size nmax (a power of two) serve every smaller power of two. */
#ifndef HUNTING_MONITOR_FFT_H
#define HUNTING_MONITOR_FFT_H

#include <stddef.h>

/* cosw, sinw: nmax / 2 values each. */
void hm_fft_twiddles(double *cosw, double *sinw, size_t nmax);
/* n a power of two <= nmax. */
void hm_fft(double *re, double *im, size_t n, const double *cosw, const double *sinw, size_t nmax);
/* The FFT of n real samples re[0..n) (n a power of two, 4 <= n <= nmax) through one complex FFT of n / 2 points (the
 * even and odd samples as real and imaginary parts, then separated): X[k] = re[k] + i im[k] for k = 0..n/2 (re and im
 * hold at least n / 2 + 1 values; im's input is ignored). About half the work of hm_fft on the zero-extended input. */
void hm_fft_real(double *re, double *im, size_t n, const double *cosw, const double *sinw, size_t nmax);

#endif
