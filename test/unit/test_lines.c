/* Periodic track excitation (lines.h): combs of sinusoids of known frequencies in white noise, computed with a direct
 * DFT here (independent of the core's FFT). */
#include <stdlib.h>
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/lines.h"
#include "hunting_monitor/model.h"

enum { N = 4000 };             /* 40 s at 100 Hz */
static const double FS = 100.0, T = 40.0;
static double x[N], power[N / 2 + 1], cos_t[N], sin_t[N];
static unsigned char excl[N / 2 + 1];

/* White noise of unit variance plus sinusoids (frequency, amplitude, random phase); its periodogram |X_k|^2. */
static void spectrum_of(const double *f, const double *amp, int n_lines) {
  for (int i = 0; i < N; ++i) x[i] = hm_test_gauss();
  for (int l = 0; l < n_lines; ++l) {
    const double ph = hm_test_uniform(0.0, 2.0 * HM_PI);
    for (int i = 0; i < N; ++i) x[i] += amp[l] * sin(2.0 * HM_PI * f[l] * i / FS + ph);
  }
  if (sin_t[1] == 0.0)
    for (int j = 0; j < N; ++j) cos_t[j] = cos(2.0 * HM_PI * j / N), sin_t[j] = sin(2.0 * HM_PI * j / N);
  for (int k = 0; k <= N / 2; ++k) {
    double re = 0.0, im = 0.0;
    for (int i = 0, j = 0; i < N; ++i, j = (j + k) % N) {
      re += x[i] * cos_t[j];
      im -= x[i] * sin_t[j];
    }
    power[k] = re * re + im * im;
  }
}

static hm_lines make(void) {
  hm_lines_config c;
  hm_lines_config_default(&c);
  hm_lines l = NULL;
  HM_CHECK(hm_lines_create(&c, N / 2 + 1, &l, NULL, 0) == HM_OK, "create");
  return l;
}

/* 25 m joints at 420 km/h: harmonics of 4.6667 Hz (1..6, amplitudes 0.3 down to 0.15: 20 to 90 times the noise
 * floor in a bin) are found as one comb with the fundamental to 2 mHz, L = V / f1 = 25.0 m; every multiple's bin is
 * excluded, bins between them are not. */
static void comb_of_joints(void) {
  hm_lines l = make();
  const double f1 = 116.6667 / 25.0;
  double f[6], a[6];
  for (int m = 1; m <= 6; ++m) f[m - 1] = m * f1, a[m - 1] = 0.3 - 0.03 * (m - 1);
  spectrum_of(f, a, 6);
  hm_lines_result r;
  HM_CHECK(hm_lines_find(l, power, N / 2 + 1, FS / N, T, 2.5, 30.0, 0.0, excl, &r) == HM_OK, "find");
  HM_CHECK(r.found && r.harmonics >= 5, "comb found %d with %u harmonics (%u candidates)", r.found, r.harmonics,
           r.candidates);
  HM_CHECK_DELTA(r.fundamental_hz, f1, 2e-3, "fundamental");
  HM_CHECK_DELTA(116.6667 / r.fundamental_hz, 25.0, 0.02, "wavelength [m]");
  int all = 1;
  for (int m = 1; m <= 6; ++m) all &= excl[(size_t)lround(m * f1 * N / FS)];
  HM_CHECK(all, "every harmonic's bin excluded");
  HM_CHECK(!excl[(size_t)lround(1.5 * f1 * N / FS)] && !excl[(size_t)lround(2.5 * f1 * N / FS)],
           "bins between the teeth kept");
  printf("  joints: f1 %.4f Hz (true %.4f), %u harmonics, %zu bins excluded, strongest %.2f Hz at %.0fx\n",
         r.fundamental_hz, f1, r.harmonics, r.bins_excluded, r.strongest_hz, r.strongest_ratio);
  hm_lines_destroy(l);
}

/* One narrow peak is not a comb (a mode near the Hopf speed is as narrow as a line): a single sinusoid 90x the floor
 * at 14.1 Hz, and white noise alone over 20 spectra, give no comb and exclude nothing. The comb is the fundamental,
 * not a sub-harmonic, when two unrelated sinusoids join it. */
static void single_lines_and_noise_are_not_combs(void) {
  hm_lines l = make();
  hm_lines_result r;
  const double f_mode = 14.1, a_mode = 0.3;
  spectrum_of(&f_mode, &a_mode, 1);
  HM_CHECK(hm_lines_find(l, power, N / 2 + 1, FS / N, T, 2.5, 30.0, 0.0, excl, &r) == HM_OK && !r.found &&
               r.bins_excluded == 0 && r.candidates >= 1,
           "one line: found %d, %u candidates", r.found, r.candidates);
  int combs = 0;
  unsigned candidates = 0;
  for (int s = 0; s < 20; ++s) {
    spectrum_of(NULL, NULL, 0);
    hm_lines_find(l, power, N / 2 + 1, FS / N, T, 2.5, 30.0, 0.0, excl, &r);
    combs += r.found;
    candidates += r.candidates;
  }
  HM_CHECK(combs == 0, "%d combs in 20 noise spectra", combs);
  printf("  noise: %u chance candidates in 20 spectra of 2750 bins (exp(-8) x 2750 = 0.9 each), no comb\n", candidates);
  const double f[] = {6.0, 12.0, 18.0, 24.0, 9.7, 21.3}, a[] = {0.25, 0.25, 0.25, 0.25, 0.25, 0.25};
  spectrum_of(f, a, 6);
  hm_lines_find(l, power, N / 2 + 1, FS / N, T, 2.5, 30.0, 0.0, excl, &r);
  HM_CHECK(r.found && fabs(r.fundamental_hz - 6.0) < 2e-3, "fundamental %g, not a sub-harmonic", r.fundamental_hz);
  hm_lines_destroy(l);
}

/* One tooth rule for the comb (lines.h): a comb of 3 Hz whose spacing is found as a candidate over n = 2 (6 Hz / 2),
 * with its fifth multiple missing and a peak 0.05 Hz beside where it would be (15.05 Hz: beyond the search's
 * (0.5 + 0.5 * 5 / 2) / T = 0.044 Hz, within (0.5 + 0.5 * 5) / T = 0.075 Hz). On a flat spectrum with one-bin peaks
 * (their frequencies exact at bin centres: no parabola shift) the comb's least-squares spacing is exactly 3 Hz
 * through the five matched teeth (with the stray peak it would be 417.25 / 139 = 3.0018 Hz), and the stray peak is a
 * lone line. */
static void one_tooth_rule_for_the_comb(void) {
  hm_lines l = make();
  const double teeth[] = {6.0, 9.0, 12.0, 18.0, 21.0, 15.05};
  for (int k = 0; k <= N / 2; ++k) power[k] = 1.0;
  for (int i = 0; i < 6; ++i) power[(int)lround(teeth[i] * T)] = 100.0;
  hm_lines_result r;
  HM_CHECK(hm_lines_find(l, power, N / 2 + 1, FS / N, T, 5.0, 22.0, 0.0, excl, &r) == HM_OK && r.found, "found");
  HM_CHECK_DELTA(r.fundamental_hz, 3.0, 1e-9, "the spacing through the matched teeth");
  HM_CHECK(r.harmonics == 5, "teeth matched: %u", r.harmonics);
  HM_CHECK(r.n_lone == 1 && fabs(r.lone_hz[0] - 15.05) < 1e-9, "the stray peak a lone line: %u at %g", r.n_lone,
           r.n_lone ? r.lone_hz[0] : 0.0);
  hm_lines_destroy(l);
}

static void bad_configuration_and_input(void) {
  hm_lines_config c;
  char why[128];
  hm_lines_config_default(&c);
  c.min_harmonics = 1;
  HM_CHECK(hm_lines_config_validate(&c, why, sizeof why) == HM_EDOMAIN && strstr(why, "min_harmonics"), "%s", why);
  hm_lines_config_default(&c);
  c.candidate_ratio = NAN;
  hm_lines l = (hm_lines)0x1;
  HM_CHECK(hm_lines_create(&c, 100, &l, why, sizeof why) == HM_EDOMAIN && l == (hm_lines)0x1 &&
               strstr(why, "candidate_ratio"),
           "%s", why);
  l = make();
  hm_lines_result r;
  memset(&r, 0x5a, sizeof r);
  const hm_lines_result before = r;
  HM_CHECK(hm_lines_find(l, power, N, FS / N, T, 2.5, 30.0, 0.0, excl, &r) == HM_EINVAL &&
               memcmp(&r, &before, sizeof r) == 0,
           "more bins than created for");
  HM_CHECK(hm_lines_find(l, power, N / 2 + 1, 0.0, T, 2.5, 30.0, 0.0, excl, &r) == HM_EINVAL, "zero bin width");
  HM_CHECK(hm_lines_find(l, NULL, N / 2 + 1, FS / N, T, 2.5, 30.0, 0.0, excl, &r) == HM_EINVAL, "NULL power");
  hm_lines_destroy(l);
}

int main(void) {
  HM_RUN(comb_of_joints);
  HM_RUN(single_lines_and_noise_are_not_combs);
  HM_RUN(one_tooth_rule_for_the_comb);
  HM_RUN(bad_configuration_and_input);
  HM_TEST_EXIT();
}
