/* Identification of the hunting mode (modal.h) against processes whose poles are known in closed form. */
#include <stdlib.h>
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/modal.h"
#include "hunting_monitor/model.h"

#include "fft.h" /* private to the core: the periodogram's real FFT */

/* A single-degree-of-freedom oscillator y'' + 2 zeta w y' + w^2 y = white noise, integrated by RK4 at 10 substeps
 * per sample with the force held over the sample (white up to far above the band), its acceleration sampled at fs
 * with white sensor noise of sensor_rel times the signal's r.m.s. Its poles are sigma = -zeta w, w_d = w sqrt(1 -
 * zeta^2): the reference. */
typedef struct {
  double y, yd, w, zeta;
} sdof;

static double sdof_step(sdof *s, double force, double h) {
  const double hh = h / 10.0;
  for (int k = 0; k < 10; ++k) {
    const double a1 = force - 2 * s->zeta * s->w * s->yd - s->w * s->w * s->y;
    const double y2 = s->y + 0.5 * hh * s->yd, v2 = s->yd + 0.5 * hh * a1;
    const double a2 = force - 2 * s->zeta * s->w * v2 - s->w * s->w * y2;
    const double y3 = s->y + 0.5 * hh * v2, v3 = s->yd + 0.5 * hh * a2;
    const double a3 = force - 2 * s->zeta * s->w * v3 - s->w * s->w * y3;
    const double y4 = s->y + hh * v3, v4 = s->yd + hh * a3;
    const double a4 = force - 2 * s->zeta * s->w * v4 - s->w * s->w * y4;
    s->y += hh / 6.0 * (s->yd + 2 * v2 + 2 * v3 + v4);
    s->yd += hh / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4);
  }
  return force - 2 * s->zeta * s->w * s->yd - s->w * s->w * s->y;
}

/* Twelve independent 40 s windows at each of three decay rates (-0.5, -2, -5 1/s at 14 Hz, damping ratios 0.006 to
 * 0.057, the range from near the Hopf speed to 100 km/h below it) at 1 kHz with 10% sensor noise: the mean decay
 * rate within 3 standard errors of the mean of the reference, the frequency likewise, and at least 75% of the
 * windows' 2-standard-error intervals covering the reference (95% if the errors are right). */
static void decay_rate_of_a_known_oscillator(void) {
  const double sigmas[] = {-0.5, -2.0, -5.0}, fs = 1000.0, f0 = 14.0;
  for (int i = 0; i < 3; ++i) {
    const double wd = 2.0 * HM_PI * f0, w = hypot(wd, sigmas[i]);
    sdof s = {0.0, 0.0, w, -sigmas[i] / w};
    hm_modal_config c;
    hm_modal_config_default(&c);
    hm_modal m = NULL;
    HM_CHECK(hm_modal_create(&c, fs, &m, NULL, 0) == HM_OK, "create");
    if (!m) return;
    double sum_s = 0.0, sum_f = 0.0, sum_se = 0.0, sum_fse = 0.0;
    int covered = 0, n = 0;
    double ms = 0.0; /* settle, and the signal's r.m.s. for the sensor noise */
    for (int k = 0; k < 20000; ++k) {
      const double a = sdof_step(&s, 1000.0 * hm_test_gauss(), 1.0 / fs);
      if (k >= 10000) ms += a * a / 10000.0;
    }
    const double sensor = 0.1 * sqrt(ms);
    for (int win = 0; win < 12; ++win) {
      hm_modal_reset(m);
      for (long k = 0; k < (long)(40.0 * fs); ++k) {
        const double a = sdof_step(&s, 1000.0 * hm_test_gauss(), 1.0 / fs);
        hm_modal_push(m, a + sensor * hm_test_gauss());
      }
      hm_mode_estimate e;
      HM_CHECK(hm_modal_fit(m, 40.0, 0.0, 1.0, &e) == HM_OK && e.valid, "sigma %g window %d: fit (valid %d)", sigmas[i], win,
               e.valid);
      if (!e.valid) continue;
      ++n;
      sum_s += e.decay_rate_1_s;
      sum_f += e.frequency_hz;
      sum_se += e.decay_rate_se_1_s;
      sum_fse += e.frequency_se_hz;
      covered += fabs(e.decay_rate_1_s - sigmas[i]) <= 2.0 * e.decay_rate_se_1_s;
    }
    if (n == 0) continue;
    const double mean_s = sum_s / n, se_mean = sum_se / n / sqrt((double)n);
    const double mean_f = sum_f / n, fse_mean = sum_fse / n / sqrt((double)n);
    printf("  sigma %5.2f: mean %6.3f (se of the mean %.3f), f %.4f Hz (%.4f), %d/%d intervals cover\n", sigmas[i],
           mean_s, se_mean, mean_f, fse_mean, covered, n);
    HM_CHECK_DELTA(mean_s, sigmas[i], 3.0 * se_mean, "mean decay rate");
    HM_CHECK_DELTA(mean_f, wd / (2.0 * HM_PI), 3.0 * fse_mean + 1e-3, "mean frequency");
    HM_CHECK(covered >= 9, "only %d of %d intervals cover the reference", covered, n);
    hm_modal_destroy(m);
  }
}

/* The same process at 500 Hz, 2 kHz and 5 kHz input gives the same mode (the decimation adapts); a rate change
 * restarts the window; white noise alone is not a mode. */
static void rates_and_no_mode(void) {
  hm_modal_config c;
  hm_modal_config_default(&c);
  const double rates[] = {500.0, 2000.0, 5000.0};
  for (int i = 0; i < 3; ++i) {
    const double fs = rates[i], wd = 2.0 * HM_PI * 12.0;
    sdof s = {0.0, 0.0, hypot(wd, 1.0), 1.0 / hypot(wd, 1.0)};
    hm_modal m = NULL;
    HM_CHECK(hm_modal_create(&c, fs, &m, NULL, 0) == HM_OK, "create at %g Hz", fs);
    if (!m) return;
    for (long k = 0; k < (long)(40.0 * fs); ++k) hm_modal_push(m, sdof_step(&s, 1000.0 * hm_test_gauss(), 1.0 / fs));
    hm_mode_estimate e;
    HM_CHECK(hm_modal_fit(m, 40.0, 0.0, 1.0, &e) == HM_OK && e.valid, "fit at %g Hz", fs);
    HM_CHECK_DELTA(e.decay_rate_1_s, -1.0, 4.0 * e.decay_rate_se_1_s, "decay rate");
    HM_CHECK_DELTA(e.frequency_hz, 12.0, 4.0 * e.frequency_se_hz + 1e-3, "frequency");
    HM_CHECK(hm_modal_set_rate(m, 1000.0) == HM_OK && !hm_modal_fit_due(m), "a new rate restarts");
    HM_CHECK(hm_modal_set_rate(m, 50.0) == HM_EDOMAIN, "50 Hz is below the decimated rate");
    hm_modal_destroy(m);
  }
  hm_modal m = NULL;
  hm_modal_create(&c, 1000.0, &m, NULL, 0);
  for (long k = 0; k < 40000; ++k) hm_modal_push(m, hm_test_gauss());
  hm_mode_estimate e;
  const hm_status st = hm_modal_fit(m, 40.0, 0.0, 1.0, &e);
  HM_CHECK(st == HM_ENOCONV || (st == HM_OK && !e.valid), "white noise taken for a mode: %g Hz, %g 1/s",
           e.frequency_hz, e.decay_rate_1_s);
  hm_modal_destroy(m);
}

/* Rail joints are not the mode (issue #18): the oscillator of the first test (sigma -2 1/s at 14 Hz) forced as well
 * by a comb of lines at multiples of 4.667 Hz (25 m joints at 420 km/h; the third on the mode's peak, 14.0 Hz), 12
 * windows of 40 s. Left out of the fit (the default), the decay rate's mean is within 3 standard errors of the
 * reference, 9 or more of the 12 intervals cover it and the comb's spacing is reported to 5 mHz; fitted with the
 * lines (reject_lines 0) the same windows fail that test (fits invalid, or intervals that miss the reference): the
 * failure this guards against. */
static void joints_are_not_the_mode(void) {
  const double sigma = -2.0, fs = 1000.0, wd = 2.0 * HM_PI * 14.0, w = hypot(wd, sigma), f1 = 116.6667 / 25.0;
  for (int reject = 1; reject >= 0; --reject) {
    sdof s = {0.0, 0.0, w, -sigma / w};
    hm_modal_config c;
    hm_modal_config_default(&c);
    c.reject_lines = reject;
    hm_modal m = NULL;
    HM_CHECK(hm_modal_create(&c, fs, &m, NULL, 0) == HM_OK, "create");
    if (!m) return;
    double ms = 0.0;
    for (int k = 0; k < 20000; ++k) {
      const double a = sdof_step(&s, 1000.0 * hm_test_gauss(), 1.0 / fs);
      if (k >= 10000) ms += a * a / 10000.0;
    }
    /* each harmonic's amplitude: a third of the response's r.m.s. (the one on the peak stands about 40x above the
     * mode's spectrum there in a 40 s window) */
    const double amp = sqrt(ms) / 3.0;
    double sum = 0.0, sum_se = 0.0, sum_f1 = 0.0, t = 0.0;
    int n = 0, covered = 0, combs = 0;
    for (int win = 0; win < 12; ++win) {
      hm_modal_reset(m);
      for (long k = 0; k < (long)(40.0 * fs); ++k, t += 1.0 / fs) {
        double lines = 0.0;
        for (int h = 1; h <= 5; ++h) lines += amp * sin(2.0 * HM_PI * h * f1 * t + h);
        hm_modal_push(m, sdof_step(&s, 1000.0 * hm_test_gauss(), 1.0 / fs) + lines);
      }
      hm_mode_estimate e;
      if (hm_modal_fit(m, 40.0, 0.0, 1.0, &e) != HM_OK || !e.valid) continue;
      ++n;
      sum += e.decay_rate_1_s;
      sum_se += e.decay_rate_se_1_s;
      covered += fabs(e.decay_rate_1_s - sigma) <= 2.0 * e.decay_rate_se_1_s;
      if (e.lines_found) ++combs, sum_f1 += e.line_fundamental_hz;
    }
    hm_modal_destroy(m);
    if (n == 0) {
      HM_CHECK(!reject, "no valid fit with the lines left out");
      continue;
    }
    const double mean = sum / n, se_mean = sum_se / n / sqrt((double)n);
    printf("  joints, lines %s: decay rate %.3f (se of the mean %.3f, reference %.1f), %d/%d intervals cover, comb in "
           "%d windows at %.4f Hz (true %.4f)\n",
           reject ? "left out" : "fitted", mean, se_mean, sigma, covered, n, combs, combs ? sum_f1 / combs : 0.0, f1);
    HM_CHECK(combs == n, "reject %d: comb found in %d of %d windows", reject, combs, n);
    if (combs) HM_CHECK_DELTA(sum_f1 / combs, f1, 5e-3, "comb spacing");
    const int good = n >= 10 && covered >= 9 && fabs(mean - sigma) <= 3.0 * se_mean;
    if (reject) {
      HM_CHECK(n >= 10, "only %d valid fits", n);
      HM_CHECK_DELTA(mean, sigma, 3.0 * se_mean, "decay rate with the lines left out");
      HM_CHECK(covered >= 9, "only %d of %d intervals cover the reference", covered, n);
    } else {
      HM_CHECK(!good, "fitted with the lines the identification is as good: the test lost its point");
    }
  }
}


/* A pole pair's exact discretisation (the coverage test's process): x_k = 2 r cos(w0 / fs) x_k-1 - r^2 x_k-2 + g e_k,
 * r = exp(sigma / fs), its spectrum the continuous pole sigma + i w0 over a smooth background. */
typedef struct {
  double a1, a2, x1, x2, g;
} pole_pair;

static pole_pair pole_pair_make(double sigma, double f_hz, double fs, double gain) {
  const double r = exp(sigma / fs), w = 2.0 * HM_PI * f_hz;
  pole_pair p = {2.0 * r * cos(w / fs), -r * r, 0.0, 0.0, gain};
  return p;
}

static double pole_pair_step(pole_pair *p) {
  const double x = p->a1 * p->x1 + p->a2 * p->x2 + p->g * hm_test_gauss();
  p->x2 = p->x1, p->x1 = x;
  return x;
}

/* One window of T seconds at fs of up to two pole pairs (gains g1, g2; g 0: absent), a sinusoid (amplitude a_line at
 * f_line) and white noise, after settling; its fit. */
static hm_status fit_window(hm_modal m, double fs, double T, pole_pair *p1, pole_pair *p2, double a_line,
                            double f_line, double noise, double *t, hm_mode_estimate *e) {
  hm_modal_reset(m);
  for (long k = 0; k < (long)(T * fs); ++k, *t += 1.0 / fs) {
    double x = noise * hm_test_gauss() + a_line * sin(2.0 * HM_PI * f_line * *t + 0.3);
    if (p1) x += pole_pair_step(p1);
    if (p2) x += pole_pair_step(p2);
    hm_modal_push(m, x);
  }
  return hm_modal_fit(m, T, 0.0, 1.0, e);
}

/* A lone line is not the mode (issue #26 item 1): a broad mode (-12 1/s at 13 Hz, the hunting mode 80 km/h below the
 * Hopf speed) with a sinusoid at 14 Hz on it (a slab's fundamental, 10-25 times the spectrum's local median), 10
 * windows of 40 s: the line is set aside (or, where the fit sat on it as a narrow mode, its narrow peak's reading
 * beside it is used, as the margin does for a line the model cannot produce there) and reported (its frequency to
 * 0.01 Hz, its amplitude to 10%), the decay rate's mean within 3 standard errors of -12; with lines not rejected the
 * same windows read the line (a decay rate over 3 times smaller in magnitude): the failure this guards against. */
static void a_lone_line_is_not_the_mode(void) {
  const double fs = 1000.0, T = 40.0, sigma = -6.0, a_line = 3.0;
  for (int reject = 1; reject >= 0; --reject) {
    hm_modal_config c;
    hm_modal_config_default(&c);
    c.reject_lines = reject;
    hm_modal m = NULL;
    HM_CHECK(hm_modal_create(&c, fs, &m, NULL, 0) == HM_OK, "create");
    if (!m) return;
    pole_pair p = pole_pair_make(sigma, 13.0, fs, 0.05);
    double t = 0.0, sum = 0.0, sum_se = 0.0, amp = 0.0, f_err = 0.0;
    int n = 0, lines = 0;
    for (int k = 0; k < 20000; ++k) pole_pair_step(&p);
    for (int win = 0; win < 10; ++win) {
      hm_mode_estimate e;
      if (fit_window(m, fs, T, &p, NULL, a_line, 14.0, 0.05, &t, &e) != HM_OK) continue;
      /* a narrow peak's line is not the mode here (14 Hz far from a mode that damped: the margin's model says so,
       * margin.h): the reading beside it is the window's */
      if (e.narrow_peak) hm_mode_estimate_use_reading(&e, &e.line_reading);
      if (!e.valid) continue;
      ++n;
      sum += e.decay_rate_1_s, sum_se += e.decay_rate_se_1_s;
      const double hz = e.narrow_peak ? e.narrow_peak_hz : e.lone_lines ? e.lone_line_hz[0] : 0.0;
      const double mps2 = e.narrow_peak ? e.narrow_peak_mps2 : e.lone_lines ? e.lone_line_mps2[0] : 0.0;
      if (hz > 0.0) ++lines, amp += mps2, f_err = fmax(f_err, fabs(hz - 14.0));
    }
    hm_modal_destroy(m);
    const double mean = n ? sum / n : 0.0, se = n ? sum_se / n / sqrt((double)n) : 0.0;
    printf("  a lone line, %s: %d valid, decay rate %.2f (se of the mean %.2f, reference %.1f), line in %d, %.3f m/s^2 "
           "(%.1f), off by %.4f Hz\n", reject ? "set aside" : "fitted", n, mean, se, sigma, lines,
           lines ? amp / lines : 0.0, a_line, f_err);
    if (reject) {
      HM_CHECK(n >= 8 && lines == n, "%d valid fits, the line in %d", n, lines);
      HM_CHECK_DELTA(mean, sigma, 3.0 * se, "decay rate beside the line");
      HM_CHECK(lines && fabs(amp / lines - a_line) <= 0.1 * a_line && f_err <= 0.01, "the line reported");
    } else {
      HM_CHECK(n < 8 || mean > sigma / 3.0, "with the line fitted: decay rate %.2f in %d windows", mean, n);
    }
  }
}

/* A line alone (a sinusoid at 14 Hz in white noise: the "identified" -0.036 +- 0.047 1/s, conicity 0.22 at
 * 400 km/h) is a narrow peak: the window's reading sits on it as narrow as a line (decay rate within two standard
 * errors of 0, the window's leakage aside) and the reading without it finds no mode; a near-Hopf mode (-0.1 1/s at
 * 14.2 Hz) is read with its decay rate within 3 standard errors of -0.1 (1/T of leakage allowed), whether or not its
 * peak passes for a line too (the margin then takes it for the mode where its conicity is supported: test_margin). */
static void a_line_alone_and_a_narrow_mode(void) {
  const double fs = 1000.0, T = 40.0;
  hm_modal_config c;
  hm_modal_config_default(&c);
  hm_modal m = NULL;
  HM_CHECK(hm_modal_create(&c, fs, &m, NULL, 0) == HM_OK, "create");
  if (!m) return;
  double t = 0.0;
  int narrow = 0, aside = 0, taken = 0, beside = 0, enveloped = 0;
  double worst_ratio = 0.0;
  for (int win = 0; win < 10; ++win) {
    hm_mode_estimate e;
    if (fit_window(m, fs, T, NULL, NULL, 1.0, 14.0, 1.0, &t, &e) != HM_OK) continue;
    narrow += e.narrow_peak && fabs(e.narrow_peak_hz - 14.0) < 0.01 &&
              fabs(e.decay_rate_1_s) <= 2.0 * e.decay_rate_se_1_s + 0.5 / T;
    if (e.narrow_peak && isfinite(e.narrow_peak_envelope_ratio)) /* a line's envelope is steady (envelope.h) */
      ++enveloped, worst_ratio = fmax(worst_ratio, e.narrow_peak_envelope_ratio - e.narrow_peak_line_ratio);
    aside += (e.lone_lines > 0 && fabs(e.lone_line_hz[0] - 14.0) < 0.01) ||
             (e.lines_found && fabs(e.line_strongest_hz - 14.0) < 0.01);
    taken += e.valid && !e.narrow_peak && fabs(e.frequency_hz - 14.0) < 0.05; /* read as a mode, silently */
    beside += e.narrow_peak ? e.line_reading.valid : e.valid;
  }
  printf("  a sinusoid in noise, 10 windows: a narrow peak at zero decay in %d, set aside as a line in %d, read as a mode "
         "unflagged in %d, a chance mode beside it in %d\n", narrow, aside, taken, beside);
  HM_CHECK(narrow + aside >= 9 && taken == 0 && beside <= 2, "narrow %d, aside %d, taken %d, beside %d", narrow, aside,
           taken, beside);
  printf("  its envelope measured in %d narrow peaks: the ratio at most %.3f above a line's\n", enveloped, worst_ratio);
  HM_CHECK(enveloped >= narrow && worst_ratio <= 0.1, "a line's envelope: %d measured, %.3f above a line's", enveloped,
           worst_ratio);
  pole_pair p = pole_pair_make(-0.1, 14.2, fs, 0.01);
  for (int k = 0; k < 200000; ++k) pole_pair_step(&p);
  int n = 0;
  narrow = 0;
  double sum = 0.0, sum_se = 0.0;
  for (int win = 0; win < 10; ++win) {
    hm_mode_estimate e;
    if (fit_window(m, fs, T, &p, NULL, 0.0, 14.0, 0.01, &t, &e) != HM_OK || !e.valid) continue;
    ++n, narrow += e.narrow_peak, sum += e.decay_rate_1_s, sum_se += e.decay_rate_se_1_s;
  }
  hm_modal_destroy(m);
  const double mean = n ? sum / n : 0.0, se = n ? sum_se / n / sqrt((double)n) : 1.0;
  printf("  a mode at -0.1 1/s: %d valid, a narrow peak in %d, decay rate %.3f (se of the mean %.3f)\n", n, narrow,
         mean, se);
  HM_CHECK(n >= 9, "%d valid (narrow in %d: the margin takes it for the mode where supported, test_margin)", n, narrow);
  HM_CHECK_DELTA(mean, -0.1, 3.0 * se + 1.0 / T, "near-Hopf decay rate (the window's leakage 1/T allowed)");
}

/* Order tracking (modal.h's speed_tracking): on a ramp of 3.3% over a 40 s window (360 -> 372 km/h, the halves'
 * mean speeds in the ratio q = (1 + 0.75 r) / (1 + 0.25 r)) a slab's line at V / L (L = 7.14 m: 14.0 -> 14.47 Hz)
 * smears into a peak a single pair reads as a mode; its frequency moves as the speed does, d ln f / d ln V = 1 by
 * construction, while a mode with fixed poles (-0.5 1/s at 14.2 Hz) does not move (0). Eight windows of each (a
 * smeared line's fit may not converge or read no valid mode): in at least five measured, the slope within 3 of its
 * standard errors of the reference, and the line's at least 3 standard errors from 0. */
static void a_peak_that_moves_with_the_speed(void) {
  const double fs = 1000.0, T = 40.0, r = 12.0 / 360.0, L = 7.14, q = (1.0 + 0.75 * r) / (1.0 + 0.25 * r);
  hm_modal_config c;
  hm_modal_config_default(&c);
  hm_modal m = NULL;
  HM_CHECK(hm_modal_create(&c, fs, &m, NULL, 0) == HM_OK, "create");
  if (!m) return;
  pole_pair bg = pole_pair_make(-8.0, 11.0, fs, 0.005);
  pole_pair p = pole_pair_make(-0.5, 14.2, fs, 0.01);
  for (int k = 0; k < 20000; ++k) pole_pair_step(&bg), pole_pair_step(&p);
  for (int kind = 0; kind < 2; ++kind) { /* 0: the line on the ramp; 1: the fixed mode */
    int n = 0, moved = 0;
    double worst = 0.0;
    for (int win = 0; win < 8; ++win) {
      hm_modal_reset(m);
      double phase = 0.0;
      for (long k = 0; k < (long)(T * fs); ++k) {
        const double v_mps = 100.0 * (1.0 + r * (double)k / (T * fs)); /* 360 km/h rising by r */
        phase += 2.0 * HM_PI * v_mps / L / fs;
        double x = 0.02 * hm_test_gauss() + pole_pair_step(&bg);
        x += kind == 0 ? 0.3 * sin(phase) : pole_pair_step(&p);
        hm_modal_push(m, x);
      }
      hm_mode_estimate e;
      const hm_status fst = hm_modal_fit(m, T, r, q, &e);
      if (fst != HM_OK || !e.valid || !isfinite(e.speed_tracking)) continue;
      const double ref = kind == 0 ? 1.0 : 0.0;
      ++n;
      worst = fmax(worst, fabs(e.speed_tracking - ref) / e.speed_tracking_se);
      moved += e.speed_tracking >= 3.0 * e.speed_tracking_se;
      if (n == 1)
        printf("  %s: peak %.2f Hz, decay %.2f 1/s, d ln f / d ln V %.2f +- %.2f (reference %.0f), lone %u\n",
               kind == 0 ? "a line on a ramp" : "a fixed mode", e.frequency_hz, e.decay_rate_1_s, e.speed_tracking,
               e.speed_tracking_se, ref, e.lone_lines);
    }
    HM_CHECK(n >= 5, "%s: measured in %d of 8 windows", kind == 0 ? "line" : "mode", n);
    HM_CHECK(worst <= 3.0, "%s: the slope %.1f standard errors from its reference", kind == 0 ? "line" : "mode", worst);
    HM_CHECK(kind == 0 ? moved == n : moved == 0, "%s: moved in %d of %d", kind == 0 ? "line" : "mode", moved, n);
  }
  /* a steady speed (q 1) measures nothing */
  hm_mode_estimate e;
  HM_CHECK(hm_modal_fit(m, T, 0.0, 1.0, &e) == HM_OK && isnan(e.speed_tracking), "steady: not measured");
  hm_modal_destroy(m);
}

/* A strong line whose frequency moves in the window, beside a damped mode (issue #26: a 6.76 m slab's line at 20.8 Hz on
 * a ramp of 0.3 km/h/s from 508 km/h, its amplitude 1.6 m/s^2 over a mode of about 1 m/s^2 r.m.s., read the mode of
 * -3.5 1/s at 14.1 Hz as -1.5 +- 0.3): the line sweeps 0.3 Hz in 20 s and fails the F test of a fixed sinusoid; its
 * bins are left out, and the decay rate's mean over 10 windows is within 3 standard errors of the pole's (the
 * discretised pole pair's exact sigma). */
static void a_sweeping_line_beside_the_mode(void) {
  const double fs = 500.0, T = 20.0, sigma = -3.5, r = 7.0 / 508.0, L = 6.764;
  hm_modal_config c;
  hm_modal_config_default(&c);
  hm_modal m = NULL;
  HM_CHECK(hm_modal_create(&c, fs, &m, NULL, 0) == HM_OK, "create");
  if (!m) return;
  pole_pair p = pole_pair_make(sigma, 14.1, fs, 0.03);
  for (int k = 0; k < 20000; ++k) pole_pair_step(&p);
  double sum = 0.0, sum_se = 0.0, phase = 0.0, ms = 0.0;
  int n = 0;
  for (int win = 0; win < 10; ++win) {
    hm_modal_reset(m);
    for (long k = 0; k < (long)(T * fs); ++k) {
      const double v_mps = 508.0 / 3.6 * (1.0 + r * (double)k / (T * fs));
      phase += 2.0 * HM_PI * v_mps / L / fs;
      const double x_mode = pole_pair_step(&p);
      ms += x_mode * x_mode;
      hm_modal_push(m, 0.2 * hm_test_gauss() + x_mode + 1.6 * sin(phase));
    }
    hm_mode_estimate e;
    const hm_status fst = hm_modal_fit(m, T, r, 1.0 + 0.5 * r, &e);
    if (fst == HM_OK && e.narrow_peak) hm_mode_estimate_use_reading(&e, &e.line_reading); /* 21 Hz: the model says line */
    if (fst != HM_OK || !e.valid || fabs(e.frequency_hz - 14.1) > 1.0) continue;
    ++n, sum += e.decay_rate_1_s, sum_se += e.decay_rate_se_1_s;
  }
  hm_modal_destroy(m);
  const double mean = n ? sum / n : 0.0, se = n ? sum_se / n / sqrt((double)n) : 0.0;
  printf("  a sweeping line beside the mode: %d valid, decay rate %.2f (se of the mean %.2f, reference %.1f), mode "
         "r.m.s. %.2f m/s^2\n", n, mean, se, sigma, sqrt(ms / (10.0 * T * fs)));
  HM_CHECK(n >= 8, "%d valid fits", n);
  HM_CHECK_DELTA(mean, sigma, 3.0 * se, "decay rate beside a sweeping line");
}

/* A track line that sweeps across the mode's peak on a ramp (issue #26 item 3: a joint harmonic on a well-damped
 * mode read -2.5 1/s for -6.3): a 8.4 m line (16.8 m joints' second harmonic, 1 m/s^2) from 13.6 to 14.4 Hz over each
 * 40 s window (114.2 to 121.0 m/s, 0.6 km/h/s) on a mode of -5 1/s at 14.0 Hz. Spread over 0.8 Hz it stands nowhere
 * above its background and passes no test in time (F 2-7). With the speed of each sample given (hm_modal_set_speed)
 * it is taken out in distance (order_lines.h, F 57-122 there): the decay rate's mean over 8 windows within 3 standard
 * errors of the pole's; without the speed the same windows read the mode more than 3 standard errors lighter damped
 * (-2.55, the failure this guards against). A line of half that amplitude (-4.0 without the speed) passes the test in
 * distance (F >= 20) in 3 windows of 8: weaker lines stay. */
static void a_line_sweeping_across_the_mode(void) {
  const double fs = 500.0, T = 40.0, sigma = -5.0, L = 8.4, v0 = 13.6 * L, v1 = 14.4 * L;
  double mean[2], se[2];
  int valid[2], lines = 0;
  for (int with_speed = 0; with_speed < 2; ++with_speed) {
    hm_modal_config c;
    hm_modal_config_default(&c);
    hm_modal m = NULL;
    HM_CHECK(hm_modal_create(&c, fs, &m, NULL, 0) == HM_OK, "create");
    if (!m) return;
    hm_test_rng_state = 0x2545F4914F6CDD1Dull; /* the same noise for both */
    pole_pair p = pole_pair_make(sigma, 14.0, fs, 0.03);
    for (int k = 0; k < 20000; ++k) pole_pair_step(&p);
    double sum = 0.0, sum_se = 0.0, phase = 0.0;
    int n = 0;
    for (int win = 0; win < 8; ++win) {
      hm_modal_reset(m);
      for (long k = 0; k < (long)(T * fs); ++k) {
        const double v = v0 + (v1 - v0) * (double)k / (T * fs);
        if (with_speed) hm_modal_set_speed(m, v);
        phase += 2.0 * HM_PI * v / L / fs;
        hm_modal_push(m, 0.2 * hm_test_gauss() + pole_pair_step(&p) + 1.0 * sin(phase));
      }
      hm_mode_estimate e;
      const hm_status fst = hm_modal_fit(m, T, (v1 - v0) / (0.5 * (v0 + v1)), v1 / v0, &e);
      if (fst != HM_OK || !e.valid || fabs(e.frequency_hz - 14.0) > 1.0) continue;
      if (with_speed) lines += e.order_lines > 0 && fabs(e.order_line_wavelength_m - L) < 0.01 * L;
      ++n, sum += e.decay_rate_1_s, sum_se += e.decay_rate_se_1_s;
    }
    hm_modal_destroy(m);
    valid[with_speed] = n;
    mean[with_speed] = n ? sum / n : 0.0, se[with_speed] = n ? sum_se / n / sqrt((double)n) : 0.0;
  }
  printf("  a line sweeping across the mode: without the speed %d valid, %.2f (se of the mean %.2f); with it %d "
         "valid, %.2f (%.2f), the 8.4 m line taken out in %d; reference %.1f\n", valid[0], mean[0], se[0], valid[1],
         mean[1], se[1], lines, sigma);
  HM_CHECK(valid[1] >= 7 && lines >= 7, "%d valid fits, the line taken out in %d", valid[1], lines);
  HM_CHECK_DELTA(mean[1], sigma, 3.0 * se[1], "decay rate with the line taken out in distance");
  HM_CHECK(valid[0] == 0 || mean[0] - sigma > 3.0 * se[0], "without the speed the line biases the reading");
}

/* A broad mode beside the hunting mode (issue #26 item 2): the mode at -0.56 1/s, 14.24 Hz, and a broader pair (-8
 * 1/s) at the same frequency with 3.5% of its peak, 12 windows of 40 s. A single pair averages them (the issue: -2.54);
 * two pairs, chosen by likelihood, give the mode: the mean within 3 standard errors of -0.56 and at most -1.5 in
 * every window chosen so (the single pair's reading is -2.5). */
static void a_mode_beside_a_broad_resonance(void) {
  const double fs = 1000.0, T = 40.0, sigma = -0.56;
  hm_modal_config c;
  hm_modal_config_default(&c);
  hm_modal m = NULL;
  HM_CHECK(hm_modal_create(&c, fs, &m, NULL, 0) == HM_OK, "create");
  if (!m) return;
  /* peak heights ~ g^2 / sigma^2: the broad one's 3.5% of the narrow's at g2 / g1 = sqrt(0.035) 8 / 0.56 */
  pole_pair p1 = pole_pair_make(sigma, 14.24, fs, 1.0), p2 = pole_pair_make(-8.0, 14.24, fs, sqrt(0.035) * 8.0 / 0.56);
  for (int k = 0; k < 100000; ++k) pole_pair_step(&p1), pole_pair_step(&p2);
  double t = 0.0, sum = 0.0, sum_se = 0.0, worst = -INFINITY;
  int n = 0, two = 0;
  for (int win = 0; win < 12; ++win) {
    hm_mode_estimate e;
    if (fit_window(m, fs, T, &p1, &p2, 0.0, 14.0, 1.0, &t, &e) != HM_OK || !e.valid) continue;
    ++n;
    if (e.poles != 2) continue;
    ++two, sum += e.decay_rate_1_s, sum_se += e.decay_rate_se_1_s, worst = fmax(worst, -e.decay_rate_1_s);
  }
  hm_modal_destroy(m);
  const double mean = two ? sum / two : 0.0, se = two ? sum_se / two / sqrt((double)two) : 1.0;
  printf("  a broad mode beside the mode: %d valid, two pairs in %d, the mode's decay rate %.3f (se of the mean %.3f, "
         "reference %.2f), the most damped %.2f\n", n, two, mean, se, sigma, -worst);
  HM_CHECK(n >= 10 && two >= 8, "%d valid, two pairs in %d", n, two);
  HM_CHECK_DELTA(mean, sigma, 3.0 * se, "the mode beside a broad one");
  HM_CHECK(worst <= 1.5, "a window read %.2f 1/s", -worst);
}

/* The coverage of the decay rate's 2-standard-error intervals (issue #18), Monte Carlo over 480 windows: a pole pair at
 * 14 Hz with decay rates -0.05, -0.2, -1, -4 and -8 1/s (damping ratios 0.0006 to 0.09: from at the Hopf speed to 100
 * km/h below it, and the 380 km/h windows of worn wheels, -7.1 1/s), windows of 20 and 40 s, input rates 2000, 1250 and
 * 250 Hz (decimation 20, 12 and 2: the periodogram zero-padded by 1.02, 1.97 and 1.64), 16 windows each, plus 10% white
 * sensor noise. The process is the pole pair's exact discretisation, x_k = 2 r cos(w0 / fs) x_k-1 - r^2 x_k-2 + e_k
 * with r = exp(sigma / fs): its spectrum has the continuous pole s = sigma + i w0 over a smooth background. Reported:
 * the share of intervals that cover sigma with the statistical error alone and with the leakage term 1 / T added
 * linearly (as the margin adds it, margin.h); the test holds the latter to at least 90% overall and 75% in every cell. */
static void coverage_of_the_intervals(void) {
  const double sigmas[] = {-0.05, -0.2, -1.0, -4.0, -8.0}, windows[] = {20.0, 40.0}, rates[] = {2000.0, 1250.0, 250.0};
  const int per_cell = 16;
  int n_all = 0, cov_stat = 0, cov_leak = 0, worst = per_cell;
  for (int si = 0; si < 5; ++si) {
    int cell_stat = 0, cell_leak = 0, cell_n = 0;
    for (int wi = 0; wi < 2; ++wi)
      for (int ri = 0; ri < 3; ++ri) {
        const double fs = rates[ri], T = windows[wi], sg = sigmas[si], w0 = 2.0 * HM_PI * 14.0;
        const double r = exp(sg / fs), a1 = 2.0 * r * cos(w0 / fs), a2 = -r * r;
        hm_modal_config c;
        hm_modal_config_default(&c);
        c.window_s = T;
        c.min_window_s = fmin(c.min_window_s, T);
        hm_modal m = NULL;
        HM_CHECK(hm_modal_create(&c, fs, &m, NULL, 0) == HM_OK, "create");
        if (!m) return;
        double x1 = 0.0, x2 = 0.0;
        for (long k = 0; k < (long)(200.0 * fs); ++k) { /* settle: 10 decay times of the slowest */
          const double x = a1 * x1 + a2 * x2 + hm_test_gauss();
          x2 = x1, x1 = x;
        }
        int n = 0, in_stat = 0, in_leak = 0;
        for (int win = 0; win < per_cell; ++win) {
          hm_modal_reset(m);
          double ms = 0.0;
          const long ns = (long)(T * fs);
          static double buf[40 * 2000];
          for (long k = 0; k < ns; ++k) {
            const double x = a1 * x1 + a2 * x2 + hm_test_gauss();
            x2 = x1, x1 = x;
            buf[k] = x;
            ms += x * x / (double)ns;
          }
          const double sensor = 0.1 * sqrt(ms);
          for (long k = 0; k < ns; ++k) hm_modal_push(m, buf[k] + sensor * hm_test_gauss());
          hm_mode_estimate e;
          if (hm_modal_fit(m, T, 0.0, 1.0, &e) != HM_OK || !e.valid) continue;
          ++n;
          const double d = fabs(e.decay_rate_1_s - sg);
          in_stat += d <= 2.0 * e.decay_rate_se_1_s;
          in_leak += d <= 2.0 * (e.decay_rate_se_1_s + 1.0 / T);
        }
        hm_modal_destroy(m);
        HM_CHECK(n >= per_cell - 2, "sigma %g, %g s, %g Hz: only %d valid fits", sg, T, fs, n);
        cell_n += n, cell_stat += in_stat, cell_leak += in_leak;
        worst = in_leak * per_cell < worst * n ? in_leak * per_cell / (n ? n : 1) : worst;
        HM_CHECK(in_leak >= 0.75 * n, "sigma %g, %g s, %g Hz: %d/%d covered", sg, T, fs, in_leak, n);
      }
    printf("  sigma %5.2f: %3d windows, covered %5.1f%% (statistical error), %5.1f%% (with 1/T)\n", sigmas[si], cell_n,
           100.0 * cell_stat / cell_n, 100.0 * cell_leak / cell_n);
    n_all += cell_n, cov_stat += cell_stat, cov_leak += cell_leak;
  }
  printf("  all: %d windows, 2-sigma coverage %.1f%% (statistical error), %.1f%% (with 1/T)\n", n_all,
         100.0 * cov_stat / n_all, 100.0 * cov_leak / n_all);
  HM_CHECK(cov_leak >= 0.9 * n_all, "coverage %d/%d below 90%%", cov_leak, n_all);
}

/* The intervals on processes the fit does not assume (issue #26: coverage measured on misspecified processes, not
 * only on the single pole): 24 windows of 40 s at 1 kHz each of (a) the mode (-2 1/s, 14.0 Hz) with a line beside
 * it (15.2 Hz, 0.5 of the mode's r.m.s.: a slab's fundamental); (b) the mode at -0.56 1/s, 14.24 Hz, with a broad
 * pair (-8 1/s) at the same frequency at 3.5% of its peak, and (c) at 14% (the 505 and 549 km/h for a truth
 * of 473.8); (d) two close modes, -1.0 1/s at 14.0 Hz and -3.0 1/s at 14.6 Hz, equally driven (the least damped is
 * the truth). Covered: |sigma - truth| within two of the margin's errors (margin.h: the statistical one in quadrature
 * with 5% + 1 / T and the difference to a two-pair reading the likelihood could not rule out). (a) and (b) at least
 * 20 of 24 each (a true 95% gives fewer with probability 0.7%): 23 and 23. (c) and (d) are measured and printed, not
 * bounded: 20 and 18 of 24 (83%, 75%; 18 and 17 before a two-pair fit still descending counted as the alternative),
 * every miss on the damped side (one pair chosen, reading -1.4..-2.3 1/s for -0.56, or the two close modes averaged to
 * -1.0..-2.3 for -1.0): a known limit (docs/TESTS.md). */
static void coverage_on_misspecified_processes(void) {
  const double fs = 1000.0, T = 40.0;
  const char *names[4] = {"a line beside the mode", "a broad mode at 3.5%", "a broad mode at 14%", "two close modes"};
  const double truth[4] = {-2.0, -0.56, -0.56, -1.0};
  int all_n = 0, all_in = 0;
  for (int p = 0; p < 4; ++p) {
    hm_modal_config c;
    hm_modal_config_default(&c);
    hm_modal m = NULL;
    HM_CHECK(hm_modal_create(&c, fs, &m, NULL, 0) == HM_OK, "create");
    if (!m) return;
    hm_test_rng_state = 0x5DEECE66Dull + (unsigned long long)p;
    pole_pair p1, p2;
    double a_line = 0.0;
    if (p == 0) {
      p1 = pole_pair_make(-2.0, 14.0, fs, 1.0);
      p2 = pole_pair_make(-2.0, 14.0, fs, 0.0);
    } else if (p <= 2) {
      p1 = pole_pair_make(-0.56, 14.24, fs, 1.0);
      p2 = pole_pair_make(-8.0, 14.24, fs, sqrt(p == 1 ? 0.035 : 0.14) * 8.0 / 0.56);
    } else {
      p1 = pole_pair_make(-1.0, 14.0, fs, 1.0);
      p2 = pole_pair_make(-3.0, 14.6, fs, 1.0);
    }
    double ms = 0.0;
    for (int k = 0; k < 200000; ++k) {
      const double x = pole_pair_step(&p1) + pole_pair_step(&p2);
      if (k >= 100000) ms += x * x / 100000.0;
    }
    if (p == 0) a_line = 0.5 * sqrt(2.0 * ms);
    double t = 0.0;
    int n = 0, in = 0;
    for (int win = 0; win < 24; ++win) {
      hm_mode_estimate e;
      if (fit_window(m, fs, T, &p1, &p2, a_line, 15.2, 0.1 * sqrt(ms), &t, &e) != HM_OK || !e.valid) continue;
      ++n;
      /* the margin's error of the decay rate (margin.h): statistical, in quadrature with the systematic 5% + 1 / T
       * and the difference to a two-pair reading the likelihood could not rule out */
      double sys = 0.05 * fabs(e.decay_rate_1_s) + 1.0 / T;
      if (e.decay_rate_alt_1_s < 0.0) sys = hypot(sys, e.decay_rate_1_s - e.decay_rate_alt_1_s);
      in += fabs(e.decay_rate_1_s - truth[p]) <= 2.0 * hypot(e.decay_rate_se_1_s, sys);
    }
    hm_modal_destroy(m);
    printf("  %s: %d valid of 24, the interval covers %d (%.0f%%)\n", names[p], n, in, n ? 100.0 * in / n : 0.0);
    HM_CHECK(n >= 20, "%s: %d valid", names[p], n);
    if (p <= 1) HM_CHECK(in >= 20, "%s: %d covered", names[p], in); /* (c) and (d): measured, a known limit */
    all_n += n, all_in += in;
  }
  printf("  misspecified processes: %d of %d covered (%.1f%%)\n", all_in, all_n, 100.0 * all_in / all_n);
}

/* A broad mode filling a narrow band (a bogie frame's over 5-13 Hz, config/monitor_bogie_frame.yaml; the process's
 * pole the reference) stands only 2-3 times above the band's mean, where a valid reading needs 3: with
 * min_peak_prominence 4 (a peak 4 times its least level on both sides) most windows of -6 1/s at 8.5 Hz are valid and
 * their mean decay rate lies within 3 standard errors of the mean of -6 (with the leakage 1 / T the margin adds,
 * margin.h). Noise whose spectrum falls, rises or is flat over the band has no dip on both sides of a broad reading:
 * on the same streams it is valid no more often with the prominence than without (the band-mean rule's own chance
 * narrow peaks, about e^-3 of the windows, aside), nor a broad mode whose spectrum rises again towards the band's
 * edge (another resonance beyond it, on which the pair reads it lighter damped). */
static void a_broad_mode_in_a_narrow_band(void) {
  const double fs = 500.0, T = 40.0, sigma = -6.0, leak = exp(-2.0 * HM_PI / fs);
  int valid_at[2] = {0, 0}, noise_at[2] = {0, 0}, leak_at[2] = {0, 0}, n = 0;
  double sum = 0.0, sum_se = 0.0;
  for (int i = 0; i < 2; ++i) {
    hm_modal_config c;
    hm_modal_config_default(&c);
    c.band_low_hz = 5.0, c.band_high_hz = 13.0;
    c.min_peak_prominence = i ? 4.0 : 0.0;
    hm_modal m = NULL;
    HM_CHECK(hm_modal_create(&c, fs, &m, NULL, 0) == HM_OK, "create");
    if (!m) return;
    hm_test_rng_state = 0x2545F4914F6CDD1Dull; /* the same streams for both rules */
    pole_pair p = pole_pair_make(sigma, 8.5, fs, 1.0);
    for (int k = 0; k < 20000; ++k) pole_pair_step(&p);
    double t = 0.0;
    for (int win = 0; win < 24; ++win) {
      hm_mode_estimate e;
      if (fit_window(m, fs, T, &p, NULL, 0.0, 0.0, 0.0, &t, &e) != HM_OK || !e.valid) continue;
      ++valid_at[i];
      if (i == 1) ++n, sum += e.decay_rate_1_s, sum_se += hypot(e.decay_rate_se_1_s, 1.0 / T);
    }
    /* the wheelset's 14 Hz mode (-0.5 1/s) leaking in beside a mode of -7 1/s (its level at 13 Hz 0.3 of the broad
     * mode's peak): the spectrum rises again towards the band's edge, the pair reads the mode lighter damped (-4.6),
     * and the prominence must not admit it (HM_MODAL_PROMINENCE_EDGE_REL) */
    pole_pair q = pole_pair_make(-7.0, 8.5, fs, 1.0), h = pole_pair_make(-0.5, 14.0, fs, 14.0 / 8.5 * 1.05 * sqrt(0.3));
    for (int k = 0; k < 20000; ++k) pole_pair_step(&q), pole_pair_step(&h);
    for (int win = 0; win < 24; ++win) {
      hm_mode_estimate e;
      leak_at[i] += fit_window(m, fs, T, &q, &h, 0.0, 0.0, 0.0, &t, &e) == HM_OK && e.valid;
    }
    /* white, 1/f^2 (a leaky integral, corner 1 Hz) and f^2 (a difference) noise, 20 windows each */
    for (int kind = 0; kind < 3; ++kind)
      for (int win = 0; win < 20; ++win) {
        double acc = 0.0, prev = 0.0;
        hm_modal_reset(m);
        for (long k = 0; k < (long)(T * fs); ++k) {
          const double g = hm_test_gauss();
          acc = leak * acc + g;
          hm_modal_push(m, kind == 0 ? g : kind == 1 ? acc : g - prev);
          prev = g;
        }
        hm_mode_estimate e;
        noise_at[i] += hm_modal_fit(m, T, 0.0, 1.0, &e) == HM_OK && e.valid;
      }
    hm_modal_destroy(m);
  }
  const double mean = n ? sum / n : 0.0, se = n ? sum_se / n / sqrt((double)n) : 1.0;
  printf("  -6 1/s at 8.5 Hz over 5-13 Hz: valid in %d of 24 windows by the band's mean, %d with the prominence (mean "
         "decay rate %.2f, se of the mean %.2f); noise valid in %d and %d of 60; -7 1/s beside a 14 Hz mode valid in %d and "
         "%d of 24\n", valid_at[0], valid_at[1], mean, se, noise_at[0], noise_at[1], leak_at[0], leak_at[1]);
  HM_CHECK(valid_at[1] >= 18 && valid_at[0] < valid_at[1], "valid %d by the mean, %d by the prominence", valid_at[0],
           valid_at[1]);
  HM_CHECK_DELTA(mean, sigma, 3.0 * se, "the broad mode's decay rate");
  HM_CHECK(noise_at[1] <= noise_at[0], "noise read as a mode in %d windows, %d by the mean alone", noise_at[1],
           noise_at[0]);
  HM_CHECK(leak_at[1] <= leak_at[0] + 2, "a mode beside a rise at the edge valid in %d windows, %d by the mean alone",
           leak_at[1], leak_at[0]);
}

static void bad_configuration(void) {
  hm_modal_config c;
  char why[128];
  hm_modal_config_default(&c);
  c.band_high_hz = 45.0;
  hm_modal m = (hm_modal)0x1;
  HM_CHECK(hm_modal_create(&c, 2000.0, &m, why, sizeof why) == HM_EDOMAIN && strstr(why, "band_high_hz") &&
               m == (hm_modal)0x1,
           "%s", why);
  hm_modal_config_default(&c);
  c.window_s = NAN;
  HM_CHECK(hm_modal_config_validate(&c, why, sizeof why) == HM_EDOMAIN && strstr(why, "window_s"), "%s", why);
  hm_modal_config_default(&c);
  c.min_peak_prominence = -1.0;
  HM_CHECK(hm_modal_config_validate(&c, why, sizeof why) == HM_EDOMAIN && strstr(why, "min_peak_prominence"), "%s",
           why);
  hm_modal_config_default(&c);
  HM_CHECK(hm_modal_create(&c, 20000.0, &m, why, sizeof why) == HM_EDOMAIN && strstr(why, "sample_rate_hz"), "%s",
           why);
}

/* The periodogram's FFT of real samples (one complex FFT of half the length, then separated) against the DFT's
 * definition, summed directly, for every power of two from 4 to 4096 (the largest size as the twiddles' table, as in
 * the identification) and against hm_fft of the same samples: the error relative to the largest |X_k| about 1e-15. */
static void real_fft_is_the_dft(void) {
  enum { NMAX = 4096 };
  static double cw[NMAX / 2], sw[NMAX / 2], re[NMAX], im[NMAX], cre[NMAX], cim[NMAX], x[NMAX];
  hm_fft_twiddles(cw, sw, NMAX);
  double worst_dft = 0.0, worst_fft = 0.0;
  for (size_t n = 4; n <= NMAX; n *= 2) {
    unsigned long long rng = 99 + n;
    for (size_t k = 0; k < n; ++k) {
      rng = rng * 6364136223846793005ull + 1442695040888963407ull;
      x[k] = re[k] = cre[k] = (double)(rng >> 11) / 9007199254740992.0 - 0.5 + 0.3 * sin(0.37 * (double)k);
      cim[k] = 0.0;
    }
    hm_fft_real(re, im, n, cw, sw, NMAX);
    hm_fft(cre, cim, n, cw, sw, NMAX);
    double scale = 0.0, e_dft = 0.0, e_fft = 0.0;
    for (size_t k = 0; k <= n / 2; ++k) scale = fmax(scale, hypot(cre[k], cim[k]));
    /* the DFT directly at a spread of bins (every bin up to 256 points) */
    const size_t step = n <= 256 ? 1 : n / 64;
    for (size_t k = 0; k <= n / 2; k += step) {
      long double sr = 0.0L, si = 0.0L;
      for (size_t j = 0; j < n; ++j) {
        const long double ph = -2.0L * 3.14159265358979323846264338327950288L * (long double)((k * j) % n) / (long double)n;
        sr += (long double)x[j] * cosl(ph);
        si += (long double)x[j] * sinl(ph);
      }
      e_dft = fmax(e_dft, hypot(re[k] - (double)sr, im[k] - (double)si) / scale);
    }
    for (size_t k = 0; k <= n / 2; ++k) e_fft = fmax(e_fft, hypot(re[k] - cre[k], im[k] - cim[k]) / scale);
    HM_CHECK(e_dft < 1e-13 && e_fft < 1e-13, "n %zu: against the DFT %.2e, against hm_fft %.2e", n, e_dft, e_fft);
    worst_dft = fmax(worst_dft, e_dft);
    worst_fft = fmax(worst_fft, e_fft);
  }
  printf("  real FFT, 4..4096 points: error relative to max |X| %.1e against the DFT, %.1e against hm_fft\n", worst_dft,
         worst_fft);
}

/* The window's spectrum handed to a model's fit (hm_modal_window_spectrum): white noise of variance s^2 sampled at
 * fs has the two-sided density s^2 / fs at every frequency, the filters' gain divided out (closed form); its bins at
 * 2 n / nfft degrees of freedom each; nothing before a fit, a band beyond the decimated Nyquist refused. */
static void the_window_spectrum_is_a_density(void) {
  hm_modal_config c;
  hm_modal_config_default(&c);
  const double fs = 500.0, sd = 0.3;
  hm_modal m = NULL;
  HM_CHECK(hm_modal_create(&c, fs, &m, NULL, 0) == HM_OK, "create");
  if (!m) return;
  static double f[2048], p[2048];
  size_t n = 0;
  double dof = 0.0, window_s = 0.0;
  HM_CHECK(hm_modal_window_spectrum(m, 4.0, 22.0, f, p, 2048, &n, &dof, &window_s) == HM_ENOCONV, "no fit: none");
  hm_test_rng_state = 0x9E3779B97F4A7C15ull;
  for (long k = 0; k < (long)(40.0 * fs); ++k) hm_modal_push(m, sd * hm_test_gauss());
  hm_mode_estimate e;
  HM_CHECK(hm_modal_fit(m, 40.0, 0.0, NAN, &e) == HM_OK, "fit");
  HM_CHECK(hm_modal_window_spectrum(m, 4.0, 22.0, f, p, 2048, &n, &dof, &window_s) == HM_OK, "the spectrum");
  double mean = 0.0;
  for (size_t k = 0; k < n; ++k) mean += p[k];
  mean /= (double)n;
  const double expect = sd * sd / fs, rel_se = 1.0 / sqrt(0.5 * dof * (double)n);
  printf("  white noise: density %.4g over %zu bins (closed form %.4g, +- %.1f%%), %.2f dof a bin, %.1f s\n", mean, n,
         expect, 100.0 * rel_se, dof, window_s);
  HM_CHECK(fabs(mean / expect - 1.0) <= 4.0 * rel_se, "the density is s^2 / fs");
  HM_CHECK(f[0] >= 4.0 && f[n - 1] <= 22.0 && dof > 0.0 && dof <= 2.0 && fabs(window_s - 40.0) < 0.1, "its bins");
  HM_CHECK(hm_modal_window_spectrum(m, 4.0, 400.0, f, p, 2048, &n, &dof, &window_s) == HM_EDOMAIN, "beyond fd / 2");
  hm_modal_reset(m);
  HM_CHECK(hm_modal_window_spectrum(m, 4.0, 22.0, f, p, 2048, &n, &dof, &window_s) == HM_ENOCONV, "reset: none");
  hm_modal_destroy(m);
}

int main(void) {
  HM_RUN(a_lone_line_is_not_the_mode);
  HM_RUN(a_line_alone_and_a_narrow_mode);
  HM_RUN(a_mode_beside_a_broad_resonance);
  HM_RUN(a_peak_that_moves_with_the_speed);
  HM_RUN(a_sweeping_line_beside_the_mode);
  HM_RUN(a_line_sweeping_across_the_mode);
  HM_RUN(real_fft_is_the_dft);
  HM_RUN(decay_rate_of_a_known_oscillator);
  HM_RUN(rates_and_no_mode);
  HM_RUN(joints_are_not_the_mode);
  HM_RUN(coverage_of_the_intervals);
  HM_RUN(coverage_on_misspecified_processes);
  HM_RUN(a_broad_mode_in_a_narrow_band);
  HM_RUN(the_window_spectrum_is_a_density);
  HM_RUN(bad_configuration);
  HM_TEST_EXIT();
}
