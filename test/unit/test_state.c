/* State that survives a restart (state.h): a monitor restored from the record of another, fed the same data, assesses
 * as the one that was never restarted; a held ALARM and a hunted-at speed come back; every damaged, foreign, future
 * or stale record is refused with its reason and leaves the monitor as it was; the file is replaced atomically with
 * the previous one kept. */
#define _POSIX_C_SOURCE 200809L /* mkdtemp */
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "hm_alloc_count.h"
#include "hm_fixtures.h"
#include "hm_test.h"
#include "hunting_monitor/linear.h"
#include "hunting_monitor/monitor.h"
#include "hunting_monitor/sensor_sim.h"
#include "hunting_monitor/state.h"


static char *table_text; /* the small table, formatted once: each monitor takes over a parsed copy */
static size_t table_len;
static hm_vehicle vehicle;
#define WALL0 1.7e9 /* the wall clock at the first record [s since the epoch] */

/* A record of a monitor that identified the mode (restart_continues_the_assessment), for the refusals. */
static unsigned char good[HM_STATE_MAX_BYTES];
static size_t good_len;

static hm_monitor make_monitor(const hm_monitor_config *cfg, const hm_vehicle *veh) {
  hm_monitor_config d;
  hm_monitor_config_default(&d);
  hm_table t = NULL;
  hm_monitor m = NULL;
  char why[256] = "";
  HM_CHECK(hm_table_parse(table_text, table_len, &t, why, sizeof why) == HM_OK, "table: %s", why);
  HM_CHECK(hm_monitor_create(cfg ? cfg : &d, veh ? veh : &vehicle, t, &m, why, sizeof why) == HM_OK, "monitor: %s",
           why);
  return m;
}

/* Monitors fed the same simulated samples, each on its own time line (t + shift), read at 20 Hz. */
typedef struct {
  hm_monitor mon[3];
  double shift[3];
  int n, fed_from;        /* monitors fed; monitors before fed_from get nothing */
  double next_read;
  hm_monitor_status last[3];
  int first_valid_seen[3];
  hm_monitor_status first_valid[3]; /* the first status with data after feeding began */
} feed;

static int on_accel(void *ctx, double t, double measured, double true_accel, const double *x) {
  feed *f = (feed *)ctx;
  (void)true_accel, (void)x;
  for (int i = f->fed_from; i < f->n; ++i) hm_monitor_push_accel(f->mon[i], t + f->shift[i], measured);
  if (t < f->next_read) return 0;
  f->next_read += 0.05;
  for (int i = f->fed_from; i < f->n; ++i) {
    HM_CHECK(hm_monitor_update(f->mon[i], t + f->shift[i], &f->last[i]) == HM_OK, "update %d at %g s", i, t);
    if (!f->first_valid_seen[i] && f->last[i].assessment.boundaries_valid)
      f->first_valid_seen[i] = 1, f->first_valid[i] = f->last[i];
  }
  return 0;
}

static int on_speed(void *ctx, double t, double v_kmh) {
  feed *f = (feed *)ctx;
  for (int i = f->fed_from; i < f->n; ++i) hm_monitor_push_speed(f->mon[i], t + f->shift[i], v_kmh);
  return 0;
}

static void checksum_is_crc32(void) {
  /* the CRC-32 check value of the IEEE 802.3 polynomial (zlib's crc32) */
  HM_CHECK(hm_state_checksum((const unsigned char *)"123456789", 9) == 0xCBF43926u, "crc32(123456789) = %08x",
           hm_state_checksum((const unsigned char *)"123456789", 9));
  HM_CHECK(hm_state_checksum(NULL, 0) == 0u, "crc32 of nothing");
  hm_state_config c;
  hm_state_config_default(&c);
  char why[128] = "";
  HM_CHECK(c.period_s == 2.0 && hm_state_config_validate(&c, why, sizeof why) == HM_OK, "default period");
  c.period_s = 0.0;
  HM_CHECK(hm_state_config_validate(&c, why, sizeof why) == HM_EDOMAIN && strstr(why, "state.period_s"), "%s", why);
}

/* 480 km/h, 35 km/h below the Hopf speed (517.6 km/h), 10% of the low-disturbance track: monitor A runs 45 s (its
 * first full window, 40 s, committed at 40 s) and writes its record; monitor B, new, on a time line 955 s later, is
 * restored from it; both, and a third that starts without it, are fed the next 6 s. B's assessment is A's to 1e-9
 * (level, interval, thresholds; the same windows, so the same conicity estimate), from its first status with data on;
 * the third shows the prior. */
static void restart_continues_the_assessment(void) {
  feed f;
  memset(&f, 0, sizeof f);
  f.mon[0] = make_monitor(NULL, NULL);
  f.n = 1;
  hm_sensor_sim_config sc;
  hm_sensor_sim_config_default(&sc);
  sc.v_start_kmh = sc.v_end_kmh = 480.0;
  sc.irregularity_scale = 0.1;
  sc.track_seed = sc.noise_seed = 7;
  sc.speed_rate_hz = 50.0;
  hm_sensor_sim sim = NULL;
  char why[256] = "";
  HM_CHECK(hm_sensor_sim_create(&vehicle, &sc, NULL, &sim, why, sizeof why) == HM_OK, "simulation: %s", why);
  const hm_sensor_sink sink = {on_accel, on_speed, &f};
  HM_CHECK(hm_sensor_sim_run(sim, 45.0, &sink) == HM_OK, "simulate to 45 s");
  const hm_assessment *a = &f.last[0].assessment;
  printf("  A at 45 s: %s, Hopf %.2f [%.2f, %.2f], %u window(s), conicity %.4f +- %.4f, from estimate %d\n",
         hm_level_name(a->level), a->boundaries.hopf_speed_kmh, a->hopf_low_kmh, a->hopf_high_kmh,
         f.last[0].margin.n_windows, f.last[0].margin.conicity, f.last[0].margin.conicity_se,
         a->conicity_from_estimate);
  HM_CHECK(a->conicity_from_estimate && f.last[0].margin.n_windows == 1, "A did not identify the conicity");
  const double t_save = hm_sensor_sim_time(sim);
  n_allocations = 0;
  HM_CHECK(hm_state_save(f.mon[0], t_save, WALL0, good, sizeof good, &good_len) == HM_OK, "save");
  HM_CHECK(n_allocations == 0, "save allocated %ld times", n_allocations);
  HM_CHECK(good_len == 136 + 72, "record of %zu bytes for one window", good_len);
  /* B: restored on its own time line at the moment of writing (age 0 on the wall clock) */
  f.mon[1] = make_monitor(NULL, NULL);
  f.shift[1] = 955.0;
  hm_state_outcome o;
  n_allocations = 0;
  HM_CHECK(hm_state_restore(f.mon[1], good, good_len, t_save + f.shift[1], WALL0, HM_STATE_CLOCK_WALL, &o) == HM_OK,
           "restore: %s", o.text);
  HM_CHECK(n_allocations == 0, "restore allocated %ld times", n_allocations);
  HM_CHECK(o.verdict == HM_STATE_RESTORED && o.n_windows == 1 && strcmp(o.text, "restored, age 0 s, 1 window") == 0,
           "outcome '%s'", o.text);
  f.mon[2] = make_monitor(NULL, NULL);
  f.shift[2] = -45.0;
  f.n = 3;
  HM_CHECK(hm_sensor_sim_run(sim, 51.0, &sink) == HM_OK, "simulate to 51 s");
  const hm_assessment *ra = &f.last[0].assessment, *rb = &f.last[1].assessment, *rc = &f.last[2].assessment;
  printf("  at 51 s: A %s [%.3f, %.3f], B (restored) %s [%.3f, %.3f], first with data at %+.2f s [%.3f, %.3f]; "
         "C (fresh) %s [%.2f, %.2f]\n",
         hm_level_name(ra->level), ra->hopf_low_kmh, ra->hopf_high_kmh, hm_level_name(rb->level), rb->hopf_low_kmh,
         rb->hopf_high_kmh, f.first_valid[1].estimate.time_s - f.shift[1] - t_save,
         f.first_valid[1].assessment.hopf_low_kmh, f.first_valid[1].assessment.hopf_high_kmh,
         hm_level_name(rc->level), rc->hopf_low_kmh, rc->hopf_high_kmh);
  HM_CHECK(ra->level == rb->level && ra->reason == rb->reason, "level %s/%s", hm_level_name(ra->level),
           hm_level_name(rb->level));
  HM_CHECK(rb->conicity_from_estimate, "B's interval is not the identified one");
  const double ref[] = {ra->hopf_low_kmh, ra->hopf_high_kmh, ra->boundaries.hopf_speed_kmh, ra->warn_from_kmh,
                        ra->watch_from_kmh, ra->conicity, f.last[0].margin.conicity_se};
  const double got[] = {rb->hopf_low_kmh, rb->hopf_high_kmh, rb->boundaries.hopf_speed_kmh, rb->warn_from_kmh,
                        rb->watch_from_kmh, rb->conicity, f.last[1].margin.conicity_se};
  const char *what[] = {"hopf_low", "hopf_high", "hopf", "warn_from", "watch_from", "conicity", "conicity_se"};
  for (size_t k = 0; k < sizeof ref / sizeof ref[0]; ++k) HM_CHECK_DELTA(got[k], ref[k], 1e-9 * fabs(ref[k]), what[k]);
  /* within one status: B's first status with data has the interval already */
  HM_CHECK(f.first_valid_seen[1] && f.first_valid[1].assessment.conicity_from_estimate, "B's first status");
  HM_CHECK_DELTA(f.first_valid[1].assessment.hopf_low_kmh, ra->hopf_low_kmh, 1e-9 * ra->hopf_low_kmh, "first low");
  /* the control: without the record, the prior (a wider interval) */
  const double width_a = ra->hopf_high_kmh - ra->hopf_low_kmh, width_c = rc->hopf_high_kmh - rc->hopf_low_kmh;
  HM_CHECK(rc->conicity_from_prior && width_c > width_a + 10.0,
           "C: [%g, %g] from the prior %d", rc->hopf_low_kmh, rc->hopf_high_kmh, rc->conicity_from_prior);
  for (int i = 0; i < 3; ++i) hm_monitor_destroy(f.mon[i]);
  hm_sensor_sim_destroy(sim);
}

/* Data for hm_monitor_push_*: a 14 Hz lateral acceleration of amp_mps2 at v_kmh over [t0, t1) at 2 kHz. */
static void push_tone(hm_monitor m, double t0, double t1, double amp_mps2, double v_kmh) {
  for (double t = t0; t < t1; t += 1.0 / 2000.0) {
    if (fmod(t - t0, 0.02) < 0.5 / 2000.0) hm_monitor_push_speed(m, t, v_kmh);
    hm_monitor_push_accel(m, t, amp_mps2 * sin(2.0 * HM_PI * 14.0 * t));
  }
}

/* An ALARM from the oscillation at 440 km/h (a 14 Hz tone of 30 m/s^2: 3.9 mm, beyond the displacement criterion's
 * 2.1 mm), then 3 s calm (held: 10 s are needed). The record restores the latch with its cause, at once and without
 * any data (the first status is ALARM held, not NO_DATA), and the hunted-at speed, which bounds the interval's lower
 * end as in the monitor that wrote it. */
static void held_alarm_and_hunted_speed_restored(void) {
  hm_monitor a = make_monitor(NULL, NULL), b = make_monitor(NULL, NULL);
  hm_monitor_status sa, sb;
  push_tone(a, 0.0, 4.0, 30.0, 440.0);
  HM_CHECK(hm_monitor_update(a, 4.0, &sa) == HM_OK && sa.assessment.level == HM_LEVEL_ALARM && sa.assessment.latched,
           "A: %s latched %d", hm_level_name(sa.assessment.level), sa.assessment.latched);
  const hm_reason cause = sa.assessment.reason;
  push_tone(a, 4.0, 7.0, 0.2, 440.0);
  HM_CHECK(hm_monitor_update(a, 7.0, &sa) == HM_OK && sa.assessment.latched, "A held after 3 s calm");
  unsigned char rec[HM_STATE_MAX_BYTES];
  size_t n = 0;
  HM_CHECK(hm_state_save(a, 7.0, WALL0, rec, sizeof rec, &n) == HM_OK, "save");
  hm_state_outcome o;
  HM_CHECK(hm_state_restore(b, rec, n, 100.0, WALL0 + 60.0, HM_STATE_CLOCK_WALL, &o) == HM_OK && o.latched, "%s",
           o.text);
  printf("  %s\n", o.text);
  HM_CHECK(strstr(o.text, "restored, age 60 s, 0 windows; ALARM held: ") && strstr(o.text, "hunted at 440.0 km/h"),
           "outcome '%s'", o.text);
  HM_CHECK(hm_monitor_update(b, 100.0, &sb) == HM_OK, "update without data");
  HM_CHECK(sb.assessment.level == HM_LEVEL_ALARM && sb.assessment.latched && sb.assessment.reason == cause &&
               !sb.assessment.boundaries_valid,
           "B without data: %s latched %d reason %d (A's %d)", hm_level_name(sb.assessment.level),
           sb.assessment.latched, sb.assessment.reason, cause);
  push_tone(a, 7.0, 10.0, 0.2, 440.0);
  push_tone(b, 100.0, 103.0, 0.2, 440.0);
  HM_CHECK(hm_monitor_update(a, 10.0, &sa) == HM_OK && hm_monitor_update(b, 103.0, &sb) == HM_OK, "updates");
  printf("  A: %s, hunted at %.1f, Hopf low %.1f (from hunting %d); B: %s, hunted at %.1f, Hopf low %.1f (%d)\n",
         hm_level_name(sa.assessment.level), sa.assessment.hunted_at_kmh, sa.assessment.hopf_low_kmh,
         sa.assessment.hopf_low_from_hunting, hm_level_name(sb.assessment.level), sb.assessment.hunted_at_kmh,
         sb.assessment.hopf_low_kmh, sb.assessment.hopf_low_from_hunting);
  HM_CHECK(sb.assessment.latched && sb.assessment.level == HM_LEVEL_ALARM, "B released too early");
  HM_CHECK(sb.assessment.hopf_low_from_hunting && sb.assessment.hopf_low_kmh == sa.assessment.hopf_low_kmh &&
               sb.assessment.hunted_at_kmh == 440.0 && sa.assessment.hunted_at_kmh == 440.0,
           "hunted-at bound: B %g, A %g", sb.assessment.hopf_low_kmh, sa.assessment.hopf_low_kmh);
  hm_monitor_destroy(a);
  hm_monitor_destroy(b);
}

/* m's record at a fixed now: equal before and after a refused restore when the refusal left m untouched. */
static size_t fingerprint(hm_monitor m, unsigned char *out) {
  size_t n = 0;
  HM_CHECK(hm_state_save(m, 5000.0, WALL0 + 10.0, out, HM_STATE_MAX_BYTES, &n) == HM_OK, "fingerprint");
  return n;
}

/* A refused restore: status st, verdict v, words in its reason, and m as it was. */
static void expect_refused(hm_monitor m, const unsigned char *rec, size_t n, double now_s, double now_unix_s,
                           hm_state_clock clock, hm_status st, hm_state_verdict v, const char *words,
                           const char *what) {
  unsigned char before[HM_STATE_MAX_BYTES], after[HM_STATE_MAX_BYTES];
  const size_t nb = fingerprint(m, before);
  hm_state_outcome o;
  const hm_status got = hm_state_restore(m, rec, n, now_s, now_unix_s, clock, &o);
  printf("  %-22s %s\n", what, o.text);
  HM_CHECK(got == st && o.verdict == v, "%s: status %d verdict %d, expected %d %d", what, got, o.verdict, st, v);
  HM_CHECK(strncmp(o.text, "not restored: ", 14) == 0 && strstr(o.text, words), "%s: '%s' lacks '%s'", what, o.text,
           words);
  const size_t na = fingerprint(m, after);
  HM_CHECK(na == nb && memcmp(before, after, na) == 0, "%s: the monitor changed", what);
}

/* The record with a new CRC-32 over it (the reference implementation checked against the check value above). */
static void reseal(unsigned char *rec, size_t n) {
  const uint32_t c = hm_state_checksum(rec, n - 4);
  for (int k = 0; k < 4; ++k) rec[n - 4 + k] = (unsigned char)(c >> (8 * k));
}

static void put_f64_at(unsigned char *rec, size_t at, double x) {
  uint64_t u;
  memcpy(&u, &x, sizeof u);
  for (int k = 0; k < 8; ++k) rec[at + k] = (unsigned char)(u >> (8 * k));
}

/* Every damaged, foreign, future-versioned or stale record is refused with its reason, the monitor untouched (it
 * holds a restored window and must keep it); ages count on the clock named: the window, 5 s old at writing, is kept
 * up to a record 895 s old and forgotten beyond (memory_s 900). */
static void refusals_leave_the_monitor_untouched(void) {
  HM_CHECK(good_len > 0, "no record (restart_continues_the_assessment)");
  if (good_len == 0) return;
  hm_monitor d = make_monitor(NULL, NULL);
  hm_state_outcome o;
  HM_CHECK(hm_state_restore(d, good, good_len, 5000.0, WALL0 + 1.0, HM_STATE_CLOCK_WALL, &o) == HM_OK, "%s", o.text);
  unsigned char bad[HM_STATE_MAX_BYTES + 8];
  const double now = 5000.0, wall = WALL0 + 10.0;
  memcpy(bad, good, good_len);
  bad[60] ^= 0x10; /* a bit of the window's speed */
  expect_refused(d, bad, good_len, now, wall, HM_STATE_CLOCK_WALL, HM_EPARSE, HM_STATE_CORRUPT, "checksum",
                 "corrupt byte");
  expect_refused(d, good, good_len - 1, now, wall, HM_STATE_CLOCK_WALL, HM_EPARSE, HM_STATE_TRUNCATED,
                 "truncated: 207 of 208 bytes", "truncated by one");
  expect_refused(d, good, 10, now, wall, HM_STATE_CLOCK_WALL, HM_EPARSE, HM_STATE_TRUNCATED, "truncated: 10 bytes",
                 "truncated to 10");
  expect_refused(d, good, 0, now, wall, HM_STATE_CLOCK_WALL, HM_EPARSE, HM_STATE_TRUNCATED, "truncated", "empty");
  memcpy(bad, good, good_len);
  bad[good_len] = 0;
  expect_refused(d, bad, good_len + 1, now, wall, HM_STATE_CLOCK_WALL, HM_EPARSE, HM_STATE_CORRUPT, "declares 208",
                 "a byte beyond");
  expect_refused(d, (const unsigned char *)"hunting_monitor_boundary_table 1\n", 33, now, wall, HM_STATE_CLOCK_WALL,
                 HM_EPARSE, HM_STATE_NOT_A_STATE, "no HMSTATE magic", "another file");
  memcpy(bad, good, good_len);
  bad[8] = 2; /* version 2, sealed again: whole, but newer */
  reseal(bad, good_len);
  expect_refused(d, bad, good_len, now, wall, HM_STATE_CLOCK_WALL, HM_EPARSE, HM_STATE_VERSION_UNKNOWN,
                 "format version 2 is newer", "future version");
  memcpy(bad, good, good_len);
  put_f64_at(bad, 44 + 8, -5.0); /* the window's speed, sealed again: intact but impossible */
  reseal(bad, good_len);
  expect_refused(d, bad, good_len, now, wall, HM_STATE_CLOCK_WALL, HM_EPARSE, HM_STATE_BAD_CONTENT,
                 "window 0 speed_kmh", "impossible speed");
  expect_refused(d, good, good_len, now, WALL0 + 900.0, HM_STATE_CLOCK_WALL, HM_EDOMAIN, HM_STATE_TOO_OLD,
                 "too old: age 900 s on the wall clock", "too old");
  expect_refused(d, good, good_len, now, WALL0 - 10.0, HM_STATE_CLOCK_WALL, HM_EDOMAIN, HM_STATE_FROM_FUTURE,
                 "written 10 s after now", "from the future");
  /* on the time line: written at 45 s */
  expect_refused(d, good, good_len, 45.0 + 1000.0, NAN, HM_STATE_CLOCK_LINE, HM_EDOMAIN, HM_STATE_TOO_OLD,
                 "too old: age 1000 s on the time line", "too old (line)");
  /* a foreign vehicle (worn wheels: lambda(0) 0.16), other settings (the margin's decay-rate error) */
  hm_vehicle worn = vehicle;
  HM_CHECK(hm_vehicle_set_conicity_at_zero(&worn, 0.16) == HM_OK, "worn vehicle");
  hm_monitor e = make_monitor(NULL, &worn);
  expect_refused(e, good, good_len, now, wall, HM_STATE_CLOCK_WALL, HM_EDOMAIN, HM_STATE_FOREIGN,
                 "another vehicle or other settings", "foreign vehicle");
  hm_monitor_config other;
  hm_monitor_config_default(&other);
  other.margin.decay_rate_model_error = 0.06;
  hm_monitor f = make_monitor(&other, NULL);
  expect_refused(f, good, good_len, now, wall, HM_STATE_CLOCK_WALL, HM_EDOMAIN, HM_STATE_FOREIGN,
                 "another vehicle or other settings", "other settings");
  /* the alarm's settings are not in the hash: they judge, and change at runtime */
  hm_monitor_config alarm_only;
  hm_monitor_config_default(&alarm_only);
  alarm_only.alarm.warn_speed_margin_kmh = 15.0;
  HM_CHECK(hm_state_hash(&alarm_only, &vehicle) != hm_state_hash(&other, &vehicle), "the margin's error not hashed");
  hm_monitor_config dflt;
  hm_monitor_config_default(&dflt);
  HM_CHECK(hm_state_hash(&alarm_only, &vehicle) == hm_state_hash(&dflt, &vehicle), "the alarm's margin in the hash");
  /* ages: the window was 5 s old at writing (45 s, its end at 40 s) */
  hm_monitor g = make_monitor(NULL, NULL);
  HM_CHECK(hm_state_restore(g, good, good_len, 0.0, WALL0 + 895.0, HM_STATE_CLOCK_WALL, &o) == HM_OK &&
               o.n_windows == 1,
           "895 s: %s", o.text);
  HM_CHECK(hm_state_restore(g, good, good_len, 0.0, WALL0 + 896.0, HM_STATE_CLOCK_WALL, &o) == HM_OK &&
               o.n_windows == 0 && strcmp(o.text, "restored, age 896 s, 0 windows") == 0,
           "896 s: %s", o.text);
  HM_CHECK(hm_state_restore(g, good, good_len, 45.0 + 15.0, NAN, HM_STATE_CLOCK_LINE, &o) == HM_OK &&
               strcmp(o.text, "restored, age 15 s, 1 window") == 0,
           "line: %s", o.text);
  hm_monitor_destroy(d);
  hm_monitor_destroy(e);
  hm_monitor_destroy(f);
  hm_monitor_destroy(g);
}

static void write_bytes(const char *path, const unsigned char *b, size_t n) {
  FILE *f = fopen(path, "wb");
  HM_CHECK(f && fwrite(b, 1, n, f) == n && fclose(f) == 0, "write %s", path);
}

/* The file: replaced atomically, the previous one kept as FILE.prev; a truncated FILE is refused and FILE.prev
 * restored; neither: the reasons of both; none: "no state file". */
static void the_file_and_its_previous_one(void) {
  char dir[] = "/tmp/hm_test_state_XXXXXX";
  HM_CHECK(mkdtemp(dir) != NULL, "mkdtemp");
  char path[128], prev[140], tmp[140];
  snprintf(path, sizeof path, "%s/state", dir);
  snprintf(prev, sizeof prev, "%s.prev", path);
  snprintf(tmp, sizeof tmp, "%s.tmp", path);
  hm_monitor a = make_monitor(NULL, NULL), b = make_monitor(NULL, NULL);
  hm_state_outcome o;
  HM_CHECK(hm_state_restore_file(b, path, 10.0, WALL0, HM_STATE_CLOCK_WALL, &o) == HM_EIO &&
               o.verdict == HM_STATE_NO_FILE && strstr(o.text, "not restored: no state file ("),
           "no file: %s", o.text);
  HM_CHECK(hm_state_restore(a, good, good_len, 45.0, WALL0, HM_STATE_CLOCK_WALL, &o) == HM_OK, "%s", o.text);
  char why[512] = "";
  HM_CHECK(hm_state_save_file(a, path, 45.0, WALL0, why, sizeof why) == HM_OK, "save: %s", why);
  HM_CHECK(hm_state_save_file(a, path, 46.0, WALL0 + 1.0, why, sizeof why) == HM_OK, "save again: %s", why);
  struct stat st;
  HM_CHECK(stat(path, &st) == 0 && stat(prev, &st) == 0 && stat(tmp, &st) != 0, "state, state.prev, no state.tmp");
  HM_CHECK(hm_state_restore_file(b, path, 100.0, WALL0 + 3.0, HM_STATE_CLOCK_WALL, &o) == HM_OK &&
               strcmp(o.text, "restored, age 2 s, 1 window") == 0,
           "%s", o.text);
  write_bytes(path, good, good_len / 2);
  HM_CHECK(hm_state_restore_file(b, path, 100.0, WALL0 + 3.0, HM_STATE_CLOCK_WALL, &o) == HM_OK &&
               strstr(o.text, "restored from ") && strstr(o.text, "state.prev, age 3 s, 1 window (") &&
               strstr(o.text, "/state: truncated: 104 of 208 bytes)") && o.from_prev,
           "from prev: %s", o.text);
  printf("  %s\n", o.text);
  write_bytes(prev, (const unsigned char *)"x", 1);
  HM_CHECK(hm_state_restore_file(b, path, 100.0, WALL0 + 3.0, HM_STATE_CLOCK_WALL, &o) == HM_EPARSE &&
               o.verdict == HM_STATE_TRUNCATED && strstr(o.text, "/state: truncated") &&
               strstr(o.text, "state.prev: not a hunting_monitor state"),
           "neither: %s", o.text);
  printf("  %s\n", o.text);
  char nowhere[160];
  snprintf(nowhere, sizeof nowhere, "%s/no/such/dir/state", dir);
  HM_CHECK(hm_state_save_file(a, nowhere, 45.0, WALL0, why, sizeof why) == HM_EIO && strstr(why, "cannot create"),
           "no directory: %s", why);
  unlink(path);
  unlink(prev);
  rmdir(dir);
  hm_monitor_destroy(a);
  hm_monitor_destroy(b);
}

/* test_state --write-seed FILE also writes the record of restart_continues_the_assessment to FILE (the fuzz seed,
 * test/fuzz/seed_state.bin). */
/* A bogie's or car's state is theirs alone (review of issue #28): a bogie monitor's record is refused by a wheelset
 * monitor with the same wheelsets, by a bogie with other yaw dampers, by the same bogie read at its frame (the same
 * settings otherwise: its windows are another sensor's reading), and restored by its own kind. */
static void a_models_state_is_its_own(void) {
  hm_car p;
  hm_car_default(&p);
  hm_table_spec spec;
  hm_table_spec_default(&spec);
  spec.n_conicity = 2, spec.conicity_min = 0.13, spec.conicity_max = 0.14, spec.speed_min_kmh = 400.0;
  spec.amp_max_m = 0.004;
  hm_monitor_config cfg;
  hm_monitor_config_default(&cfg);
  hm_monitor bogie[3] = {NULL, NULL, NULL}, wheelset = NULL;
  char why[256] = "";
  for (int k = 0; k < 3; ++k) {
    hm_car q = p;
    hm_monitor_config c = cfg;
    if (k == 1) q.bogie.yaw_damper_stiffness_n_m *= 0.8;
    if (k == 2) c.estimator.measurement_point = HM_POINT_BOGIE_FRAME;
    hm_table t = NULL;
    HM_CHECK(hm_table_build_model(HM_MODEL_BOGIE, &q, &spec, NULL, NULL, &t) == HM_OK, "bogie table");
    HM_CHECK(hm_monitor_create_model(&c, HM_MODEL_BOGIE, &q, t, NULL, NULL, &bogie[k], why, sizeof why) == HM_OK,
             "bogie monitor: %s", why);
  }
  wheelset = make_monitor(NULL, &p.bogie.wheelset);
  if (!bogie[0] || !bogie[1] || !bogie[2] || !wheelset) goto done;
  unsigned char rec[HM_STATE_MAX_BYTES];
  size_t n = 0;
  HM_CHECK(hm_state_save(bogie[0], 10.0, WALL0, rec, sizeof rec, &n) == HM_OK, "save");
  expect_refused(wheelset, rec, n, 11.0, WALL0 + 1.0, HM_STATE_CLOCK_WALL, HM_EDOMAIN, HM_STATE_FOREIGN,
                 "another vehicle or other settings", "a bogie's, to a wheelset");
  expect_refused(bogie[1], rec, n, 11.0, WALL0 + 1.0, HM_STATE_CLOCK_WALL, HM_EDOMAIN, HM_STATE_FOREIGN,
                 "another vehicle or other settings", "other yaw dampers");
  expect_refused(bogie[2], rec, n, 11.0, WALL0 + 1.0, HM_STATE_CLOCK_WALL, HM_EDOMAIN, HM_STATE_FOREIGN,
                 "another vehicle or other settings", "read at the frame");
  hm_state_outcome o;
  HM_CHECK(hm_state_restore(bogie[0], rec, n, 11.0, WALL0 + 1.0, HM_STATE_CLOCK_WALL, &o) == HM_OK, "its own: %s",
           o.text);
done:
  hm_monitor_destroy(bogie[0]);
  hm_monitor_destroy(bogie[1]);
  hm_monitor_destroy(bogie[2]);
  hm_monitor_destroy(wheelset);
}

int main(int argc, char **argv) {
  hm_vehicle_default(&vehicle);
  if (hm_test_small_table_text(&table_text, &table_len) != HM_OK) {
    printf("FAIL table_build\n");
    return 1;
  }
  HM_RUN(checksum_is_crc32);
  HM_RUN(restart_continues_the_assessment);
  if (argc == 3 && strcmp(argv[1], "--write-seed") == 0) write_bytes(argv[2], good, good_len);
  HM_RUN(held_alarm_and_hunted_speed_restored);
  HM_RUN(refusals_leave_the_monitor_untouched);
  HM_RUN(the_file_and_its_previous_one);
  HM_RUN(a_models_state_is_its_own);
  free(table_text);
  HM_TEST_EXIT();
}
