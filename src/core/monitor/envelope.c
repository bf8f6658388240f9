/* The envelope of a narrow peak (envelope.h). */
#include "envelope.h"

#include <math.h>

#include "hunting_monitor/model.h" /* HM_PI */

size_t hm_envelope_work_size(size_t n, double fs_hz, double bandwidth_hz) {
  if (!(fs_hz > 0.0) || !(bandwidth_hz > 0.0) || !isfinite(fs_hz / bandwidth_hz)) return 0;
  const double len = round(1.5 * fs_hz / bandwidth_hz) - 1.0;
  return 2 * n + (len > 0.0 ? (size_t)len : 0);
}

hm_status hm_envelope_stats_of(const double *x, size_t n, double fs_hz, double f_hz, double bandwidth_hz,
                               double *work, size_t work_len, hm_envelope_stats *out) {
  if (!x || !work || !out) return HM_EINVAL;
  if (!(isfinite(fs_hz) && fs_hz > 0.0) || !(isfinite(f_hz) && f_hz > 0.0 && f_hz < 0.5 * fs_hz) ||
      !(isfinite(bandwidth_hz) && bandwidth_hz > 0.0 && bandwidth_hz <= f_hz && bandwidth_hz <= 0.5 * fs_hz - f_hz))
    return HM_EDOMAIN;
  /* the weights' equivalent noise bandwidth: 1.5 fs / (len + 1) */
  const double len_d = round(1.5 * fs_hz / bandwidth_hz) - 1.0;
  if (!(len_d >= 2.0) || !(2.0 * len_d <= (double)n)) return HM_EDOMAIN;
  const size_t len = (size_t)len_d;
  if (work_len < 2 * n + len) return HM_EINVAL;
  double mean = 0.0;
  for (size_t k = 0; k < n; ++k) mean += x[k];
  mean /= (double)n;
  if (!isfinite(mean)) return HM_EDOMAIN;
  double *zr = work, *zi = work + n, *h = work + 2 * n;
  const double dw = 2.0 * HM_PI * f_hz / fs_hz;
  for (size_t k = 0; k < n; ++k) {
    const double ph = dw * (double)k, v = x[k] - mean;
    zr[k] = v * cos(ph), zi[k] = -v * sin(ph);
  }
  /* the weights sin^2(pi (j + 1) / (len + 1)) over their sum (len + 1) / 2: unit gain at f_hz */
  for (size_t j = 0; j < len; ++j) {
    const double sj = sin(HM_PI * (double)(j + 1) / (double)(len + 1));
    h[j] = 2.0 * sj * sj / (double)(len + 1);
  }
  /* the outputs every len / 8 samples: the envelope's correlation time is the filter's length, and eight a length
   * estimate its moments as well as every sample does */
  double m2 = 0.0, m4 = 0.0;
  const size_t n_out = n - len + 1, stride = len / 8 > 1 ? len / 8 : 1;
  size_t count = 0;
  for (size_t s = 0; s < n_out; s += stride, ++count) {
    double re = 0.0, im = 0.0;
    for (size_t j = 0; j < len; ++j) re += h[j] * zr[s + j], im += h[j] * zi[s + j];
    const double p = re * re + im * im;
    m2 += p, m4 += p * p;
  }
  m2 /= (double)count, m4 /= (double)count;
  if (!(m2 > 0.0) || !isfinite(m4)) return HM_EDOMAIN;
  out->ratio = m4 / (m2 * m2);
  out->band_power = m2;
  return HM_OK;
}

double hm_envelope_line_ratio(double kappa) {
  if (!(kappa >= 0.0)) return NAN;
  if (isinf(kappa)) return 1.0;
  return (kappa * kappa + 4.0 * kappa + 2.0) / ((kappa + 1.0) * (kappa + 1.0));
}
