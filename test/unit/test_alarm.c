/* Alarm levels: thresholds from the boundary table, hysteresis, hold time, NO_DATA, reasons. The alarm is driven
 * with the Hopf interval (interval.h) built beside it as the monitor builds it: the evidence rules of alarm.h are
 * tested here through the levels they lead to; test_interval checks the interval's own numbers. */
#include <string.h>

#include "hm_fixtures.h"
#include "hm_test.h"
#include "hunting_monitor/alarm.h"
#include "hunting_monitor/interval.h"
#include "hunting_monitor/linear.h"

static hm_table table;
static hm_vehicle vehicle;

/* A current estimate at speed v with displacement amplitude amp [m] (no criterion met, no conicity estimate). */
static hm_estimate estimate(double v, double amp) {
  hm_estimate e;
  memset(&e, 0, sizeof e);
  e.accel_valid = e.speed_valid = 1;
  e.speed_kmh = v;
  e.oscillation_valid = amp > 0.0;
  e.amplitude_displacement_m = amp;
  e.frequency_hz = amp > 0.0 ? 14.0 : 0.0;
  e.sample_rate_supported = 1;
  return e;
}


/* Each alarm with the interval it decides on (interval.h), paired as the monitor pairs them. */
#define MAX_PAIRS 16
static struct {
  hm_alarm a;
  hm_interval iv;
} pairs[MAX_PAIRS];

static hm_interval interval_of(hm_alarm a) {
  for (int k = 0; k < MAX_PAIRS; ++k)
    if (pairs[k].a == a) return pairs[k].iv;
  return NULL;
}

/* The alarm and its interval for the settings c (HM_EDOMAIN with why from either; *out untouched then). */
static hm_status create(const hm_alarm_config *c, hm_alarm *out, char *why, size_t len) {
  hm_interval_config ic;
  hm_alarm_interval_config(c, &ic);
  hm_interval iv = NULL;
  hm_alarm a = NULL;
  hm_status st = hm_alarm_create(c, &a, why, len);
  if (st == HM_OK) st = hm_interval_create(&ic, &vehicle, table, &iv, why, len);
  int k = 0;
  while (k < MAX_PAIRS && pairs[k].a) ++k;
  if (st == HM_OK && k == MAX_PAIRS) st = HM_ENOMEM;
  if (st != HM_OK) {
    hm_alarm_destroy(a);
    hm_interval_destroy(iv);
    return st;
  }
  pairs[k].a = a, pairs[k].iv = iv;
  *out = a;
  return HM_OK;
}

static void destroy(hm_alarm a) {
  for (int k = 0; k < MAX_PAIRS; ++k)
    if (pairs[k].a == a) hm_interval_destroy(pairs[k].iv), pairs[k].a = NULL, pairs[k].iv = NULL;
  hm_alarm_destroy(a);
}

/* One update as the monitor makes it: the interval at the estimate's speed where the data is current, then the
 * level. */
static hm_status update(hm_alarm a, const hm_estimate *e, const hm_margin_estimate *g, double now, hm_assessment *s) {
  hm_hopf_interval h;
  const int data = e && e->accel_valid && e->speed_valid;
  const hm_status st = data ? hm_interval_update(interval_of(a), e->speed_kmh, g, now, &h) : HM_OK;
  return st == HM_OK ? hm_alarm_update(a, e, data ? &h : NULL, now, s) : st;
}

static void restart(hm_alarm a) {
  hm_alarm_restart(a);
  hm_interval_restart(interval_of(a));
}

static hm_status set_config(hm_alarm a, const hm_alarm_config *c, char *why, size_t len) {
  hm_interval_config ic;
  hm_alarm_interval_config(c, &ic);
  /* (both validated first, as the monitor's runtime settings are, so neither changes alone) */
  hm_status st = hm_alarm_config_validate(c, why, len);
  if (st == HM_OK) st = hm_interval_set_config(interval_of(a), &ic, &vehicle, why, len);
  return st == HM_OK ? hm_alarm_set_config(a, c, why, len) : st;
}

typedef struct {
  hm_alarm_snapshot alarm;
  hm_interval_snapshot interval;
} snapshot;

static void take_snapshot(hm_alarm a, double now, snapshot *out) {
  hm_alarm_take_snapshot(a, now, &out->alarm);
  hm_interval_take_snapshot(interval_of(a), &out->interval);
}

static hm_status restore(hm_alarm a, double now, const snapshot *snap, char *why, size_t len) {
  hm_status st = hm_interval_restore(interval_of(a), &snap->interval, why, len);
  return st == HM_OK ? hm_alarm_restore(a, now, &snap->alarm, why, len) : st;
}

/* An alarm whose prior is the range [lo, hi] (0, 0: the default, the fallback -+ 0.03). */
static hm_alarm make_prior(double lo, double hi) {
  hm_alarm_config c;
  hm_alarm_config_default(&c);
  c.conicity_prior_low = lo;
  c.conicity_prior_high = hi;
  hm_alarm a = NULL;
  char why[160];
  HM_CHECK(create(&c, &a, why, sizeof why) == HM_OK, "create: %s", why);
  return a;
}

/* The level logic against known boundaries: a prior so narrow (0.1358 -+ 1e-5) that the table's stated error at the
 * fallback makes the interval, as a vehicle whose conicity was measured. */
static hm_alarm make(void) { return make_prior(0.1358 - 1e-5, 0.1358 + 1e-5); }

/* The default WARN rule's standard errors (alarm.h: WARN from the point less max(margin, k standard errors)). */
static double warn_k(void) {
  hm_alarm_config c;
  hm_alarm_config_default(&c);
  return c.warn_standard_errors;
}

static double hopf_closed_form(double conicity) {
  double vc;
  hm_linear_critical_speed(&vehicle, conicity, &vc);
  return hm_kmh_from_mps(vc);
}

/* Levels at the default vehicle's boundaries with the fallback conicity (the vehicle's lambda(0) = 0.1358: Hopf
 * 517.618 km/h (closed form), lowest cycle about 239.5 km/h, basin edge about 8.35 mm at 400 km/h - MODEL.md
 * section 7). 400 km/h is in the bistable band, and OK: the band is stated in the fields, not as a level. */
/* An identified conicity as margin.h makes it: 0.16 +- 0.003, the interval at +-2 standard errors. */
static hm_margin_estimate identified(void) {
  hm_margin_estimate g;
  memset(&g, 0, sizeof g);
  g.conicity_valid = g.hopf_model_valid = 1;
  g.conicity = 0.16;
  g.conicity_se = 0.003;
  g.conicity_low = 0.154;
  g.conicity_high = 0.166;
  g.interval_z = 2.0;
  g.hopf_model_kmh = hopf_closed_form(0.16);
  g.hopf_model_low_kmh = hopf_closed_form(0.166);
  g.hopf_model_high_kmh = hopf_closed_form(0.154);
  return g;
}

static void levels_follow_the_boundaries(void) {
  const double hopf = hopf_closed_form(0.1358);
  const struct {
    double v, amp;
    hm_level level;
    hm_reason reason;
  } cases[] = {
      {200.0, 0.0, HM_LEVEL_OK, HM_REASON_BELOW_LOWEST_CYCLE},
      {400.0, 0.0, HM_LEVEL_OK, HM_REASON_NORMAL},
      {hopf - 25.0, 0.0, HM_LEVEL_WATCH, HM_REASON_APPROACHING_HOPF},
      {400.0, 0.005, HM_LEVEL_WARN, HM_REASON_AMPLITUDE_NEAR_EDGE},
      {400.0, 0.009, HM_LEVEL_ALARM, HM_REASON_AMPLITUDE_BEYOND_EDGE},
      {hopf - 5.0, 0.0, HM_LEVEL_WARN, HM_REASON_NEAR_HOPF},
      {hopf + 0.5, 0.0, HM_LEVEL_ALARM, HM_REASON_ABOVE_HOPF},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    hm_alarm a = make();
    hm_assessment s;
    const hm_estimate e = estimate(cases[i].v, cases[i].amp);
    HM_CHECK(update(a, &e, NULL, 10.0, &s) == HM_OK, "update");
    HM_CHECK(s.level == cases[i].level && s.reason == cases[i].reason, "v %g amp %g: %s (%s)", cases[i].v,
             cases[i].amp, hm_level_name(s.level), hm_reason_text(s.reason));
    HM_CHECK(s.boundaries_valid && s.changed, "boundaries and change flag");
    HM_CHECK_DELTA(s.margin_hopf_kmh, hopf - cases[i].v, 1e-6, "margin to the Hopf speed");
    HM_CHECK((s.margin_lowest_cycle_kmh < 0.0) == (cases[i].v > 250.0), "v %g: bistable band in the fields", cases[i].v);
    destroy(a);
  }
  hm_estimate e = estimate(300.0, 0.0);
  e.rms_exceeded = 1;
  hm_alarm a = make();
  hm_assessment s;
  update(a, &e, NULL, 0.0, &s);
  HM_CHECK(s.level == HM_LEVEL_ALARM && s.reason == HM_REASON_RMS_CRITERION, "r.m.s. criterion");
  e.rms_exceeded = 0;
  e.peaks_exceeded = 1;
  update(a, &e, NULL, 0.1, &s);
  HM_CHECK(s.level == HM_LEVEL_ALARM && s.reason == HM_REASON_PEAKS_CRITERION && !s.changed, "peaks criterion");
  destroy(a);
}

/* A stale input gives NO_DATA at once, with no boundaries presented; data back gives the level at once. */
static void stale_input_is_no_data(void) {
  hm_alarm a = make();
  hm_assessment s;
  hm_estimate e = estimate(520.0, 0.0);
  update(a, &e, NULL, 0.0, &s);
  HM_CHECK(s.level == HM_LEVEL_ALARM, "alarm");
  e.speed_valid = 0;
  update(a, &e, NULL, 0.1, &s);
  HM_CHECK(s.level == HM_LEVEL_NO_DATA && s.reason == HM_REASON_NO_SPEED && !s.boundaries_valid && s.changed,
           "stale speed: %s", hm_level_name(s.level));
  /* speeds that arrive and are refused (a train at 601 km/h with max_speed_kmh 600) are told apart from none */
  char said[160];
  hm_assessment_reason_text(&s, 0.0, said, sizeof said);
  HM_CHECK(strcmp(said, "no current speed") == 0, "none arrive: '%s'", said);
  e.speed_refused = HM_SPEED_ABOVE_MAX;
  update(a, &e, NULL, 0.15, &s);
  hm_assessment_reason_text(&s, 0.0, said, sizeof said);
  HM_CHECK(s.level == HM_LEVEL_NO_DATA &&
               strcmp(said, "no current speed (speeds arrive, refused: above max_speed_kmh)") == 0, "refused: '%s'",
           said);
  e.speed_valid = 1;
  e.speed_refused = HM_SPEED_ACCEPTED;
  e.accel_valid = 0;
  update(a, &e, NULL, 0.2, &s);
  HM_CHECK(s.level == HM_LEVEL_NO_DATA && s.reason == HM_REASON_NO_ACCEL, "stale acceleration");
  e = estimate(200.0, 0.0);
  update(a, &e, NULL, 0.3, &s);
  HM_CHECK(s.level == HM_LEVEL_OK && s.changed, "data back: %s", hm_level_name(s.level));
  destroy(a);
  /* a held ALARM (the r.m.s. criterion at 470 km/h) through 20 s of stale acceleration (the sensor lost to violent
   * hunting, issue #27): ALARM, latched, with its cause, the margins not current; then a restarted time line (a
   * clock step): still held; data back and calm below the interval: released after release_s (10 s) of it */
  a = make();
  e = estimate(470.0, 2.5e-3);
  e.rms_exceeded = 1;
  update(a, &e, NULL, 0.0, &s);
  HM_CHECK(s.level == HM_LEVEL_ALARM && s.latched, "latched");
  e.accel_valid = e.oscillation_valid = e.rms_exceeded = 0;
  int held = 1;
  for (int k = 1; k <= 200; ++k) {
    update(a, &e, NULL, 0.1 * k, &s);
    held &= s.level == HM_LEVEL_ALARM && s.latched && s.reason == HM_REASON_RMS_CRITERION && !s.boundaries_valid &&
            s.release_in_s == 10.0;
  }
  HM_CHECK(held, "stale while latched: %s (%s), latched %d, boundaries %d", hm_level_name(s.level),
           hm_reason_text(s.reason), s.latched, s.boundaries_valid);
  /* what it says while stale: the hunted-at speed (470 km/h at 0 s, it counts while held) and which input is missing
   * (the review had found the hunted-at speed NaN and "no current data") */
  char text[256];
  hm_assessment_reason_text(&s, 0.0, text, sizeof text);
  HM_CHECK(s.hunted_at_kmh == 470.0 && s.hunted_at_s == 0.0 && s.hold_no_data == HM_REASON_NO_ACCEL &&
               strstr(text, "hunting seen down to 470.0 km/h at 0.0 s") && strstr(text, "no current lateral acceleration"),
           "stale while latched: hunted at %.1f km/h at %.1f s, missing %d: '%s'", s.hunted_at_kmh, s.hunted_at_s,
           (int)s.hold_no_data, text);
  restart(a);
  e = estimate(440.0, 0.3e-3);
  update(a, &e, NULL, 1000.0, &s); /* another time line */
  HM_CHECK(s.level == HM_LEVEL_ALARM && s.latched && s.reason == HM_REASON_RMS_CRITERION && s.hopf_low_kmh == 470.0,
           "after a restart: %s latched %d, low end %.1f", hm_level_name(s.level), s.latched, s.hopf_low_kmh);
  double released = -1.0;
  for (int k = 1; k <= 150 && released < 0.0; ++k) {
    update(a, &e, NULL, 1000.0 + 0.1 * k, &s);
    if (!s.latched) released = 0.1 * k;
  }
  HM_CHECK_DELTA(released, 10.1, 0.11, "released after 10 s of calm with data");
  destroy(a);
}

/* Hysteresis and hold: from ALARM (above Hopf) down to 3 km/h below it the level stays ALARM; further down it
 * falls to WARN only after 3 s; a speed dithering around the WARN threshold changes the level once; a lower level is
 * not taken while the speed accelerates back toward the threshold. */
static void hysteresis_and_hold_prevent_chatter(void) {
  const double hopf = hopf_closed_form(0.1358);
  hm_alarm a = make();
  hm_assessment s;
  hm_estimate e = estimate(hopf + 1.0, 0.0);
  update(a, &e, NULL, 0.0, &s);
  HM_CHECK(s.level == HM_LEVEL_ALARM, "alarm above Hopf");
  e = estimate(hopf - 2.0, 0.0); /* inside the 3 km/h hysteresis */
  for (double t = 0.1; t < 10.0; t += 0.1) {
    update(a, &e, NULL, t, &s);
    HM_CHECK(s.level == HM_LEVEL_ALARM, "t %g: %s inside the hysteresis", t, hm_level_name(s.level));
  }
  e = estimate(hopf - 5.0, 0.0);
  double changed_at = -1.0;
  for (double t = 10.0; t < 20.0; t += 0.1) {
    update(a, &e, NULL, t, &s);
    if (s.changed && changed_at < 0.0) changed_at = t;
  }
  HM_CHECK(s.level == HM_LEVEL_WARN && s.reason == HM_REASON_NEAR_HOPF, "down to WARN: %s", hm_level_name(s.level));
  HM_CHECK_DELTA(changed_at, 13.0, 0.11, "WARN after the 3 s hold");
  /* dither around the WARN threshold (hopf - 10 km/h) by +-0.5 km/h every 0.1 s for 20 s */
  int changes = 0;
  for (int k = 0; k < 200; ++k) {
    e = estimate(hopf - 10.0 + (k % 2 ? 0.5 : -0.5), 0.0);
    update(a, &e, NULL, 20.0 + 0.1 * k, &s);
    changes += s.changed;
  }
  HM_CHECK(changes == 0, "%d level changes while dithering inside the hysteresis", changes);
  destroy(a);
  /* on a ramp: WARN at a speed 1 km/h above the WARN threshold; then the known conicity changes (the settings, as a
   * new identification would) so that WARN starts about 15 km/h higher. Steady at that speed (beyond the hysteresis)
   * the level falls to WATCH after the 3 s hold; accelerating at 1 km/h/s it stays WARN (the speed 30 s ahead would
   * call for WARN again): no level change at all, where it would otherwise have gone down and come back seconds later */
  for (int ramp = 0; ramp < 2; ++ramp) {
    a = make();
    e = estimate(400.0, 0.0);
    update(a, &e, NULL, -10.0, &s);
    const double w0 = s.warn_from_kmh;
    HM_CHECK_DELTA(w0, s.hopf_low_kmh - 10.0, 1e-9, "WARN from the lower end - 10 km/h (a range)");
    hm_alarm_config c;
    hm_alarm_config_default(&c);
    c.conicity_fallback = 0.1290;
    c.conicity_prior_low = 0.1290 - 1e-5;
    c.conicity_prior_high = 0.1290 + 1e-5;
    int n_changes = 0;
    double w1 = 0.0;
    for (int k = 0; k <= 200; ++k) { /* 20 s */
      const double t = 0.1 * k;
      if (k == 50) {
        char why[160] = "";
        HM_CHECK(set_config(a, &c, why, sizeof why) == HM_OK, "%s", why);
      }
      e = estimate(w0 + 1.0 + (ramp && t > 5.0 ? t - 5.0 : 0.0), 0.0);
      update(a, &e, NULL, t, &s);
      if (k == 51) w1 = s.warn_from_kmh;
      n_changes += k > 0 && s.changed;
    }
    HM_CHECK(w1 > w0 + 12.0 && w1 < w0 + 17.0, "the new threshold %.1f, %.1f above", w1, w1 - w0);
    if (ramp)
      HM_CHECK(s.level == HM_LEVEL_WARN && n_changes == 0, "accelerating: %s after %d changes", hm_level_name(s.level),
               n_changes);
    else
      HM_CHECK(s.level == HM_LEVEL_WATCH && n_changes == 1, "steady: %s after %d changes", hm_level_name(s.level),
               n_changes);
    destroy(a);
  }
}

/* Latching by cause (issue #21): an ALARM from the oscillation holds while the oscillation comes and goes, and is
 * released only after release_s (10 s) of calm (no criterion, displacement below half the 2.1 mm limit) with the
 * speed below the Hopf interval, which reaches down to the speed it hunted at (470 km/h, far below the model's), then
 * falls after the 3 s hold: 13 s after the calm began. A criterion met for 1 s
 * in every 5 s (a hunting wheelset on a varying track: the gaps outlast the 3 s hold) never lets the level below
 * ALARM; a calm oscillation
 * above the interval's lower end keeps it; a speed-only ALARM is not latched. */
static void oscillation_alarm_latches(void) {
  const double hopf = hopf_closed_form(0.1358);
  hm_alarm a = make();
  hm_alarm_set_displacement_limit(a, 2.1e-3);
  hm_assessment s;
  hm_estimate e = estimate(470.0, 2.5e-3);
  e.rms_exceeded = 1;
  update(a, &e, NULL, 0.0, &s);
  HM_CHECK(s.level == HM_LEVEL_ALARM && s.reason == HM_REASON_RMS_CRITERION && s.latched, "latched ALARM");
  int below = 0;
  for (int k = 1; k <= 400; ++k) { /* 40 s: the criterion on for 1 s of every 5 s, 1.5 mm in between */
    const double t = 0.1 * k;
    e = estimate(470.0, (k / 10) % 5 ? 1.5e-3 : 2.5e-3);
    e.rms_exceeded = (k / 10) % 5 == 0;
    update(a, &e, NULL, t, &s);
    below += s.level != HM_LEVEL_ALARM;
  }
  HM_CHECK(below == 0 && s.latched, "%d statuses below ALARM while the oscillation came and went", below);
  /* calm (0.5 mm, no criterion) at the speed it hunted at, 470 km/h, 47.6 km/h below the model's interval: held,
   * the interval's lower end at 470 km/h (the vehicle hunted there), the calm not counted (the speed is not below it) */
  for (int k = 1; k <= 200; ++k) {
    e = estimate(470.0, 0.5e-3);
    update(a, &e, NULL, 40.0 + 0.1 * k, &s);
  }
  HM_CHECK(s.level == HM_LEVEL_ALARM && s.latched && s.hopf_low_from_hunting && s.hopf_low_kmh == 470.0 &&
               s.release_in_s == 10.0,
           "calm at the hunting speed: %s, latched %d, low end %.1f (from hunting %d), release in %g s",
           hm_level_name(s.level), s.latched, s.hopf_low_kmh, s.hopf_low_from_hunting, s.release_in_s);
  /* calm at 466 km/h (below 470 by more than the 3 km/h hysteresis): released after 10 s and lowered at once to WARN
   * (the 10 s calm was the hold; the 3 s min_hold_s after it had shown ALARM neither latched nor held, issue #27):
   * the vehicle hunted at 470 km/h, a one-sided bound on its Hopf (or fold) speed for memory_s (900 s by default,
   * issue #27), WARN from it less the 10 km/h margin; back at 470 km/h still WARN (it was WATCH before: the
   * interval forgot the hunting); after the memory, the model's interval again and OK at 466 km/h */
  double released = -1.0, lowered = -1.0;
  for (int k = 1; k <= 200; ++k) {
    const double t = 60.0 + 0.1 * k;
    e = estimate(466.0, 0.5e-3);
    update(a, &e, NULL, t, &s);
    if (k == 50) HM_CHECK(s.latched && fabs(s.release_in_s - 5.1) < 0.11, "release in %g s after 4.9 s", s.release_in_s);
    if (!s.latched && released < 0.0) released = t;
    if (s.level != HM_LEVEL_ALARM && lowered < 0.0) lowered = t;
  }
  HM_CHECK_DELTA(released, 60.1 + 10.0, 0.11, "released after 10 s of calm");
  HM_CHECK(lowered == released, "lowered at %.1f s, released at %.1f s", lowered, released);
  HM_CHECK(s.level == HM_LEVEL_WARN && s.reason == HM_REASON_NEAR_HOPF && s.hopf_low_from_hunting &&
               s.hopf_low_kmh == 470.0 && s.hunted_at_kmh == 470.0 && s.warn_from_kmh == 460.0,
           "level after release: %s, low end %.1f (from hunting %d), WARN from %.1f", hm_level_name(s.level),
           s.hopf_low_kmh, s.hopf_low_from_hunting, s.warn_from_kmh);
  e = estimate(470.0, 0.5e-3);
  update(a, &e, NULL, 81.0, &s);
  HM_CHECK(s.level == HM_LEVEL_WARN && !s.latched, "back at 470 km/h: %s", hm_level_name(s.level));
  e = estimate(466.0, 0.5e-3);
  for (int k = 0; k <= 50; ++k) update(a, &e, NULL, 81.0 + 900.0 + 0.1 * k, &s);
  HM_CHECK(s.level == HM_LEVEL_OK && !s.hopf_low_from_hunting && s.hopf_low_kmh > 500.0 && isnan(s.hunted_at_kmh),
           "after memory_s: %s, low end %.1f", hm_level_name(s.level), s.hopf_low_kmh);
  destroy(a);
  /* a latch longer than memory_s (the review's case, issue #27): hunting at 440 km/h, then 920 s of stale acceleration
   * (held), calm at 420 km/h: released 10 s after the data came back, and the hunted-at speed bounds the interval for
   * memory_s (900 s) after the release, not after the hunting (it had been dropped at the release: OK at 438 km/h) */
  a = make();
  e = estimate(440.0, 2.5e-3);
  e.rms_exceeded = 1;
  update(a, &e, NULL, 0.0, &s);
  e = estimate(440.0, 0.0);
  e.accel_valid = 0;
  for (int k = 1; k <= 92; ++k) update(a, &e, NULL, 10.0 * k, &s);
  HM_CHECK(s.level == HM_LEVEL_ALARM && s.latched, "held through 920 s of stale input: %s", hm_level_name(s.level));
  double released_long = -1.0;
  for (int k = 1; k <= 150; ++k) {
    e = estimate(420.0, 0.2e-3);
    update(a, &e, NULL, 920.0 + 0.1 * k, &s);
    if (!s.latched && released_long < 0.0) released_long = 920.0 + 0.1 * k;
  }
  HM_CHECK_DELTA(released_long, 930.1, 0.11, "released 10 s after the data came back");
  e = estimate(438.0, 0.2e-3);
  update(a, &e, NULL, released_long + 899.0, &s);
  HM_CHECK(s.level == HM_LEVEL_WARN && s.hopf_low_from_hunting && s.hunted_at_kmh == 440.0 && s.warn_from_kmh == 430.0,
           "at 438 km/h 899 s after the release: %s, hunted at %.1f, WARN from %.1f", hm_level_name(s.level),
           s.hunted_at_kmh, s.warn_from_kmh);
  for (int k = 1; k <= 40; ++k) update(a, &e, NULL, released_long + 901.0 + 0.1 * k, &s);
  HM_CHECK(s.level != HM_LEVEL_WARN && isnan(s.hunted_at_kmh), "901 s after the release: %s, hunted at %.1f",
           hm_level_name(s.level), s.hunted_at_kmh);
  destroy(a);
  /* accelerating while held (the review's case, issue #27): an identified 0.14 +- 0.001 (its interval 505-513 km/h),
   * the r.m.s. criterion down to 480 km/h until 25 s, then 0.1 mm and 0.8 km/h/s from 480 km/h: held throughout (the
   * speed never below the release speed, 477 km/h), the criterion last met at 25 s. The look-ahead that keeps a level
   * while accelerating had handed the latch's cause back as if a criterion were met: held 0 with "sliding r.m.s.
   * criterion exceeded" from 61.5 to 87.5 s and the last-met time advancing */
  hm_margin_estimate g14 = identified();
  g14.conicity = 0.14, g14.conicity_se = 0.001, g14.conicity_low = 0.138, g14.conicity_high = 0.142;
  g14.hopf_model_kmh = hopf_closed_form(0.14);
  g14.hopf_model_low_kmh = hopf_closed_form(0.142), g14.hopf_model_high_kmh = hopf_closed_form(0.138);
  a = make_prior(0.0, 0.0);
  hm_alarm_set_displacement_limit(a, 2.1e-3);
  for (int k = 0; k < 300; ++k) {
    e = estimate(505.0, 0.1e-3);
    update(a, &e, &g14, 0.1 * k, &s);
  }
  int held_all = 1, n_latched = 0;
  double last_met_max = 0.0;
  for (int k = 1; k <= 1500; ++k) {
    const double tt = 0.1 * k, v = tt <= 10.0 ? 505.0 - 2.5 * tt : tt <= 20.0 ? 480.0 : 480.0 + 0.8 * (tt - 20.0);
    const int crit = tt <= 25.0;
    e = estimate(v, crit ? 2.5e-3 : 0.1e-3);
    e.rms_exceeded = crit;
    update(a, &e, &g14, 30.0 + tt, &s);
    if (tt > 25.05 && s.latched) {
      ++n_latched;
      held_all &= s.held && s.level == HM_LEVEL_ALARM;
      last_met_max = fmax(last_met_max, s.hold_last_met_s);
    }
  }
  HM_CHECK(n_latched > 1000 && held_all && last_met_max == 55.0,
           "accelerating while held: %d latched statuses, held in all %d, last met at most %.1f s (55.0)", n_latched,
           held_all, last_met_max);
  destroy(a);
  /* calm oscillation but the speed inside the Hopf interval: held */
  a = make();
  hm_alarm_set_displacement_limit(a, 2.1e-3);
  e = estimate(hopf - 0.2, 2.5e-3);
  e.peaks_exceeded = 1;
  update(a, &e, NULL, 0.0, &s);
  for (int k = 1; k <= 300; ++k) {
    e = estimate(hopf - 0.2, 0.3e-3);
    update(a, &e, NULL, 0.1 * k, &s);
  }
  HM_CHECK(s.level == HM_LEVEL_ALARM && s.latched && s.reason == HM_REASON_PEAKS_CRITERION,
           "inside the interval: %s latched %d", hm_level_name(s.level), s.latched);
  destroy(a);
  /* a speed-only ALARM follows the speed */
  a = make();
  e = estimate(hopf + 1.0, 0.0);
  update(a, &e, NULL, 0.0, &s);
  HM_CHECK(s.level == HM_LEVEL_ALARM && s.reason == HM_REASON_ABOVE_HOPF && !s.latched, "speed-only ALARM latched");
  destroy(a);
}

/* A hold that says what it is (issue #27 item 7): braking at 1 km/h/s from 490 km/h with the wheelset hunting (the
 * r.m.s. criterion down to 300 km/h, then only the displacement criterion, down to 234.0 km/h: the fold of worn
 * wheels), then 0.05 mm of motion, the braking stopping at 225 km/h. References, from the input: the hunted-at speed
 * is the last speed with a criterion met (234.0 km/h, at 256.0 s); while held the reason is the cause that latched the
 * ALARM (the r.m.s. criterion at 0 s, not the displacement criterion met last), the release speed that speed less the
 * 3 km/h hysteresis, the calm needed release_s (10 s) and the calm so far the time since the speed fell below the
 * release speed (from 259.1 s, the first status below 231.0 km/h); released 10 s after; the published interval's lower end the hunted-at speed, WARN and
 * WATCH below it by their margins (10 and 30 km/h). Until issue #27 the reason said "displacement amplitude criterion
 * exceeded" with no criterion met, and release_in_s stayed 10 without saying what it waited for. */
static void a_hold_says_what_it_is(void) {
  hm_alarm a = make_prior(0.0, 0.0);
  hm_alarm_set_displacement_limit(a, 2.1e-3);
  hm_assessment s;
  char text[512];
  double released = NAN, t_below = NAN;
  int held_ok = 1, current_ok = 1, calm_ok = 1;
  for (int k = 0; k <= 10 * 300 && isnan(released); ++k) {
    const double t = 0.1 * k, v = fmax(490.0 - t, 225.0);
    hm_estimate e = estimate(v, v >= 234.0 - 1e-9 ? 3.0e-3 : 0.05e-3);
    e.rms_exceeded = v > 300.0;
    e.displacement_exceeded = v >= 234.0 - 1e-9;
    HM_CHECK(update(a, &e, NULL, t, &s) == HM_OK, "update");
    hm_assessment_reason_text(&s, 0.0, text, sizeof text);
    if (e.displacement_exceeded) { /* hunting now: the current criterion, latched, not held */
      current_ok &= s.level == HM_LEVEL_ALARM && s.latched && !s.held &&
                    s.reason == (e.rms_exceeded ? HM_REASON_RMS_CRITERION : HM_REASON_DISPLACEMENT_CRITERION) &&
                    s.hold_cause == HM_REASON_RMS_CRITERION && s.hold_waits == (HM_HOLD_WAITS_OSCILLATION | HM_HOLD_WAITS_SPEED) &&
                    s.release_in_s == 10.0 && !strstr(text, "held");
      continue;
    }
    if (!s.latched) {
      released = t;
      break;
    }
    if (isnan(t_below) && v < 234.0 - 3.0) t_below = t;
    held_ok &= s.level == HM_LEVEL_ALARM && s.held && s.reason == HM_REASON_RMS_CRITERION &&
               s.hold_cause == HM_REASON_RMS_CRITERION && s.hold_since_s == 0.0 && fabs(s.hold_last_met_s - 256.0) < 1e-9 &&
               s.hunted_at_kmh == 234.0 && fabs(s.hunted_at_s - 256.0) < 1e-9 &&
               fabs(s.hold_release_below_kmh - 231.0) < 1e-9 && s.calm_needed_s == 10.0 &&
               s.hopf_low_kmh == 234.0 && s.warn_from_kmh == 224.0 && s.watch_from_kmh == 204.0;
    const double calm = isnan(t_below) ? 0.0 : t - t_below;
    calm_ok &= fabs(s.calm_s - calm) < 1e-9 && fabs(s.release_in_s - (10.0 - calm)) < 1e-9 &&
               s.hold_waits == (isnan(t_below) ? HM_HOLD_WAITS_SPEED : HM_HOLD_WAITS_TIME);
    if (k == 10 * 257) { /* 257 s: 233 km/h, waiting for the speed */
      printf("  at 257 s: %s\n", text);
      HM_CHECK(strcmp(text, "held (sliding r.m.s. criterion exceeded at 0.0 s, last met at 256.0 s): hunting seen "
                            "down to 234.0 km/h at 256.0 s; releases below 231.0 km/h after 10 s calm (calm 0.0 s: "
                            "waits for the speed, 233.0 km/h)") == 0,
               "the held reason: %s", text);
    }
    if (k == 10 * 264) { /* 264 s: 226 km/h, calm for 4.9 s (since 259.1 s, the first status below 231.0 km/h) */
      printf("  at 264 s: %s\n", text);
      HM_CHECK(strstr(text, "releases below 231.0 km/h after 10 s calm (calm 4.9 s)") != NULL, "calm: %s", text);
      char aged[512];
      hm_assessment_reason_text(&s, NAN, aged, sizeof aged);
      HM_CHECK(strstr(aged, "exceeded 264.0 s ago, last met 8.0 s ago): hunting seen down to 234.0 km/h 8.0 s ago;"),
               "as ages: %s", aged);
    }
  }
  HM_CHECK(current_ok, "while hunting: the current criterion, latched, not held");
  HM_CHECK(held_ok, "held: %s, reason %s, cause %s, since %g, last met %g, hunted %.1f at %g, release below %.1f, "
           "interval from %.1f, WARN from %.1f, WATCH from %.1f", hm_level_name(s.level), hm_reason_text(s.reason),
           hm_reason_text(s.hold_cause), s.hold_since_s, s.hold_last_met_s, s.hunted_at_kmh, s.hunted_at_s,
           s.hold_release_below_kmh, s.hopf_low_kmh, s.warn_from_kmh, s.watch_from_kmh);
  HM_CHECK(calm_ok, "calm so far %.2f s at %.1f s (below the release speed from %.1f s)", s.calm_s, s.time_s, t_below);
  HM_CHECK_DELTA(t_below, 259.0 + 0.1, 1e-9, "first status below 231.0 km/h");
  HM_CHECK_DELTA(released, t_below + 10.0, 1e-9, "released after 10 s of calm below the release speed");
  HM_CHECK(!s.held && isnan(s.hold_release_below_kmh) && s.calm_s == 0.0, "released: the hold's fields cleared");
  destroy(a);
  /* the published fields agree (item 7): a speed it hunted at inside an identified interval (0.16 +- 0.009: Hopf
   * 473.8 [442.0, 511.2], WARN from one standard error below the point, 456) bounds WARN and WATCH there too, and the
   * WARN rule's risk is not stated for a threshold the interval did not set; before, WARN stayed at 456 km/h above a
   * speed the wheelset had hunted at */
  hm_margin_estimate g = identified();
  g.conicity_se = 0.009, g.conicity_low = 0.142, g.conicity_high = 0.178;
  g.hopf_model_low_kmh = hopf_closed_form(0.178), g.hopf_model_high_kmh = hopf_closed_form(0.142);
  a = make();
  hm_estimate e = estimate(450.0, 3.0e-3);
  e.rms_exceeded = 1;
  HM_CHECK(update(a, &e, &g, 0.0, &s) == HM_OK && s.conicity_from_estimate && s.latched, "latched");
  HM_CHECK(s.hopf_low_kmh < 450.0 && !s.hopf_low_from_hunting, "450 km/h inside the interval [%.1f, %.1f]",
           s.hopf_low_kmh, s.hopf_high_kmh);
  HM_CHECK(s.warn_from_kmh == 440.0 && s.watch_from_kmh == 420.0 && isnan(s.warn_risk),
           "WARN from %.1f, WATCH from %.1f (hunted at 450), risk %g", s.warn_from_kmh, s.watch_from_kmh, s.warn_risk);
  destroy(a);
}

static void bad_configuration_and_input(void) {
  hm_alarm_config c;
  char why[128];
  hm_alarm_config_default(&c);
  c.warn_amplitude_fraction = 1.5;
  HM_CHECK(hm_alarm_config_validate(&c, why, sizeof why) == HM_EDOMAIN && strstr(why, "warn_amplitude_fraction"),
           "%s", why);
  hm_alarm bad = (hm_alarm)0x1;
  HM_CHECK(create(&c, &bad, why, sizeof why) == HM_EDOMAIN && bad == (hm_alarm)0x1 &&
               strstr(why, "warn_amplitude_fraction"),
           "created with a bad configuration: %s", why);
  hm_alarm_config_default(&c);
  c.min_hold_s = NAN;
  HM_CHECK(hm_alarm_config_validate(&c, why, sizeof why) == HM_EDOMAIN && strstr(why, "min_hold_s"), "%s", why);
  /* a cross-field rule is stated, not only the value (a refused runtime change tells the operator why) */
  hm_alarm_config_default(&c);
  c.watch_speed_margin_kmh = c.warn_speed_margin_kmh - 5.0;
  HM_CHECK(hm_alarm_config_validate(&c, why, sizeof why) == HM_EDOMAIN &&
               strstr(why, "watch_speed_margin_kmh: must be at least warn_speed_margin_kmh") &&
               strstr(why, "(got 5)"),
           "%s", why);
  hm_alarm a = make();
  hm_assessment s;
  const hm_estimate e = estimate(300.0, 0.0);
  HM_CHECK(update(a, &e, NULL, NAN, &s) == HM_EINVAL, "NaN time");
  HM_CHECK(update(a, NULL, NULL, 1.0, &s) == HM_EINVAL, "NULL estimate");
  destroy(a);
}

/* With a conicity estimate (0.16 +- 0.003, as margin.h makes them): the Hopf interval is the closed form's at the
 * interval's conicities; WARN from the point less the larger of the 10 km/h margin and one standard error (h / 2, the
 * interval's lower half-width h in standard errors), WATCH from point - sqrt(h^2 + 30^2) (in quadrature), 0.5 km/h
 * either side; inside it above the point estimate a small oscillation is WARN, not ALARM; above it ALARM; a large
 * standard error falls back to the vehicle's conicity; a mismatch or a sensor at another rate is WATCH; a rate the
 * filters cannot use is NO_DATA. */
static void levels_with_a_conicity_estimate(void) {
  const hm_margin_estimate g = identified();
  const double h = g.hopf_model_kmh - g.hopf_model_low_kmh;
  const double warn_from = g.hopf_model_kmh - fmax(10.0, warn_k() * h / 2.0), watch_from = g.hopf_model_kmh - sqrt(h * h + 900.0);
  const struct {
    double v, amp;
    hm_level level;
    hm_reason reason;
  } cases[] = {
      {400.0, 0.0, HM_LEVEL_OK, HM_REASON_NORMAL},
      {watch_from + 0.5, 0.0, HM_LEVEL_WATCH, HM_REASON_APPROACHING_HOPF},
      {warn_from - 0.5, 0.0, HM_LEVEL_WATCH, HM_REASON_APPROACHING_HOPF},
      {warn_from + 0.5, 0.0, HM_LEVEL_WARN, HM_REASON_NEAR_HOPF},
      {g.hopf_model_kmh + 2.0, 0.0002, HM_LEVEL_WARN, HM_REASON_NEAR_HOPF},
      {g.hopf_model_kmh + 2.0, 0.009, HM_LEVEL_ALARM, HM_REASON_AMPLITUDE_BEYOND_EDGE},
      {g.hopf_model_high_kmh + 0.5, 0.0, HM_LEVEL_ALARM, HM_REASON_ABOVE_HOPF},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
    hm_alarm a = make();
    hm_assessment s;
    const hm_estimate e = estimate(cases[i].v, cases[i].amp);
    HM_CHECK(update(a, &e, &g, 10.0, &s) == HM_OK, "update");
    HM_CHECK(s.level == cases[i].level && s.reason == cases[i].reason, "case %zu: v %.1f amp %g: %s (%s)", i,
             cases[i].v, cases[i].amp, hm_level_name(s.level), hm_reason_text(s.reason));
    HM_CHECK(s.conicity_from_estimate && s.conicity == 0.16, "estimate in use");
    HM_CHECK(s.hopf_low_kmh == g.hopf_model_low_kmh && s.hopf_high_kmh == g.hopf_model_high_kmh, "interval");
    HM_CHECK_DELTA(s.warn_from_kmh, warn_from, 1e-6, "WARN from");
    HM_CHECK_DELTA(s.watch_from_kmh, watch_from, 1e-6, "WATCH from");
    HM_CHECK_DELTA(s.boundaries.hopf_speed_kmh, g.hopf_model_kmh, 1e-6, "table Hopf vs closed form");
    destroy(a);
  }
  /* too uncertain to be used alone (0.16 +- 0.05): with a lightly damped mode held (near_evidence) not replaced by
   * the narrower prior (0.1358 in 0.1058..0.1658) but combined with it, the more cautious of each: the estimate's point (its Hopf speed is the lower), its low end
   * (Hopf at 0.26), the prior's high end (Hopf at 0.1058); WARN from the more cautious of the prior's (its low end
   * less 10 km/h) and the estimate's own (its point less one standard error, h / 2, at most 20 km/h): at 400 km/h
   * WATCH, WARN above */
  hm_margin_estimate wide = g;
  wide.conicity_se = 0.05;
  wide.conicity_low = 0.06;
  wide.conicity_high = 0.26;
  wide.hopf_model_low_kmh = hopf_closed_form(0.26);
  wide.hopf_model_high_kmh = hopf_closed_form(0.06);
  /* without a lightly damped mode held (near_evidence 0) the uncertain estimate is not used: the prior's alone */
  hm_alarm a = make_prior(0.0, 0.0);
  hm_assessment s;
  hm_estimate e = estimate(400.0, 0.0);
  HM_CHECK(update(a, &e, &wide, 0.0, &s) == HM_OK && !s.conicity_from_estimate && s.conicity_from_prior &&
               s.conicity == 0.1358,
           "uncertain estimate, no near evidence: conicity %g (the prior's 0.1358)", s.conicity);
  HM_CHECK_DELTA(s.hopf_low_kmh, hopf_closed_form(0.1658), 1e-9, "no near evidence: the prior's low end");
  HM_CHECK_DELTA(s.hopf_high_kmh, hopf_closed_form(0.1358 - 0.03), 1e-9, "no near evidence: the prior's high end");
  destroy(a);
  wide.near_evidence = 1;
  a = make_prior(0.0, 0.0);
  HM_CHECK(update(a, &e, &wide, 0.0, &s) == HM_OK && !s.conicity_from_estimate && !s.conicity_from_prior &&
               s.conicity == 0.16,
           "uncertain estimate (it lowers the low end: not the prior's interval): conicity %g, from estimate %d, from "
           "prior %d", s.conicity, s.conicity_from_estimate, s.conicity_from_prior);
  HM_CHECK_DELTA(s.hopf_low_kmh, hopf_closed_form(0.26), 1e-9, "uncertain estimate: low end");
  HM_CHECK_DELTA(s.hopf_high_kmh, hopf_closed_form(0.1358 - 0.03), 1e-9, "uncertain estimate: high end");
  const double from_e =
      hopf_closed_form(0.16) - fmax(10.0, fmin(warn_k() * 0.5 * (hopf_closed_form(0.16) - hopf_closed_form(0.26)),
                                               HM_ALARM_WARN_MAX_BELOW_KMH));
  HM_CHECK_DELTA(s.warn_from_kmh, fmin(hopf_closed_form(0.1658) - 10.0, from_e), 1e-9, "uncertain estimate: WARN from");
  HM_CHECK(s.level == HM_LEVEL_WATCH && s.reason == HM_REASON_APPROACHING_HOPF, "uncertain estimate at 400 km/h: %s",
           hm_level_name(s.level));
  destroy(a);
  a = make_prior(0.0, 0.0);
  e = estimate(from_e + 0.5, 0.0);
  HM_CHECK(update(a, &e, &wide, 0.0, &s) == HM_OK && s.level == HM_LEVEL_WARN &&
               s.reason == HM_REASON_NEAR_HOPF,
           "uncertain estimate at %.1f km/h: %s", from_e + 0.5, hm_level_name(s.level));
  destroy(a);
  /* the model-free interval 30 km/h lower (and valid): its lower end does not count from two windows, does from
   * three with a lightly damped mode held (WARN from the point less h / 2, h now down to the model-free end; from two,
   * or three without one, WATCH there) */
  hm_margin_estimate lower = g;
  lower.hopf_free_valid = 1;
  lower.hopf_free_kmh = g.hopf_model_kmh - 30.0;
  lower.hopf_free_low_kmh = g.hopf_model_low_kmh - 30.0;
  lower.hopf_free_high_kmh = g.hopf_model_high_kmh - 30.0;
  const double h_free = g.hopf_model_kmh - lower.hopf_free_low_kmh;
  const double v_free = g.hopf_model_kmh - fmax(10.0, warn_k() * h_free / 2.0) + 0.5;
  e = estimate(v_free, 0.0);
  for (unsigned n = 2; n <= 4; ++n) {
    /* n 2: two windows; 3: three with a lightly damped mode held; 4: three without one (the zero extrapolated) */
    lower.n_windows = n == 4 ? 3 : n;
    lower.near_evidence = n != 4;
    a = make();
    HM_CHECK(update(a, &e, &lower, 0.0, &s) == HM_OK, "update");
    HM_CHECK_DELTA(s.hopf_low_kmh, n == 3 ? lower.hopf_free_low_kmh : g.hopf_model_low_kmh, 1e-9, "low end");
    HM_CHECK_DELTA(s.hopf_high_kmh, g.hopf_model_high_kmh, 1e-9, "high end (no mismatch: the model's)");
    HM_CHECK(s.level == (n == 3 ? HM_LEVEL_WARN : HM_LEVEL_WATCH), "model-free lower, case %u: %s", n,
             hm_level_name(s.level));
    destroy(a);
  }
  /* the estimate's use has a hysteresis: a new alarm refuses 0.011 (above conicity_max_se 0.01); one that used 0.009
   * keeps it at 0.011 and 0.0124, and leaves it at 0.0126 (above 1.25 x 0.01) */
  {
    hm_margin_estimate h = g;
    e = estimate(400.0, 0.0);
    a = make();
    h.conicity_se = 0.011;
    HM_CHECK(update(a, &e, &h, 0.0, &s) == HM_OK && !s.conicity_from_estimate, "0.011 at first: refused");
    destroy(a);
    a = make();
    const double ses[4] = {0.009, 0.011, 0.0124, 0.0126};
    const int used[4] = {1, 1, 1, 0};
    for (int k = 0; k < 4; ++k) {
      h.conicity_se = ses[k];
      HM_CHECK(update(a, &e, &h, 0.1 * k, &s) == HM_OK && s.conicity_from_estimate == used[k],
               "se %g after the others: from estimate %d", ses[k], s.conicity_from_estimate);
    }
    destroy(a);
  }
  e = estimate(400.0, 0.0);
  hm_margin_estimate mismatch = g;
  mismatch.model_mismatch = 1;
  a = make();
  HM_CHECK(update(a, &e, &mismatch, 0.0, &s) == HM_OK && s.level == HM_LEVEL_WATCH &&
               s.reason == HM_REASON_MODEL_MISMATCH,
           "mismatch: %s", hm_reason_text(s.reason));
  destroy(a);
  e.sample_rate_mismatch = 1;
  a = make();
  HM_CHECK(update(a, &e, &g, 0.0, &s) == HM_OK && s.level == HM_LEVEL_WATCH &&
               s.reason == HM_REASON_RATE_MISMATCH,
           "rate: %s", hm_reason_text(s.reason));
  /* partly blind: a third of the last 10 s of samples lost (bridged gaps) is WATCH; a tenth is not */
  destroy(a);
  a = make();
  e = estimate(400.0, 0.0);
  e.loss_fraction = 0.3;
  HM_CHECK(update(a, &e, &g, 0.0, &s) == HM_OK && s.level == HM_LEVEL_WATCH &&
               s.reason == HM_REASON_PARTLY_BLIND,
           "blind: %s", hm_reason_text(s.reason));
  destroy(a);
  a = make();
  e.loss_fraction = 0.1;
  HM_CHECK(update(a, &e, &g, 0.0, &s) == HM_OK && s.level == HM_LEVEL_OK, "10%% lost: %s",
           hm_level_name(s.level));
  e.sample_rate_supported = 0;
  e.accel_valid = 0;
  HM_CHECK(update(a, &e, &g, 0.1, &s) == HM_OK && s.level == HM_LEVEL_NO_DATA &&
               s.reason == HM_REASON_BAD_SAMPLE_RATE && !s.boundaries_valid,
           "unusable rate: %s", hm_reason_text(s.reason));
  destroy(a);
}

/* Before identification the interval comes from the prior, not from the table's interpolation error (issue #18):
 * the default prior (the vehicle's 0.1358 -+ 0.03) gives the Hopf speeds at 0.1658 and 0.1058, checked against the
 * eigenvalue search (dgeev, a second method) to 0.01 km/h, with the table's point inside; a configured range
 * (0.08..0.25) gives its own ends. Worn wheels (0.16: Hopf 473.8 km/h) on a speed ramp: WARN at least 5 km/h (10 s
 * at 0.5 km/h/s) below their Hopf speed and not more than 40 km/h below it. A prior that does not hold the fallback
 * is refused. */
static void prior_before_identification(void) {
  double v_mps;
  hm_linear_critical_speed_eig(&vehicle, 0.1358 + 0.03, 50.0, 400.0, 1e-6, &v_mps);
  const double lo_eig = hm_kmh_from_mps(v_mps);
  hm_linear_critical_speed_eig(&vehicle, 0.1358 - 0.03, 50.0, 400.0, 1e-6, &v_mps);
  const double hi_eig = hm_kmh_from_mps(v_mps);
  hm_alarm a = make_prior(0.0, 0.0);
  hm_assessment s;
  hm_estimate e = estimate(300.0, 0.0);
  HM_CHECK(update(a, &e, NULL, 0.0, &s) == HM_OK && s.conicity_from_prior && !s.conicity_from_estimate &&
               s.conicity == 0.1358,
           "prior in use");
  HM_CHECK_DELTA(s.hopf_low_kmh, lo_eig, 0.01, "prior: low end (Hopf at 0.1658)");
  HM_CHECK_DELTA(s.hopf_high_kmh, hi_eig, 0.01, "prior: high end (Hopf at 0.1058)");
  HM_CHECK(s.hopf_low_kmh < s.boundaries.hopf_speed_kmh && s.boundaries.hopf_speed_kmh < s.hopf_high_kmh,
           "the point %g inside [%g, %g]", s.boundaries.hopf_speed_kmh, s.hopf_low_kmh, s.hopf_high_kmh);
  /* the worn-wheel ramp, speed only (no oscillation yet) */
  const double worn_hopf = hopf_closed_form(0.16);
  double warn_at = -1.0;
  for (double v = 400.0; v < worn_hopf; v += 0.05) {
    e = estimate(v, 0.0);
    update(a, &e, NULL, 10.0 + (v - 400.0) / 0.5, &s);
    if (s.level >= HM_LEVEL_WARN && warn_at < 0.0) warn_at = v;
  }
  HM_CHECK(warn_at > 0.0 && warn_at <= worn_hopf - 5.0 && warn_at >= worn_hopf - 40.0,
           "worn wheels on a ramp: WARN at %.1f km/h, their Hopf speed %.1f", warn_at, worn_hopf);
  destroy(a);
  a = make_prior(0.08, 0.25);
  e = estimate(300.0, 0.0);
  update(a, &e, NULL, 0.0, &s);
  HM_CHECK_DELTA(s.hopf_low_kmh, hopf_closed_form(0.25), 1e-9, "range 0.08..0.25: low end");
  HM_CHECK_DELTA(s.hopf_high_kmh, hopf_closed_form(0.08), 1e-9, "range 0.08..0.25: high end");
  HM_CHECK(s.level == HM_LEVEL_OK, "range 0.08..0.25 at 300 km/h: %s", hm_level_name(s.level));
  destroy(a);
  hm_alarm_config c;
  hm_alarm_config_default(&c);
  c.conicity_prior_low = 0.15;
  c.conicity_prior_high = 0.30;
  char why[160];
  hm_alarm bad = (hm_alarm)0x1;
  HM_CHECK(create(&c, &bad, why, sizeof why) == HM_EDOMAIN && bad == (hm_alarm)0x1 &&
               strstr(why, "must hold the fallback conicity 0.1358"),
           "a prior without the fallback: %s", why);
  c.conicity_prior_low = 0.0;
  HM_CHECK(hm_alarm_config_validate(&c, why, sizeof why) == HM_EDOMAIN && strstr(why, "conicity_prior_high"),
           "one end only: %s", why);
}

/* A sustained acceleration raises WARN early below an identified interval (alarm.h): the thresholds are judged on the
 * speed 20 s ahead. References: a ramp at a km/h/s gives the anticipation a x 20 km/h once the 2.5 s blocks span 20 s
 * (the least-squares slope of block means of a straight line is exact), so WARN comes when v + 20 a reaches warn_from; below the
 * prior's range none (WARN when v itself reaches it); updates 5 s apart the same; a step of the speed signal (40 km/h
 * in one update, steady before and after) and a steady speed with the speed sensor's noise (0.3 km/h r.m.s. at 20 Hz)
 * anticipate nothing beyond the noise's bound (1 km/h); braking anticipates nothing. */
static void anticipates_a_sustained_acceleration(void) {
  const hm_margin_estimate g = identified();
  hm_alarm a = make();
  hm_assessment s;
  hm_estimate e = estimate(400.0, 0.0);
  HM_CHECK(update(a, &e, &g, 0.0, &s) == HM_OK && s.conicity_from_estimate, "update");
  const double warn_from = s.warn_from_kmh;
  HM_CHECK_DELTA(warn_from, g.hopf_model_kmh - 10.0, 1e-9, "WARN from the point less 10 km/h");
  destroy(a);
  /* the prior's range: no anticipation on a ramp of 0.5 km/h/s */
  a = make();
  double prior_most = 0.0;
  for (int k = 0; k <= 20 * 60; ++k) {
    e = estimate(400.0 + 0.025 * k, 0.0);
    HM_CHECK(update(a, &e, NULL, 0.05 * k, &s) == HM_OK, "update");
    prior_most = fmax(prior_most, s.anticipation_kmh);
  }
  HM_CHECK(prior_most == 0.0, "the prior's range anticipated %.2f km/h", prior_most);
  destroy(a);
  /* ramps at 0.2 and 0.5 km/h/s from 60 km/h below the threshold, updates at 20 Hz */
  const double rates[2] = {0.2, 0.5};
  for (int i = 0; i < 2; ++i) {
    a = make();
    double t_warn = NAN, worst = 0.0;
    for (int k = 0; k <= 20 * 400 && isnan(t_warn); ++k) {
      const double t = 0.05 * k;
      e = estimate(warn_from - 60.0 + rates[i] * t, 0.0);
      HM_CHECK(update(a, &e, &g, t, &s) == HM_OK, "update");
      if (t > 25.0) worst = fmax(worst, fabs(s.anticipation_kmh - 20.0 * rates[i]));
      if (s.level == HM_LEVEL_WARN) t_warn = t;
    }
    /* WARN where v + 20 a reaches the threshold: t = (60 - 20 a) / a */
    const double t_expected = (60.0 - 20.0 * rates[i]) / rates[i];
    printf("  ramp %.1f km/h/s: anticipation within %.2g km/h of %.0f, WARN at %.2f s (expected %.2f s, 20 s early)\n",
           rates[i], worst, 20.0 * rates[i], t_warn, t_expected);
    HM_CHECK(worst < 1e-6, "ramp %.1f: anticipation off by %g km/h", rates[i], worst);
    HM_CHECK(fabs(t_warn - t_expected) <= 0.051, "ramp %.1f: WARN at %.2f s, expected %.2f", rates[i], t_warn,
             t_expected);
    destroy(a);
  }
  /* updates 5 s apart (a slow status rate): a block each, the same anticipation */
  a = make();
  for (int k = 0; k <= 6; ++k) {
    e = estimate(400.0 + 0.5 * 5.0 * k, 0.0);
    HM_CHECK(update(a, &e, &g, 5.0 * k, &s) == HM_OK, "update");
  }
  HM_CHECK_DELTA(s.anticipation_kmh, 10.0, 1e-9, "updates 5 s apart on a ramp of 0.5 km/h/s");
  destroy(a);
  /* a step of 40 km/h to 5 km/h below the threshold (in one update, or over two 0.05 s apart), with the sensor's
   * noise; then braking at 0.5 km/h/s */
  for (int spread = 0; spread < 2; ++spread) {
    a = make();
    double most = 0.0;
    int warned = 0;
    for (int k = 0; k <= 20 * 120; ++k) {
      const double t = 0.05 * k;
      const double v = t < 30.0                       ? warn_from - 45.0
                       : spread && t < 30.05 - 1e-9 ? warn_from - 25.0
                       : t < 80.0                     ? warn_from - 5.0
                                                      : warn_from - 5.0 - 0.5 * (t - 80.0);
      e = estimate(v + 0.3 * hm_test_gauss(), 0.0);
      HM_CHECK(update(a, &e, &g, t, &s) == HM_OK, "update");
      most = fmax(most, s.anticipation_kmh);
      warned |= s.level >= HM_LEVEL_WARN;
    }
    printf("  a 40 km/h step%s, the sensor's noise, braking: anticipation at most %.2f km/h, WARN %s\n",
           spread ? " over two updates" : "", most, warned ? "raised" : "not raised");
    HM_CHECK(most < 1.0 && !warned, "step and noise: anticipation up to %.2f km/h, WARN %d", most, warned);
    destroy(a);
  }
}

/* A driver's notches do not defeat the anticipation (issue #27 item 6): the same mean acceleration of 0.5 km/h/s as a
 * smooth ramp, as 5 s at 1 km/h/s and 5 s held (or 10 s and 10 s), from 60 km/h below the WARN threshold with updates
 * at 20 Hz. References: the mean acceleration gives the anticipation 0.5 x 20 = 10 km/h, so WARN comes where the
 * notched speed itself reaches the threshold less 10 km/h: the first time the staircase (closed form) reaches 50 km/h
 * above its start, 95 s (10/10: 90 s), against 100 s on the smooth ramp; the anticipation within 1 km/h of 10 km/h
 * once 35 s of the ramp are in (the least-squares slope over the blocks of the last 30 s ripples by 4% with the
 * notches), so WARN between the times the staircase reaches 49 and 51 km/h. A notched ramp had anticipated nothing
 * (5/5: its held parts set the least slope between blocks to 0, WARN 20 s later than the smooth ramp's). */
static double staircase_kmh(double t, double on_s, double off_s, double rate_kmh_s) {
  const double cycle = on_s + off_s, k = floor(t / cycle);
  return rate_kmh_s * (k * on_s + fmin(t - k * cycle, on_s));
}

static void anticipation_is_not_defeated_by_notches(void) {
  const hm_margin_estimate g = identified();
  const double notches[3][2] = {{0.0, 0.0}, {5.0, 5.0}, {10.0, 10.0}}; /* on, off [s]; 0: the smooth ramp */
  double t_warn[3];
  for (int i = 0; i < 3; ++i) {
    hm_alarm a = make();
    hm_assessment s;
    hm_estimate e = estimate(400.0, 0.0);
    HM_CHECK(update(a, &e, &g, -1.0, &s) == HM_OK && s.conicity_from_estimate, "update");
    const double warn_from = s.warn_from_kmh, on = notches[i][0], off = notches[i][1];
    destroy(a);
    a = make();
    t_warn[i] = NAN;
    double worst = 0.0, t_ref = NAN, t_lo = NAN, t_hi = NAN;
    for (int k = 0; k <= 20 * 200 && (isnan(t_warn[i]) || isnan(t_hi)); ++k) {
      const double t = 0.05 * k;
      const double rise = on > 0.0 ? staircase_kmh(t, on, off, 0.5 * (on + off) / on) : 0.5 * t;
      if (isnan(t_ref) && rise >= 50.0 - 1e-9) t_ref = t;
      if (isnan(t_lo) && rise >= 49.0 - 1e-9) t_lo = t; /* the anticipation 11 km/h */
      if (isnan(t_hi) && rise >= 51.0 - 1e-9) t_hi = t; /* 9 km/h */
      if (!isnan(t_warn[i])) continue;
      e = estimate(warn_from - 60.0 + rise, 0.0);
      HM_CHECK(update(a, &e, &g, t, &s) == HM_OK, "update");
      if (t >= 35.0) worst = fmax(worst, fabs(s.anticipation_kmh - 10.0));
      if (s.level == HM_LEVEL_WARN) t_warn[i] = t;
    }
    printf("  %s: anticipation within %.2f km/h of 10 km/h, WARN at %.2f s (where the speed reaches the threshold "
           "less 10 km/h: %.2f s)\n", on > 0.0 ? (on == 5.0 ? "notches 5 s / 5 s" : "notches 10 s / 10 s")
                                                : "smooth ramp", worst, t_warn[i], t_ref);
    HM_CHECK(worst <= 1.0, "notches %g/%g: anticipation off by %.2f km/h", on, off, worst);
    HM_CHECK(t_warn[i] >= t_lo && t_warn[i] <= t_hi, "notches %g/%g: WARN at %.2f s, expected %.2f s (%.2f-%.2f)", on,
             off, t_warn[i], t_ref, t_lo, t_hi);
    destroy(a);
  }
  HM_CHECK(fabs(t_warn[1] - t_warn[0]) <= 6.0 && fabs(t_warn[2] - t_warn[0]) <= 11.0,
           "WARN at %.2f s smooth, %.2f and %.2f s notched", t_warn[0], t_warn[1], t_warn[2]);
}

/* Flags that flip with the provisional window (issue #27 item 7; margin.h counts the current stretch's window while it
 * lasts, replaced every fit): model_mismatch, the model-free interval's window count (its lower end counts from three
 * windows with a lightly damped mode held) and the estimate's use alone (precise: here outside_prior flipping) each
 * alternate 2 s on, 2 s off for 60 s, then stay off. References, from the input: the flag raised at its first "on"
 * (3 s) and kept until HM_ALARM_FLAG_CLEAR_S (20 s) after its last "on" ended (61 s, so cleared at 81 s), the
 * published interval and model_mismatch changing twice; the estimate's use alone (from the start) dropped at the first
 * "off" (5 s) and taken again only after 20 s in which it could have been (never while it flips: at 63 + 20 s),
 * meanwhile combined with the prior (model_interval_used; its standard error 0.011, within the hysteresis of the
 * 0.01 limit once used, as while it was used). Before, each flipped with every provisional window: 29-30 times. */
static void provisional_windows_do_not_chatter(void) {
  const hm_margin_estimate g = identified();
  hm_margin_estimate lower = g; /* the model-free interval 30 km/h below the model's, valid */
  lower.hopf_free_valid = 1, lower.near_evidence = 1;
  lower.hopf_free_kmh = g.hopf_model_kmh - 30.0;
  lower.hopf_free_low_kmh = g.hopf_model_low_kmh - 30.0;
  lower.hopf_free_high_kmh = g.hopf_model_high_kmh - 30.0;
  for (int flag = 0; flag < 3; ++flag) { /* 0 model_mismatch, 1 the model-free window count, 2 outside_prior */
    hm_alarm a = make();
    hm_assessment s;
    const hm_estimate e = estimate(400.0, 0.0);
    int flips = 0, prev = -1, left_out = 0;
    double first_on = NAN, last_off = NAN;
    for (int k = 0; k <= 10 * 120; ++k) {
      const double t = 0.1 * k;
      const int on = t >= 3.0 && t < 63.0 && ((int)floor((t - 3.0) / 2.0)) % 2 == 0;
      hm_margin_estimate m = flag == 1 ? lower : g;
      if (flag == 0) m.model_mismatch = on;
      if (flag == 1) m.n_windows = on ? 3 : 2;
      if (flag == 2) m.outside_prior = t >= 3.0 && t < 63.0 && !on ? -1 : 0; /* 0: it may be used alone */
      if (flag == 2) m.conicity_se = t < 3.0 ? 0.009 : 0.011; /* within the standard error's hysteresis once used */
      HM_CHECK(update(a, &e, &m, t, &s) == HM_OK, "update");
      const int shown = flag == 0 ? s.model_mismatch : flag == 1 ? s.hopf_free_used : s.conicity_from_estimate;
      /* waiting to be used alone again, the estimate is combined with the prior, not left out */
      if (flag == 2 && m.outside_prior == 0) left_out += !s.model_interval_used;
      flips += prev >= 0 && shown != prev;
      if (prev == 0 && shown == 1 && isnan(first_on)) first_on = t;
      if (prev == 1 && shown == 0) last_off = t;
      prev = shown;
    }
    static const char *const names[3] = {"model_mismatch", "the model-free window count", "the estimate alone"};
    printf("  %s flipping every 2 s for 60 s: shown changed %d times, raised at %.1f s, cleared at %.1f s\n",
           names[flag], flips, first_on, last_off);
    if (flag < 2) {
      HM_CHECK(flips == 2 && fabs(first_on - 3.0) < 1e-9 && fabs(last_off - (61.0 + 20.0)) < 0.051,
               "%s: %d changes, raised at %.1f, cleared at %.1f", names[flag], flips, first_on, last_off);
      HM_CHECK_DELTA(s.hopf_low_kmh, g.hopf_model_low_kmh, 1e-9, "after: the model's low end");
    } else {
      /* used alone from the start; dropped at the first "off" (5 s); used again 20 s after the last "off" ended (63 s) */
      HM_CHECK(flips == 2 && fabs(last_off - 5.0) < 1e-9 && fabs(first_on - (63.0 + 20.0)) < 0.051,
               "%s: %d changes, dropped at %.1f, taken again at %.1f", names[flag], flips, last_off, first_on);
      HM_CHECK(left_out == 0, "%d statuses left a usable estimate out while it waited", left_out);
    }
    destroy(a);
  }
}

/* A conicity in use outside the table's range (issue #27 item 8): identified 0.20 +- 0.003 with a table of 0.12-0.16.
 * References: the family continued directly at 0.20 (test_tables: lowest cycle speed 226.8 km/h, the edge at 399.7 km/h
 * 7.396 mm, at 252.4 km/h 9.469 mm) and the closed-form Hopf speed (420.7 km/h). The level's boundaries are at or below
 * them, and the status says so (conicity_outside_table +1; -1 for 0.10 below the table); the end conicity's (234.5 km/h,
 * 8.13 mm), which the monitor took before, are not. */
static void conicity_outside_the_table(void) {
  hm_margin_estimate g = identified();
  g.conicity = 0.20, g.conicity_low = 0.194, g.conicity_high = 0.206;
  g.hopf_model_kmh = hopf_closed_form(0.20);
  g.hopf_model_low_kmh = hopf_closed_form(0.206), g.hopf_model_high_kmh = hopf_closed_form(0.194);
  const double speeds[2] = {399.7, 252.4}, edges[2] = {7.396e-3, 9.469e-3};
  for (int k = 0; k < 2; ++k) {
    hm_alarm a = make_prior(0.0, 0.0);
    hm_assessment s;
    const hm_estimate e = estimate(speeds[k], 0.0);
    HM_CHECK(update(a, &e, &g, 0.0, &s) == HM_OK && s.conicity_from_estimate && s.conicity == 0.20, "0.20");
    printf("  0.20 at %.1f km/h: outside %d, Hopf %.2f, lowest cycle %.1f km/h, edge %.3f mm\n", speeds[k],
           s.conicity_outside_table, s.boundaries.hopf_speed_kmh, s.boundaries.lowest_cycle_speed_kmh,
           1e3 * s.edge_used_m);
    HM_CHECK(s.conicity_outside_table == 1 && s.boundaries.widened, "flagged: %d", s.conicity_outside_table);
    HM_CHECK_REL(s.boundaries.hopf_speed_kmh, hopf_closed_form(0.20), 1e-9, "the Hopf speed at 0.20");
    HM_CHECK(s.boundaries.lowest_cycle_speed_kmh <= 226.8, "lowest cycle speed %.1f", s.boundaries.lowest_cycle_speed_kmh);
    HM_CHECK(s.edge_used_m > 0.0 && s.edge_used_m <= edges[k], "edge %.4f mm", 1e3 * s.edge_used_m);
    destroy(a);
  }
  hm_margin_estimate n = identified();
  n.conicity = 0.10, n.conicity_low = 0.097, n.conicity_high = 0.103;
  n.hopf_model_kmh = hopf_closed_form(0.10);
  n.hopf_model_low_kmh = hopf_closed_form(0.103), n.hopf_model_high_kmh = hopf_closed_form(0.097);
  hm_alarm a = make_prior(0.08, 0.16);
  hm_assessment s;
  const hm_estimate e = estimate(400.0, 0.0);
  HM_CHECK(update(a, &e, &n, 0.0, &s) == HM_OK && s.conicity_from_estimate && s.conicity_outside_table == -1,
           "0.10: from estimate %d, outside %d", s.conicity_from_estimate, s.conicity_outside_table);
  destroy(a);
  a = make();
  HM_CHECK(update(a, &e, NULL, 0.0, &s) == HM_OK && s.conicity_outside_table == 0, "inside");
  destroy(a);
}

/* What the model may not explain (issue #26), with the default prior (0.1358 -+ 0.03: Hopf 464.8-593.8 km/h by the
 * closed form): a precise estimate of 0.08 (Hopf 690 km/h, the dangerous direction) outside the prior raises WATCH
 * and the interval stays the prior's (the more cautious of each end), so at 470 km/h WARN as the prior gives; 0.29
 * (Hopf 350 km/h, cautious) lowers it: ALARM at 360 km/h, with a lightly damped mode held or precise without one,
 * and 0.176 +- 0.005 WARN 5 km/h below its Hopf speed; as uncertain without one, WATCH; with model_mismatch, and from a bogie-frame sensor, the
 * model-based interval is not used (the prior's at 470 km/h, WARN, where the estimate of 0.16 alone gives more
 * room); a conicity change's first window is combined with the prior (the more cautious), the second used alone;
 * an ambiguous narrow peak within 60 s raises WATCH. The WARN rule's risk: with h/2 = 1 standard error above the
 * 10 km/h margin, Phi(-1) = 0.1587; with the margin larger, Phi(-10 / se). */
static void what_the_model_may_not_explain(void) {
  const double prior_lo = hopf_closed_form(0.1658), prior_hi = hopf_closed_form(0.1058);
  hm_margin_estimate low = identified(), high = identified();
  low.conicity = 0.08, low.conicity_low = 0.074, low.conicity_high = 0.086, low.outside_prior = -1;
  low.hopf_model_kmh = hopf_closed_form(0.08);
  low.hopf_model_low_kmh = hopf_closed_form(0.086), low.hopf_model_high_kmh = hopf_closed_form(0.074);
  high.conicity = 0.29, high.conicity_low = 0.284, high.conicity_high = 0.296, high.outside_prior = 1;
  high.near_evidence = 1;
  high.hopf_model_kmh = hopf_closed_form(0.29);
  high.hopf_model_low_kmh = hopf_closed_form(0.296), high.hopf_model_high_kmh = hopf_closed_form(0.284);
  hm_alarm a = make_prior(0.0, 0.0);
  hm_assessment s;
  hm_estimate e = estimate(470.0, 0.0);
  HM_CHECK(update(a, &e, &low, 0.0, &s) == HM_OK && s.level == HM_LEVEL_WARN && !s.conicity_from_estimate,
           "0.08 at 470 km/h: %s (%s), from estimate %d", hm_level_name(s.level), hm_reason_text(s.reason),
           s.conicity_from_estimate);
  HM_CHECK_DELTA(s.hopf_low_kmh, prior_lo, 1e-9, "0.08: the prior's low end");
  HM_CHECK_DELTA(s.hopf_high_kmh, prior_hi, 1e-9, "0.08: the prior's high end");
  destroy(a);
  a = make_prior(0.0, 0.0);
  e = estimate(400.0, 0.0);
  HM_CHECK(update(a, &e, &low, 0.0, &s) == HM_OK && s.level == HM_LEVEL_WATCH &&
               s.reason == HM_REASON_OUTSIDE_PRIOR,
           "0.08 at 400 km/h: %s (%s)", hm_level_name(s.level), hm_reason_text(s.reason));
  destroy(a);
  a = make_prior(0.0, 0.0);
  e = estimate(hopf_closed_form(0.284) + 1.0, 0.0);
  HM_CHECK(update(a, &e, &high, 0.0, &s) == HM_OK && s.level == HM_LEVEL_ALARM &&
               s.reason == HM_REASON_ABOVE_HOPF,
           "0.29: %s (%s)", hm_level_name(s.level), hm_reason_text(s.reason));
  HM_CHECK_DELTA(s.hopf_low_kmh, hopf_closed_form(0.296), 1e-9, "0.29 lowers the low end");
  HM_CHECK_DELTA(s.hopf_high_kmh, hopf_closed_form(0.284), 1e-9, "0.29 lowers the high end");
  destroy(a);
  /* the same estimate with no window near its Hopf speed: precise (0.003) and on the cautious side it still lowers
   * the interval (the review's 0.176 +- 0.005 for a true 0.18 above a prior of 0.106-0.166 had given back the
   * prior's 465-594 km/h for a Hopf speed of 445); as uncertain (0.02 > conicity_max_se 0.01) it is reported
   * (WATCH) and the prior's interval kept: at 360 km/h WATCH, not ALARM */
  high.near_evidence = 0;
  a = make_prior(0.0, 0.0);
  HM_CHECK(update(a, &e, &high, 0.0, &s) == HM_OK && s.level == HM_LEVEL_ALARM && s.model_interval_used,
           "0.29 precise without near evidence: %s (%s)", hm_level_name(s.level), hm_reason_text(s.reason));
  HM_CHECK_DELTA(s.hopf_low_kmh, hopf_closed_form(0.296), 1e-9, "0.29 precise without near evidence: low end");
  destroy(a);
  high.conicity_se = 0.02;
  a = make_prior(0.0, 0.0);
  HM_CHECK(update(a, &e, &high, 0.0, &s) == HM_OK && s.level == HM_LEVEL_WATCH &&
               s.reason == HM_REASON_OUTSIDE_PRIOR && !s.model_interval_used,
           "0.29 +- 0.02 without near evidence: %s (%s)", hm_level_name(s.level), hm_reason_text(s.reason));
  HM_CHECK_DELTA(s.hopf_low_kmh, prior_lo, 1e-9, "0.29 +- 0.02 without near evidence: the prior's low end");
  destroy(a);
  /* the review's case: 0.176 +- 0.005 (interval 0.166-0.186), the prior's WARN (from 454.8) not kept at 440 km/h */
  hm_margin_estimate near = identified();
  near.conicity = 0.176, near.conicity_se = 0.005, near.conicity_low = 0.166, near.conicity_high = 0.186;
  near.outside_prior = 1, near.near_evidence = 0;
  near.hopf_model_kmh = hopf_closed_form(0.176);
  near.hopf_model_low_kmh = hopf_closed_form(0.186), near.hopf_model_high_kmh = hopf_closed_form(0.166);
  a = make_prior(0.0, 0.0);
  e = estimate(hopf_closed_form(0.176) - 5.0, 0.0);
  HM_CHECK(update(a, &e, &near, 0.0, &s) == HM_OK && s.level == HM_LEVEL_WARN && s.model_interval_used,
           "0.176 +- 0.005 at %.1f km/h: %s (%s)", e.speed_kmh, hm_level_name(s.level), hm_reason_text(s.reason));
  HM_CHECK_DELTA(s.hopf_low_kmh, hopf_closed_form(0.186), 1e-9, "0.176: the estimate's low end");
  destroy(a);
  /* mismatch and a frame sensor: the prior at 470 km/h (WARN), not the estimate (0.16 alone: WARN from 463.8) */
  hm_margin_estimate g = identified();
  for (int k = 0; k < 2; ++k) {
    hm_margin_estimate gk = g;
    a = make_prior(0.0, 0.0);
    if (k == 0) gk.model_mismatch = 1;
    else hm_interval_set_measurement_point(interval_of(a), HM_POINT_BOGIE_FRAME);
    e = estimate(460.0, 0.0);
    HM_CHECK(update(a, &e, &gk, 0.0, &s) == HM_OK && !s.model_interval_used && !s.conicity_from_estimate,
             "%s: model interval used %d", k ? "frame" : "mismatch", s.model_interval_used);
    HM_CHECK_DELTA(s.hopf_low_kmh, prior_lo, 1e-9, "the prior's low end");
    HM_CHECK_DELTA(s.hopf_high_kmh, prior_hi, 1e-9, "the prior's high end");
    HM_CHECK_DELTA(s.warn_from_kmh, prior_lo - 10.0, 1e-9, "WARN from the prior's low end less 10 km/h");
    destroy(a);
  }
  /* a frame sensor with the model-free interval valid: it bounds both ends */
  hm_margin_estimate fr = g;
  fr.hopf_free_valid = 1, fr.n_windows = 2;
  fr.hopf_free_kmh = 500.0, fr.hopf_free_low_kmh = 480.0, fr.hopf_free_high_kmh = 530.0;
  a = make_prior(0.0, 0.0);
  hm_interval_set_measurement_point(interval_of(a), HM_POINT_BOGIE_FRAME);
  e = estimate(440.0, 0.0);
  HM_CHECK(update(a, &e, &fr, 0.0, &s) == HM_OK, "frame, model-free");
  HM_CHECK_DELTA(s.hopf_low_kmh, prior_lo, 1e-9, "frame: the lower of the prior's and the model-free low ends");
  HM_CHECK_DELTA(s.hopf_high_kmh, 530.0, 1e-9, "frame: the model-free high end");
  destroy(a);
  /* a change's first window: with the prior, the more cautious; the second alone */
  hm_margin_estimate ch = g;
  ch.n_changes = 1, ch.windows_since_change = 1, ch.near_evidence = 1;
  a = make_prior(0.0, 0.0);
  e = estimate(400.0, 0.0);
  HM_CHECK(update(a, &e, &ch, 0.0, &s) == HM_OK && !s.conicity_from_estimate && s.model_interval_used,
           "first window after a change: alone %d", s.conicity_from_estimate);
  HM_CHECK_DELTA(s.hopf_low_kmh, fmin(prior_lo, g.hopf_model_low_kmh), 1e-9, "after a change: the lower low end");
  HM_CHECK_DELTA(s.hopf_high_kmh, fmin(prior_hi, g.hopf_model_high_kmh), 1e-9, "after a change: the lower high end");
  ch.windows_since_change = 2;
  HM_CHECK(update(a, &e, &ch, 0.1, &s) == HM_OK && s.conicity_from_estimate, "second window: alone");
  destroy(a);
  /* the review's case (issue #27): a precise change's first window far below its Hopf speed (no near evidence), 0.18
   * +- 0.0077 after windows at 0.12; it had been left out, the prior's [464.8, 593.8] alone and WATCH at 450 km/h,
   * above the new Hopf speed: now the more cautious of it and the prior, its interval (the closed forms at 0.18 -+ 2 x
   * 0.0077, both below the prior's ends) and WARN at 450 (from 444.9 less one standard error), not the prior's
   * interval (conicity_from_prior 0) */
  hm_margin_estimate far = g;
  far.n_changes = 1, far.windows_since_change = 1, far.near_evidence = 0;
  far.conicity = 0.18, far.conicity_se = 0.0077, far.conicity_low = 0.18 - 0.0154, far.conicity_high = 0.18 + 0.0154;
  far.hopf_model_kmh = hopf_closed_form(0.18);
  far.hopf_model_low_kmh = hopf_closed_form(far.conicity_high), far.hopf_model_high_kmh = hopf_closed_form(0.1646);
  a = make_prior(0.0, 0.0);
  e = estimate(450.0, 0.0);
  HM_CHECK(update(a, &e, &far, 0.0, &s) == HM_OK && s.model_interval_used && !s.conicity_from_estimate &&
               !s.conicity_from_prior && s.level == HM_LEVEL_WARN && s.reason == HM_REASON_NEAR_HOPF,
           "a precise change window far below: %s (%s), used %d, from prior %d", hm_level_name(s.level),
           hm_reason_text(s.reason), s.model_interval_used, s.conicity_from_prior);
  HM_CHECK_DELTA(s.hopf_low_kmh, hopf_closed_form(far.conicity_high), 1e-9, "change far below: its low end");
  HM_CHECK_DELTA(s.hopf_high_kmh, hopf_closed_form(0.1646), 1e-9, "change far below: its high end");
  destroy(a);
  /* the same window too uncertain to count alone (0.02 > conicity_max_se): left to the prior until a second window
   * (far below the Hopf speed an uncertain window's conicity leans on the model) */
  far.conicity_se = 0.02;
  a = make_prior(0.0, 0.0);
  HM_CHECK(update(a, &e, &far, 0.0, &s) == HM_OK && !s.model_interval_used && s.conicity_from_prior,
           "an uncertain change window far below: used %d", s.model_interval_used);
  destroy(a);
  e = estimate(400.0, 0.0);
  /* an ambiguous narrow peak 30 s ago: WATCH; 70 s ago: not */
  hm_margin_estimate amb = g;
  amb.ambiguous_at_s = 100.0;
  a = make_prior(0.0, 0.0);
  HM_CHECK(update(a, &e, &amb, 130.0, &s) == HM_OK && s.level == HM_LEVEL_WATCH &&
               s.reason == HM_REASON_NARROW_PEAK,
           "narrow peak: %s (%s)", hm_level_name(s.level), hm_reason_text(s.reason));
  destroy(a);
  a = make_prior(0.0, 0.0);
  HM_CHECK(update(a, &e, &amb, 170.0, &s) == HM_OK && s.level == HM_LEVEL_OK, "70 s later: %s",
           hm_level_name(s.level));
  /* the WARN rule's risk */
  HM_CHECK(update(a, &e, &g, 171.0, &s) == HM_OK && s.conicity_from_estimate, "identified");
  const double se = (g.hopf_model_kmh - g.hopf_model_low_kmh) / 2.0;
  HM_CHECK_DELTA(s.warn_risk, 0.5 * erfc(fmax(10.0, warn_k() * se) / se / sqrt(2.0)), 1e-12, "risk, 0.16 +- 0.003");
  hm_margin_estimate wide = g;
  wide.conicity_se = 0.009, wide.conicity_low = 0.142, wide.conicity_high = 0.178;
  wide.hopf_model_low_kmh = hopf_closed_form(0.178), wide.hopf_model_high_kmh = hopf_closed_form(0.142);
  HM_CHECK(update(a, &e, &wide, 172.0, &s) == HM_OK && s.conicity_from_estimate, "identified, wide");
  const double se_wide = (g.hopf_model_kmh - wide.hopf_model_low_kmh) / 2.0;
  HM_CHECK(se_wide > 10.0, "one standard error above the margin");
  HM_CHECK_DELTA(s.warn_risk, 0.5 * erfc(fmax(10.0, warn_k() * se_wide) / se_wide / sqrt(2.0)), 1e-12,
                 "risk at the default k standard errors (k 1: Phi(-1) = 0.1587)");
  destroy(a);
  /* warn_standard_errors k: WARN from the point less max(10, k se); the risk Phi(-max(10, k se) / se); k = 0.5 on the
   * wide estimate (se 13.2 km/h: 10 km/h below the point, the margin), k = 2 (26.4: the 20 km/h cap) */
  const double se_w = (wide.hopf_model_kmh - wide.hopf_model_low_kmh) / 2.0;
  const double ks[] = {0.5, 2.0};
  for (size_t i = 0; i < 2; ++i) {
    hm_alarm_config c;
    hm_alarm_config_default(&c);
    c.conicity_prior_low = 0.1358 - 1e-5, c.conicity_prior_high = 0.1358 + 1e-5;
    c.warn_standard_errors = ks[i];
    char why[160];
    HM_CHECK(create(&c, &a, why, sizeof why) == HM_OK, "create: %s", why);
    HM_CHECK(update(a, &e, &wide, 172.0, &s) == HM_OK && s.conicity_from_estimate, "k %g: identified", ks[i]);
    const double below = fmax(10.0, fmin(ks[i] * se_w, 20.0));
    HM_CHECK(fabs(s.warn_from_kmh - (wide.hopf_model_kmh - below)) < 1e-9, "k %g: WARN from %.3f", ks[i], s.warn_from_kmh);
    HM_CHECK(fabs(s.warn_risk - 0.5 * erfc(below / se_w / sqrt(2.0))) < 1e-12, "k %g: risk %g", ks[i], s.warn_risk);
    destroy(a);
  }
  HM_CHECK(fabs(se_w - 13.2) < 0.5 && ks[0] * se_w < 10.0 && ks[1] * se_w > 20.0, "the cases as described: se %.2f",
           se_w);
}

/* A restore keeps the estimate's hysteresis (state.h, hm_alarm_snapshot): restored while the estimate of 0.16 is in
 * use alone with a standard error of 0.011 (inside 1.25 times conicity_max_se, 0.010, which only its hysteresis
 * admits), the restored alarm assesses as the one never restarted for 30 s, the interval its closed-form critical
 * speeds at 0.16 -+ 0.006 (the review's case: a restore had refused it and shown the prior's higher interval); restored
 * while a dropped estimate waits out HM_ALARM_FLAG_CLEAR_S before it is used alone again, it waits too (the restore had
 * skipped the wait). */
static void a_restore_keeps_the_hysteresis(void) {
  hm_margin_estimate g = identified();
  const hm_estimate e = estimate(400.0, 0.0);
  hm_assessment s, t;
  snapshot snap;
  char why[200] = "";
  hm_alarm a = make(), b = make();
  g.conicity_se = 0.009;
  update(a, &e, &g, 0.0, &s);
  g.conicity_se = 0.011;
  update(a, &e, &g, 1.0, &s);
  take_snapshot(a, 1.0, &snap);
  HM_CHECK(restore(b, 1.0, &snap, why, sizeof why) == HM_OK, "restore: %s", why);
  int same = 1;
  for (int k = 2; k <= 30; ++k) {
    update(a, &e, &g, k, &s);
    update(b, &e, &g, k, &t);
    same = same && s.conicity_from_estimate == t.conicity_from_estimate && s.hopf_low_kmh == t.hopf_low_kmh &&
           s.hopf_high_kmh == t.hopf_high_kmh && s.warn_from_kmh == t.warn_from_kmh;
  }
  printf("  se 0.011, restored: alone %d (never restarted %d), [%.1f, %.1f] km/h\n", t.conicity_from_estimate,
         s.conicity_from_estimate, t.hopf_low_kmh, t.hopf_high_kmh);
  HM_CHECK(s.conicity_from_estimate && same, "the restored alarm as the one never restarted");
  HM_CHECK_DELTA(t.hopf_low_kmh, hopf_closed_form(0.166), 1e-6, "interval's lower end");
  HM_CHECK_DELTA(t.hopf_high_kmh, hopf_closed_form(0.154), 1e-6, "interval's upper end");
  destroy(a), destroy(b);
  /* dropped (outside the prior for one update), in again, waiting: restored at 2 s, neither uses it alone at 3 s */
  hm_alarm c = make(), d = make();
  g = identified();
  update(c, &e, &g, 0.0, &s);
  g.outside_prior = -1;
  update(c, &e, &g, 1.0, &s);
  g.outside_prior = 0;
  update(c, &e, &g, 2.0, &s);
  take_snapshot(c, 2.0, &snap);
  HM_CHECK(restore(d, 2.0, &snap, why, sizeof why) == HM_OK, "restore: %s", why);
  update(c, &e, &g, 3.0, &s);
  update(d, &e, &g, 3.0, &t);
  HM_CHECK(!s.conicity_from_estimate && !t.conicity_from_estimate, "waiting: never restarted %d, restored %d",
           s.conicity_from_estimate, t.conicity_from_estimate);
  destroy(c), destroy(d);
}

int main(void) {
  hm_vehicle_default(&vehicle);
  if (hm_test_small_table(&table) != HM_OK) {
    printf("FAIL table_build\n");
    return 1;
  }
  HM_RUN(levels_follow_the_boundaries);
  HM_RUN(levels_with_a_conicity_estimate);
  HM_RUN(prior_before_identification);
  HM_RUN(stale_input_is_no_data);
  HM_RUN(hysteresis_and_hold_prevent_chatter);
  HM_RUN(oscillation_alarm_latches);
  HM_RUN(a_hold_says_what_it_is);
  HM_RUN(bad_configuration_and_input);
  HM_RUN(anticipates_a_sustained_acceleration);
  HM_RUN(anticipation_is_not_defeated_by_notches);
  HM_RUN(what_the_model_may_not_explain);
  HM_RUN(provisional_windows_do_not_chatter);
  HM_RUN(conicity_outside_the_table);
  HM_RUN(a_restore_keeps_the_hysteresis);
  hm_table_destroy(table);
  HM_TEST_EXIT();
}
