/* Radix-2 complex FFT (see fft.h). */
#include "fft.h"

#include <math.h>

#include "hunting_monitor/model.h"

void hm_fft_twiddles(double *cosw, double *sinw, size_t nmax) {
  for (size_t k = 0; k < nmax / 2; ++k) {
    cosw[k] = cos(2.0 * HM_PI * (double)k / (double)nmax);
    sinw[k] = sin(2.0 * HM_PI * (double)k / (double)nmax);
  }
}

void hm_fft(double *re, double *im, size_t n, const double *cosw, const double *sinw, size_t nmax) {
  for (size_t i = 1, j = 0; i < n; ++i) { /* bit reversal */
    size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j |= bit;
    if (i < j) {
      double t = re[i];
      re[i] = re[j];
      re[j] = t;
      t = im[i];
      im[i] = im[j];
      im[j] = t;
    }
  }
  for (size_t len = 2; len <= n; len <<= 1) {
    const size_t stride = nmax / len;
    for (size_t i = 0; i < n; i += len)
      for (size_t k = 0; k < len / 2; ++k) {
        const double c = cosw[k * stride], s = -sinw[k * stride];
        const size_t a = i + k, b = i + k + len / 2;
        const double tr = re[b] * c - im[b] * s, ti = re[b] * s + im[b] * c;
        re[b] = re[a] - tr;
        im[b] = im[a] - ti;
        re[a] += tr;
        im[a] += ti;
      }
  }
}
