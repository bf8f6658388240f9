/* The envelope of a narrow peak (src/core/monitor/envelope.h, private) against closed forms: a pure line's ratio 1
 * and power A^2 / 4, a Gaussian narrow-band process's ratio 2 (|z|^2 exponential), a line over white noise's
 * (kappa^2 + 4 kappa + 2) / (kappa + 1)^2 with kappa from the line's and the noise's powers (L = A^2 / 4; P the
 * noise's two-sided density s^2 / fs times the band); a line sweeping inside the band keeps its ratio; the filter's
 * band its equivalent noise bandwidth (white noise's power in it). */
#include <stdlib.h>

#include "hm_test.h"
#include "hunting_monitor/model.h"

#include "envelope.h" /* private to the core */

enum { N_MAX = 200000 };
static double x[N_MAX], work[2 * N_MAX + 4096];

/* A pole pair of decay rate sigma at f_hz driven by white noise (its discrete-time twin, r = e^{sigma / fs}) into
 * y[0..n), 3000 samples of start-up dropped; unit variance. */
static void mode(double *y, size_t n, double fs, double sigma, double f_hz) {
  const double r = exp(sigma / fs), th = 2.0 * HM_PI * f_hz / fs, a1 = 2.0 * r * cos(th), a2 = -r * r;
  double y1 = 0.0, y2 = 0.0, ss = 0.0;
  for (size_t k = 0; k < n + 3000; ++k) {
    const double v = a1 * y1 + a2 * y2 + hm_test_gauss();
    y2 = y1, y1 = v;
    if (k >= 3000) y[k - 3000] = v, ss += v * v;
  }
  const double sd = sqrt(ss / (double)n);
  for (size_t k = 0; k < n; ++k) y[k] /= sd;
}

static void closed_forms(void) {
  const double fs = 100.0, f = 13.0, B = 1.0;
  hm_envelope_stats s;
  /* a pure line: ratio 1, power A^2 / 4 */
  const size_t n = 4000;
  for (size_t k = 0; k < n; ++k) x[k] = 2.0 * cos(2.0 * HM_PI * f * (double)k / fs + 0.3);
  HM_CHECK(hm_envelope_stats_of(x, n, fs, f, B, work, sizeof work / sizeof *work, &s) == HM_OK, "a line");
  HM_CHECK_DELTA(s.ratio, 1.0, 1e-6, "a line's ratio");
  HM_CHECK_REL(s.band_power, 1.0, 1e-3, "a line's power A^2 / 4");
  /* a Gaussian process: 2 (a long record: 2000 s) */
  const size_t nl = 200000;
  mode(x, nl, fs, -1.0, f);
  HM_CHECK(hm_envelope_stats_of(x, nl, fs, f, B, work, sizeof work / sizeof *work, &s) == HM_OK, "a mode");
  printf("  a mode (-1 1/s) over 2000 s: ratio %.4f (2)\n", s.ratio);
  HM_CHECK_DELTA(s.ratio, 2.0, 0.06, "a Gaussian process's ratio");
  /* white noise of variance 1: its two-sided density 1 / fs, its power in the band B / fs */
  for (size_t k = 0; k < nl; ++k) x[k] = hm_test_gauss();
  HM_CHECK(hm_envelope_stats_of(x, nl, fs, f, B, work, sizeof work / sizeof *work, &s) == HM_OK, "white noise");
  /* (2000 s in a 1 Hz band: about 2000 independent values, a relative error of 2.2%: three of them allowed) */
  HM_CHECK_REL(s.band_power, B / fs, 0.07, "white noise's power in the band: the equivalent noise bandwidth");
  /* a line over white noise: kappa = (A^2 / 4) / (s^2 / fs * B) */
  const double amps[3] = {0.3, 0.6, 1.5}, sd = 2.0;
  for (int i = 0; i < 3; ++i) {
    for (size_t k = 0; k < nl; ++k) x[k] = amps[i] * cos(2.0 * HM_PI * f * (double)k / fs) + sd * hm_test_gauss();
    HM_CHECK(hm_envelope_stats_of(x, nl, fs, f, B, work, sizeof work / sizeof *work, &s) == HM_OK, "line + noise");
    const double kappa = 0.25 * amps[i] * amps[i] / (sd * sd / fs * B), ref = hm_envelope_line_ratio(kappa);
    printf("  a line over white noise, kappa %.2f: ratio %.4f (%.4f)\n", kappa, s.ratio, ref);
    HM_CHECK_DELTA(s.ratio, ref, 0.04, "line over noise");
  }
  HM_CHECK_DELTA(hm_envelope_line_ratio(0.0), 2.0, 1e-15, "kappa 0");
  HM_CHECK_DELTA(hm_envelope_line_ratio(1.0), 7.0 / 4.0, 1e-15, "kappa 1");
  HM_CHECK(hm_envelope_line_ratio(INFINITY) == 1.0 && isnan(hm_envelope_line_ratio(-1.0)), "kappa's ends");
  /* a line sweeping 0.36 Hz in 20 s (a ramp's 2.8%, bogie_unstable_349): the phase runs away, the envelope stays */
  for (size_t k = 0; k < 2000; ++k) {
    const double t = (double)k / fs;
    x[k] = cos(2.0 * HM_PI * ((f - 0.18) * t + 0.5 * (0.36 / 20.0) * t * t));
  }
  HM_CHECK(hm_envelope_stats_of(x, 2000, fs, f, B, work, sizeof work / sizeof *work, &s) == HM_OK, "sweep");
  printf("  a line sweeping 0.36 Hz in 20 s: ratio %.4f (1)\n", s.ratio);
  HM_CHECK_DELTA(s.ratio, 1.0, 0.02, "a swept line's ratio");
}

static void bad_input(void) {
  hm_envelope_stats s = {.ratio = 7.0};
  for (size_t k = 0; k < 1000; ++k) x[k] = sin(0.3 * (double)k);
  const size_t wl = sizeof work / sizeof *work;
  HM_CHECK(hm_envelope_stats_of(NULL, 1000, 100.0, 13.0, 1.0, work, wl, &s) == HM_EINVAL, "NULL x");
  HM_CHECK(hm_envelope_stats_of(x, 1000, 100.0, 13.0, 1.0, work, 100, &s) == HM_EINVAL, "too little work");
  HM_CHECK(hm_envelope_stats_of(x, 1000, 100.0, 60.0, 1.0, work, wl, &s) == HM_EDOMAIN, "above Nyquist");
  HM_CHECK(hm_envelope_stats_of(x, 1000, 100.0, 13.0, 20.0, work, wl, &s) == HM_EDOMAIN, "a band wider than f");
  HM_CHECK(hm_envelope_stats_of(x, 1000, 100.0, 49.5, 2.0, work, wl, &s) == HM_EDOMAIN, "its image would pass");
  HM_CHECK(hm_envelope_stats_of(x, 200, 100.0, 13.0, 1.0, work, wl, &s) == HM_EDOMAIN, "shorter than the filter");
  HM_CHECK(hm_envelope_stats_of(x, 1000, NAN, 13.0, 1.0, work, wl, &s) == HM_EDOMAIN, "NaN rate");
  for (size_t k = 0; k < 1000; ++k) x[k] = 1.0;
  HM_CHECK(hm_envelope_stats_of(x, 1000, 100.0, 13.0, 1.0, work, wl, &s) == HM_EDOMAIN, "no power");
  x[5] = NAN;
  HM_CHECK(hm_envelope_stats_of(x, 1000, 100.0, 13.0, 1.0, work, wl, &s) == HM_EDOMAIN, "a NaN sample");
  HM_CHECK(s.ratio == 7.0, "out untouched on failure");
  HM_CHECK(hm_envelope_work_size(1000, 100.0, 1.0) == 2149 && hm_envelope_work_size(10, 0.0, 1.0) == 0, "work size");
}

int main(void) {
  HM_RUN(closed_forms);
  HM_RUN(bad_input);
  HM_TEST_EXIT();
}
