/* Track lines by their wavelength across speeds (track_lines.h): lines at V / L from the closed form, and the
 * hunting mode's frequency from the eigenvalues of the linear model (linear.h), which a line's wavelength must not
 * match at another speed. */
#include <string.h>

#include "hm_test.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/model.h"
#include "hunting_monitor/track_lines.h"

static hm_track_lines fresh(void) {
  hm_track_lines_config c;
  hm_track_lines_config_default(&c);
  hm_track_lines t;
  HM_CHECK(hm_track_lines_init(&t, &c, NULL, 0) == HM_OK, "init");
  return t;
}

static double line_hz(double v_kmh, double l_m) { return v_kmh / 3.6 / l_m; }

/* The hunting mode's damped frequency [Hz] of the default vehicle at conicity lambda and v km/h (the Jacobian's
 * least-damped pair). */
static double mode_hz(double lambda, double v_kmh) {
  hm_vehicle veh;
  hm_vehicle_default(&veh);
  double re[4], im[4];
  hm_linear_eigenvalues(&veh, lambda, hm_mps_from_kmh(v_kmh), re, im);
  return fabs(im[0]) / (2.0 * HM_PI);
}

/* slab_1590 of the campaign: 6.081 m slabs seen at 250 km/h (11.423 Hz); the narrow peak at 280.6 km/h at V / L
 * (12.818 Hz) is that line, its wavelength 6.081 m; seen again at 250.5 km/h (0.2% faster) it is no evidence. */
static void slab_line_across_speeds(void) {
  hm_track_lines t = fresh();
  const double L = 6.081;
  HM_CHECK(hm_track_lines_observe(&t, 50.0, 250.0, line_hz(250.0, L), 4.0, 0) == HM_OK, "observe");
  hm_track_line seen;
  memset(&seen, 0, sizeof seen);
  HM_CHECK(hm_track_lines_match(&t, 90.0, 280.6, line_hz(280.6, L), &seen), "the slab line at 280.6 km/h");
  HM_CHECK_REL(seen.wavelength_m, L, 1e-12, "its wavelength");
  HM_CHECK_DELTA(seen.speed_kmh, 250.0, 0.0, "seen at");
  HM_CHECK(!hm_track_lines_match(&t, 90.0, 250.5, line_hz(250.5, L), NULL), "the same speed is no evidence");
  /* the tolerance: 1% of the wavelength */
  HM_CHECK(hm_track_lines_match(&t, 90.0, 280.6, line_hz(280.6, L * 1.009), NULL), "0.9%% off: the line");
  HM_CHECK(!hm_track_lines_match(&t, 90.0, 280.6, line_hz(280.6, L * 1.011), NULL), "1.1%% off: not");
  /* 4.9% faster is within min_speed_change_rel, 5.1% beyond */
  HM_CHECK(!hm_track_lines_match(&t, 90.0, 250.0 / 0.951, line_hz(250.0 / 0.951, L), NULL), "4.9%% faster");
  HM_CHECK(hm_track_lines_match(&t, 90.0, 250.0 / 0.949, line_hz(250.0 / 0.949, L), NULL), "5.1%% faster");
}

/* The hunting mode near its Hopf speed is as narrow as a line (modal.h): seen at 480 km/h (conicity 0.1358, Hopf
 * 517.6 km/h) and then at every speed from 481 to 540 km/h in 1 km/h steps, its peak never matches what was seen at
 * another speed: its frequency changes with the speed far less than V / L (0.2-0.3 of it), and each observation keeps
 * its own speed, so that a peak moving slowly cannot creep into a line. */
static void mode_never_a_line(void) {
  hm_track_lines t = fresh();
  const double lambda = 0.1358;
  int matched = 0;
  double k_min = 1.0, k_max = 0.0;
  for (int v = 480; v <= 540; ++v) {
    const double f = mode_hz(lambda, v);
    matched += hm_track_lines_match(&t, v, v, f, NULL);
    HM_CHECK(hm_track_lines_observe(&t, v, v, f, 1.0, 0) == HM_OK, "observe at %d", v);
    if (v > 480) {
      const double k = log(f / mode_hz(lambda, v - 1)) / log(v / (v - 1.0));
      k_min = fmin(k_min, k), k_max = fmax(k_max, k);
    }
  }
  printf("  the mode's d ln f / d ln V over 480-540 km/h: %.3f..%.3f\n", k_min, k_max);
  HM_CHECK(k_max < 0.5, "the mode's tracking exponent %g", k_max);
  HM_CHECK(matched == 0, "the mode matched %d times", matched);
  /* a line among the mode's observations is still found */
  HM_CHECK(hm_track_lines_observe(&t, 600.0, 480.0, line_hz(480.0, 9.5), 1.0, 0) == HM_OK, "observe");
  HM_CHECK(hm_track_lines_match(&t, 610.0, 520.0, line_hz(520.0, 9.5), NULL), "a 9.5 m line among them");
}

/* A comb's fundamental (25 m joints at 380 km/h: 4.22 Hz) makes its harmonics lines: the third at 420 km/h (14.0 Hz)
 * matches with the wavelength 25 / 3 m; 14.3 Hz (between harmonics) does not. A lone line's wavelength is not a
 * comb's: its half is not matched. */
static void comb_harmonics(void) {
  hm_track_lines t = fresh();
  HM_CHECK(hm_track_lines_observe(&t, 40.0, 380.0, line_hz(380.0, 25.0), 0.0, 1) == HM_OK, "observe the comb");
  hm_track_line seen;
  HM_CHECK(hm_track_lines_match(&t, 80.0, 420.0, 3.0 * line_hz(420.0, 25.0), &seen), "the third harmonic");
  HM_CHECK(seen.comb == 1, "seen as a comb");
  HM_CHECK_DELTA(3.0 * line_hz(420.0, 25.0), 14.0, 1e-3, "the harmonic (closed form)");
  HM_CHECK(!hm_track_lines_match(&t, 80.0, 420.0, 14.3, NULL), "14.3 Hz is no harmonic");
  HM_CHECK(hm_track_lines_observe(&t, 40.0, 380.0, line_hz(380.0, 6.0), 1.0, 0) == HM_OK, "observe a lone line");
  HM_CHECK(!hm_track_lines_match(&t, 80.0, 420.0, line_hz(420.0, 3.0), NULL), "a lone line's half wavelength");
}

/* Memory: an observation older than memory_s (900 s) is forgotten; a known time step keeps it; clear forgets all. The
 * same line at the same speed every second for 1000 s is one entry; 40 lines fill the 32 slots, the oldest go. */
static void memory_and_capacity(void) {
  hm_track_lines t = fresh();
  hm_track_lines_observe(&t, 0.0, 300.0, line_hz(300.0, 6.45), 2.0, 0);
  HM_CHECK(hm_track_lines_match(&t, 900.0, 330.0, line_hz(330.0, 6.45), NULL), "900 s later: kept");
  HM_CHECK(!hm_track_lines_match(&t, 900.1, 330.0, line_hz(330.0, 6.45), NULL), "900.1 s later: forgotten");
  hm_track_lines_shift_time(&t, 1000.0);
  HM_CHECK(hm_track_lines_match(&t, 1900.0, 330.0, line_hz(330.0, 6.45), NULL), "the time line moved with it");
  hm_track_lines_clear(&t);
  HM_CHECK(t.n == 0 && !hm_track_lines_match(&t, 1900.0, 330.0, line_hz(330.0, 6.45), NULL), "cleared");
  for (int s = 0; s < 1000; ++s) hm_track_lines_observe(&t, s, 300.0 + 0.01 * (s % 7), line_hz(300.0, 6.45), 2.0, 0);
  HM_CHECK(t.n == 1, "one line at one speed: %zu entries", t.n);
  HM_CHECK_DELTA(t.obs[0].seen_s, 999.0, 0.0, "its latest sight");
  for (int j = 0; j < 40; ++j) hm_track_lines_observe(&t, 1000.0 + j, 300.0, line_hz(300.0, 10.0 + 0.3 * j), 1.0, 0);
  HM_CHECK(t.n == HM_TRACK_LINES_MAX, "full: %zu", t.n);
  HM_CHECK(!hm_track_lines_match(&t, 1100.0, 330.0, line_hz(330.0, 6.45), NULL), "the oldest went");
  HM_CHECK(hm_track_lines_match(&t, 1100.0, 330.0, line_hz(330.0, 10.0 + 0.3 * 39), NULL), "the newest kept");
}

/* Bad input: refused with its reason, nothing kept or changed. */
static void bad_input(void) {
  hm_track_lines_config c;
  hm_track_lines_config_default(&c);
  char why[128] = "";
  hm_track_lines t = fresh(), before;
  memcpy(&before, &t, sizeof t);
  const struct {
    double tol, change, mem;
    const char *field;
  } bad[] = {{0.0, 0.05, 900.0, "wavelength_tol_rel"},  {NAN, 0.05, 900.0, "wavelength_tol_rel"},
             {0.06, 0.2, 900.0, "wavelength_tol_rel"}, {0.03, 0.05, 900.0, "min_speed_change_rel"},
             {0.01, 0.6, 900.0, "min_speed_change_rel"}, {0.01, 0.05, 0.5, "memory_s"},
             {0.01, 0.05, INFINITY, "memory_s"}};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
    hm_track_lines_config b = c;
    b.wavelength_tol_rel = bad[i].tol, b.min_speed_change_rel = bad[i].change, b.memory_s = bad[i].mem;
    HM_CHECK(hm_track_lines_init(&t, &b, why, sizeof why) == HM_EDOMAIN && strstr(why, bad[i].field) &&
                 strstr(why, "track_lines."),
             "case %zu: '%s'", i, why);
    HM_CHECK(memcmp(&t, &before, sizeof t) == 0, "case %zu: untouched", i);
  }
  HM_CHECK(hm_track_lines_init(NULL, &c, NULL, 0) == HM_EINVAL && hm_track_lines_init(&t, NULL, NULL, 0) == HM_EINVAL,
           "NULL");
  const double vals[][4] = {{NAN, 300.0, 14.0, 1.0}, {0.0, -300.0, 14.0, 1.0}, {0.0, 300.0, 0.0, 1.0},
                            {0.0, 300.0, INFINITY, 1.0}, {0.0, 300.0, 14.0, -1.0}, {0.0, 300.0, 14.0, NAN}};
  for (size_t i = 0; i < sizeof vals / sizeof vals[0]; ++i)
    HM_CHECK(hm_track_lines_observe(&t, vals[i][0], vals[i][1], vals[i][2], vals[i][3], 0) == HM_EINVAL,
             "observe case %zu", i);
  HM_CHECK(t.n == 0, "nothing kept: %zu", t.n);
  hm_track_lines_observe(&t, 0.0, 300.0, 14.0, 1.0, 0);
  HM_CHECK(!hm_track_lines_match(&t, NAN, 330.0, 15.4, NULL) && !hm_track_lines_match(&t, 1.0, 0.0, 15.4, NULL) &&
               !hm_track_lines_match(&t, 1.0, 330.0, -15.4, NULL) && !hm_track_lines_match(NULL, 1.0, 330.0, 15.4, NULL),
           "match refuses bad values");
}

int main(void) {
  HM_RUN(slab_line_across_speeds);
  HM_RUN(mode_never_a_line);
  HM_RUN(comb_harmonics);
  HM_RUN(memory_and_capacity);
  HM_RUN(bad_input);
  HM_TEST_EXIT();
}
