/* Track lines in the distance domain (order_lines.h), against signals built in closed form: a line of the track is
 * A cos(2 pi s(t) / L + phi) with s(t) the distance of a uniformly accelerated train, v0 t + a t^2 / 2; a mode as
 * narrow as a line is a sinusoid fixed in time. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/model.h"
#include "hunting_monitor/order_lines.h"

enum { N = 4000, NFFT = 4096 };
#define FS 100.0

static hm_order_lines make(void) {
  hm_order_lines_config c;
  hm_order_lines_config_default(&c);
  hm_lines_config lc;
  hm_lines_config_default(&lc);
  hm_order_lines o = NULL;
  HM_CHECK(hm_order_lines_create(&c, &lc, N, NFFT, &o, NULL, 0) == HM_OK, "create");
  return o;
}

/* white Gaussian noise of r.m.s. sd (an LCG and Box-Muller: the test's own) */
static double gauss(unsigned long long *st, double sd) {
  *st = *st * 6364136223846793005ULL + 1442695040888963407ULL;
  const double u1 = ((double)(*st >> 11) + 0.5) / 9007199254740992.0;
  *st = *st * 6364136223846793005ULL + 1442695040888963407ULL;
  const double u2 = ((double)(*st >> 11) + 0.5) / 9007199254740992.0;
  return sd * sqrt(-2.0 * log(u1)) * cos(2.0 * HM_PI * u2);
}

/* A ramp from v0 by dv over the window: a 6.45 m slab line (0.5 m/s^2), a sinusoid fixed at 14 Hz (0.3 m/s^2: a
 * mode at its Hopf speed looks so in one window) and noise. The line is taken out at 6.45 m; what stays is the
 * sinusoid and the noise (the residue of the line below 5% of its amplitude in r.m.s.); the fixed sinusoid is
 * not taken. */
static void ramp_line_taken_out(void) {
  hm_order_lines o = make();
  static double x[N], v[N], keep[N];
  const double L = 6.45, A = 0.5, v0 = 110.0, dv = 6.0, acc = dv / (N / FS);
  unsigned long long st = 7;
  for (int i = 0; i < N; ++i) {
    const double t = i / FS, s = v0 * t + 0.5 * acc * t * t;
    v[i] = v0 + acc * t;
    keep[i] = 0.3 * cos(2.0 * HM_PI * 14.0 * t + 0.4) + gauss(&st, 0.05);
    x[i] = A * cos(2.0 * HM_PI * s / L + 1.1) + keep[i];
  }
  hm_order_lines_result r;
  HM_CHECK(hm_order_lines_clean(o, x, v, N, FS, NFFT, 2.5, 30.0, &r) == HM_OK, "clean");
  HM_CHECK(r.n >= 1, "a line taken (%u)", r.n);
  int found = -1;
  for (unsigned q = 0; q < r.n; ++q) {
    HM_CHECK(fabs(r.f_hz[q] - 14.0) > 0.2, "the fixed sinusoid not taken (%g Hz)", r.f_hz[q]);
    if (fabs(r.wavelength_m[q] - L) < 0.05 * L) found = (int)q;
  }
  HM_CHECK(found >= 0, "the slab line among them");
  if (found >= 0) {
    HM_CHECK_REL(r.wavelength_m[found], L, 2e-3, "its wavelength");
    HM_CHECK_REL(r.amp_mps2[found], A, 0.05, "its amplitude");
    HM_CHECK(r.f_distance[found] >= 3.0 * r.f_time[found], "sharper in distance (F %g) than in time (F %g)",
             r.f_distance[found], r.f_time[found]);
  }
  HM_CHECK_REL(r.speed_mean_mps, v0 + 0.5 * dv, 1e-3, "the mean speed");
  double e = 0.0;
  for (int i = 0; i < N; ++i) e += (x[i] - keep[i]) * (x[i] - keep[i]);
  HM_CHECK(sqrt(e / N) < 0.05 * A / sqrt(2.0), "the line's residue %g r.m.s.", sqrt(e / N));
  hm_order_lines_destroy(o);
}

/* At one steady speed distance and time are the same axis: nothing is sharper in either, nothing is taken, x is
 * unchanged. */
static void steady_takes_nothing(void) {
  hm_order_lines o = make();
  static double x[N], v[N], x0[N];
  unsigned long long st = 11;
  for (int i = 0; i < N; ++i) {
    const double t = i / FS;
    v[i] = 120.0;
    x[i] = x0[i] = 0.5 * cos(2.0 * HM_PI * 120.0 * t / 6.45) + gauss(&st, 0.05);
  }
  hm_order_lines_result r;
  HM_CHECK(hm_order_lines_clean(o, x, v, N, FS, NFFT, 2.5, 30.0, &r) == HM_OK, "clean");
  HM_CHECK(r.n == 0, "nothing taken (%u)", r.n);
  HM_CHECK(memcmp(x, x0, sizeof x) == 0, "x unchanged");
  hm_order_lines_destroy(o);
}

/* Rail joints every 16.8 m (a comb: each joint a 1 m raised cosine of the acceleration) over a ramp of 120-126 m/s:
 * the harmonics m V / L in 2.5-30 Hz taken out, their wavelengths L / m. */
static void joints_comb(void) {
  hm_order_lines o = make();
  static double x[N], v[N];
  const double L = 16.8, v0 = 120.0, acc = 6.0 / (N / FS);
  unsigned long long st = 3;
  for (int i = 0; i < N; ++i) {
    const double t = i / FS, s = v0 * t + 0.5 * acc * t * t, p = fmod(s, L);
    v[i] = v0 + acc * t;
    /* a smooth bump per joint: the comb's harmonics fall off with frequency as a real joint's do */
    x[i] = (p < 1.0 ? 0.8 * (1.0 - cos(2.0 * HM_PI * p)) : 0.0) + gauss(&st, 0.05);
  }
  hm_order_lines_result r;
  HM_CHECK(hm_order_lines_clean(o, x, v, N, FS, NFFT, 2.5, 30.0, &r) == HM_OK, "clean");
  HM_CHECK(r.n >= 2, "harmonics taken (%u)", r.n);
  for (unsigned q = 0; q < r.n; ++q) {
    const double m = round(L / r.wavelength_m[q]);
    HM_CHECK(m >= 1.0 && fabs(r.wavelength_m[q] - L / m) < 0.01 * L / m, "wavelength %g is L / %g",
             r.wavelength_m[q], m);
  }
  hm_order_lines_destroy(o);
}

/* A long comb and a lone line together (review of issue #26: with the teeth listed first and a cap of 8, a 6.45 m
 * slab line beside 60 m joints was never examined): 60 m joints (a comb of 14 teeth in 2.5-30 Hz at 120 m/s) and
 * a 6.45 m line of 0.4 m/s^2 over a ramp of 120-126 m/s: the line taken out at 6.45 m, the comb's spacing V / 60. */
static void comb_and_lone_line(void) {
  hm_order_lines o = make();
  static double x[N], v[N];
  const double L = 60.0, Ls = 6.45, v0 = 120.0, acc = 6.0 / (N / FS);
  unsigned long long st = 5;
  for (int i = 0; i < N; ++i) {
    const double t = i / FS, s = v0 * t + 0.5 * acc * t * t, p = fmod(s, L);
    v[i] = v0 + acc * t;
    x[i] = (p < 1.0 ? 0.8 * (1.0 - cos(2.0 * HM_PI * p)) : 0.0) + 0.4 * cos(2.0 * HM_PI * s / Ls) + gauss(&st, 0.05);
  }
  hm_order_lines_result r;
  HM_CHECK(hm_order_lines_clean(o, x, v, N, FS, NFFT, 2.5, 30.0, &r) == HM_OK, "clean");
  int slab = 0;
  for (unsigned q = 0; q < r.n; ++q) slab |= fabs(r.wavelength_m[q] - Ls) < 0.005 * Ls;
  HM_CHECK(slab, "the 6.45 m line among the %u taken", r.n);
  HM_CHECK_REL(r.comb_fundamental_hz, r.speed_mean_mps / L, 0.01, "the comb's spacing");
  hm_order_lines_destroy(o);
}

/* With the window's DFT in time given (hm_order_lines_clean_dft; here a direct DFT, the sum over the samples at each
 * bin, not the FFT) the same lines are taken as when it computes it, and x is the same to rounding: the comb and
 * lone line above. */
static void dft_given_is_the_same(void) {
  hm_order_lines o = make();
  static double x[N], y[N], v[N], re[NFFT / 2 + 1], im[NFFT / 2 + 1], pw[NFFT / 2 + 1];
  const double L = 60.0, Ls = 6.45, v0 = 120.0, acc = 6.0 / (N / FS);
  unsigned long long st = 5;
  double mean = 0.0;
  for (int i = 0; i < N; ++i) {
    const double t = i / FS, s = v0 * t + 0.5 * acc * t * t, p = fmod(s, L);
    v[i] = v0 + acc * t;
    x[i] = y[i] = (p < 1.0 ? 0.8 * (1.0 - cos(2.0 * HM_PI * p)) : 0.0) + 0.4 * cos(2.0 * HM_PI * s / Ls) +
                  gauss(&st, 0.05);
    mean += x[i] / N;
  }
  for (int k = 0; k <= NFFT / 2; ++k) {
    double a = 0.0, b = 0.0;
    for (int i = 0; i < N; ++i) {
      const double ph = -2.0 * HM_PI * (double)((long)k * i % NFFT) / NFFT;
      a += (x[i] - mean) * cos(ph), b += (x[i] - mean) * sin(ph);
    }
    re[k] = a, im[k] = b, pw[k] = a * a + b * b;
  }
  hm_order_lines_result r, q;
  HM_CHECK(hm_order_lines_clean(o, x, v, N, FS, NFFT, 2.5, 30.0, &r) == HM_OK, "clean");
  HM_CHECK(hm_order_lines_clean_dft(o, y, v, N, FS, NFFT, 2.5, 30.0, re, im, pw, &q) == HM_OK, "clean, DFT given");
  HM_CHECK(r.n >= 2 && q.n == r.n, "lines taken: %u and %u", r.n, q.n);
  for (unsigned k = 0; k < r.n && k < q.n; ++k)
    HM_CHECK_REL(q.wavelength_m[k], r.wavelength_m[k], 1e-9, "a line's wavelength");
  double worst = 0.0;
  for (int i = 0; i < N; ++i) worst = fmax(worst, fabs(x[i] - y[i]));
  HM_CHECK(worst < 1e-9, "x differs by %g", worst);
  HM_CHECK(hm_order_lines_clean_dft(o, y, v, N, FS, NFFT, 2.5, 30.0, re, NULL, pw, &q) == HM_EINVAL, "NULL im");
  v[7] = NAN; /* (a NULL argument is HM_EINVAL whatever else is wrong, as for hm_order_lines_clean) */
  HM_CHECK(hm_order_lines_clean_dft(o, y, v, N, FS, NFFT, 2.5, 30.0, NULL, im, pw, &q) == HM_EINVAL, "NULL re");
  hm_order_lines_destroy(o);
}

static void bad_input(void) {
  hm_order_lines_config c;
  hm_order_lines_config_default(&c);
  hm_lines_config lc;
  hm_lines_config_default(&lc);
  char why[128] = "";
  hm_order_lines o = (hm_order_lines)&c; /* untouched on failure */
  c.dominance = 0.5;
  HM_CHECK(hm_order_lines_create(&c, &lc, N, NFFT, &o, why, sizeof why) == HM_EDOMAIN && strstr(why, "dominance"),
           "dominance below 1 refused: %s", why);
  hm_order_lines_config_default(&c);
  c.min_f = NAN;
  HM_CHECK(hm_order_lines_config_validate(&c, why, sizeof why) == HM_EDOMAIN && strstr(why, "min_f"), "min_f NaN");
  hm_order_lines_config_default(&c);
  HM_CHECK(hm_order_lines_create(&c, &lc, N, 3000, &o, why, sizeof why) == HM_EDOMAIN, "nfft not a power of two");
  HM_CHECK(hm_order_lines_create(&c, &lc, N, 2048, &o, why, sizeof why) == HM_EDOMAIN, "nfft below the window");
  HM_CHECK(o == (hm_order_lines)&c, "out untouched");
  o = make();
  static double x[N], v[N], x0[N];
  for (int i = 0; i < N; ++i) x[i] = x0[i] = sin(0.3 * i), v[i] = 100.0 + 0.001 * i;
  hm_order_lines_result r, r0;
  memset(&r, 0x5a, sizeof r);
  r0 = r;
  v[17] = 0.0;
  HM_CHECK(hm_order_lines_clean(o, x, v, N, FS, NFFT, 2.5, 30.0, &r) == HM_EDOMAIN, "a speed of 0");
  v[17] = NAN;
  HM_CHECK(hm_order_lines_clean(o, x, v, N, FS, NFFT, 2.5, 30.0, &r) == HM_EDOMAIN, "a speed NaN");
  v[17] = 100.0;
  HM_CHECK(hm_order_lines_clean(o, x, v, N + 1, FS, NFFT, 2.5, 30.0, &r) == HM_EINVAL, "a window too long");
  HM_CHECK(hm_order_lines_clean(o, x, v, N, FS, NFFT, 30.0, 2.5, &r) == HM_EINVAL, "a band upside down");
  HM_CHECK(hm_order_lines_clean(o, NULL, v, N, FS, NFFT, 2.5, 30.0, &r) == HM_EINVAL, "NULL");
  HM_CHECK(memcmp(x, x0, sizeof x) == 0 && memcmp(&r, &r0, sizeof r) == 0, "x and out untouched");
  hm_order_lines_destroy(o);
  hm_order_lines_destroy(NULL);
}

int main(void) {
  HM_RUN(ramp_line_taken_out);
  HM_RUN(steady_takes_nothing);
  HM_RUN(joints_comb);
  HM_RUN(comb_and_lone_line);
  HM_RUN(dft_given_is_the_same);
  HM_RUN(bad_input);
  HM_TEST_EXIT();
}
