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

void hm_fft_real(double *re, double *im, size_t n, const double *cosw, const double *sinw, size_t nmax) {
  const size_t h = n / 2, stride = nmax / n;
  for (size_t k = 0; k < h; ++k) { /* z_k = x_2k + i x_2k+1 (ascending: re[2k], re[2k+1] are not yet overwritten) */
    im[k] = re[2 * k + 1];
    re[k] = re[2 * k];
  }
  hm_fft(re, im, h, cosw, sinw, nmax);
  /* X_k = E_k + W^k O_k with E_k = (Z_k + conj Z_h-k) / 2, O_k = (Z_k - conj Z_h-k) / 2i, W = e^{-2 pi i / n};
   * X_h-k = conj E_k + W^(h-k) conj O_k */
  const double z0r = re[0], z0i = im[0];
  re[0] = z0r + z0i, im[0] = 0.0;
  re[h] = z0r - z0i, im[h] = 0.0;
  for (size_t k = 1; k <= h / 2; ++k) {
    const size_t m = h - k;
    const double ar = re[k], ai = im[k], br = re[m], bi = im[m];
    const double er = 0.5 * (ar + br), ei = 0.5 * (ai - bi); /* E_k */
    const double or_ = 0.5 * (ai + bi), oi = -0.5 * (ar - br); /* O_k = (Z_k - conj Z_m) / 2i */
    const double c = cosw[k * stride], s = -sinw[k * stride]; /* W^k = c + i s */
    const double tr = or_ * c - oi * s, ti = or_ * s + oi * c;
    re[k] = er + tr, im[k] = ei + ti;
    /* W^m = -conj(W^k) for m = h - k: (-c + i s) conj O_k */
    const double ur = -c * or_ + s * oi, ui = s * or_ + c * oi;
    re[m] = er + ur, im[m] = -ei + ui;
  }
}
